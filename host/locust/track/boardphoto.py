"""SYNTHETIC photos of a printed board with a bank card beside it, of known print scale and pose.

What ``locust track board --check`` is tested on (trackpy's ``artificial`` idea): the sheet
``locust track board`` writes (:mod:`locust.track.boardsheet`), printed at ``print_scale``
of its size on an A4 page, lies on a table beside an ID-1 card at its true size (85.60 x
53.98 mm, corners of 3.18 mm radius, ISO/IEC 7810), turned a little. A pinhole camera
photographs the table from ``tilt_deg`` off square; the picture is drawn at twice the
resolution and reduced by area (each pixel the mean of what covers it), then blurred a little,
given sensor noise and stored as a JPEG, as a phone would. The truth (the scale, the tilt,
the plane -> image homography) never sees any of that.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from ..arucoboard import BOARD_MARGIN_MM, BoardSpec
from .boardsheet import MM_PER_IN, SHEET_DPI, draw_sheet

CARD_MM = (85.60, 53.98)          # ISO/IEC 7810 ID-1
CARD_RADIUS_MM = 3.18
A4_MM = (297.0, 210.0)            # landscape
TEXTURE_PX_PER_MM = 10.0          # the table, drawn before the camera sees it
SUPERSAMPLE = 2


@dataclass(frozen=True)
class BoardPhotoTruth:
    """What a SYNTHETIC board photo truly shows.

    Attributes
    ----------
    print_scale : float
        The printed sheet's size over its intended size.
    tilt_deg : float
        The camera's axis from the table's normal [deg].
    board_to_image : ndarray
        3x3: the board's plane as printed, in the mm it would have at 100 % (origin at the
        board's bottom-left corner, y up), to the photo's pixels (OpenCV's).
    card_corners_px : ndarray
        (4, 2) the card's corners as the straight edges meet [px].
    """

    print_scale: float
    tilt_deg: float
    board_to_image: np.ndarray
    card_corners_px: np.ndarray


def sheet_image(spec: BoardSpec) -> np.ndarray:
    """The printed sheet as ``locust track board`` writes it (grey levels, 300 DPI).

    Parameters
    ----------
    spec : BoardSpec
        The board.

    Returns
    -------
    ndarray
        2-D uint8.
    """
    from ..plotting import pyplot

    fig = draw_sheet(spec)
    fig.canvas.draw()
    rgba = np.asarray(fig.canvas.buffer_rgba())
    pyplot().close(fig)
    return cv2.cvtColor(np.ascontiguousarray(rgba[..., :3]), cv2.COLOR_RGB2GRAY)


def _card_cover(x_mm: np.ndarray, y_mm: np.ndarray, k: float) -> np.ndarray:
    """How much of each pixel (its centre at x, y in the card's frame, mm from the card's
    centre; ``k`` px/mm) the card covers: its rounded outline's signed distance, exact to a
    small fraction of a pixel."""
    half = np.array(CARD_MM) / 2 - CARD_RADIUS_MM
    qx, qy = np.abs(x_mm) - half[0], np.abs(y_mm) - half[1]
    outside = np.hypot(np.maximum(qx, 0), np.maximum(qy, 0)) + np.minimum(np.maximum(qx, qy), 0)
    return np.clip(0.5 - (outside - CARD_RADIUS_MM) * k, 0.0, 1.0).astype(np.float32)


def _camera(tilt_deg: float, yaw_deg: float, centre_mm: tuple[float, float], distance_mm: float,
            f_px: float, size_px: tuple[int, int]) -> np.ndarray:
    """The table plane (mm, z = 0) -> image homography of a camera ``distance_mm`` from
    ``centre_mm``, its axis ``tilt_deg`` from the table's normal (leaning towards -y)."""
    t, y = math.radians(tilt_deg), math.radians(yaw_deg)
    # straight down: image x along +x, image y along -y, looking along -z
    down = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]).T
    rx = np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])
    rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    r_wc = rz @ rx @ down                      # the camera's axes in the world, as columns
    centre = np.array([centre_mm[0], centre_mm[1], 0.0]) - distance_mm * r_wc[:, 2]
    r_cw = r_wc.T
    tvec = -r_cw @ centre
    K = np.array([[f_px, 0, (size_px[0] - 1) / 2], [0, f_px, (size_px[1] - 1) / 2], [0, 0, 1]])
    return K @ np.c_[r_cw[:, 0], r_cw[:, 1], tvec]


