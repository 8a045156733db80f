"""Metres from the picture: a plane homography from an ArUco grid board, or four points.

``--board aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM`` names an OpenCV grid board
(``cv2.aruco.GridBoard``; DICT as OpenCV names it without ``DICT_``, e.g. ``4X4_50``)
lying in the plane the markers move in. It is detected in the first frames of the clip
(``cv2.aruco.ArucoDetector``, sub-pixel corners), every detected corner is matched to its
place on the board (``GridBoard.matchImagePoints``) and ``cv2.findHomography`` fits the
image -> plane map. ``--plane-points`` gives the same map from four (or more) pixels whose
plane coordinates were measured by hand.

Plane coordinates: metres, origin at the board's bottom-left corner (the outer corner of
the bottom-left marker), x along the board's bottom edge, y up the board. A homography is
exact for points *in* the plane; a marker in front of it (a sticker on a robot 2 cm
nearer the camera) reads a little off, by its distance over the camera's distance.

``locust track board FILE.png`` writes the board to print (:mod:`locust.track.boardsheet`: a
PNG at 300 DPI and a PDF of the sheet's size, with a 100 mm scale bar and the board's spec);
``--check PHOTO`` measures a print's scale (:mod:`locust.track.boardcheck`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import cv2
import numpy as np

# the board itself is defined once, beside the simulation's stills and the photo measurement
from ..arucoboard import DEFAULT_BOARD, MIN_BOARD_MARKERS, BoardSpec, parse_board  # noqa: F401
from ..errors import TrackError
from .calib import NUM, PIXEL_CONVENTIONS
from .video import read_frames

DETECT_FRAMES = 30       # frames searched for the board at the start of the clip
# --plane-points span an area: their narrowest spread at least this fraction of their widest
# (a sheet's corners seen at 80 deg from square still span 0.17); below it the map is a guess
MIN_POINT_SPREAD = 0.01


@dataclass(frozen=True)
class PlaneHomography:
    """Image pixels -> plane metres (x along the board, y up), through a 3x3 homography."""

    H: np.ndarray                      # image (px, py, 1) -> plane (x_m, y_m, 1)
    source: str
    residual_mm: float = math.nan      # RMS of the fitted points in the plane
    n_points: int = 0
    frame: int | None = None
    H_inv: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "H_inv", np.linalg.inv(self.H))

    @property
    def m_per_px(self) -> float:
        """Scale near the plane origin (a guide only: it varies across a tilted plane)."""
        o = self.H_inv @ np.array([0.0, 0.0, 1.0])
        o = o[:2] / o[2]
        x, _ = self.to_world(np.array([o[0], o[0] + 1.0]), np.array([o[1], o[1]]))
        y, _ = self.to_world(np.array([o[0], o[0]]), np.array([o[1], o[1] + 1.0]))
        return float(math.hypot(x[1] - x[0], y[1] - y[0]))

    def to_world(self, px: np.ndarray, py: np.ndarray, marker: str | None = None,
                 frames: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Pixels to plane metres through the homography.

        Parameters
        ----------
        px, py : ndarray
            Pixel positions, OpenCV convention [px].
        marker : str, optional
            Unused (one plane for every marker); there for the calibrations' common call.
        frames : ndarray, optional
            Unused (a fixed camera); there for the calibrations' common call.

        Returns
        -------
        x_m, y_m : ndarray
            Positions in the plane, origin at its corner, y up [m].
        """
        px, py = np.asarray(px, float), np.asarray(py, float)
        v = np.stack([px, py, np.ones_like(px)], axis=-1) @ self.H.T
        with np.errstate(divide="ignore", invalid="ignore"):
            return v[..., 0] / v[..., 2], v[..., 1] / v[..., 2]

    def to_image(self, x_m: np.ndarray, y_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Plane metres to pixels through the inverse homography.

        Parameters
        ----------
        x_m, y_m : ndarray
            Positions in the plane [m].

        Returns
        -------
        px, py : ndarray
            Pixel positions, OpenCV convention [px].
        """
        v = np.stack([np.asarray(x_m, float), np.asarray(y_m, float), np.ones(np.shape(x_m))], axis=-1) @ self.H_inv.T
        return v[..., 0] / v[..., 2], v[..., 1] / v[..., 2]

    def axes_px(self):
        """The plane's origin in pixels and the on-screen unit directions of its x and y axes.

        Returns
        -------
        origin : tuple of float
            (px, py) of the plane's origin [px].
        x_dir, y_dir : tuple of float
            Unit vectors in the image of the plane's +x and +y.
        """
        o = self.to_image(np.array([0.0, 0.01, 0.0]), np.array([0.0, 0.0, 0.01]))
        uv = np.stack(o, axis=-1)
        dirs = [(uv[k] - uv[0]) / np.linalg.norm(uv[k] - uv[0]) for k in (1, 2)]
        return tuple(uv[0]), tuple(dirs[0]), tuple(dirs[1])

    def summary(self) -> str:
        """One line saying where the plane comes from, its fit residual [mm] and scale [mm/px].

        Returns
        -------
        str
            The line.
        """
        where = f" on frame {self.frame}" if self.frame is not None else ""
        return (f"plane from {self.source}{where}: {self.n_points} points, fit residual {self.residual_mm:.2f} mm; "
                f"x_m/y_m in the plane, origin at its corner, y up (about {self.m_per_px * 1000:.3g} mm/px there)")

    def as_dict(self) -> dict:
        """The calibration as the tracks' JSON sidecar records it.

        Returns
        -------
        dict
            Source, model, the 3x3 image-to-plane homography, fit residual [mm], points and frame.
        """
        return {"source": self.source, "model": "plane homography, image px -> plane m (y up)",
                "H_image_to_plane": self.H.tolist(), "fit_residual_mm": self.residual_mm,
                "points": self.n_points, "frame": self.frame}


def _fit(image_pts: np.ndarray, plane_pts: np.ndarray, source: str, frame: int | None = None) -> PlaneHomography:
    H, _ = cv2.findHomography(image_pts.astype(np.float64), plane_pts.astype(np.float64), 0)
    if H is None or not np.isfinite(H).all() or abs(np.linalg.det(H)) < 1e-300:
        raise TrackError(f"{source}: no homography fits these points",
                         "the points must not lie on one line; spread them over the plane")
    v = np.c_[image_pts, np.ones(len(image_pts))] @ H.T
    resid = np.hypot(*(v[:, :2] / v[:, 2:] - plane_pts).T)
    return PlaneHomography(H, source, float(np.sqrt(np.mean(resid ** 2)) * 1000.0), len(image_pts), frame)


def board_points(spec: BoardSpec, image_bgr: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Detected board corners in ``image_bgr`` (px) and their plane positions (m, y up), or None.

    Parameters
    ----------
    spec : BoardSpec
        The board.
    image_bgr : ndarray
        A frame, BGR.

    Returns
    -------
    tuple of ndarray or None
        (N, 2) corners [px] and (N, 2) plane positions [m]; None when fewer than the board's
        minimum of markers are seen.
    """
    from .aruco import make_detector

    gray = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2GRAY) if image_bgr.ndim == 3 else image_bgr
    corners, ids, _ = make_detector(spec.dictionary).detectMarkers(gray)
    if ids is None or len(ids) < MIN_BOARD_MARKERS:
        return None
    obj, img = spec.board().matchImagePoints(corners, ids)
    if obj is None or len(obj) < 4 * MIN_BOARD_MARKERS:
        return None
    obj = obj.reshape(-1, 3)
    plane = np.c_[obj[:, 0], spec.height_mm / 1000.0 - obj[:, 1]]   # OpenCV's board: y down from the top
    return img.reshape(-1, 2).astype(np.float64), plane


