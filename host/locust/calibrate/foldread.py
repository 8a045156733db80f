"""A fold test's photos read: the board's corners and the three stickers of each, with how
precisely each sticker's centre is found (``locust calibrate fold``'s input).

A state of the fold (unloaded, loaded) is one photo, a folder of photos, or a clip (its frames,
at most :data:`MAX_FRAMES` spread over it). In each photo the ArUco board of ``locust track
board`` (:mod:`locust.track.board`), standing upright in the stickers' plane, gives the plane's
metric frame, x right and y up (a homography of its detected corners; their reprojection
scatter is kept for the intervals), and the stickers of :data:`locust.markers.FOLD_STICKER_COLOURS`
are found by colour (:mod:`locust.track.color`, as ``locust measure stance`` finds its own).

A sticker centre's precision in one photo is measured on the photo itself: its sensor noise
is estimated from the image (Immerkær's fast noise estimate, J. Immerkær, Computer Vision and
Image Understanding 64, 1996: the mean absolute response to the difference of two Laplacians,
times sqrt(pi/2)/6, in each colour channel), noise of that level is added again
:data:`NOISE_DRAWS` times around the sticker and the sticker found again: the scatter of those
centres (one coordinate), and never less than :data:`MIN_STICKER_SD_PX`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..arucoboard import BoardSpec
from ..errors import CalibrationError, TrackError
from ..fileio import opencv_path
from ..markers import FOLD_STICKER_COLOURS

FOLD_STICKERS = tuple(FOLD_STICKER_COLOURS)      # axis, tip, base
MAX_FRAMES = 60                # frames taken from a clip (spread over it)
NOISE_DRAWS = 24               # re-detections of each sticker under added noise
MIN_STICKER_SD_PX = 0.1        # the least scatter a sticker's centre is given (one coordinate; as measure stance's)
ROI_HALF_PX = 48               # half the window a sticker is found again in
OBLIQUE_LIMIT = 0.05           # the board's scale may differ this much between opposite edges (a warning)
_LAPLACE_DIFF = np.array([[1.0, -2.0, 1.0], [-2.0, 4.0, -2.0], [1.0, -2.0, 1.0]])


@dataclass(frozen=True)
class FoldPhoto:
    """One photo of a fold test: its board and its stickers.

    Attributes
    ----------
    name : str
        The photo (a clip's: ``clip.mp4#12``, its frame).
    corners_px, corners_m : numpy.ndarray
        (N, 2) the board's detected corners [px] and their places on the board [m, x right, y up].
    corner_sd_px : float
        The corners' reprojection scatter [px, one coordinate].
    stickers_px : dict of str to (float, float)
        Each sticker's centre [px, OpenCV's convention].
    sticker_sd_px : dict of str to float
        Each centre's scatter [px, one coordinate].
    noise_levels : float
        The photo's sensor noise [grey levels of 255].
    oblique : float
        How much larger the board's nearer edge looks than its opposite one (0: square to the camera).
    """

    name: str
    corners_px: np.ndarray
    corners_m: np.ndarray
    corner_sd_px: float
    stickers_px: dict[str, tuple[float, float]]
    sticker_sd_px: dict[str, float]
    noise_levels: float
    oblique: float

    def plane_points(self, corner_noise: np.ndarray | None = None,
                     sticker_noise: np.ndarray | None = None) -> np.ndarray:
        """The stickers on the board's plane (FOLD_STICKERS order), metres, x right, y up.

        Parameters
        ----------
        corner_noise : numpy.ndarray, optional
            (N, 2) added to the corners [px] before the homography.
        sticker_noise : numpy.ndarray, optional
            (3, 2) added to the stickers [px].

        Returns
        -------
        numpy.ndarray
            (3, 2) [m].
        """
        corners = self.corners_px if corner_noise is None else self.corners_px + corner_noise
        px = np.array([self.stickers_px[n] for n in FOLD_STICKERS], float)
        if sticker_noise is not None:
            px = px + sticker_noise
        H, _ = cv2.findHomography(corners, self.corners_m, 0)
        return cv2.perspectiveTransform(px[None], H)[0]

    def m_per_px(self) -> float:
        """The plane's scale at the stickers [m/px] (the mean of the three)."""
        from ..track.board import scale_px_per_m

        H, _ = cv2.findHomography(self.corners_px, self.corners_m, 0)
        px = np.array([self.stickers_px[n] for n in FOLD_STICKERS], float)
        return float(np.mean([scale_px_per_m(H, x, y) for x, y in px]))   # image -> plane: m per px


