"""Tracker's autotracker: ``--marker ball=template:X,Y@FRAME``.

The same steps as Tracker's ``TemplateMatcher`` / ``AutoTracker`` (Open Source Physics):

1. On the key frame, the template is the circle of radius ``radius_px`` (Tracker's
   default mask is 16 px across) around (X, Y).
2. On each later frame, the search window (+-``search_half_px``, Tracker's 40) is
   centred on where the track's motion puts the marker: a constant-acceleration fit to
   its last positions (:class:`.predict.MotionFit`), extrapolated across frames where it
   was lost. Until two positions give a velocity the window is twice as large: Tracker's
   own BallToss ball moves 70 px between its first two steps.
3. The match is the position of least RGB square difference (masked) in the window.
   Its score is Tracker's *peak height*: mean difference / best difference - 1.
4. Sub-pixel: a Gaussian through the peak heights of the best position and its two
   neighbours, per axis (a three-point fit, exact, done in closed form). Tracker 6's
   ``TemplateMatcher`` fits a parabola to the three square differences instead; on
   Tracker's CupsClips and BallToss the two agree within 0.015 px mean (0.505 / 0.560 /
   0.426 px from Tracker's points with the parabola, 0.499 / 0.563 / 0.439 with the Gaussian).
5. A match is accepted when the peak height exceeds ``accept`` (Tracker's "automark");
   the template then evolves toward the matched image by ``evolve`` (Tracker's
   evolution rate, default 20 %), so it follows a marker whose look changes. Tracker
   also draws the template back toward the key frame's by its *tether* (default 5 %);
   that is left out here: it gains under 0.01 px on CupsClips and BallToss and halves
   the frames found on a hand-held clip whose marker changes its look (the servo label of
   tests/test_track_markerless.py: 104 of 300 frames, under that test's floor of 200).

Rules keep it off still things, which Tracker leaves to the user's eye:

- *Ambiguity*: where several places match almost as well as the best (within
  ``AMBIGUITY`` of its square difference: a row of look-alike cups, a textured desk), the
  one nearest the predicted position is taken, not the best by a hair.
- *Motion gate*: a match farther from the prediction than ``GATE_MIN_PX`` or
  ``GATE_STEP_FRACTION`` of the predicted step (whichever is larger) along the predicted
  motion, or ``GATE_MIN_PX`` across it, does not follow the motion its track predicts: the
  marker is lost there (two cups falling side by side, 12 px apart).
- *Likeness*: the matched patch must correlate with the template (zero-mean normalised
  correlation over the mask, all three channels) at ``min_likeness`` or more; an empty
  background where the marker was, after it left the picture, does not.
- *First steps*: until three positions in a row give the track an acceleration, a match
  farther than ``GATE_MIN_PX`` from the prediction is taken only when nothing else in the
  window matches within ``AMBIGUITY`` of the best: a cup keyed in mid-fall, in a row of
  look-alike cups closer together than it falls in a frame, could be any of them.

A lost marker is ``nan`` (never a guess); it is looked for again on every later frame,
around its path (extrapolated at most ``EXTRAPOLATE_FRAMES``) in a window and gate that grow
while it stays lost (a marker never seen to move: within ``GATE_MIN_PX``, grown, of its key
point), or within the ungrown gate of where it was last seen (a hand-held camera
jerks, and a jerk is no path to extrapolate). It comes back only where its match stands out
and looks like it: Tracker's peak height ``REACQUIRE_PEAK`` and likeness
``REACQUIRE_LIKENESS`` (a small cup among look-alike cups peaks near 10 and stays lost). A
marker that reappears far from both stays lost: a black blob matches any dark patch of the
background just as well.

A fourth rule, *position*: when the places matching within ``AMBIGUITY`` of the match reach
more than ``SPREAD_RADII`` template radii from it (the template slides along a straight
edge, or sits on a plain patch), the frame has no position.

The reported point is the key point plus the measured displacement, so it follows the exact
spot picked on the key frame. Frames before the key frame are not searched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import TrackError
from .detection import Detection, window
from .predict import MotionFit

AMBIGUITY = 1.5            # matches within this factor of the best square difference are look-alikes
AMBIGUITY_IN_GATE = 3.0    # ... and within this factor, inside the motion gate
GATE_MIN_PX = 8.0          # a match may always land this far from the prediction
GATE_STEP_FRACTION = 0.5   # ... or this fraction of the predicted step, whichever is larger
LOST_GROWTH = 0.5          # window and gate grow by this fraction per frame lost ...
LOST_GROWTH_MAX = 3.0      # ... up to this many times their size
REACQUIRE_PEAK = 50.0      # a lost marker comes back only with a peak height this high ...
REACQUIRE_LIKENESS = 0.7   # ... and this likeness
SPREAD_RADII = 2.0         # a match whose near-equals reach this many template radii has no position
EXTRAPOLATE_FRAMES = 5     # a lost marker is looked for along its path this many frames on, then there


@dataclass(frozen=True)
class Gate:
    """Where a match may land around the prediction: an ellipse, ``along_px`` along the
    predicted motion (unit vector ``ux``, ``uy``) and ``across_px`` across it (a constant-
    acceleration prediction errs along the path, hardly across it); a circle without motion."""

    along_px: float
    across_px: float
    ux: float = 1.0
    uy: float = 0.0

    def ratio(self, dx, dy):
        """Distance of the offset (dx, dy) from the prediction in gate sizes (<= 1: inside).

        Parameters
        ----------
        dx, dy : float or ndarray
            Offset from the predicted position [px].

        Returns
        -------
        float or ndarray
            The elliptical distance, in units of the gate's half-axes (dimensionless).
        """
        along = dx * self.ux + dy * self.uy
        across = -dx * self.uy + dy * self.ux
        return np.hypot(along / self.along_px, across / self.across_px)


@dataclass
class TemplateMarker:
    """A feature tracked as Tracker's autotracker does: a template cut on the key frame,
    matched by masked square difference in a window around the predicted position (see the
    module docstring).

    Attributes
    ----------
    name, spec : str
        The marker's name and its ``--marker`` spec.
    key_x_px, key_y_px : float
        The point picked on the key frame [px].
    key_frame : int
        The frame the template is cut from; earlier frames are not searched.
    radius_px : int
        Radius of the circular template mask [px].
    search_half_px : int
        Half-size of the search window around the prediction [px].
    accept : float
        Smallest peak height a match needs (Tracker's "automark").
    evolve : float
        Share of the matched patch mixed into the template on each accepted match (0..1).
    min_likeness : float
        Smallest zero-mean normalised correlation of a match with the template (-1..1).
    motion : MotionFit
        Its positions so far, for the prediction.
    """

    name: str
    spec: str
    key_x_px: float
    key_y_px: float
    key_frame: int
    radius_px: int = 8
    search_half_px: int = 40
    accept: float = 0.5
    evolve: float = 0.2
    min_likeness: float = 0.5
    motion: MotionFit = field(default_factory=MotionFit)
    _template: np.ndarray | None = None
    _mask: np.ndarray | None = None
    _offset: tuple[float, float] = (0.0, 0.0)  # key point minus template centre pixel

    def locate(self, frame: int, image_bgr: np.ndarray) -> Detection:
        """Find the marker in one frame (on the key frame: cut the template there).

        Parameters
        ----------
        frame : int
            The frame number (frames come in order).
        image_bgr : ndarray
            The frame, BGR.

        Returns
        -------
        Detection
            Its point [px] (the key point plus the measured displacement); ``score`` is
            Tracker's peak height (inf on the key frame, nan before it).

        Raises
        ------
        TrackError
            The key frame was skipped, or the template does not fit inside the image there.
        """
        if frame < self.key_frame:
            return Detection.missing()
        if self._template is None:
            if frame != self.key_frame:
                raise TrackError(f"marker {self.name}: key frame {self.key_frame} was not in the clip",
                                 f"start the clip at or before frame {self.key_frame} with a step that reaches it")
            return self._start(frame, image_bgr)
        det = self._match(frame, image_bgr)
        self.motion.add(frame, det.point())
        return det

    def _start(self, frame: int, image: np.ndarray) -> Detection:
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
        self.motion.add(frame, (self.key_x_px, self.key_y_px))
        return Detection(self.key_x_px, self.key_y_px, math.inf, True)

    def _prediction(self, frame: int) -> tuple[tuple[float, float], float, Gate]:
        """Predicted point, search half-size (px) and gate for ``frame``."""
        traj = self.motion
        lost = traj.frames_lost(frame)
        growth = min(1.0 + LOST_GROWTH * lost, LOST_GROWTH_MAX)
        if traj.stretch < 2:
            half = 2 * self.search_half_px * growth
            if traj.max_speed_px == 0.0:   # the key frame alone: no velocity yet, anywhere in the window ...
                if lost == 0:
                    return traj.last_point, half, Gate(math.inf, math.inf)
                # ... but once lost there, it comes back only near where it was picked
                return traj.last_point, half, Gate(GATE_MIN_PX * growth, GATE_MIN_PX * growth)
            # just re-acquired: no velocity yet, but no faster than the marker has been seen to move
            radius = max(GATE_MIN_PX, GATE_STEP_FRACTION * traj.max_speed_px) * growth
            return traj.last_point, half, Gate(radius, radius)
        # lost for long, the fit is not extrapolated further: where it led after EXTRAPOLATE_FRAMES
        ahead = min(frame, traj.last_frame + 1 + EXTRAPOLATE_FRAMES)
        point, motion = traj.predict_motion(ahead)
        step = math.hypot(*motion)
        along = max(GATE_MIN_PX, GATE_STEP_FRACTION * step) * growth
        ux, uy = (motion[0] / step, motion[1] / step) if step > 0 else (1.0, 0.0)
        # with two positions the look-ahead is a straight line: it may err across the path too
        across = GATE_MIN_PX * growth if traj.stretch >= 3 else along
        return point, self.search_half_px * growth, Gate(along, across, ux, uy)

    def _match(self, frame: int, image: np.ndarray) -> Detection:
        r = self.radius_px
        (px, py), half, gate = self._prediction(frame)
        ox, oy = self._offset
        # the window holds every template *centre* within +-half of the prediction
        x0, y0, x1, y1 = window((px - ox, py - oy), int(math.ceil(half)) + r, image.shape)
        roi = image[y0:y1, x0:x1].astype(np.float32)
        if roi.shape[0] < 2 * r + 3 or roi.shape[1] < 2 * r + 3:
            return Detection.missing()
        diff = np.maximum(cv2.matchTemplate(roi, self._template, cv2.TM_SQDIFF, mask=self._mask), 0.0)
        lost = self.motion.frames_lost(frame)
        iy, ix = _nearest_lookalike(diff, px - ox - x0 - r, py - oy - y0 - r,
                                    gate if lost == 0 else Gate(math.inf, math.inf))
        best = float(diff[iy, ix])
        mean = float(diff.mean())
        if best <= 0.0:
            return self._accept(image, x0 + ix + r, y0 + iy + r, 0.0, 0.0, math.inf)
        peak = lambda d: mean / max(d, 1e-12) - 1.0  # noqa: E731 - Tracker's peak height
        height = peak(best)
        spread = _valley_extent(diff, iy, ix)
        mx, my = x0 + ix + r + ox, y0 + iy + r + oy
        off = float(gate.ratio(mx - px, my - py))
        if lost > 0:   # lost: where it was last seen is as good a guess, the gate not grown
            growth = min(1.0 + LOST_GROWTH * lost, LOST_GROWTH_MAX)
            lx, ly = self.motion.last_point
            off = min(off, math.hypot(mx - lx, my - ly) * growth / gate.along_px)
        like = self._likeness(image, x0 + ix + r, y0 + iy + r)
        if not height > self.accept:
            return Detection.missing(height)
        if spread > SPREAD_RADII * r:   # the match slides along an edge or over a plain patch: no position
            return Detection.missing(height)
        if lost > 0 and (height < REACQUIRE_PEAK or like < REACQUIRE_LIKENESS):
            return Detection.missing(height)   # coming back takes a match that stands out in its window
        if off > 1.0:   # off its path
            return Detection.missing(height)
        if self.motion.stretch < 3 and math.hypot(mx - px, my - py) > GATE_MIN_PX and _has_lookalike(diff, iy, ix):
            return Detection.missing(height)   # no path yet to tell the marker from its look-alikes
        if like < self.min_likeness:
            return Detection.missing(height)
        dx = _gaussian_peak(*(peak(diff[iy, ix + k]) if 0 <= ix + k < diff.shape[1] else math.nan for k in (-1, 0, 1)))
        dy = _gaussian_peak(*(peak(diff[iy + k, ix]) if 0 <= iy + k < diff.shape[0] else math.nan for k in (-1, 0, 1)))
        return self._accept(image, x0 + ix + r, y0 + iy + r, dx, dy, height)

    def _likeness(self, image: np.ndarray, ix: int, iy: int, template: np.ndarray | None = None) -> float:
        """Zero-mean normalised correlation of ``template`` (default: the evolved one) and the
        patch centred on (ix, iy)."""
        r = self.radius_px
        template = self._template if template is None else template
        patch = image[iy - r:iy + r + 1, ix - r:ix + r + 1].astype(np.float32)
        if patch.shape != template.shape:
            return -1.0
        inside = self._mask > 0
        a = patch[inside] - patch[inside].mean()
        b = template[inside] - template[inside].mean()
        norm = math.sqrt(float(a @ a) * float(b @ b))
        return float(a @ b) / norm if norm > 0 else -1.0

    def _accept(self, image, ix: int, iy: int, dx: float, dy: float, height: float) -> Detection:
        r = self.radius_px
        patch = image[iy - r:iy + r + 1, ix - r:ix + r + 1].astype(np.float32)
        if patch.shape == self._template.shape:
            self._template = (1.0 - self.evolve) * self._template + self.evolve * patch
        return Detection(ix + dx + self._offset[0], iy + dy + self._offset[1], height, True)


def _nearest_lookalike(diff: np.ndarray, pred_x: float, pred_y: float, gate: Gate) -> tuple[int, int]:
    """The match in ``diff`` (indices iy, ix) given the predicted position (``pred_x``,
    ``pred_y``, in ``diff``'s own indices): of the local minima within ``AMBIGUITY`` of the
    best, the one nearest the prediction; when that one lies outside ``gate``, the
    lowest local minimum within the gate if it is within ``AMBIGUITY_IN_GATE`` of the best
    (a look-alike outside the path matched the evolved template a little better)."""
    best = float(diff.min())
    minima = diff <= cv2.erode(diff, np.ones((3, 3), np.uint8))
    ys, xs = np.nonzero(minima & (diff <= AMBIGUITY * best))
    if ys.size == 0:
        iy, ix = np.unravel_index(int(np.argmin(diff)), diff.shape)
        return int(iy), int(ix)
    k = int(np.argmin((xs - pred_x) ** 2 + (ys - pred_y) ** 2))
    if gate.ratio(xs[k] - pred_x, ys[k] - pred_y) <= 1.0:
        return int(ys[k]), int(xs[k])
    ys, xs = np.nonzero(minima & (diff <= AMBIGUITY_IN_GATE * best))
    inside = gate.ratio(xs - pred_x, ys - pred_y) <= 1.0
    if not inside.any():
        return int(ys[k]), int(xs[k])
    ys, xs = ys[inside], xs[inside]
    k = int(np.argmin(diff[ys, xs]))
    return int(ys[k]), int(xs[k])


def _has_lookalike(diff: np.ndarray, iy: int, ix: int) -> bool:
    """Whether a local minimum of ``diff`` other than the match at (iy, ix) matches within
    ``AMBIGUITY`` of the best."""
    minima = diff <= cv2.erode(diff, np.ones((3, 3), np.uint8))
    minima[iy, ix] = False
    return bool((minima & (diff <= AMBIGUITY * float(diff.min()))).any())


def _valley_extent(diff: np.ndarray, iy: int, ix: int) -> float:
    """How far (px) the places matching within ``AMBIGUITY`` of the match at (iy, ix) reach from
    it, connected to it: a few pixels on a textured spot, long along a straight edge (the
    match slides along it) or over a plain area."""
    low = (diff <= AMBIGUITY * diff[iy, ix]).astype(np.uint8)
    _, labels = cv2.connectedComponents(low, connectivity=8)
    ys, xs = np.nonzero(labels == labels[iy, ix])
    return float(np.sqrt(((ys - iy) ** 2 + (xs - ix) ** 2).max()))


def _gaussian_peak(left: float, centre: float, right: float) -> float:
    """Offset (-0.5..0.5) of the peak of the Gaussian through three equally spaced values."""
    if not (left > 0 and centre > 0 and right > 0):
        return 0.0
    ll, lc, lr = math.log(left), math.log(centre), math.log(right)
    curvature = ll - 2 * lc + lr
    if curvature >= 0:
        return 0.0
    return float(np.clip(0.5 * (ll - lr) / curvature, -0.5, 0.5))
