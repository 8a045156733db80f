"""Coloured stickers: ``--marker nose=color:#ff00ff``.

Colour picks the marker, brightness locates it. Pixels within ``tolerance`` of the
marker colour (largest channel difference, 0-255) form the core; the marker is the
connected core blob nearest the predicted position (the largest one when there is no
prediction). Its centre is the centroid of each pixel's *coverage* -- the fraction of
the pixel the sticker covers, estimated from luma between the local background and the
sticker's own level -- over the blob grown by two pixels, so anti-aliased edge pixels
count by the share they hold. Luma is used for the weights because video codecs keep it
at full resolution while they halve the colour planes (4:2:0).

A blob much smaller than the marker's usual area is partly hidden, and its centroid
would be pulled toward the visible part: such frames are reported as not found.
"""

from __future__ import annotations

import math
import statistics
from collections import deque
from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import TrackError
from .detection import Detection, window
from .predict import MotionHistory

LUMA_BGR = np.array([0.114, 0.587, 0.299], dtype=np.float32)


def parse_hex(colour: str) -> tuple[int, int, int]:
    """``#RRGGBB`` -> (B, G, R) as OpenCV stores pixels."""
    h = colour.strip().lstrip("#")
    if len(h) != 6 or any(c not in "0123456789abcdefABCDEF" for c in h):
        raise TrackError(f"colour {colour!r} is not #RRGGBB", "write the colour as 6 hex digits, e.g. color:#ff00ff")
    r, g, b = (int(h[i:i + 2], 16) for i in (0, 2, 4))
    return b, g, r


@dataclass
class ColorMarker:
    name: str
    spec: str
    bgr: tuple[int, int, int]
    tolerance: int = 80
    search_half_px: int = 40
    min_area_px: int = 4
    partial_fraction: float = 0.6  # below this share of the usual area: partly hidden
    history: MotionHistory = field(default_factory=MotionHistory)
    _areas: deque = field(default_factory=lambda: deque(maxlen=15))
    _usual_area: float = 0.0       # median of _areas, kept up to date as areas arrive

    def __post_init__(self) -> None:
        self._lo = np.array([max(c - self.tolerance, 0) for c in self.bgr], dtype=np.uint8)
        self._hi = np.array([min(c + self.tolerance, 255) for c in self.bgr], dtype=np.uint8)

    def locate(self, frame: int, image_bgr: np.ndarray) -> Detection:
        centre = self.history.search_centre()
        det = None
        if centre is not None and self._areas:
            # a tight window first (three radii around the prediction): cheap, and the
            # blob must lie wholly inside it; otherwise the full search window
            radius = math.sqrt(self._usual_area / math.pi)
            det = self._locate_in(image_bgr, window(centre, int(3 * radius) + 6, image_bgr.shape), centre, True)
        if det is None and centre is not None:
            det = self._locate_in(image_bgr, window(centre, self.search_half_px, image_bgr.shape), centre)
        if det is None:  # first frame, or lost: search the whole image
            det = self._locate_in(image_bgr, (0, 0, image_bgr.shape[1], image_bgr.shape[0]), None)
        det = det or Detection.missing(0.0)
        self.history.add(det.point())
        return det

    def _locate_in(self, image, box, centre, whole_inside: bool = False) -> Detection | None:
        x0, y0, x1, y1 = box
        roi = image[y0:y1, x0:x1]          # a view: nothing outside the window is converted
        core = cv2.inRange(roi, self._lo, self._hi)
        if not cv2.hasNonZero(core):   # labelling an empty frame costs milliseconds: a hidden marker
            return None
        n, labels = cv2.connectedComponents(core, connectivity=8)
        if n <= 1:
            return None
        if n == 2:   # one blob (the usual case): its statistics cost less than OpenCV's general ones
            stats = np.array([[0, 0, 0, 0, 0], [*cv2.boundingRect(core), cv2.countNonZero(core)]])
            cents = None
        else:
            n, labels, stats, cents = cv2.connectedComponentsWithStats(core, connectivity=8)
        areas = stats[1:, cv2.CC_STAT_AREA]
        candidates = np.flatnonzero(areas >= self.min_area_px) + 1
        if candidates.size == 0:
            return None
        if candidates.size == 1:
            best = int(candidates[0])
        elif centre is None:
            best = candidates[np.argmax(stats[candidates, cv2.CC_STAT_AREA])]
        else:
            d = np.hypot(cents[candidates, 0] + x0 - centre[0], cents[candidates, 1] + y0 - centre[1])
            best = candidates[np.argmin(d)]
        if _touches_edge(stats[best], roi.shape, box, image.shape):
            if whole_inside:
                return None
            # the window cut the blob (the prediction was off): look again around what it saw
            bx, by, bw, bh = (int(v) for v in stats[best, :4])
            seen_at = (x0 + bx + bw / 2, y0 + by + bh / 2)
            radius = math.sqrt(self._usual_area / math.pi) if self._areas else max(bw, bh)
            return self._locate_in(image, window(seen_at, int(3 * radius) + 6, image.shape), seen_at, True)
        area = float(stats[best, cv2.CC_STAT_AREA])
        usual = self._usual_area if self._areas else area
        score = area / usual
        if self._areas and score < self.partial_fraction:
            return Detection.missing(score)
        self._areas.append(area)
        self._usual_area = statistics.median(self._areas)
        # the centroid needs the blob and four pixels around it (two dilations of 5x5)
        bx, by, bw, bh = (int(v) for v in stats[best, :4])
        cx0, cy0 = max(bx - RING_PX, 0), max(by - RING_PX, 0)
        cx1, cy1 = min(bx + bw + RING_PX, roi.shape[1]), min(by + bh + RING_PX, roi.shape[0])
        blob = labels[cy0:cy1, cx0:cx1] == best
        px, py = _coverage_centroid(roi[cy0:cy1, cx0:cx1], blob)
        return Detection(px + x0 + cx0, py + y0 + cy0, score, True)


