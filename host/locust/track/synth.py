"""Synthetic videos with known sub-pixel truth (trackpy's ``artificial`` idea).

Everything here is SYNTHETIC and says so: file names carry ``synthetic`` and the truth
CSV starts with a ``# synthetic`` line.

The scene imitates the simulation's renders: a dark checker floor, a black chassis
carrying the magenta nose dot, red/green/yellow/blue links, the cyan foot dot. Each dot is
drawn with OpenCV ``S`` times larger (``cv2.circle`` with sub-pixel ``shift``) and
reduced with ``INTER_AREA``, so each pixel holds the exact share of the dot that covers
it; the pixel grid is OpenCV's (pixel i covers [i - 0.5, i + 0.5]). Then the frame goes
through a camera: a little optical blur, sensor noise, 8-bit rounding, and a lossy codec
(MPEG-4 part 2, 4:2:0 chroma) -- the truth never sees any of that.

An occluder (a grey card, as a hand passing in front) can hide a marker completely on
chosen frames; the truth marks those frames not visible.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..fileio import atomic_write_text
from ..markers import MARKER_COLOURS
from .color import parse_hex
from .video import encode_video as write_video  # synthetic clips are written like any other

SUPERSAMPLE = 8
SHIFT = 4  # cv2 drawing: coordinates in 1/16 of a (supersampled) pixel
LINK_BGR = [(0, 0, 200), (0, 170, 0), (0, 200, 220), (200, 60, 0)]  # red, green, yellow, blue


@dataclass
class SynthTruth:
    """The true marker centres of a SYNTHETIC video.

    Attributes
    ----------
    frames : ndarray
        Frame numbers.
    fps : float
        Frame rate [1/s].
    px, py : dict of str to ndarray
        Per marker, its true centre per frame, OpenCV convention [px].
    visible : dict of str to ndarray
        Per marker, whether it is in view on each frame.
    """

    frames: np.ndarray
    fps: float
    px: dict[str, np.ndarray]
    py: dict[str, np.ndarray]
    visible: dict[str, np.ndarray]

    def write_csv(self, path: Path) -> Path:
        """Write the truth as CSV (``frame, t_s`` and per marker ``px, py, visible``), atomically.

        Parameters
        ----------
        path : Path
            The file.

        Returns
        -------
        Path
            The file written.
        """
        names = list(self.px)
        lines = ["# synthetic: locust.track.synth; true marker centres, pixels, OpenCV convention",
                 ",".join(["frame", "t_s"] + [f"{n}_{c}" for n in names for c in ("px", "py", "visible")])]
        for i, f in enumerate(self.frames):
            row = [str(int(f)), f"{f / self.fps:.6f}"]
            for n in names:
                row += [f"{self.px[n][i]:.5f}", f"{self.py[n][i]:.5f}", str(int(self.visible[n][i]))]
            lines.append(",".join(row))
        return atomic_write_text(path, "\n".join(lines) + "\n")


def checker_floor(width: int, height: int, square_px: int = 40, levels: tuple[int, int] = (38, 52)) -> np.ndarray:
    """A grey checkerboard floor, float32 BGR.

    Parameters
    ----------
    width, height : int
        Image size [px].
    square_px : int
        Square side [px].
    levels : tuple of int
        Dark and light grey (8-bit levels).

    Returns
    -------
    ndarray
        ``(height, width, 3)`` float32 image.
    """
    yy, xx = np.indices((height, width))
    dark = ((xx // square_px + yy // square_px) % 2).astype(bool)
    img = np.where(dark, levels[0], levels[1]).astype(np.float32)
    return np.repeat(img[:, :, None], 3, axis=2)


def dot_coverage(cx: float, cy: float, radius_px: float, shape: tuple[int, int]) -> tuple[np.ndarray, int, int]:
    """Exact-ish coverage (0..1) of a disc on a small patch; returns (alpha, x0, y0).

    Parameters
    ----------
    cx, cy : float
        The disc's centre, OpenCV convention [px].
    radius_px : float
        Its radius [px].
    shape : tuple of int
        The image's (height, width).

    Returns
    -------
    alpha : ndarray
        Coverage of each patch pixel, 0..1.
    x0, y0 : int
        The patch's top-left pixel [px].
    """
    pad = int(np.ceil(radius_px)) + 2
    x0, y0 = int(np.floor(cx)) - pad, int(np.floor(cy)) - pad
    size = 2 * pad + 2
    big = np.zeros((size * SUPERSAMPLE, size * SUPERSAMPLE), np.uint8)
    # low-res u -> supersampled U = (u - x0 + 0.5) * S - 0.5
    centre = (int(round(((cx - x0 + 0.5) * SUPERSAMPLE - 0.5) * (1 << SHIFT))),
              int(round(((cy - y0 + 0.5) * SUPERSAMPLE - 0.5) * (1 << SHIFT))))
    cv2.circle(big, centre, int(round(radius_px * SUPERSAMPLE * (1 << SHIFT))), 255, -1, cv2.LINE_8, SHIFT)
    alpha = cv2.resize(big, (size, size), interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0
    h, w = shape
    ys, xs = slice(max(y0, 0), min(y0 + size, h)), slice(max(x0, 0), min(x0 + size, w))
    return alpha[ys.start - y0:ys.stop - y0, xs.start - x0:xs.stop - x0], xs.start, ys.start


def paint_dot(img: np.ndarray, cx: float, cy: float, radius_px: float, bgr) -> None:
    """Paint a disc into ``img`` in place, each pixel blended by the share of it the disc covers.

    Parameters
    ----------
    img : ndarray
        Float BGR image.
    cx, cy : float
        The disc's centre, OpenCV convention [px].
    radius_px : float
        Its radius [px].
    bgr : sequence of int
        Its colour.
    """
    alpha, x0, y0 = dot_coverage(cx, cy, radius_px, img.shape[:2])
    h, w = alpha.shape
    region = img[y0:y0 + h, x0:x0 + w]
    region[:] = region * (1 - alpha[:, :, None]) + np.array(bgr, np.float32) * alpha[:, :, None]


def camera(img: np.ndarray, rng: np.random.Generator, blur_sigma_px: float = 0.6, noise_dn: float = 2.0) -> np.ndarray:
    """Optics blur, sensor noise, 8-bit output.

    Parameters
    ----------
    img : ndarray
        A float image.
    rng : numpy.random.Generator
        Source of the noise.
    blur_sigma_px : float
        Gaussian blur [px]; 0 for none.
    noise_dn : float
        Noise standard deviation [8-bit levels].

    Returns
    -------
    ndarray
        The uint8 image.
    """
    if blur_sigma_px > 0:
        img = cv2.GaussianBlur(img, (0, 0), blur_sigma_px)
    img = img + rng.normal(0.0, noise_dn, img.shape).astype(np.float32)
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


def hop_truth(n_frames: int, width: int, height: int, fps: float, rng: np.random.Generator,
              occluded: tuple[int, int] | None = None) -> SynthTruth:
    """A forward hop: the nose flies a parabola, the foot swings below it.

    Parameters
    ----------
    n_frames : int
        Frames.
    width, height : int
        Frame size [px].
    fps : float
        Frame rate [1/s].
    rng : numpy.random.Generator
        Source of the sub-pixel offsets.
    occluded : tuple of int, optional
        First and last frame the foot is hidden.

    Returns
    -------
    SynthTruth
        The true centres [px].
    """
    t = np.arange(n_frames) / fps
    T = t[-1] if n_frames > 1 else 1.0
    x0 = 0.2 * width + rng.uniform(0, 1)
    nose_x = x0 + 0.55 * width * t / T
    apex = 0.35 * height
    nose_y = 0.72 * height - apex * 4 * (t / T) * (1 - t / T) + rng.uniform(0, 1)
    foot_x = nose_x - 0.06 * width + 0.02 * width * np.sin(2 * np.pi * t / T)
    foot_y = nose_y + 0.16 * height - 0.03 * height * np.sin(np.pi * t / T)
    visible = {"nose": np.ones(n_frames, bool), "foot": np.ones(n_frames, bool)}
    if occluded:
        visible["foot"][occluded[0]:occluded[1] + 1] = False
    return SynthTruth(np.arange(n_frames), fps, {"nose": nose_x, "foot": foot_x}, {"nose": nose_y, "foot": foot_y},
                      visible)


def render_hop_frame(i: int, truth: SynthTruth, floor: np.ndarray, radius_px: float,
                     rng: np.random.Generator) -> np.ndarray:
    """Frame ``i`` of the SYNTHETIC hop video: chassis, links and the two marker dots on the
    floor, a grey card over the foot where it is hidden, then optics blur and noise.

    Parameters
    ----------
    i : int
        The frame's index into ``truth``.
    truth : SynthTruth
        The true marker centres.
    floor : ndarray
        The background (:func:`checker_floor`).
    radius_px : float
        The dots' radius [px].
    rng : numpy.random.Generator
        Source of the sensor noise.

    Returns
    -------
    ndarray
        The frame, uint8 BGR.
    """
    img = floor.copy()
    nx, ny = truth.px["nose"][i], truth.py["nose"][i]
    fx, fy = truth.px["foot"][i], truth.py["foot"][i]
    # black chassis behind the nose dot
    cv2.rectangle(img, (int(nx - 70), int(ny - 12)), (int(nx + 12), int(ny + 12)), (8, 8, 8), -1)
    # links from the chassis toward the foot, stopping short of the foot dot
    hip = np.array([nx - 40, ny + 10])
    foot = np.array([fx, fy])
    d = foot - hip
    end = foot - d / max(np.linalg.norm(d), 1e-9) * (radius_px + 6)
    knee = hip + 0.5 * d + np.array([-12.0, 0.0])
    for k, (a, b) in enumerate([(hip, knee), (knee, end), (hip + (6, 0), knee + (6, 0)), (knee + (6, 0), end)]):
        cv2.line(img, tuple(int(v) for v in a), tuple(int(v) for v in b), LINK_BGR[k], 3, cv2.LINE_AA)
    paint_dot(img, nx, ny, radius_px, parse_hex(MARKER_COLOURS["nose"][0]))
    paint_dot(img, fx, fy, radius_px, parse_hex(MARKER_COLOURS["foot"][0]))
    if not truth.visible["foot"][i]:  # a grey card passes in front of the foot
        r = int(3 * radius_px)
        cv2.rectangle(img, (int(fx) - r, int(fy) - r), (int(fx) + r, int(fy) + r), (90, 92, 95), -1)
    return camera(img, rng)


def make_hop_video(path: str | os.PathLike, width: int = 640, height: int = 360, n_frames: int = 48,
                   fps: float = 60.0, radius_px: float = 6.0, occluded: tuple[int, int] | None = None,
                   seed: int = 0, fourcc: str = "mp4v") -> SynthTruth:
    """Write a synthetic hop video and ``<stem>.truth.csv`` beside it; return the truth.

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
    radius_px : float
        The dots' radius [px].
    occluded : tuple of int, optional
        First and last frame the foot is hidden.
    seed : int
        Seed of the offsets and noise.
    fourcc : str
        The codec's four-character code.

    Returns
    -------
    SynthTruth
        The truth.
    """
    path = Path(path)
    rng = np.random.default_rng(seed)
    truth = hop_truth(n_frames, width, height, fps, rng, occluded)
    floor = checker_floor(width, height)
    write_video(path, (render_hop_frame(i, truth, floor, radius_px, rng) for i in range(n_frames)), fps,
                (width, height), fourcc)
    truth.write_csv(path.with_suffix(".truth.csv"))
    return truth


def aruco_frame(marker_id: int, centre_px: tuple[float, float], side_px: float, angle_deg: float,
                size: tuple[int, int] = (640, 480), dictionary: str = "DICT_4X4_50",
                rng: np.random.Generator | None = None) -> np.ndarray:
    """A grey frame holding one ArUco marker (with a white quiet zone) at a sub-pixel pose.

    The marker is warped onto an ``S`` times larger canvas and reduced with INTER_AREA,
    like the dots. ``side_px`` is the black square's side; its centre is ``centre_px``.

    Parameters
    ----------
    marker_id : int
        The ArUco id.
    centre_px : tuple of float
        The marker's centre, OpenCV convention [px].
    side_px : float
        The black square's side [px].
    angle_deg : float
        Its rotation in the image, counter-clockwise on screen [deg].
    size : tuple of int
        The frame's (width, height) [px].
    dictionary : str
        The ArUco dictionary.
    rng : numpy.random.Generator, optional
        Source of the noise; default seeded 0.

    Returns
    -------
    ndarray
        The frame, uint8 BGR.
    """
    rng = rng or np.random.default_rng(0)
    cells = int(dictionary.split("_")[1].split("X")[0]) + 2  # data bits + black border
    px_per_cell = 40
    art = cv2.aruco.generateImageMarker(cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)),
                                        marker_id, cells * px_per_cell)
    quiet = px_per_cell
    art = cv2.copyMakeBorder(art, quiet, quiet, quiet, quiet, cv2.BORDER_CONSTANT, value=255)
    n = art.shape[0]
    w, h = size
    S = SUPERSAMPLE
    scale = side_px * S / (cells * px_per_cell)
    a = np.radians(angle_deg)
    rot = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]]) * scale  # ccw on screen
    src_c = np.array([(n - 1) / 2.0, (n - 1) / 2.0])
    dst_c = (np.array(centre_px) + 0.5) * S - 0.5
    m = np.hstack([rot, (dst_c - rot @ src_c)[:, None]])
    big = cv2.warpAffine(art, m, (w * S, h * S), flags=cv2.INTER_AREA, borderValue=120)
    small = cv2.resize(big, (w, h), interpolation=cv2.INTER_AREA).astype(np.float32)
    return cv2.cvtColor(camera(small, rng), cv2.COLOR_GRAY2BGR)
