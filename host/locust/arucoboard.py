"""The ArUco grid board a photo or a clip is measured against, as printed.

``aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM`` names an OpenCV grid board (``cv2.aruco.GridBoard``;
DICT as OpenCV names it without ``DICT_``). The tracker finds it in a clip
(:mod:`locust.track.board`), ``locust measure stance`` in a photo, and the simulation draws
it into its stills (:mod:`locust.sim.still`): one definition for all three.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import cv2
import numpy as np

from .errors import TrackError

BOARD_MARGIN_MM = 10.0
DEFAULT_BOARD = "aruco:4X4_50:5x4:40:10"   # 240 x 190 mm: fits an A4 sheet
MIN_BOARD_MARKERS = 2    # 8 corners: enough for a homography, with some redundancy
# A printed marker: at 300 dpi a 4x4 marker's 6 cells need 1 mm at least; a board is printed
# on at most an A0 sheet (1189 mm).
BOARD_MARKER_MM = (1.0, 500.0)
BOARD_MAX_MM = 1189.0


@dataclass(frozen=True)
class BoardSpec:
    """An ArUco grid board, as printed."""

    dictionary: str          # cv2.aruco name, e.g. DICT_4X4_50
    cols: int
    rows: int
    marker_mm: float
    gap_mm: float

    @property
    def width_mm(self) -> float:
        """The printed grid's width, markers and gaps [mm]."""
        return self.cols * self.marker_mm + (self.cols - 1) * self.gap_mm

    @property
    def height_mm(self) -> float:
        """The printed grid's height, markers and gaps [mm]."""
        return self.rows * self.marker_mm + (self.rows - 1) * self.gap_mm

    def text(self) -> str:
        """The board as the command line spells it: ``aruco:4X4_50:COLSxROWS:MARKER_MM:GAP_MM``.

        Returns
        -------
        str
        """
        return f"aruco:{self.dictionary[5:]}:{self.cols}x{self.rows}:{self.marker_mm:g}:{self.gap_mm:g}"

    def board(self) -> cv2.aruco.GridBoard:
        """OpenCV's grid board, its marker and gap in metres.

        Returns
        -------
        cv2.aruco.GridBoard
        """
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        return cv2.aruco.GridBoard((self.cols, self.rows), self.marker_mm / 1000.0, self.gap_mm / 1000.0, d)

    def image(self, px_per_mm: float, margin_mm: float = BOARD_MARGIN_MM) -> np.ndarray:
        """The board drawn at ``px_per_mm``, with a white margin (grey levels, uint8): marker k
        at column k % cols, row k // cols from the top, as ``cv2.aruco.GridBoard`` numbers them.

        Parameters
        ----------
        px_per_mm : float
            Resolution [px/mm].
        margin_mm : float
            The white margin [mm].

        Returns
        -------
        numpy.ndarray
            2-D uint8.
        """
        d = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, self.dictionary))
        to_px = lambda mm: int(round(mm * px_per_mm))   # noqa: E731
        img = np.full((to_px(self.height_mm + 2 * margin_mm), to_px(self.width_mm + 2 * margin_mm)), 255, np.uint8)
        for k in range(self.cols * self.rows):
            x0 = to_px(margin_mm + (k % self.cols) * (self.marker_mm + self.gap_mm))
            y0 = to_px(margin_mm + (k // self.cols) * (self.marker_mm + self.gap_mm))
            x1 = to_px(margin_mm + (k % self.cols) * (self.marker_mm + self.gap_mm) + self.marker_mm)
            y1 = to_px(margin_mm + (k // self.cols) * (self.marker_mm + self.gap_mm) + self.marker_mm)
            side = max(x1 - x0, y1 - y0)
            img[y0:y0 + side, x0:x0 + side] = cv2.aruco.generateImageMarker(d, k, side, borderBits=1)
        return img


def parse_board(text: str) -> BoardSpec:
    """``aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM`` -> :class:`BoardSpec`.

    Parameters
    ----------
    text : str
        e.g. ``aruco:4X4_50:5x7:30:6`` (sizes in mm).

    Returns
    -------
    BoardSpec

    Raises
    ------
    locust.errors.TrackError
        Not that form, an unknown dictionary, too few markers or too many for the dictionary,
        or sizes no printed board has.
    """
    m = re.fullmatch(r"\s*aruco:(\w+):(\d+)[xX](\d+):(\d+(?:\.\d*)?):(\d+(?:\.\d*)?)\s*", text)
    hint = "e.g. --board aruco:4X4_50:5x4:40:10 (5 x 4 markers of 40 mm, 10 mm apart)"
    if not m:
        raise TrackError(f"--board {text!r}: expected aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM", hint)
    name = m.group(1).upper()
    dictionary = name if name.startswith("DICT_") else f"DICT_{name}"
    if not hasattr(cv2.aruco, dictionary):
        raise TrackError(f"--board {text!r}: unknown ArUco dictionary {m.group(1)!r}",
                         "use OpenCV's name without DICT_, e.g. 4X4_50, 5X5_100, 6X6_250")
    cols, rows, marker_mm, gap_mm = int(m.group(2)), int(m.group(3)), float(m.group(4)), float(m.group(5))
    if cols < 1 or rows < 1 or cols * rows < MIN_BOARD_MARKERS or not marker_mm > 0 or gap_mm < 0:
        raise TrackError(f"--board {text!r}: needs at least {MIN_BOARD_MARKERS} markers of positive size", hint)
    low, high = BOARD_MARKER_MM
    if not low <= marker_mm <= high:
        raise TrackError(f"--board {text!r}: markers of {marker_mm:g} mm; a printed marker is {low:g} to {high:g} mm "
                         f"(below {low:g} mm a 300 dpi print cannot draw its cells)", hint)
    width_mm = max(cols, rows) * (marker_mm + gap_mm)
    if width_mm > BOARD_MAX_MM:
        raise TrackError(f"--board {text!r}: {width_mm:g} mm across; a printed board is at most {BOARD_MAX_MM:g} mm "
                         "(A0's long side)", hint)
    spec = BoardSpec(dictionary, cols, rows, marker_mm, gap_mm)
    n_ids = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, dictionary)).bytesList.shape[0]
    if cols * rows > n_ids:
        raise TrackError(f"--board {text!r}: {cols * rows} markers, but {dictionary} holds {n_ids}",
                         "use a larger dictionary or fewer markers")
    return spec