RING_PX = 4
_KERNEL_5 = np.ones((5, 5), np.uint8)
_KERNEL_3 = np.ones((3, 3), np.uint8)


def _coverage_centroid(roi: np.ndarray, blob: np.ndarray) -> tuple[float, float]:
    """Centroid of per-pixel coverage over ``blob`` grown by two pixels.

    ``roi`` must hold the blob and the ``RING_PX`` pixels around it (or the image edge).
    """
    blob_u8 = blob.view(np.uint8)
    grown = cv2.dilate(blob_u8, _KERNEL_5)
    ring = cv2.dilate(grown, _KERNEL_5) & ~grown & 1
    luma = roi.astype(np.float32) @ LUMA_BGR
    inner = cv2.erode(blob_u8, _KERNEL_3).view(bool)
    level = float(_median(luma[inner])) if inner.any() else float(_median(luma[blob]))
    ring_b = ring.view(bool)
    background = float(_median(luma[ring_b])) if ring_b.any() else 0.0
    if abs(level - background) >= 20:
        cover = np.clip((luma - background) / (level - background), 0.0, 1.0)
    else:  # sticker as bright as its surround: fall back to the colour core alone
        cover = blob.astype(np.float32)
    m = cv2.moments(cover * grown)
    return m["m10"] / m["m00"], m["m01"] / m["m00"]


def _median(values: np.ndarray) -> np.floating:
    """``np.median`` of a 1-D float32 array, without its general-purpose overhead."""
    n = values.size
    k = n // 2
    if n % 2:
        return np.partition(values, k)[k]
    part = np.partition(values, (k - 1, k))
    return (part[k - 1] + part[k]) / np.float32(2)


def _touches_edge(stat: np.ndarray, roi_shape, box, image_shape) -> bool:
    """True if a blob reaches a window edge that is not also the image edge."""
    x, y, w, h = (int(v) for v in stat[:4])
    x0, y0, x1, y1 = box
    margin = 3  # the coverage ring needs room too
    return ((x < margin and x0 > 0) or (y < margin and y0 > 0)
            or (x + w > roi_shape[1] - margin and x1 < image_shape[1])
            or (y + h > roi_shape[0] - margin and y1 < image_shape[0]))
