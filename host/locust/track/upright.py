"""Whether tracked heights are upright: a hopping robot starts standing on the floor.

A hop starts from the floor: before its first push the robot stands on its feet, and every
marker on it stands still at its standing height. From there the robot can only rise (the
floor is below it): its hops, and a robot that goes over and comes to rest on its back, lie
above. So the still sightings before a marker's first move lie at the bottom of its range
of heights. Where they lie at the top instead, world y points down: the video was filmed
with the phone upside down (or its axes turned over with ``--angle``), and every height is
inverted. Where the robot rests later (on its back, high) says nothing about the floor and
is not used. The verdict is the video's, from the marker that moves up and down the most (a
sticker low on a leg dips as the leg pushes); a marker that moves from its first sighting,
or hardly moves up or down, gives none.
"""

from __future__ import annotations

import numpy as np

from .runner import TrackResult

STILL_SHARE = 0.02     # a step between frames under this share of the height range is standing still
MIN_STILL = 5          # still steps before the first move needed for a verdict
MIN_RISE_PX = 10.0     # least vertical travel in the picture (px) to judge by
TOP_SHARE = 0.5        # standing before the first move above this share of the height range: upside down


def standing_still(x: np.ndarray, y: np.ndarray, ok: np.ndarray, tolerance: float) -> np.ndarray:
    """Frames of the still stretch a track opens with: consecutive sightings that move under
    ``tolerance`` until the first that moves more (or a lost frame).

    Parameters
    ----------
    x, y : ndarray
        Positions per frame, in the track's unit.
    ok : ndarray of bool
        Found per frame.
    tolerance : float
        Largest step from the first sighting that is still standing, in the positions' unit.

    Returns
    -------
    ndarray
        Indices of the still frames after the first sighting.
    """
    idx = np.flatnonzero(ok)
    step = np.hypot(np.diff(x[idx]), np.diff(y[idx]))
    moves = (np.diff(idx) != 1) | (step > tolerance)
    first_move = int(np.argmax(moves)) if moves.any() else step.size
    return idx[1:first_move + 1]


def upside_down_warnings(result: TrackResult) -> list[str]:
    """One line when the video's heights look upside down, judged from the marker that moves
    up and down the most (in pixels) among those that stand still before their first move: a
    marker low on a leg may dip as the leg pushes, the robot's rise decides.

    Parameters
    ----------
    result : TrackResult
        The tracks, with their calibration.

    Returns
    -------
    list of str
        The warning, or empty.
    """
    best = None
    t = result.tracks
    for name in t.markers:
        x, y, py = t.x_m[name], t.y_m[name], t.py[name]
        ok = t.ok[name] & np.isfinite(y) & np.isfinite(py)
        if ok.sum() < 2 * MIN_STILL or np.ptp(py[ok]) < MIN_RISE_PX:
            continue
        low, high = np.percentile(y[ok], [1, 99])
        if not high > low:
            continue
        still = standing_still(x, y, ok, STILL_SHARE * (high - low))
        if still.size < MIN_STILL:
            continue
        rise_px = float(np.ptp(py[ok]))
        if best is None or rise_px > best[0]:
            best = (rise_px, name, still.size, float(np.median(y[still])), low, high)
    if best is None:
        return []
    _, name, n_still, rest, low, high = best
    share = (rest - low) / (high - low)
    if share <= TOP_SHARE:
        return []
    return [f"{name} stands still at the top of its heights ({n_still} still frames at y = {rest:.4g} m, "
            f"{share:.0%} of the way from {low:.4g} to {high:.4g} m) before its first move: a robot starts "
            "standing on the floor, at the bottom; the heights look upside down (a video filmed upside down?); "
            "rotate the video, or give --angle 180 to turn the axes over"]
