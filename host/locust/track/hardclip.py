"""SYNTHETIC phone-like hop clips with known truth, the kind that fooled a colour tracker.

One sticker hops in a plane seen at a tilt, with what a phone video of a real hop holds:

- a **distractor** of the same colour elsewhere in the scene (a pen cap lying still);
- a **shadow** sweeping across (it darkens, it does not change hue);
- **motion blur** in flight (the exposure is a share of the frame time);
- the sticker **leaving the top of the frame** at the top of its hop, and coming back;
- an **ArUco grid board** (``cv2.aruco.GridBoard``) lying in the plane of motion, drawn
  through the same homography as the sticker, so every frame has a metric truth.

The truth (``<stem>.truth.csv``, first line ``# synthetic``) holds per frame the true pixel
position (NaN when the centre is out of the picture), whether the whole sticker is in the
picture, and the true position in the board plane (metres, origin at the board's
bottom-left corner, y up: what ``--board`` measures). The truth pixel is the projection of
the sticker's centre at mid-exposure, which is the centre of its blur streak.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_text
from .board import BoardSpec
from .color import parse_hex
from .synth import SUPERSAMPLE, camera, dot_coverage, write_video

HARD_BOARD = BoardSpec("DICT_4X4_50", 5, 3, 40.0, 10.0)   # 240 x 140 mm
STICKER_HEX = "#e8308c"          # a pink sticker, and a pen cap of the very same colour
GRAVITY_M_S2 = 9.81
TRUTH_HEADER = "frame,t_s,px,py,in_picture,whole_in_picture,x_m,y_m"


@dataclass
class HardTruth:
    """The truth of a SYNTHETIC hard clip.

    Attributes
    ----------
    frames : ndarray
        Frame numbers.
    fps : float
        Frame rate [1/s].
    px, py : ndarray
        True sticker centre [px] (nan when out of the picture).
    whole : ndarray of bool
        The whole sticker is inside the picture.
    x_m, y_m : ndarray
        True position in the board plane, y up [m].
    radius_px : float
        The sticker's radius [px].
    board : BoardSpec
        The board filmed.
    plane_to_image : ndarray
        3x3 homography, plane metres to pixels.
    sticker_hex : str
        The sticker's colour, ``#RRGGBB``.
    """

    frames: np.ndarray
    fps: float
    px: np.ndarray            # true centre, pixels (NaN when out of the picture)
    py: np.ndarray
    whole: np.ndarray         # the whole sticker is inside the picture
    x_m: np.ndarray           # true position in the board plane, metres, y up
    y_m: np.ndarray
    radius_px: float
    board: BoardSpec
    plane_to_image: np.ndarray  # 3x3 homography, plane metres -> pixels
    sticker_hex: str = STICKER_HEX

    @property
    def in_picture(self) -> np.ndarray:
        """Whether the sticker's centre is in the picture, per frame."""
        return np.isfinite(self.px)

    def write_csv(self, path: Path) -> Path:
        """``<stem>.truth.csv``; :func:`read_truth_csv` reads it back.

        Parameters
        ----------
        path : Path
            The file to write (atomically).

        Returns
        -------
        Path
            The file written.
        """
        meta = {"fps": self.fps, "radius_px": self.radius_px, "board": self.board.text(),
                "plane_to_image": self.plane_to_image.tolist(), "sticker_hex": self.sticker_hex}
        lines = ["# synthetic: locust.track.hardclip; sticker centre in pixels (OpenCV convention, nan out of "
                 f"the picture) and in the plane of board {self.board.text()} (m, origin bottom-left, y up)",
                 f"# meta {json.dumps(meta)}",
                 TRUTH_HEADER]
        for i, f in enumerate(self.frames):
            lines.append(f"{int(f)},{f / self.fps:.6f},{self.px[i]:.5f},{self.py[i]:.5f},{int(self.in_picture[i])},"
                         f"{int(self.whole[i])},{self.x_m[i]:.6f},{self.y_m[i]:.6f}")
        return atomic_write_text(path, "\n".join(lines) + "\n")


def read_truth_csv(path: str | os.PathLike) -> HardTruth:
    """A hard clip's ``<stem>.truth.csv`` as written by :meth:`HardTruth.write_csv`.

    Parameters
    ----------
    path : str or os.PathLike
        The truth file.

    Returns
    -------
    HardTruth
        The truth it holds.

    Raises
    ------
    TrackError
        Not a hard-clip truth file.
    """
    from .board import parse_board

    lines = Path(path).read_text().splitlines()
    meta = json.loads(next(ln for ln in lines if ln.startswith("# meta "))[len("# meta "):])
    table = [ln for ln in lines if ln and not ln.startswith("#")]
    if table[0] != TRUTH_HEADER:
        raise TrackError(f"{path}: not a hard-clip truth file (header {table[0]!r})",
                         "read the .truth.csv written beside a locust.track.hardclip video")
    rows = np.array([[float(v) for v in ln.split(",")] for ln in table[1:]])
    return HardTruth(rows[:, 0].astype(int), float(meta["fps"]), rows[:, 2], rows[:, 3], rows[:, 5].astype(bool),
                     rows[:, 6], rows[:, 7], float(meta["radius_px"]), parse_board(meta["board"]),
                     np.array(meta["plane_to_image"]), meta["sticker_hex"])