def render_board_photo(spec: BoardSpec, print_scale: float, tilt_deg: float = 20.0, seed: int = 0,
                       size_px: tuple[int, int] = (2400, 1800), blur_px: float = 0.8, noise: float = 2.0,
                       jpeg_quality: int = 90, card: bool = True) -> tuple[np.ndarray, BoardPhotoTruth]:
    """A SYNTHETIC photo of the board printed at ``print_scale`` with a card beside it.

    Parameters
    ----------
    spec : BoardSpec
        The board printed.
    print_scale : float
        The print's size over the sheet's (0.97: a "fit to page" at 97 %).
    tilt_deg : float
        The camera's axis from the table's normal [deg].
    seed : int
        Where the sheet and the card lie, the camera's yaw and the noise.
    size_px : tuple of int
        The photo (width, height) [px].
    blur_px : float
        Optical blur, Gaussian sigma [px].
    noise : float
        Sensor noise, sd [grey levels].
    jpeg_quality : int
        The JPEG's quality (0-100).
    card : bool
        Lay the card beside the sheet (False: the sheet alone).

    Returns
    -------
    image : ndarray
        The photo, BGR uint8 (decoded from its JPEG).
    truth : BoardPhotoTruth
        The scale, the tilt and where things are.
    """
    rng = np.random.default_rng(seed)
    k = TEXTURE_PX_PER_MM
    # the table around the page and the card: x -20 .. 320 mm, y -110 .. 230 mm
    x0, y1, w_mm, h_mm = -20.0, 230.0, 340.0, 340.0
    tw, th = int(w_mm * k), int(h_mm * k)
    table = np.empty((th, tw, 3), np.float32)
    grain = cv2.GaussianBlur(rng.normal(0, 1, (th // 8, tw // 8)).astype(np.float32), (0, 0), 3)
    grain = cv2.resize(grain, (tw, th))[..., None]
    table[:] = np.array([150, 170, 190], np.float32) + 25 * grain       # a light wooden table (BGR)
    to_px = lambda x, y: (int(round((x - x0) * k)), int(round((y1 - y) * k)))   # noqa: E731

    # the A4 page, the sheet printed on it at print_scale about the page's centre
    page = (rng.uniform(-3, 3), rng.uniform(-3, 3))
    a, b = to_px(page[0], page[1] + A4_MM[1]), to_px(page[0] + A4_MM[0], page[1])
    table[a[1]:b[1], a[0]:b[0]] = 242.0
    sheet = sheet_image(spec).astype(np.float32) / 255.0
    sheet_mm = (sheet.shape[1] * MM_PER_IN / SHEET_DPI, sheet.shape[0] * MM_PER_IN / SHEET_DPI)
    printed_mm = (sheet_mm[0] * print_scale, sheet_mm[1] * print_scale)
    sx0 = page[0] + (A4_MM[0] - printed_mm[0]) / 2
    sy0 = page[1] + (A4_MM[1] - printed_mm[1]) / 2
    # the sheet into the table's pixels: sheet pixel j's centre at x = sx0 + scale (j + 0.5) / dpmm
    s = print_scale * k * MM_PER_IN / SHEET_DPI            # table px per sheet px
    M = np.array([[s, 0, (sx0 - x0) * k + 0.5 * s - 0.5], [0, s, (y1 - sy0 - printed_mm[1]) * k + 0.5 * s - 0.5]])
    ink = cv2.warpAffine(sheet, M, (tw, th), flags=cv2.INTER_LINEAR, borderValue=1.0)
    table *= ink[..., None]
    # the board's origin (its bottom-left marker's outer corner) on the table, at print scale
    origin = (sx0 + BOARD_MARGIN_MM * print_scale, sy0 + BOARD_MARGIN_MM * print_scale)

    # the card below the page, turned a little: dark blue, a light band, a gold chip
    angle = rng.uniform(-12, 12)
    centre = (rng.uniform(60, 240), rng.uniform(-50, -42))
    rows, cols = np.mgrid[0:th, 0:tw].astype(np.float32)
    px_x, px_y = x0 + (cols + 0.5) / k - centre[0], y1 - (rows + 0.5) / k - centre[1]
    c, sn = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    u, v = c * px_x + sn * px_y, -sn * px_x + c * px_y          # the card's frame: u along its long side
    m = _card_cover(u, v, k)[..., None] * card
    face = np.empty((th, tw, 3), np.float32)
    face[:] = (120, 55, 25)
    face[(v > -0.20 * CARD_MM[1]) & (v < -0.05 * CARD_MM[1])] = (200, 170, 140)
    face[(u > -0.40 * CARD_MM[0]) & (u < -0.26 * CARD_MM[0]) & (v > 0.05 * CARD_MM[1]) & (v < 0.25 * CARD_MM[1])] = \
        (60, 170, 210)
    table = table * (1 - m) + face * m
    del rows, cols, px_x, px_y, u, v, face

    # the camera: as near as keeps the page and the card in view, 5 % of the frame to spare
    w, h = size_px
    f_px = 0.8 * w                             # a phone's main camera: 64 deg across
    yaw = rng.uniform(-8, 8)
    scene = np.array([[-5.0, -90.0, 1.0], [305.0, -90.0, 1.0], [305.0, 215.0, 1.0], [-5.0, 215.0, 1.0]])
    distance = 200.0
    while True:
        H_plane = _camera(tilt_deg, yaw, (150.0, 62.0), distance, f_px * SUPERSAMPLE,
                          (w * SUPERSAMPLE, h * SUPERSAMPLE))
        v = scene @ H_plane.T
        uv = v[:, :2] / v[:, 2:] / SUPERSAMPLE
        if (v[:, 2] > 0).all() and (uv >= 0.05 * np.array(size_px)).all() and (uv <= 0.95 * np.array(size_px)).all():
            break
        distance *= 1.03
    tex_to_plane = np.array([[1 / k, 0, x0 + 0.5 / k], [0, -1 / k, y1 - 0.5 / k], [0, 0, 1]])
    big = cv2.warpPerspective(np.clip(table, 0, 255), H_plane @ tex_to_plane, (w * SUPERSAMPLE, h * SUPERSAMPLE),
                              flags=cv2.INTER_LINEAR, borderValue=(90, 90, 90))
    img = cv2.resize(big, size_px, interpolation=cv2.INTER_AREA)
    img = cv2.GaussianBlur(img, (0, 0), blur_px) + rng.normal(0, noise, img.shape)
    ok, jpeg = cv2.imencode(".jpg", np.clip(np.round(img), 0, 255).astype(np.uint8),
                            [cv2.IMWRITE_JPEG_QUALITY, jpeg_quality])
    photo = cv2.imdecode(jpeg, cv2.IMREAD_COLOR)

    # truth in the photo's pixels (OpenCV's: a supersampled pixel i covers [i - 0.5, i + 0.5])
    down = np.array([[1 / SUPERSAMPLE, 0, (1 / SUPERSAMPLE - 1) / 2], [0, 1 / SUPERSAMPLE, (1 / SUPERSAMPLE - 1) / 2],
                     [0, 0, 1]])
    board_to_plane = np.array([[print_scale, 0, origin[0]], [0, print_scale, origin[1]], [0, 0, 1]])
    board_to_image = down @ H_plane @ board_to_plane
    half = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * np.array(CARD_MM) / 2
    corners = np.array(centre) + half @ np.array([[c, sn], [-sn, c]])
    v = np.c_[corners, np.ones(4)] @ (down @ H_plane).T
    return photo, BoardPhotoTruth(print_scale, tilt_deg, board_to_image, v[:, :2] / v[:, 2:])