def noise_levels(image_bgr: np.ndarray) -> float:
    """The photo's sensor noise [grey levels], the median over its colour channels of Immerkær's estimate.

    Parameters
    ----------
    image_bgr : numpy.ndarray
        The photo.

    Returns
    -------
    float
    """
    out = []
    for c in range(image_bgr.shape[2]):
        channel = image_bgr[:, :, c]
        resp = cv2.filter2D(channel.astype(np.float64), -1, _LAPLACE_DIFF)
        # where the noise was clipped (black, white) it is not seen: those pixels are left out
        inside = cv2.erode(((channel > 0) & (channel < 255)).astype(np.uint8), np.ones((3, 3), np.uint8))
        inside[[0, -1], :] = inside[:, [0, -1]] = 0
        if inside.sum() > 100:
            out.append(math.sqrt(math.pi / 2) * float(np.mean(np.abs(resp[inside > 0]))) / 6.0)
    return float(np.median(out)) if out else 0.0


def _marker(name: str, start_px: tuple[float, float] | None = None):
    from ..track.color import ColorMarker, parse_hex

    colour = FOLD_STICKER_COLOURS[name][0]
    return ColorMarker(name, f"color:{colour}", parse_hex(colour), start_px=start_px)


def _missing(photo: str, name: str) -> CalibrationError:
    colour, where = FOLD_STICKER_COLOURS[name]
    return CalibrationError(f"{photo}: the {name} sticker ({colour}, {where}) is not found",
                            f"stick a {colour} dot there (docs/calibrate.md, Fold), keep it in view and evenly lit, "
                            "and photograph the fold again")


def find_stickers(image_bgr: np.ndarray, photo: str) -> dict[str, tuple[float, float]]:
    """Each fold sticker's centre [px], found by its colour.

    Parameters
    ----------
    image_bgr : numpy.ndarray
        The photo.
    photo : str
        Its name, for messages.

    Returns
    -------
    dict of str to (float, float)

    Raises
    ------
    locust.errors.CalibrationError
        A sticker not found.
    """
    out = {}
    for name in FOLD_STICKERS:
        found = _marker(name).locate(0, image_bgr)
        if not found.ok:
            raise _missing(photo, name)
        out[name] = (float(found.px), float(found.py))
    return out


def centre_sd_px(image_bgr: np.ndarray, name: str, centre_px: tuple[float, float], levels: float,
                 rng: np.random.Generator) -> float:
    """A sticker centre's scatter [px, one coordinate] under the photo's own noise level added again.

    Parameters
    ----------
    image_bgr : numpy.ndarray
        The photo.
    name : str
        The sticker.
    centre_px : (float, float)
        Where it was found [px].
    levels : float
        The photo's noise [grey levels] (:func:`noise_levels`).
    rng : numpy.random.Generator
        The added noise's generator.

    Returns
    -------
    float
    """
    h, w = image_bgr.shape[:2]
    x0, y0 = max(int(centre_px[0]) - ROI_HALF_PX, 0), max(int(centre_px[1]) - ROI_HALF_PX, 0)
    roi = image_bgr[y0:min(int(centre_px[1]) + ROI_HALF_PX, h), x0:min(int(centre_px[0]) + ROI_HALF_PX, w)]
    moved = []
    for _ in range(NOISE_DRAWS):
        noisy = np.clip(roi + rng.normal(0.0, max(levels, 0.5), roi.shape), 0, 255).astype(np.uint8)
        found = _marker(name, (centre_px[0] - x0, centre_px[1] - y0)).locate(0, noisy)
        if found.ok:
            moved.append((found.px + x0 - centre_px[0], found.py + y0 - centre_px[1]))
    if len(moved) < NOISE_DRAWS // 2:
        return math.inf
    d = np.array(moved)
    return max(float(np.sqrt(np.mean(d ** 2))), MIN_STICKER_SD_PX)