@dataclass(frozen=True)
class BoardView:
    """A board found in one photo: its corners, the homography from its plane onto the photo,
    and the corners' reprojection scatter.

    Attributes
    ----------
    corners_px : ndarray
        (N, 2) detected corners [px].
    corners_m : ndarray
        (N, 2) their places on the board [m], x right, y up.
    homography : ndarray
        (3, 3) board plane [m] -> photo [px] (``cv2.findHomography``, all corners).
    sd_px : float
        The corners' reprojection scatter, one coordinate [px] (the fit's 8 parameters taken off).
    """

    corners_px: np.ndarray
    corners_m: np.ndarray
    homography: np.ndarray
    sd_px: float


def board_view(spec: BoardSpec, image_bgr: np.ndarray) -> BoardView | None:
    """The board in a photo (:func:`board_points`) with its homography and scatter; None when
    it is not found.

    Parameters
    ----------
    spec : BoardSpec
        The printed board.
    image_bgr : ndarray
        The photo, BGR.

    Returns
    -------
    BoardView or None
    """
    found = board_points(spec, image_bgr)
    if found is None:
        return None
    img, plane = found
    H, _ = cv2.findHomography(plane, img, 0)
    back = cv2.perspectiveTransform(plane[None], H)[0]
    sd = float(np.sqrt(np.sum((back - img) ** 2) / max(2 * len(img) - 8, 1)))
    return BoardView(img, plane, H, sd)


def scale_px_per_m(H: np.ndarray, x: float, y: float) -> float:
    """The local scale of a plane -> image homography at plane point (x, y): the square root of
    its Jacobian's determinant [px/m].

    Parameters
    ----------
    H : ndarray
        (3, 3) plane [m] -> image [px].
    x, y : float
        The plane point [m].

    Returns
    -------
    float
    """
    v = H @ np.array([x, y, 1.0])
    J = (H[:2, :2] * v[2] - np.outer(v[:2], H[2, :2])) / v[2] ** 2
    return math.sqrt(abs(np.linalg.det(J)))


