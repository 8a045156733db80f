"""Tracks drawn on the footage: a PNG to glance at, or a whole annotated video."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_bytes
from .runner import TrackResult
from .video import encode_video, read_frame, read_frames

PALETTE_BGR = [(255, 0, 255), (255, 255, 0), (0, 255, 255), (0, 128, 255), (255, 128, 0), (128, 255, 0)]


def _colour(spec: str, k: int) -> tuple[int, int, int]:
    if spec.lower().startswith(("color:#", "colour:#")):
        h = spec.split("#", 1)[1]
        return int(h[4:6], 16), int(h[2:4], 16), int(h[0:2], 16)
    return PALETTE_BGR[k % len(PALETTE_BGR)]


TRAIL_FRAMES = 15   # the video overlay's trail, as Tracker's default trail length


def draw_tracks(image: np.ndarray, result: TrackResult, upto: int | None = None,
                trail: int | None = None) -> np.ndarray:
    """Draw each marker's path (and its latest point) on a copy of ``image``: the whole path,
    or with ``upto`` (a frame of a video) the last ``trail`` frames of it, the point found in
    that frame ringed, and a marker lost there named as lost in the top-left corner.

    Parameters
    ----------
    image : ndarray
        A frame, BGR.
    result : TrackResult
        The tracks.
    upto : int, optional
        The frame drawn on; None: the whole paths.
    trail : int, optional
        Frames of path drawn before ``upto``.

    Returns
    -------
    ndarray
        The annotated copy.
    """
    out = image.copy()
    t = result.tracks
    n = len(t.frame) if upto is None else upto + 1
    first = 0 if trail is None else max(n - trail, 0)
    shift = 4  # sub-pixel drawing: coordinates in 1/16 px
    for k, name in enumerate(t.markers):
        colour = _colour(result.specs[name], k)
        pts = np.stack([t.px[name][:n], t.py[name][:n]], axis=1)
        good = t.ok[name][:n].copy()
        good[:first] = False
        # break the path where the marker was missing
        for seg in np.split(np.arange(n), np.flatnonzero(~good) + 1):
            seg = seg[good[seg]] if seg.size else seg
            if seg.size >= 2:
                poly = np.round(pts[seg] * (1 << shift)).astype(np.int32)
                cv2.polylines(out, [poly], False, colour, 1, cv2.LINE_AA, shift)
        for i in np.flatnonzero(good):
            c = tuple(int(v) for v in np.round(pts[i] * (1 << shift)))
            cv2.circle(out, c, 3 << shift, colour, 1, cv2.LINE_AA, shift)
        if upto is not None and not good[n - 1]:
            cv2.putText(out, f"{name}: lost", (8, 20 + 18 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, 1,
                        cv2.LINE_AA)
            continue
        last = np.flatnonzero(good)
        if last.size:
            x, y = pts[last[-1]]
            if upto is not None:
                c = tuple(int(v) for v in np.round(pts[n - 1] * (1 << shift)))
                cv2.circle(out, c, 8 << shift, colour, 2, cv2.LINE_AA, shift)
            cv2.putText(out, name, (int(x) + 8, int(y) - 8), cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv2.LINE_AA)
    origin, x_dir, y_dir = result.calibration.axes_px()
    o = (int(round(origin[0])), int(round(origin[1])))
    for direction, colour in ((x_dir, (0, 0, 255)), (y_dir, (0, 255, 0))):
        cv2.arrowedLine(out, o, (int(o[0] + 40 * direction[0]), int(o[1] + 40 * direction[1])), colour, 1, cv2.LINE_AA)
    return out


def write_png(result: TrackResult, path: Path) -> Path:
    """The clip's last frame with every track on it.

    Parameters
    ----------
    result : TrackResult
        The tracks, with their video.
    path : Path
        The PNG to write (atomically).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    TrackError
        The result has no video (tracks read from a Tracker project).
    """
    if result.video is None:
        raise TrackError("no video to draw on", "give the video to draw tracks on")
    image = read_frame(result.video, int(result.tracks.frame[-1]))
    ok, png = cv2.imencode(".png", draw_tracks(image, result))
    return atomic_write_bytes(path, png.tobytes())


def write_video(result: TrackResult, path: Path, progress: Callable[[int], None] | None = None) -> Path:
    """The whole clip, each frame with the last ``TRAIL_FRAMES`` of every track and the point
    found in it, or the marker named as lost (MPEG-4, at the clip's rate).

    Parameters
    ----------
    result : TrackResult
        The tracks, with their video.
    path : Path
        The video to write.
    progress : callable, optional
        Called with 1 after each frame.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    TrackError
        The result has no video, or the video cannot be written.
    """
    v = result.video

    def drawn():
        for i, (_, image) in enumerate(read_frames(v, result.clip)):
            yield draw_tracks(image, result, upto=i, trail=TRAIL_FRAMES)
            if progress:
                progress(1)

    return encode_video(Path(path), drawn(), float(result.clip.fps), (v.width_px, v.height_px))