def board_corners(spec: BoardSpec, image_bgr: np.ndarray, photo: str) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The board's detected corners [px], their board places [m], their reprojection scatter
    [px] and how oblique the board is seen (the larger edge's scale over the opposite one's, less 1).

    Parameters
    ----------
    spec : locust.arucoboard.BoardSpec
        The printed board.
    image_bgr : numpy.ndarray
        The photo.
    photo : str
        Its name, for messages.

    Returns
    -------
    corners_px, corners_m : numpy.ndarray
    sd_px, oblique : float

    Raises
    ------
    locust.errors.CalibrationError
        The board is not found.
    """
    from ..track.board import board_view, edge_scales

    view = board_view(spec, image_bgr)
    if view is None:
        raise CalibrationError(f"{photo}: board {spec.text()} not found",
                               "the whole board must be in the photo, sharp and uncovered, standing upright in the "
                               "stickers' plane; check --board against the printed one (`locust track board`)")
    oblique = max(max(sa, sb) / min(sa, sb) - 1.0 for sa, sb in edge_scales(view.homography, spec).values())
    return view.corners_px, view.corners_m, view.sd_px, float(oblique)


def read_image(image_bgr: np.ndarray, name: str, spec: BoardSpec, rng: np.random.Generator) -> FoldPhoto:
    """One photo's board, stickers and their precision.

    Parameters
    ----------
    image_bgr : numpy.ndarray
        The photo.
    name : str
        Its name, for messages.
    spec : locust.arucoboard.BoardSpec
        The printed board.
    rng : numpy.random.Generator
        The precision's added noise.

    Returns
    -------
    FoldPhoto

    Raises
    ------
    locust.errors.CalibrationError
        No board, or a sticker not found.
    """
    corners_px, corners_m, corner_sd, oblique = board_corners(spec, image_bgr, name)
    stickers = find_stickers(image_bgr, name)
    levels = noise_levels(image_bgr)
    sds = {n: centre_sd_px(image_bgr, n, stickers[n], levels, rng) for n in FOLD_STICKERS}
    for n, sd in sds.items():
        if not math.isfinite(sd):
            raise CalibrationError(f"{name}: the {n} sticker is found only now and then under the photo's own noise",
                                   "photograph it larger (closer), sharper and evenly lit")
    return FoldPhoto(name, corners_px, corners_m, corner_sd, stickers, sds, levels, oblique)


def _images(path: Path) -> list[tuple[str, np.ndarray]]:
    """A state's images: a photo, a folder of photos, or a clip's frames (at most MAX_FRAMES)."""
    from ..track.video import IMAGE_SUFFIXES, Clip, image_sequence, probe, read_frames

    if path.is_file() and path.suffix.lower() in IMAGE_SUFFIXES:
        files = [path]
    elif path.is_dir():
        files = list(image_sequence(path))
        if not files:
            raise CalibrationError(f"{path}: a folder without photos", "give a photo, a folder of photos or a clip")
    else:
        try:
            info = probe(path)
            step = max(1, math.ceil(info.frame_count / MAX_FRAMES))
            return [(f"{path.name}#{k}", image) for k, image in read_frames(info, Clip(step=step).resolved(info))]
        except TrackError as exc:
            raise CalibrationError(exc.message, exc.hint) from None
    out = []
    for f in files[:MAX_FRAMES]:
        with opencv_path(f) as name:
            image = cv2.imread(name, cv2.IMREAD_COLOR)
        if image is None:
            raise CalibrationError(f"{f}: not a readable image", "give photos as PNG or JPEG")
        out.append((f.name, image))
    return out


def read_state(path: str | Path, spec: BoardSpec, seed: int = 0) -> list[FoldPhoto]:
    """One state of the fold: each of its photos read (:func:`read_image`).

    Parameters
    ----------
    path : path-like
        A photo, a folder of photos, or a clip.
    spec : locust.arucoboard.BoardSpec
        The printed board.
    seed : int
        The precision's added noise.

    Returns
    -------
    list of FoldPhoto

    Raises
    ------
    locust.errors.CalibrationError
        Nothing there, an unreadable image, no board, a sticker not found.
    """
    path = Path(path)
    if not path.exists():
        raise CalibrationError(f"{path}: no such photo", "give the photo of the fold (or a folder of photos, a clip)")
    rng = np.random.default_rng(seed)
    return [read_image(image, name, spec, rng) for name, image in _images(path)]


__all__ = ["FOLD_STICKERS", "MAX_FRAMES", "MIN_STICKER_SD_PX", "FoldPhoto", "board_corners", "centre_sd_px",
           "find_stickers", "noise_levels", "read_image", "read_state"]
