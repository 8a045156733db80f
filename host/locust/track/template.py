"""Tracker's autotracker: ``--marker ball=template:X,Y@FRAME``.

The same steps as Tracker's ``TemplateMatcher`` / ``AutoTracker`` (Open Source Physics):

1. On the key frame, the template is the circle of radius ``radius_px`` (Tracker's
   default mask is 16 px across) around (X, Y).
2. On each later frame, the search window (+-``search_half_px``, Tracker's 40) is
   centred on the constant-acceleration look-ahead of the recent positions
   (:mod:`.predict`). Until two positions give a velocity the window is twice as
   large: Tracker's own BallToss ball moves 70 px between its first two steps.
3. The match is the position of least RGB square difference (masked) in the window.
   Its score is Tracker's *peak height*: mean difference / best difference - 1.
4. Sub-pixel: a Gaussian through the peak heights of the best position and its two
   neighbours, per axis (a three-point fit, exact, done in closed form).
5. A match is accepted when the peak height exceeds ``accept`` (Tracker's "automark",
   default 4); the template then evolves toward the matched image by ``evolve``
   (Tracker's default rate 20 %).

The reported point is the key point plus the measured displacement, so it follows the
exact spot picked on the key frame. Frames before the key frame are not searched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import TrackError
from .detection import Detection, window
from .predict import MotionHistory


@dataclass
class TemplateMarker:
    name: str
    spec: str
    key_x_px: float
    key_y_px: float
    key_frame: int
    radius_px: int = 8
    search_half_px: int = 40
    accept: float = 4.0
    evolve: float = 0.2
    history: MotionHistory = field(default_factory=MotionHistory)
    _template: np.ndarray | None = None
    _mask: np.ndarray | None = None
    _offset: tuple[float, float] = (0.0, 0.0)  # key point minus template centre pixel

    def locate(self, frame: int, image_bgr: np.ndarray) -> Detection:
        if frame < self.key_frame:
            return Detection.missing()
        if self._template is None:
            if frame != self.key_frame:
                raise TrackError(f"marker {self.name}: key frame {self.key_frame} was not in the clip",
                                 f"start the clip at or before frame {self.key_frame} with a step that reaches it")
            return self._start(image_bgr)
        det = self._match(image_bgr)
        self.history.add(det.point())
        return det

    def _start(self, image: np.ndarray) -> Detection:
        cx, cy, r = int(round(self.key_x_px)), int(round(self.key_y_px)), self.radius_px
        h, w = image.shape[:2]
        if not (r <= cx < w - r and r <= cy < h - r):
            raise TrackError(f"marker {self.name}: template at ({self.key_x_px}, {self.key_y_px}) on frame "
                             f"{self.key_frame} does not fit inside the {w}x{h} image",
                             "pick a point at least the template radius away from the edge")
        self._template = image[cy - r:cy + r + 1, cx - r:cx + r + 1].astype(np.float32)
        self._mask = np.zeros((2 * r + 1, 2 * r + 1), np.uint8)
        cv2.circle(self._mask, (r, r), r, 1, -1)
        self._mask = np.repeat(self._mask[:, :, None], 3, axis=2).astype(np.float32)
        self._offset = (self.key_x_px - cx, self.key_y_px - cy)
        self.history.add((self.key_x_px, self.key_y_px))
        return Detection(self.key_x_px, self.key_y_px, math.inf, True)

    def _match(self, image: np.ndarray) -> Detection:
        r = self.radius_px
        cx, cy = self.history.search_centre()
        # until two positions give a velocity there is no look-ahead: search twice as far
        half = self.search_half_px * (1 if self.history.has_velocity() else 2)
        # the window holds every template *centre* within +-half of the prediction
        x0, y0, x1, y1 = window((cx - self._offset[0], cy - self._offset[1]), half + r, image.shape)
        roi = image[y0:y1, x0:x1].astype(np.float32)
        if roi.shape[0] < 2 * r + 3 or roi.shape[1] < 2 * r + 3:
            return Detection.missing()
        diff = cv2.matchTemplate(roi, self._template, cv2.TM_SQDIFF, mask=self._mask)
        diff = np.maximum(diff, 0.0)
        iy, ix = np.unravel_index(int(np.argmin(diff)), diff.shape)
        best = float(diff[iy, ix])
        mean = float(diff.mean())
        if best <= 0.0:
            return self._accept(image, x0 + ix + r, y0 + iy + r, 0.0, 0.0, math.inf)
        peak = lambda d: mean / max(d, 1e-12) - 1.0  # noqa: E731 - Tracker's peak height
        height = peak(best)
        if not height > self.accept:
            return Detection.missing(height)
        dx = _gaussian_peak(*(peak(diff[iy, ix + k]) if 0 <= ix + k < diff.shape[1] else math.nan for k in (-1, 0, 1)))
        dy = _gaussian_peak(*(peak(diff[iy + k, ix]) if 0 <= iy + k < diff.shape[0] else math.nan for k in (-1, 0, 1)))
        return self._accept(image, x0 + ix + r, y0 + iy + r, dx, dy, height)

    def _accept(self, image, ix: int, iy: int, dx: float, dy: float, height: float) -> Detection:
        r = self.radius_px
        patch = image[iy - r:iy + r + 1, ix - r:ix + r + 1].astype(np.float32)
        if patch.shape == self._template.shape:
            self._template = (1.0 - self.evolve) * self._template + self.evolve * patch
        return Detection(ix + dx + self._offset[0], iy + dy + self._offset[1], height, True)


def _gaussian_peak(left: float, centre: float, right: float) -> float:
    """Offset (-0.5..0.5) of the peak of the Gaussian through three equally spaced values."""
    if not (left > 0 and centre > 0 and right > 0):
        return 0.0
    ll, lc, lr = math.log(left), math.log(centre), math.log(right)
    curvature = ll - 2 * lc + lr
    if curvature >= 0:
        return 0.0
    return float(np.clip(0.5 * (ll - lr) / curvature, -0.5, 0.5))