def plane_to_image(width: int, height: int) -> np.ndarray:
    """A tilted view of the plane: the plane rectangle x -0.15..0.95 m, y -0.05..0.45 m seen as
    a trapezoid (its right side nearer the camera, its top leaning away).

    Parameters
    ----------
    width, height : int
        The frame's size [px].

    Returns
    -------
    ndarray
        3x3 homography, plane metres to pixels.
    """
    plane = np.float32([[-0.15, -0.05], [0.95, -0.05], [0.95, 0.45], [-0.15, 0.45]])
    image = np.float32([[0.03, 0.97], [0.99, 0.99], [0.96, 0.02], [0.08, 0.10]]) * np.float32([width, height])
    return cv2.getPerspectiveTransform(plane, image).astype(np.float64)


def hop_path(t: np.ndarray, rest_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Plane position (m) at times ``t`` (s): at rest for ``rest_s``, a ballistic hop whose
    apex is out of the picture, a short bounce on landing, rest.

    Parameters
    ----------
    t : ndarray
        Times [s].
    rest_s : float
        Time at rest before the hop [s].

    Returns
    -------
    x_m, y_m : ndarray
        Plane position, y up [m].
    """
    flight = 0.62                                      # s
    x0, x1, y0 = 0.30, 0.78, 0.22                      # above the board, which spans 0..0.24 x 0..0.14 m
    vy = GRAVITY_M_S2 * flight / 2
    x = x0 + (x1 - x0) * np.clip((t - rest_s) / flight, 0, 1)
    tf = np.clip(t - rest_s, 0, flight)
    y = y0 + vy * tf - GRAVITY_M_S2 * tf ** 2 / 2
    bounce = 0.12
    tb = np.clip(t - rest_s - flight, 0, bounce)
    return x, y + 0.9 * tb * (bounce - tb) * GRAVITY_M_S2 / 2


def _project(H: np.ndarray, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.stack([x, y, np.ones_like(x)], axis=-1) @ H.T
    return v[..., 0] / v[..., 2], v[..., 1] / v[..., 2]


def _background(width: int, height: int, H: np.ndarray, board: BoardSpec, rng) -> np.ndarray:
    """A pale, slightly textured wall with the board warped onto it (rendered 2x, reduced)."""
    yy, xx = np.indices((height, width), dtype=np.float32)
    wall = 170 + 25 * (xx / width) - 20 * (yy / height)
    texture = cv2.GaussianBlur(rng.normal(0, 6, (height, width)).astype(np.float32), (0, 0), 3)
    img = np.repeat((wall + texture)[:, :, None], 3, axis=2) * np.float32([0.97, 1.0, 1.02])
    s = 2
    px_per_mm = 12.0
    margin_mm = 8.0
    art = board.image(px_per_mm, margin_mm).astype(np.float32)
    # art pixel (u, v) -> plane metres; then plane -> supersampled image
    to_plane = np.array([[1 / (px_per_mm * 1000), 0, -margin_mm / 1000 + 0.5 / (px_per_mm * 1000)],
                         [0, -1 / (px_per_mm * 1000), (board.height_mm + margin_mm) / 1000 - 0.5 / (px_per_mm * 1000)],
                         [0, 0, 1]])
    up = np.array([[s, 0, (s - 1) / 2], [0, s, (s - 1) / 2], [0, 0, 1]])
    M = up @ H @ to_plane
    big_art = cv2.warpPerspective(art * 0.92 + 10, M, (width * s, height * s), flags=cv2.INTER_AREA)
    big_mask = cv2.warpPerspective(np.ones_like(art), M, (width * s, height * s), flags=cv2.INTER_AREA)
    small_art = cv2.resize(big_art, (width, height), interpolation=cv2.INTER_AREA)
    small_mask = cv2.resize(big_mask, (width, height), interpolation=cv2.INTER_AREA)[:, :, None]
    return img * (1 - small_mask) + small_art[:, :, None] * small_mask


def _pen_cap(img: np.ndarray, centre: tuple[float, float], length_px: float, width_px: float, bgr) -> None:
    S = SUPERSAMPLE
    pad = int(length_px) + 4
    x0, y0 = int(centre[0]) - pad, int(centre[1]) - pad
    size = 2 * pad
    big = np.zeros((size * S, size * S), np.uint8)
    c = ((centre[0] - x0 + 0.5) * S - 0.5, (centre[1] - y0 + 0.5) * S - 0.5)
    box = cv2.boxPoints((c, (length_px * S, width_px * S), -25.0))
    cv2.fillPoly(big, [np.int32(np.round(box))], 255)
    cv2.circle(big, tuple(int(v) for v in (box[0] + box[3]) / 2), int(width_px * S / 2), 255, -1)
    alpha = cv2.resize(big, (size, size), interpolation=cv2.INTER_AREA).astype(np.float32)[:, :, None] / 255
    region = img[y0:y0 + size, x0:x0 + size]
    region[:] = region * (1 - alpha) + np.float32(bgr) * alpha


def _shadow(width: int, height: int, i: int, n: int) -> np.ndarray:
    """Light share (0.45 in the shadow, 1 outside): a soft-edged band sweeping right to left."""
    xx = np.arange(width, dtype=np.float32)[None, :] + 0.35 * np.arange(height, dtype=np.float32)[:, None]
    centre = width * (1.25 - 1.4 * i / max(n - 1, 1))
    half, soft = 0.16 * width, 0.03 * width
    inside = np.clip((half - np.abs(xx - centre)) / soft + 0.5, 0, 1)
    return (1 - 0.55 * inside)[:, :, None]


def make_hard_video(path: str | os.PathLike, width: int = 1920, height: int = 1080, n_frames: int = 120,
                    fps: float = 60.0, exposure_frames: float = 0.3, seed: int = 0,
                    fourcc: str = "mp4v", sticker_hex: str = STICKER_HEX) -> HardTruth:
    """Write a SYNTHETIC hard clip and ``<stem>.truth.csv`` beside it; return the truth.

    The sticker and the pen cap are both ``sticker_hex``; the exposure is ``exposure_frames``
    of the frame time (0.3: a phone in daylight at 60 fps; 1.0: indoors).

    Parameters
    ----------
    path : str or os.PathLike
        The video to write.
    width, height : int
        Frame size [px].
    n_frames : int
        Frames.
    fps : float
        Frame rate [1/s].
    exposure_frames : float
        Exposure as a share of the frame time (motion blur).
    seed : int
        Seed of the noise.
    fourcc : str
        The codec's four-character code.
    sticker_hex : str
        The sticker's (and the look-alike's) colour, ``#RRGGBB``.

    Returns
    -------
    HardTruth
        The truth, also written as ``<stem>.truth.csv``.
    """
    path = Path(path)
    rng = np.random.default_rng(seed)
    H = plane_to_image(width, height)
    rest_s = 0.15 * n_frames / fps
    xm, ym = hop_path(np.arange(n_frames) / fps, rest_s)
    cx, cy = _project(H, xm, ym)
    scale = width / 1920
    radius = 11.0 * scale
    in_pic = (cx >= -0.5) & (cx <= width - 0.5) & (cy >= -0.5) & (cy <= height - 0.5)
    whole = (cx >= radius) & (cx <= width - 1 - radius) & (cy >= radius) & (cy <= height - 1 - radius)
    sticker = np.float32(parse_hex(sticker_hex))
    base = _background(width, height, H, HARD_BOARD, rng)
    # the pen cap lies still, right of the landing spot
    cap_x, cap_y = _project(H, np.array([0.90]), np.array([0.08]))
    _pen_cap(base, (float(cap_x[0]), float(cap_y[0])), 70 * scale, 11 * scale, parse_hex(sticker_hex))
    # blur samples: positions over the exposure, centred on the frame time
    k = 9
    offsets = (np.arange(k) / (k - 1) - 0.5) * exposure_frames / fps

    def frames():
        for i in range(n_frames):
            img = base.copy()
            t = i / fps + offsets
            sx, sy = hop_path(t, rest_s)
            px, py = _project(H, sx, sy)
            _paint_streak(img, px, py, radius, sticker)
            img *= _shadow(width, height, i, n_frames)
            yield camera(img, rng, blur_sigma_px=0.7 * max(scale, 0.5), noise_dn=2.5)

    write_video(path, frames(), fps, (width, height), fourcc)
    truth = HardTruth(np.arange(n_frames), fps, np.where(in_pic, cx, np.nan), np.where(in_pic, cy, np.nan),
                      whole, xm, ym, radius, HARD_BOARD, H, sticker_hex)
    truth.write_csv(path.with_suffix(".truth.csv"))
    return truth


def _paint_streak(img: np.ndarray, px: np.ndarray, py: np.ndarray, radius: float, bgr: np.ndarray) -> None:
    """The sticker averaged over its positions during the exposure (motion blur)."""
    h, w = img.shape[:2]
    pad = int(radius) + 3
    x0 = int(np.floor(np.nanmin(px))) - pad
    y0 = int(np.floor(np.nanmin(py))) - pad
    x1 = int(np.ceil(np.nanmax(px))) + pad + 1
    y1 = int(np.ceil(np.nanmax(py))) + pad + 1
    if x1 <= 0 or y1 <= 0 or x0 >= w or y0 >= h:
        return
    acc = np.zeros((y1 - y0, x1 - x0), np.float32)
    for x, y in zip(px, py):
        alpha, ax, ay = dot_coverage(x - x0, y - y0, radius, acc.shape)
        acc[ay:ay + alpha.shape[0], ax:ax + alpha.shape[1]] += alpha
    acc /= len(px)
    cx0, cy0, cx1, cy1 = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
    a = acc[cy0 - y0:cy1 - y0, cx0 - x0:cx1 - x0, None]
    region = img[cy0:cy1, cx0:cx1]
    region[:] = region * (1 - a) + bgr * a
