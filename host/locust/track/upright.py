"""Whether tracked heights are upright: a hopping robot rests on the floor.

A marker on the robot stands still only while the robot stands on the floor (before,
between and after its hops); in flight it moves. Its still sightings therefore lie at the
bottom of its range of heights. Where they lie at the top instead, world y points down: the
video was filmed with the phone upside down (or its axes turned over with ``--angle``), and
every height is inverted. A marker that never stands still, or hardly moves up or down,
gives no verdict.
"""

from __future__ import annotations

import numpy as np

from .runner import TrackResult

STILL_SHARE = 0.02     # a step between frames under this share of the height range is standing still
MIN_STILL = 5          # still steps needed for a verdict
MIN_RISE_PX = 10.0     # least vertical travel in the picture (px) to judge by
TOP_SHARE = 0.5        # still sightings above this share of the height range: upside down


def upside_down_warnings(result: TrackResult) -> list[str]:
    """One line for each marker whose still sightings lie at the top of its heights."""
    lines = []
    for track in result.markers:
        _, y = result.world(track)
        ok = track.ok & np.isfinite(y) & np.isfinite(track.py)
        if ok.sum() < 2 * MIN_STILL or np.ptp(track.py[ok]) < MIN_RISE_PX:
            continue
        x, _ = result.world(track)
        low, high = np.percentile(y[ok], [1, 99])
        if not high > low:
            continue
        idx = np.flatnonzero(ok)
        next_frame = np.diff(idx) == 1
        step = np.hypot(np.diff(x[idx]), np.diff(y[idx]))
        still = idx[1:][next_frame & (step <= STILL_SHARE * (high - low))]
        if still.size < MIN_STILL:
            continue
        rest = float(np.median(y[still]))
        share = (rest - low) / (high - low)
        if share > TOP_SHARE:
            lines.append(f"{track.name} stands still at the top of its heights ({still.size} still frames at "
                         f"y = {rest:.4g} m, {share:.0%} of the way from {low:.4g} to {high:.4g} m): a robot rests "
                         "on the floor, at the bottom; the heights look upside down (a video filmed upside down?); "
                         "rotate the video, or give --angle 180 to turn the axes over")
    return lines
