"""By how much a printer scaled the board: ``locust track board --check PHOTO``.

A photo alone cannot tell a board printed at 97 % from one photographed from farther away:
the check needs something of known size in the board's plane. That is an ID-1 card (ISO/IEC
7810: 85.60 x 53.98 mm; a bank, student, library or ID card), laid flat on the table beside
the printed sheet, its whole outline in view, on a surface it stands out from.

The board's corners (``cv2.aruco``'s detector, matched to their board places as
``locust track`` does) give the image -> board-plane homography in the millimetres the board
would have at 100 % (``cv2.findHomography``). The card is found in the photo made square to
the board (``cv2.warpPerspective``): a closed outline of the card's proportions and a
plausible size. Each of its four straight edges is then located along 40 cross-sections
(the steepest colour change, to a tenth of a pixel) and fitted as a line; the corners are
where the lines meet (the rounded corners are left out). In the print's millimetres the card
measures ``true / scale``: the scale is the card's true perimeter over its measured one.

Interval (95 %): a parametric bootstrap: each draw moves every detected board corner by the
board's own reprojection scatter and every edge point by its line's residual scatter, and
takes the card's size anywhere within ISO/IEC 7810's tolerance (85.60 +- 0.12 mm, 53.98 +-
0.05 mm).

The camera's angle to the board comes from the board's own pose (``cv2.calibrateCamera``
on the one view, its focal length free, the principal point at the centre, no distortion):
past :data:`OBLIQUE_DEG` the photo is said to be too oblique (a sheet or card lifted off the
table by a fraction of a millimetre reads off by that lift times the angle's tangent).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..arucoboard import BOARD_MARGIN_MM, BoardSpec
from ..errors import TrackError
from ..fileio import opencv_path

CARD_MM = (85.60, 53.98)                 # ISO/IEC 7810 ID-1
CARD_TOLERANCE_MM = (0.12, 0.05)         # its width 85.47 .. 85.72, its height 53.92 .. 54.03 mm
CARD_RADIUS_MM = 3.18
# a print between 80 % and 125 % of its size; beyond, a "fit to page" is not what happened
SCALE_RANGE = (0.8, 1.25)
ASPECT_TOLERANCE = 0.06
OBLIQUE_DEG = 35.0
TRUE_TO_SIZE = 0.005                     # within 0.5 %: as printers print at 100 %
SEARCH_MM = 160.0                        # how far beside the sheet the card is looked for
PROFILES = 40                            # cross-sections per edge
DRAWS = 400
INTERVAL = 0.95


@dataclass(frozen=True)
class PrintCheck:
    """What a photo of the printed board says of the print.

    Attributes
    ----------
    photo : Path
        The photo.
    board : str
        The board, as ``--board`` spells it.
    scale : float
        The print's size over its intended size (1: printed at 100 %).
    scale_low, scale_high : float
        Its 95 % interval.
    card_mm : tuple of float
        The card's long and short sides in the print's millimetres (at 100 %) [mm].
    markers : int
        Board markers found.
    tilt_deg : float
        The camera's axis from the board's normal [deg]; nan when the photo cannot tell.
    """

    photo: Path
    board: str
    scale: float
    scale_low: float
    scale_high: float
    card_mm: tuple[float, float]
    markers: int
    tilt_deg: float

    @property
    def true_to_size(self) -> bool:
        """Whether the print is within 0.5 % (or its interval) of 100 %."""
        return self.scale_low <= 1.0 <= self.scale_high or abs(self.scale - 1.0) <= TRUE_TO_SIZE

    @property
    def oblique(self) -> bool:
        """Whether the photo is more than :data:`OBLIQUE_DEG` from square to the board."""
        return math.isfinite(self.tilt_deg) and self.tilt_deg > OBLIQUE_DEG

    def measured_board(self, spec: BoardSpec) -> str:
        """The board as printed, in ``--board``'s spelling: its sizes times the scale.

        Parameters
        ----------
        spec : BoardSpec
            The board as intended.

        Returns
        -------
        str
        """
        return (f"aruco:{spec.dictionary[5:]}:{spec.cols}x{spec.rows}:{spec.marker_mm * self.scale:.1f}:"
                f"{spec.gap_mm * self.scale:.1f}")

    def lines(self, spec: BoardSpec) -> list[str]:
        """What the check says, for a person.

        Parameters
        ----------
        spec : BoardSpec
            The board as intended.

        Returns
        -------
        list of str
            The finding, the verdict and what to do; a ``warning:`` line for an oblique photo.
        """
        pct = lambda v: f"{v * 100:.1f} %"   # noqa: E731
        out = [f"{self.photo.name}: board {self.board} ({self.markers} markers) and a card of "
               f"{self.card_mm[0]:.2f} x {self.card_mm[1]:.2f} mm in the board's millimetres (ID-1: "
               f"{CARD_MM[0]:.2f} x {CARD_MM[1]:.2f} mm)"]
        where = f"printed at {pct(self.scale)} of its size (95 % interval {pct(self.scale_low)} .. " \
                f"{pct(self.scale_high)})"
        if self.true_to_size:
            out.append(f"{where}: true to size; markers {spec.marker_mm:g} mm as --board says")
        else:
            out.append(f"{where}: the printer scaled it; its markers are {spec.marker_mm * self.scale:.1f} mm, "
                       f"not {spec.marker_mm:g}")
            out.append(f"hint: reprint at 100 % (actual size, no fit to page), or track with the board as printed: "
                       f"--board {self.measured_board(spec)}")
        if math.isfinite(self.tilt_deg):
            out.append(f"photo {self.tilt_deg:.0f} deg from square to the board")
        if self.oblique:
            out.append(f"warning: the photo is {self.tilt_deg:.0f} deg from square to the board (over "
                       f"{OBLIQUE_DEG:g} deg): a sheet or card lifted off the table reads off by the lift times "
                       f"{math.tan(math.radians(self.tilt_deg)):.1f}; photograph it from straight above")
        return out


# -- the board ----------------------------------------------------------------------------
def _homography(img_px: np.ndarray, board_mm: np.ndarray) -> np.ndarray:
    H, _ = cv2.findHomography(img_px, board_mm, 0)
    if H is None:
        raise TrackError("no homography fits the board's corners", "photograph the whole board, sharp")
    return H


def _apply(H: np.ndarray, pts: np.ndarray) -> np.ndarray:
    v = np.c_[pts, np.ones(len(pts))] @ H.T
    return v[:, :2] / v[:, 2:]


def tilt_deg(img_px: np.ndarray, board_mm: np.ndarray, size_px: tuple[int, int]) -> float:
    """The camera's axis from the board's normal, from the board's pose in this one view.

    Parameters
    ----------
    img_px : ndarray
        (N, 2) its detected corners [px].
    board_mm : ndarray
        (N, 2) their board places [mm].
    size_px : tuple of int
        The photo (width, height) [px].

    Returns
    -------
    float
        The angle [deg]; nan when the view fixes no plausible focal length (a board seen
        almost square on leaves it free: then the angle is small, but not known).
    """
    w, h = size_px
    K0 = np.array([[max(w, h), 0, (w - 1) / 2], [0, max(w, h), (h - 1) / 2], [0, 0, 1]], np.float64)
    flags = (cv2.CALIB_USE_INTRINSIC_GUESS | cv2.CALIB_FIX_PRINCIPAL_POINT | cv2.CALIB_FIX_ASPECT_RATIO
             | cv2.CALIB_ZERO_TANGENT_DIST | cv2.CALIB_FIX_K1 | cv2.CALIB_FIX_K2 | cv2.CALIB_FIX_K3)
    obj = np.c_[board_mm, np.zeros(len(board_mm))].astype(np.float32)
    try:
        _, K, _, rvecs, _ = cv2.calibrateCamera([obj], [img_px.astype(np.float32)], (w, h), K0, np.zeros(5),
                                                flags=flags)
    except cv2.error:
        return math.nan
    f = K[0, 0]
    if not 0.3 * max(w, h) <= f <= 5.0 * max(w, h):
        return math.nan
    R, _ = cv2.Rodrigues(rvecs[0])
    return float(math.degrees(math.acos(min(1.0, abs(R[2, 2])))))


# -- the card ------------------------------------------------------------------------------
def _square_view(image: np.ndarray, H_img_to_mm: np.ndarray, spec: BoardSpec, px_per_mm: float):
    """The photo made square to the board around the sheet, and its pixel -> board mm map."""
    from .boardsheet import layout

    lay = layout(spec)
    m = BOARD_MARGIN_MM
    x0, x1 = -m - SEARCH_MM, lay.width_mm - m + SEARCH_MM
    y0, y1 = -m - SEARCH_MM, lay.height_mm - m + SEARCH_MM
    w, h = int((x1 - x0) * px_per_mm), int((y1 - y0) * px_per_mm)
    view_to_mm = np.array([[1 / px_per_mm, 0, x0], [0, -1 / px_per_mm, y1], [0, 0, 1]])
    view_to_img = np.linalg.inv(H_img_to_mm) @ view_to_mm
    sq = cv2.warpPerspective(image, view_to_img, (w, h), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                             borderMode=cv2.BORDER_CONSTANT, borderValue=(0, 0, 0))
    inside = cv2.warpPerspective(np.full(image.shape[:2], 255, np.uint8), view_to_img, (w, h),
                                 flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP)
    # the sheet itself (its markers and text) is no card
    sheet = np.array([[-m, -m], [lay.width_mm - m, -m], [lay.width_mm - m, lay.height_mm - m],
                      [-m, lay.height_mm - m]])
    corners = _apply(np.linalg.inv(view_to_mm), sheet)
    cv2.fillConvexPoly(inside, np.round(corners).astype(np.int32), 0)
    return sq, inside, view_to_mm


def find_card(image: np.ndarray, H_img_to_mm: np.ndarray, spec: BoardSpec, px_per_mm: float):
    """The card's outline in the square view: (centre, (long, short), angle) in board mm.

    Parameters
    ----------
    image : ndarray
        The photo, BGR.
    H_img_to_mm : ndarray
        Image px -> board mm (at 100 %).
    spec : BoardSpec
        The board.
    px_per_mm : float
        The square view's resolution [px/mm].

    Returns
    -------
    tuple
        ``cv2.minAreaRect``'s (centre, size, angle) in the square view's pixels, and the
        view's pixel -> mm map.

    Raises
    ------
    TrackError
        No outline of a card's proportions beside the board.
    """
    sq, inside, view_to_mm = _square_view(image, H_img_to_mm, spec, px_per_mm)
    grey = cv2.cvtColor(sq, cv2.COLOR_BGR2GRAY)
    best, best_err = None, math.inf
    long_mm = [CARD_MM[0] / s for s in SCALE_RANGE[::-1]]
    edges = np.zeros_like(grey)
    for channel in (grey, *cv2.split(sq)):
        edges |= cv2.Canny(cv2.GaussianBlur(channel, (0, 0), 1.0), 20, 60)
    edges = cv2.dilate(edges, np.ones((3, 3), np.uint8)) & cv2.erode(inside, np.ones((7, 7), np.uint8))
    contours, _ = cv2.findContours(edges, cv2.RETR_LIST, cv2.CHAIN_APPROX_NONE)
    aspect = CARD_MM[0] / CARD_MM[1]
    for c in contours:
        if len(c) < 20:
            continue
        rect = cv2.minAreaRect(c)
        a, b = sorted(rect[1], reverse=True)
        if b <= 0:
            continue
        la, lb = a / px_per_mm, b / px_per_mm
        err = abs(la / lb / aspect - 1.0)
        fill = cv2.contourArea(cv2.convexHull(c)) / (a * b)
        if long_mm[0] <= la <= long_mm[1] and err <= ASPECT_TOLERANCE and fill >= 0.9 and err < best_err:
            best, best_err = rect, err
    if best is None:
        raise TrackError("no card found beside the board",
                         "lay an ID-1 card (a bank, student or library card, 85.60 x 53.98 mm) flat on the table "
                         "beside the printed sheet, not touching it, its whole outline in view, on a surface it "
                         "stands out from; or lay a ruler along the sheet's 100 mm bar: a 97 mm bar is a 97 % print")
    return best, view_to_mm


def _edge_points(image: np.ndarray, H_mm_to_img: np.ndarray, p0: np.ndarray, p1: np.ndarray,
                 normal: np.ndarray) -> np.ndarray:
    """Where the colour changes most steeply across the edge p0-p1 (board mm), at PROFILES
    cross-sections over its straight middle, as photo pixels."""
    img = image.astype(np.float32)
    length = np.linalg.norm(p1 - p0)
    keep = max(0.0, 1.0 - 2.5 * CARD_RADIUS_MM / length)      # clear of the rounded corners
    ts = 0.5 + (np.arange(PROFILES) / (PROFILES - 1) - 0.5) * keep
    offsets = np.linspace(-3.0, 3.0, 121)                     # mm across the edge, 0.05 mm apart
    out = []
    for t in ts:
        line_mm = (p0 + t * (p1 - p0))[None] + offsets[:, None] * normal[None]
        px = _apply(H_mm_to_img, line_mm).astype(np.float32)
        samples = cv2.remap(img, px[:, 0].reshape(1, -1), px[:, 1].reshape(1, -1), cv2.INTER_LINEAR)[0]
        # the colour's rate of change along the cross-section, all channels, smoothed over 0.25 mm
        grad = np.sqrt((np.gradient(samples.reshape(len(offsets), -1), axis=0) ** 2).sum(axis=1))
        grad = np.convolve(grad, np.ones(5) / 5, mode="same")
        k = int(np.argmax(grad[3:-3])) + 3
        y0, y1, y2 = grad[k - 1], grad[k], grad[k + 1]
        den = y0 - 2 * y1 + y2
        shift = 0.5 * (y0 - y2) / den if den < 0 else 0.0
        off = offsets[k] + shift * (offsets[1] - offsets[0])
        out.append(_apply(H_mm_to_img, (p0 + t * (p1 - p0) + off * normal)[None])[0])
    return np.array(out)


def _fit_line(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Total least squares: (a point, its unit direction, the residual sd), after one pass
    that drops points more than 3 robust sd off."""
    for _ in range(2):
        c = pts.mean(axis=0)
        _, _, vt = np.linalg.svd(pts - c)
        d, n = vt[0], vt[1]
        r = (pts - c) @ n
        sd = 1.4826 * np.median(np.abs(r - np.median(r)))
        keep = np.abs(r) <= 3 * max(sd, 1e-9)
        if keep.all():
            break
        pts = pts[keep]
    return c, d, float(np.std(r, ddof=2)) if len(r) > 2 else 0.0


