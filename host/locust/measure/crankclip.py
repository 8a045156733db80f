"""The crank's angle in a side clip of a push, from four stickers.

The stickers are those of ``locust measure stance`` (:data:`locust.markers.STICKER_COLOURS`,
placed as :mod:`locust.sim.stickers` says), of which four are read: ``axis`` (on the crank
over the servo horn's axis) and ``crank`` (on the crank near its tip) give the crank's
direction, ``nose`` and ``tail`` (on the plate's side) the plate's, so that the crank is
measured against the robot itself and a camera that is not level does not matter. Each is
found in every frame by its colour (:mod:`locust.track.color`, the frame loop of
:func:`locust.track.runner.track_video`).

The crank's angle from its ground link, in the four-bar frame of :mod:`locust.sim.fourbar`
(the model's): the crank's direction less the plate's, in the picture's plane (y up), less
the ground link's angle to the plate (``geometry.ground_angle_deg``); seen from the robot's
right (the picture mirrored: its nose to the right of its tail) the difference changes
sign. A square-on camera maps each plane parallel to the picture by a similarity, so the
angle between two directions each in one such plane is the picture's, whatever their depth.

Its standard deviation per frame: each sticker's centre scatters by ``sd_px`` (the same in
both directions), so the angle of a pair ``L`` pixels apart by ``sqrt(2) * sd_px / L``; the
two pairs add in quadrature. ``sd_px`` is read from the clip itself: the distance between
the two stickers of a pair is fixed, and its scatter over the frames is ``sqrt(2) * sd_px``
(the two pairs pooled; at least :data:`MIN_STICKER_SD_PX`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MeasureError, TrackError
from ..markers import STICKER_COLOURS
from ..track.pipeline import Bars, no_bars

POINTS = ("nose", "tail", "axis", "crank")
PAIRS = {"crank": ("axis", "crank"), "plate": ("nose", "tail")}
MIN_STICKER_SD_PX = 0.1      # the least scatter a sticker's centre is given (as measure stance's)
SIDES = {"left": "L", "right": "R"}
REST_FRAMES = 5              # the frames that say which side the clip shows


@dataclass(frozen=True)
class CrankSeries:
    """The crank's angle over a clip.

    Attributes
    ----------
    path : Path
        The clip.
    side : str
        ``L`` (seen from the robot's left) or ``R``.
    t_s : ndarray
        Each frame's time from the clip's first [s].
    angle_deg : ndarray
        The crank's angle from its ground link [deg]; nan where a sticker is not found.
    sd_deg : ndarray
        Its standard deviation per frame [deg].
    sticker_sd_px : float
        The scatter of a sticker's centre [px].
    pair_px : dict of str to float
        The median distance between each pair's stickers (``crank``, ``plate``) [px].
    found : dict of str to int
        Frames each sticker was found on.
    frames : int
        Frames read.
    fps : float
        The frame rate the times come from [1/s].
    """

    path: Path
    side: str
    t_s: np.ndarray
    angle_deg: np.ndarray
    sd_deg: np.ndarray
    sticker_sd_px: float
    pair_px: dict[str, float]
    found: dict[str, int]
    frames: int
    fps: float


def _direction_deg(px: dict[str, np.ndarray], py: dict[str, np.ndarray], pair: tuple[str, str]) -> np.ndarray:
    a, b = pair
    return np.degrees(np.arctan2(-(py[b] - py[a]), px[b] - px[a]))    # the picture's y runs down


def side_seen(px: dict[str, np.ndarray], ok: np.ndarray, path: Path) -> str:
    """Which side of the robot a clip shows: its left when the plate's nose is left of its
    tail in the first frames where both are found.

    Parameters
    ----------
    px : dict of str to ndarray
        Per sticker, its x per frame [px].
    ok : ndarray
        The frames where every sticker is found.
    path : Path
        The clip, for messages.

    Returns
    -------
    str
        ``L`` or ``R``.

    Raises
    ------
    MeasureError
        No frame with every sticker.
    """
    first = np.nonzero(ok)[0][:REST_FRAMES]
    if not len(first):
        raise MeasureError(f"{path.name}: no frame shows all four stickers ({', '.join(POINTS)}) at once",
                           "keep the plate's two dots and the crank's two in view (docs/hardware.md, "
                           "\"Measure the stroke\")")
    return "L" if float(np.median(px["tail"][first] - px["nose"][first])) > 0 else "R"


def crank_angle_deg(px: dict[str, np.ndarray], py: dict[str, np.ndarray], side: str,
                    ground_angle_deg: float) -> np.ndarray:
    """The crank's angle from its ground link from the four stickers' pixels (module doc).

    Parameters
    ----------
    px, py : dict of str to ndarray
        Per sticker of :data:`POINTS`, its pixel per frame (x right, y down) [px].
    side : str
        ``L`` or ``R``: the side the picture shows.
    ground_angle_deg : float
        The ground link's angle to the plate [deg].

    Returns
    -------
    ndarray
        Per frame [deg], unwrapped; nan where a sticker is missing.
    """
    turn = _direction_deg(px, py, PAIRS["crank"]) - _direction_deg(px, py, PAIRS["plate"])
    angle = (1.0 if side == "L" else -1.0) * turn - ground_angle_deg
    out = np.full(angle.shape, np.nan)
    ok = np.isfinite(angle)
    if ok.any():
        out[ok] = np.degrees(np.unwrap(np.radians(angle[ok])))
        out[ok] -= 360.0 * round(float(np.median(out[ok])) / 360.0)
    return out


def sticker_sd_px(px: dict[str, np.ndarray], py: dict[str, np.ndarray]) -> tuple[float, dict[str, float]]:
    """The scatter of a sticker's centre from the pairs' fixed distances, and their medians.

    Parameters
    ----------
    px, py : dict of str to ndarray
        Per sticker, its pixel per frame [px].

    Returns
    -------
    sd_px : float
        [px], at least :data:`MIN_STICKER_SD_PX`.
    pair_px : dict of str to float
        The median distance of each pair [px].
    """
    var, count, medians = 0.0, 0, {}
    for name, (a, b) in PAIRS.items():
        d = np.hypot(px[b] - px[a], py[b] - py[a])
        d = d[np.isfinite(d)]
        medians[name] = float(np.median(d)) if len(d) else math.nan
        if len(d) > 2:
            var += float(np.var(d, ddof=1)) / 2.0
            count += 1
    sd = math.sqrt(var / count) if count else 0.0
    return max(sd, MIN_STICKER_SD_PX), medians


def _track(path: Path, fps: float | None, bars):
    """Each sticker's pixels in every frame of ``path``, and the frames' times."""
    from ..track.calib import build
    from ..track.runner import track_video
    from ..track.spec import parse_markers
    from ..track.video import Clip, probe

    try:
        info = probe(path)
        clip = Clip(0, None, 1, fps).resolved(info)
        models = parse_markers([f"{n}=color:{STICKER_COLOURS[n][0]}" for n in POINTS])
        with bars(len(clip.frames()), f"reading {path.name}") as update:
            result = track_video(info, clip, models, build(info.height_px), progress=update, require_found=False)
    except TrackError as exc:
        raise MeasureError(f"{path.name}: {exc.message}", exc.hint) from None
    return result.tracks, clip.fps or info.fps


def read_crank_clip(path: str | Path, ground_angle_deg: float, side: str | None = None, fps: float | None = None,
                    bars: Bars = no_bars) -> CrankSeries:
    """The crank's angle over a side clip (module doc).

    Parameters
    ----------
    path : str or Path
        A video file or an image sequence.
    ground_angle_deg : float
        The ground link's angle to the plate [deg] (the robot's).
    side : str, optional
        ``L`` or ``R``: the side the clip must show (None: whichever it shows).
    fps : float, optional
        The true frame rate [1/s], for a slow-motion clip whose file says another.
    bars : callable
        Progress over the frames read (:data:`locust.track.pipeline.Bars`).

    Returns
    -------
    CrankSeries

    Raises
    ------
    MeasureError
        An unreadable clip, a sticker never found, or the other side of the robot than ``side``.
    """
    path = Path(path)
    tracks, rate = _track(path, fps, bars)
    lost = [n for n in POINTS if not tracks.ok[n].any()]
    if lost:
        raise MeasureError(
            f"{path.name}: the " + ", ".join(f"{n} sticker ({STICKER_COLOURS[n][0]}, {STICKER_COLOURS[n][1]})"
                                              for n in lost) + " not found in any frame",
            "stick the dots on the side filmed, 6 mm across, each of its colour (docs/measure.md); "
            "`locust track preview CLIP` lists the coloured patches of a frame")
    px = {n: np.where(tracks.ok[n], tracks.px[n], np.nan) for n in POINTS}
    py = {n: np.where(tracks.ok[n], tracks.py[n], np.nan) for n in POINTS}
    ok = np.all([tracks.ok[n] for n in POINTS], axis=0)
    seen = side_seen(px, ok, path)
    if side is not None and side != seen:
        names = {v: k for k, v in SIDES.items()}
        raise MeasureError(f"{path.name} shows the robot's {names[seen]} side (its nose "
                           f"{'left' if seen == 'L' else 'right'} of its tail), not its {names[side]}",
                           f"film the {names[side]} side (the camera on the robot's {names[side]}), or give "
                           f"--side {names[seen]}")
    sd_px, pairs = sticker_sd_px(px, py)
    lengths = {name: np.hypot(px[b] - px[a], py[b] - py[a]) for name, (a, b) in PAIRS.items()}
    sd = np.degrees(np.sqrt(sum(2.0 * sd_px ** 2 / lengths[k] ** 2 for k in PAIRS)))
    angle = crank_angle_deg(px, py, seen, ground_angle_deg)
    return CrankSeries(path, seen, np.asarray(tracks.t_s, float) - float(tracks.t_s[0]), angle,
                       np.where(np.isfinite(angle), sd, np.nan), sd_px, pairs,
                       {n: int(tracks.ok[n].sum()) for n in POINTS}, len(tracks.t_s), float(rate))


__all__ = ["MIN_STICKER_SD_PX", "PAIRS", "POINTS", "SIDES", "CrankSeries", "crank_angle_deg", "read_crank_clip",
           "side_seen", "sticker_sd_px"]