def edge_scales(H: np.ndarray, spec: BoardSpec) -> dict[tuple[str, str], tuple[float, float]]:
    """The scale at the middle of each pair of the board's opposite edges: a board seen square
    has them equal, one seen at a slant has its nearer edge larger.

    Parameters
    ----------
    H : ndarray
        (3, 3) board plane [m] -> photo [px].
    spec : BoardSpec

    Returns
    -------
    dict
        ``("left", "right")`` and ``("bottom", "top")`` -> the two edges' scales [px/m].
    """
    w, h = spec.width_mm / 1000.0, spec.height_mm / 1000.0
    pairs = {("left", "right"): ((0.0, h / 2), (w, h / 2)), ("bottom", "top"): ((w / 2, 0.0), (w / 2, h))}
    return {names: (scale_px_per_m(H, *pa), scale_px_per_m(H, *pb)) for names, (pa, pb) in pairs.items()}


def board_homography(info, clip, spec: BoardSpec, frames: int = DETECT_FRAMES) -> PlaneHomography:
    """Fit the plane to the board's corners in every one of the clip's first ``frames`` frames
    that shows it (a still camera: the corners' noise averages out over the frames).

    Parameters
    ----------
    info : VideoInfo
        The probed video.
    clip : Clip
        The resolved clip.
    spec : BoardSpec
        The board filmed.
    frames : int
        How many of the clip's first frames to look in.

    Returns
    -------
    PlaneHomography
        Pixels to plane metres, with its fit residual [mm].

    Raises
    ------
    TrackError
        The board is in none of those frames, or no homography fits.
    """
    image_pts, plane_pts, first = [], [], None
    for k, (frame, image) in enumerate(read_frames(info, clip)):
        if k >= frames:
            break
        found = board_points(spec, image)
        if found is not None:
            image_pts.append(found[0])
            plane_pts.append(found[1])
            first = frame if first is None else first
    if not image_pts:
        raise TrackError(f"board {spec.text()} not found in the first {frames} frames of {info.path.name}",
                         "check the dictionary, the marker count and that the board is in view and sharp; "
                         "or give --plane-points")
    return _fit(np.vstack(image_pts), np.vstack(plane_pts), f"board {spec.text()} ({len(image_pts)} frames)", first)


def parse_plane_points(text: str, pixels: str = "tracker") -> PlaneHomography:
    """``PX,PY=X_M,Y_M;...`` (four or more) -> the homography through them; the pixels typed
    in convention ``pixels`` (:func:`locust.track.spec.typed_px`).

    Parameters
    ----------
    text : str
        The ``--plane-points`` value: pixels and plane metres.
    pixels : str
        ``tracker`` or ``opencv``.

    Returns
    -------
    PlaneHomography
        Pixels to plane metres.

    Raises
    ------
    TrackError
        Fewer than four points, a bad number, or points on one line.
    """
    pairs = [p for p in re.split(r"[;\s]+", text.strip()) if p]
    rx = re.compile(rf"({NUM}),({NUM})=({NUM}),({NUM})")
    rows = [rx.fullmatch(p) for p in pairs]
    if len(rows) < 4 or not all(rows):
        raise TrackError(f"--plane-points {text!r}: expected four or more PX,PY=X_M,Y_M separated by ';'",
                         "e.g. --plane-points '102,880=0,0;1650,870=1.2,0;1600,240=1.2,0.5;150,250=0,0.5'")
    v = np.array([[float(x) for x in m.groups()] for m in rows])
    v[:, :2] += PIXEL_CONVENTIONS[pixels]
    for pts, unit, what in ((v[:, :2], "px", "pixels"), (v[:, 2:], "m", "plane positions")):
        if not np.isfinite(pts).all() or len(np.unique(pts, axis=0)) < 4 or _spread(pts) < MIN_POINT_SPREAD:
            raise TrackError(f"--plane-points {text!r}: the {what} are not four distinct points spread off one line "
                             f"(their narrowest spread under {MIN_POINT_SPREAD:g} of their widest)",
                             f"give four or more points spread over the plane ({unit}), no three of them on one "
                             "line, e.g. the corners of a sheet")
    return _fit(v[:, :2], v[:, 2:], "plane points")


def _spread(pts: np.ndarray) -> float:
    """How far ``pts`` are from lying on one line: the ratio of the smaller to the larger
    singular value of the centred points (0 on a line)."""
    sv = np.linalg.svd(pts - pts.mean(axis=0), compute_uv=False)
    return float(sv[-1] / sv[0]) if sv[0] > 0 else 0.0