def _meet(c1, d1, c2, d2) -> np.ndarray:
    A = np.array([d1, -d2]).T
    s = np.linalg.solve(A, c2 - c1)
    return c1 + s[0] * d1


def _perimeter_mm(H_img_to_mm: np.ndarray, sides_px: list[np.ndarray]) -> tuple[float, float]:
    """The card's long and short sides in board mm, from its four edges' points (photo px):
    each edge fitted as a line in board mm, the corners where they meet."""
    lines = [_fit_line(_apply(H_img_to_mm, s))[:2] for s in sides_px]
    corners = [_meet(*lines[k], *lines[(k + 1) % 4]) for k in range(4)]
    sides = [np.linalg.norm(corners[(k + 1) % 4] - corners[k]) for k in range(4)]
    # the edges go long, short, long, short: corner k ends edge k
    return (sides[1] + sides[3]) / 2, (sides[0] + sides[2]) / 2


def check_print(photo: Path, spec: BoardSpec, draws: int = DRAWS, seed: int = 0) -> PrintCheck:
    """Measure a photo of the printed board and a card beside it: the print's scale.

    Parameters
    ----------
    photo : Path
        The photo (PNG or JPEG).
    spec : BoardSpec
        The board as intended (``--board``).
    draws : int
        Bootstrap draws for the interval.
    seed : int
        The bootstrap's seed.

    Returns
    -------
    PrintCheck
        The scale, its interval, the card as measured and the camera's angle.

    Raises
    ------
    TrackError
        Not a readable image, no board, or no card.
    """
    from .board import board_points

    if not photo.is_file():
        raise TrackError(f"--check {photo}: no such file", "give the photo of the printed board and the card")
    with opencv_path(photo) as name:
        image = cv2.imread(name, cv2.IMREAD_COLOR)
    if image is None:
        raise TrackError(f"--check {photo}: not a readable image", "give a photo as JPEG or PNG")
    found = board_points(spec, image)
    if found is None:
        raise TrackError(f"--check {photo}: board {spec.text()} not found",
                         "the whole sheet must be in the photo, sharp and lit evenly; check --board against the "
                         "sheet's own label")
    img_px, board_m = found
    board_mm = board_m * 1000.0
    H = _homography(img_px, board_mm)
    back = _apply(np.linalg.inv(H), board_mm)
    corner_sd = float(np.sqrt(np.sum((back - img_px) ** 2) / max(2 * len(img_px) - 8, 1)))
    # the square view at about the photo's own resolution on the board
    centre = np.array([[spec.width_mm / 2, spec.height_mm / 2]])
    J = np.array([_apply(np.linalg.inv(H), centre + d)[0] for d in ([0, 0], [1, 0], [0, 1])])
    px_per_mm = float(np.clip(math.sqrt(abs(np.linalg.det(np.array([J[1] - J[0], J[2] - J[0]])))), 2.0, 8.0))
    rect, view_to_mm = find_card(image, H, spec, px_per_mm)

    # the rectangle's corners in board mm, its edges long, short, long, short
    box = _apply(view_to_mm, cv2.boxPoints(rect).astype(np.float64))
    if np.linalg.norm(box[1] - box[0]) < np.linalg.norm(box[2] - box[1]):
        box = np.roll(box, -1, axis=0)
    middle = box.mean(axis=0)
    H_inv = np.linalg.inv(H)
    sides_px = []
    for k in range(4):
        p0, p1 = box[k], box[(k + 1) % 4]
        d = (p1 - p0) / np.linalg.norm(p1 - p0)
        n = np.array([-d[1], d[0]])
        n = n if np.dot(n, (p0 + p1) / 2 - middle) > 0 else -n
        sides_px.append(_edge_points(image, H_inv, p0, p1, n))
    long_mm, short_mm = _perimeter_mm(H, sides_px)
    scale = (CARD_MM[0] + CARD_MM[1]) / (long_mm + short_mm)

    # the interval: the board's corners, the edge points and the card's own tolerance drawn
    rng = np.random.default_rng(seed)
    edge_sd = []
    for s in sides_px:       # each edge's scatter about its line, in photo px
        c, d, _ = _fit_line(s)
        edge_sd.append(float(np.std((s - c) @ np.array([-d[1], d[0]]), ddof=2)))
    scales = np.empty(draws)
    for i in range(draws):
        Hd = _homography(img_px + rng.normal(0, corner_sd, img_px.shape), board_mm)
        sd_pts = [s + rng.normal(0, sd, s.shape) for s, sd in zip(sides_px, edge_sd)]
        lm, sm = _perimeter_mm(Hd, sd_pts)
        true = [CARD_MM[j] + rng.uniform(-1, 1) * CARD_TOLERANCE_MM[j] for j in (0, 1)]
        scales[i] = (true[0] + true[1]) / (lm + sm)
    low, high = np.quantile(scales, [(1 - INTERVAL) / 2, (1 + INTERVAL) / 2])
    tilt = tilt_deg(img_px, board_mm, (image.shape[1], image.shape[0]))
    return PrintCheck(photo, spec.text(), float(scale), float(low), float(high), (long_mm, short_mm),
                      len(img_px) // 4, tilt)
