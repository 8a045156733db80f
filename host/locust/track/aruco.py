"""ArUco markers: ``--marker nose=aruco:7`` (or ``aruco:7@DICT_5X5_100``).

Detected with ``cv2.aruco.ArucoDetector`` with sub-pixel corner refinement. The centre
is the intersection of the diagonals, which is the true centre of the square under
perspective; the side length in pixels gives a scale (``--scale-aruco ID=SIDE_M``).
The search is in a window around the predicted position first, then the whole image.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import TrackError
from .detection import Detection, window
from .predict import MotionHistory

DEFAULT_DICTIONARY = "DICT_4X4_50"


def make_detector(dictionary: str = DEFAULT_DICTIONARY) -> cv2.aruco.ArucoDetector:
    """An ArUco detector for ``dictionary`` with sub-pixel corner refinement.

    Parameters
    ----------
    dictionary : str
        One of ``cv2.aruco``'s predefined dictionaries, e.g. ``DICT_4X4_50``.

    Returns
    -------
    cv2.aruco.ArucoDetector
        The detector.

    Raises
    ------
    TrackError
        The dictionary is not one of OpenCV's.
    """
    if not dictionary.startswith("DICT_") or not hasattr(cv2.aruco, dictionary):
        raise TrackError(f"unknown ArUco dictionary {dictionary!r}",
                         "use one of cv2.aruco's names, e.g. DICT_4X4_50, DICT_5X5_100, DICT_6X6_250")
    params = cv2.aruco.DetectorParameters()
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    params.cornerRefinementWinSize = 3
    params.cornerRefinementMinAccuracy = 0.01
    params.cornerRefinementMaxIterations = 50
    return cv2.aruco.ArucoDetector(cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)), params)


def find_corners(detector: cv2.aruco.ArucoDetector, image_bgr: np.ndarray, marker_id: int) -> np.ndarray | None:
    """The four corners (4x2, pixels) of ``marker_id`` in ``image_bgr``, or None.

    Parameters
    ----------
    detector : cv2.aruco.ArucoDetector
        From :func:`make_detector`.
    image_bgr : ndarray
        The image, BGR or grey.
    marker_id : int
        The ArUco id.

    Returns
    -------
    ndarray or None
        (4, 2) corners [px], OpenCV's order; None when the marker is not seen.
    """
    gray = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2GRAY) if image_bgr.ndim == 3 else image_bgr
    corners, ids, _ = detector.detectMarkers(gray)
    if ids is None:
        return None
    hits = [c.reshape(4, 2) for c, i in zip(corners, ids.ravel()) if int(i) == marker_id]
    return hits[0].astype(np.float64) if hits else None


def centre_of(corners: np.ndarray) -> tuple[float, float]:
    """Intersection of the diagonals 0-2 and 1-3.

    Parameters
    ----------
    corners : ndarray
        (4, 2) corners in order [px].

    Returns
    -------
    tuple of float
        The centre (px, py) [px].
    """
    p0, p1, p2, p3 = corners
    d1, d2 = p2 - p0, p3 - p1
    a = np.array([d1, -d2]).T
    s, _ = np.linalg.solve(a, p1 - p0)
    c = p0 + s * d1
    return float(c[0]), float(c[1])


def side_px(corners: np.ndarray) -> float:
    """Mean side length of a marker's four-corner outline.

    Parameters
    ----------
    corners : ndarray
        (4, 2) corners in order [px].

    Returns
    -------
    float
        Mean side [px].
    """
    return float(np.mean(np.linalg.norm(corners - np.roll(corners, -1, axis=0), axis=1)))


@dataclass
class ArucoMarker:
    """An ArUco marker tracked by its id: searched near the predicted position, else in the
    whole frame; its position is the intersection of its diagonals.

    Attributes
    ----------
    name, spec : str
        The marker's name and its ``--marker`` spec.
    marker_id : int
        The ArUco id.
    dictionary : str
        The ArUco dictionary's name.
    history : MotionHistory
        Its last positions, for the search window.
    """

    name: str
    spec: str
    marker_id: int
    dictionary: str = DEFAULT_DICTIONARY
    history: MotionHistory = field(default_factory=MotionHistory)
    _detector: cv2.aruco.ArucoDetector | None = None
    _side_px: float = 0.0

    def locate(self, frame: int, image_bgr: np.ndarray) -> Detection:
        """Find the marker in one frame.

        Parameters
        ----------
        frame : int
            The frame number (frames come in order).
        image_bgr : ndarray
            The frame, BGR (or grey).

        Returns
        -------
        Detection
            Its centre [px]; ``score`` is its mean side length [px] (0 when not found).
        """
        if self._detector is None:
            self._detector = make_detector(self.dictionary)
        corners = None
        centre = self.history.search_centre()
        if centre is not None and self._side_px > 0:
            x0, y0, x1, y1 = window(centre, int(2 * self._side_px) + 8, image_bgr.shape)
            corners = find_corners(self._detector, image_bgr[y0:y1, x0:x1], self.marker_id)
            if corners is not None:
                corners += (x0, y0)
        if corners is None:
            corners = find_corners(self._detector, image_bgr, self.marker_id)
        if corners is None:
            self.history.add(None)
            return Detection.missing(0.0)
        self._side_px = side_px(corners)
        x, y = centre_of(corners)
        self.history.add((x, y))
        return Detection(x, y, self._side_px, True)


def side_px_in_video(info, clip, marker_id: int, dictionary: str = DEFAULT_DICTIONARY) -> tuple[int, float]:
    """The first frame of ``clip`` showing ``marker_id``, and the marker's side there (px).

    Parameters
    ----------
    info : VideoInfo
        The probed video.
    clip : Clip
        The resolved clip.
    marker_id : int
        The ArUco id.
    dictionary : str
        Its dictionary.

    Returns
    -------
    frame : int
        The first frame showing the marker.
    side_px : float
        Its mean side there [px].

    Raises
    ------
    TrackError
        The marker is in no frame of the clip.
    """
    from .video import read_frames

    detector = make_detector(dictionary)
    for frame, image in read_frames(info, clip):
        corners = find_corners(detector, image, marker_id)
        if corners is not None:
            return frame, side_px(corners)
    raise TrackError(f"ArUco marker {marker_id} ({dictionary}) is in no frame of {info.path.name} "
                     f"{clip.start}..{clip.end}",
                     "check the id and dictionary (e.g. 7=0.04 with --marker ...=aruco:7@DICT_4X4_50), "
                     "or calibrate with --scale")
