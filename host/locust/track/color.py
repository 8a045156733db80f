"""Coloured stickers: ``--marker nose=color:#ff00ff``.

Colour picks the marker and locates it. Pixels within ``tolerance`` of the marker colour
(largest channel difference, 0-255) form the core; the marker is the connected core blob
nearest the predicted position (the largest one when there is no prediction). Its centre
is the centroid of each pixel's *coverage* -- the fraction of the pixel the sticker
covers -- over the blob grown by two pixels (:mod:`.coverage`), so anti-aliased edge pixels
count by the share they hold. Coverage is estimated from luma, which codecs keep at full resolution
(4:2:0 halves the colour planes), where the surround is uniform; around a textured surround
(a ruler's marks) from chroma (the pixel's colour less its grey level) between the local
background's and the sticker's, so the texture weighs nothing.

A blob much smaller than the marker's usual area is partly hidden, and its centroid
would be pulled toward the visible part: such frames are reported as not found.

A blob's shape and mean colour are judged against what the marker has shown (a look-alike,
a blur streak, a shadow); a blob alone in the tight window around the prediction, at the
marker's usual size, is judged only every ``JUDGE_EVERY``-th frame.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import cv2
import numpy as np

from ..errors import TrackError
from .blobs import (
    BlobShape,
    along,
    blob_shape,
    contours,
    every,
    filled,
    labelled_blobs,
    median_of,
    on_image_border,
    touches_edge,
)
from .coverage import RING_PX, coverage_centroid
from .detection import Detection, window
from .predict import MotionFit

JUDGE_EVERY = 4   # a marker found as usual has its shape and colour judged every this many frames
FIRST_SIGHTING_MIN_PX = 3.0   # least width of a first sighting: a 2 x 2 speck (2.3 px) is noise, not a sticker
DISC_FILL = 0.65  # least share of its box a blob taken as usual fills (a disc: pi/4, 0.79)


def parse_hex(colour: str) -> tuple[int, int, int]:
    """``#RRGGBB`` -> (B, G, R) as OpenCV stores pixels.

    Parameters
    ----------
    colour : str
        ``#RRGGBB`` (the ``#`` may be left out).

    Returns
    -------
    tuple of int
        (B, G, R), 8-bit.

    Raises
    ------
    TrackError
        Not six hex digits.
    """
    h = colour.strip().lstrip("#")
    if len(h) != 6 or any(c not in "0123456789abcdefABCDEF" for c in h):
        raise TrackError(f"colour {colour!r} is not #RRGGBB", "write the colour as 6 hex digits, e.g. color:#ff00ff")
    r, g, b = (int(h[i:i + 2], 16) for i in (0, 2, 4))
    return b, g, r


class FrameHSV:
    """The HSV picture of the frame being tracked, converted once for every colour marker that
    asks for it (the runner hands one to all of them). Held for one frame index and one image
    object: another frame, or another array, is converted afresh."""

    def __init__(self) -> None:
        self._frame: int | None = None
        self._image: np.ndarray | None = None
        self._hsv: dict[int, np.ndarray] = {}

    def of(self, frame: int, image: np.ndarray, step: int = 1) -> np.ndarray:
        """HSV of every ``step``-th pixel of every ``step``-th row of ``image``.

        Computed once per frame and step, shared by the markers that ask.

        Parameters
        ----------
        frame : int
            The frame number (another frame, or another image array, drops the cached pictures).
        image : ndarray
            The frame, BGR.
        step : int
            Sampling step [px].

        Returns
        -------
        ndarray
            The HSV picture, OpenCV 8-bit (hue 0..179).
        """
        if frame != self._frame or image is not self._image:
            self._frame, self._image, self._hsv = frame, image, {}
        if step not in self._hsv:
            self._hsv[step] = cv2.cvtColor(every(image, step), cv2.COLOR_BGR2HSV)
        return self._hsv[step]


@dataclass
class ColorMarker:
    """A coloured sticker tracked by colour: the blob nearest the predicted position, its
    coverage-weighted centroid (see the module docstring).

    Attributes
    ----------
    name, spec : str
        The marker's name and its ``--marker`` spec.
    bgr : tuple of int
        The sticker's colour, 8-bit BGR.
    tolerance : int
        Largest per-channel difference from ``bgr`` a marker pixel may have (8-bit levels).
    search_half_px : int
        Half-size of the search window around the prediction [px].
    min_area_px : int
        Smallest blob taken for the marker [px].
    partial_fraction : float
        Below this share of the usual area a blob is partly hidden: not found.
    start_px : tuple of float or None
        Where to look for the sticker until it is first seen [px]; None: the whole frame.
    hue_tol_deg : float
        Largest hue difference from the marker's colour [deg].
    motion : MotionFit
        Its positions so far, for the prediction.
    frame_hsv : FrameHSV
        The frame's HSV picture, shared by the markers of one run.
    """

    name: str
    spec: str
    bgr: tuple[int, int, int]
    tolerance: int = 80
    search_half_px: int = 40
    min_area_px: int = 4
    partial_fraction: float = 0.6  # below this share of the usual area: partly hidden
    start_px: tuple[float, float] | None = None
    hue_tol_deg: float = 16.0
    motion: MotionFit = field(default_factory=MotionFit)
    _areas: deque = field(default_factory=lambda: deque(maxlen=15))
    _widths: deque = field(default_factory=lambda: deque(maxlen=15))
    _usual_area: float = 0.0       # median of _areas (round, whole blobs), kept up to date
    _usual_width: float = 0.0      # median of _widths: the sticker's diameter in pixels
    _speed: float = 0.0            # predicted motion over this frame (px), for the blur allowance
    _tries: int = 0                # frames searched before the first sighting
    _frame: int = 0                # the frame being searched
    _velocity: tuple[float, float] = (0.0, 0.0)   # predicted motion over this frame (px)
    _distractors: list = field(default_factory=list)  # other blobs of the colour seen at the start: (x, y, w, h)
    _lost: int = 0                 # frames the marker has been lost before the one searched
    # (hue, saturation, chroma, cos and sin of the hue angle) of the round sightings
    _colours: deque = field(default_factory=lambda: deque(maxlen=15))
    _own: tuple | None = None      # _own_colour() of _colours, None when it must be computed again
    _unjudged: int = 0             # frames in a row found as usual without judging shape and colour
    frame_hsv: FrameHSV = field(default_factory=FrameHSV)   # shared by the markers of one run

    def __post_init__(self) -> None:
        self._lo = np.array([max(c - self.tolerance, 0) for c in self.bgr], dtype=np.uint8)
        self._hi = np.array([min(c + self.tolerance, 255) for c in self.bgr], dtype=np.uint8)
        h, s, v = (int(c) for c in cv2.cvtColor(np.uint8([[self.bgr]]), cv2.COLOR_BGR2HSV)[0, 0])
        # hue is only a colour's identity when the colour has one: grey stickers match by RGB alone
        self._hsv = (h, s, v) if s >= 80 and v >= 60 else None
        # a box reaching near the grey diagonal (R = G = B) takes grey pixels for the marker:
        # then a blob of the box is also checked for the marker's hue
        self._box_holds_grey = int(self._lo.max()) <= int(self._hi.min()) + 30
        self._bounds = self._hue_bounds() if self._hsv is not None else None
        # one pixel and its HSV, for a blob's mean colour (made once: a blob is judged every frame)
        self._pixel, self._pixel_hsv = np.zeros((1, 1, 3), np.uint8), np.zeros((1, 1, 3), np.uint8)

    def locate(self, frame: int, image_bgr: np.ndarray) -> Detection:
        """Find the sticker in one frame.

        Parameters
        ----------
        frame : int
            The frame number (frames come in order).
        image_bgr : ndarray
            The frame, BGR.

        Returns
        -------
        Detection
            Its centre [px]; ``score`` is the blob's area over the usual area (1 on the first
            sightings).
        """
        det = self._find(frame, image_bgr) or Detection.missing(0.0)
        if det.ok and self.motion.last_frame is None:
            self._note_distractors(image_bgr, det)
        self.motion.add(frame, det.point())
        return det

    def _note_distractors(self, image: np.ndarray, marker: Detection) -> None:
        """Remember every other blob of the marker's colour on the first sighting (a pen cap
        lying in the scene): a lost marker is never re-acquired on one of them. A look-alike has
        the marker's own colour (a loose colour test passes a shadowed brown wall, which is no
        look-alike: the marker is refused there by its colour when lost). A blob whose
        look-alike zone holds the marker itself is a piece of the marker (its edge, split off by
        a shadow), not a look-alike: it would blind the marker where it was first seen."""
        # The widest test (the last of _cores) finds every pixel that could be taken for it: on
        # every second pixel of every second row first (a quarter of the picture to convert; any
        # blob holding a 2x2 square has one there), then in full around what that found.
        h, w = image.shape[:2]
        seen = set()
        hsv = self.frame_hsv.of(self._frame, image, 2)
        for c in contours(self._widest(every(image, 2) if self._hsv is None else None, hsv)):
            x, y, bw, bh = cv2.boundingRect(c)
            x0, y0, x1, y1 = max(2 * x - 2, 0), max(2 * y - 2, 0), min(2 * (x + bw) + 2, w), min(2 * (y + bh) + 2, h)
            roi = image[y0:y1, x0:x1]
            for piece in contours(self._widest(roi)):
                bx, by, bw, bh = cv2.boundingRect(piece)
                box = (bx + x0, by + y0, bw, bh)
                if box in seen:
                    continue
                seen.add(box)
                if bw * bh >= self.min_area_px and not self._in_zone(box, marker.px, marker.py) \
                        and self._has_own_colour(self._blob_hs(roi, filled(piece, (bx, by, bw, bh)), bx, by)):
                    self._distractors.append(box)

    def _widest(self, roi: np.ndarray | None, hsv: np.ndarray | None = None) -> np.ndarray:
        """The widest colour test (the last of ``_cores``): every pixel that could be taken for
        the marker; ``hsv``: ``roi`` converted, if it is at hand (then ``roi`` is only needed
        by a grey marker)."""
        if self._hsv is None:
            return cv2.inRange(roi, self._lo, self._hi)
        return self._hue_mask(roi, hsv)

    def _find(self, frame: int, image: np.ndarray) -> Detection | None:
        self._frame = frame
        if not self._areas:   # not seen yet: around the start point, or anywhere
            self._tries += 1
            if self.start_px is None:
                return self._locate_in(image, (0, 0, image.shape[1], image.shape[0]), None)
            return self._locate_in(image, window(self.start_px, 2 * self.search_half_px * self._tries, image.shape),
                                   self.start_px)
        centre, self._velocity = self.motion.predict_motion(frame)
        lost = self._lost = self.motion.frames_lost(frame)
        self._speed = math.hypot(*self._velocity)
        if lost:
            self._speed = max(self._speed, self.motion.max_speed_px)
        if lost == 0:
            # a tight window first (three radii around the prediction): cheap, and the
            # blob must lie wholly inside it; otherwise the full search window
            radius = math.sqrt(self._usual_area / math.pi)
            tight = window(centre, int(3 * radius + 0.5 * self._speed) + 6, image.shape)
            det = self._locate_in(image, tight, centre, True, tight=True)
            if det is not None:
                return det
        # the search window: at least five marker diameters (a hop starts from rest within a
        # frame); lost, it grows by its own size each frame around the extrapolated path
        half = int(max(self.search_half_px, 5 * self._usual_width)) * (1 + lost)
        if self.motion.stretch == 1:   # no velocity yet (first sighting, or re-acquired): twice as far, as Tracker does
            half *= 2
        if not lost:   # it may stop dead (a landing) as it starts from rest: reach back to where it was
            half = max(half, int(math.dist(centre, self.motion.last_point) + self._usual_width))
        h, w = image.shape[:2]
        box = window((min(max(centre[0], 0), w - 1), min(max(centre[1], 0), h - 1)), half, image.shape)
        return self._locate_in(image, box, centre)

    def _may_hold(self, roi: np.ndarray) -> bool:
        """False if no blob the marker could be taken for lies in ``roi``, judged from every
        ``step``-th pixel of every ``step``-th row: a blob is taken only if its least width is
        at least 0.6 of the marker's (``_fits``), so it holds a square of 0.6 / sqrt(2) of its
        width, which a grid of 0.3 of it cannot miss. While the marker is hidden its window
        grows by its size every frame; this keeps the colour tests, the HSV conversion above
        all, to a sixteenth of it (the step is at most 4)."""
        step = min(int(0.3 * self._usual_width), 4)
        if step < 2 or self._usual_width < 5.0:   # a few pixels across: its shape is not judged
            return True
        sub = every(roi[step // 2:, step // 2:], step)
        if cv2.hasNonZero(cv2.inRange(sub, self._lo, self._hi)):
            return True
        return self._hsv is not None and cv2.hasNonZero(self._hue_mask(sub))

    def _cores(self, roi: np.ndarray):
        """Pixels of the marker's colour, with whether their hue is already checked: first those
        within ``tolerance`` in RGB (exact on a well-lit sticker; a blob of them is then taken
        only if its mean colour has the marker's hue); if no blob of those fits, all those of
        its hue, somewhat paler or much darker (a shadow darkens, it does not change hue). A
        grey marker (no hue to speak of) is matched in RGB alone. While the marker is followed,
        its own colour comes between the two: where a deep shadow makes the surround dark enough
        for the loose bounds, the sticker still stands out by its chroma. Not while it is lost:
        far from any prediction, skin stands out by it as well."""
        box = cv2.inRange(roi, self._lo, self._hi)
        if self._hsv is None:
            yield box, True
            return
        yield box, not self._box_holds_grey
        hsv = cv2.cvtColor(roi, cv2.COLOR_BGR2HSV)
        if self._colours and not self._lost:
            yield self._own_mask(roi, hsv), True
        yield self._hue_mask(roi, hsv), True

    def _own_colour(self) -> tuple[float, float, float]:
        """Hue (circular mean), saturation (median) and chroma (the largest: in the best light it
        has been seen in; a shadow only takes from it) of the marker's round sightings; computed
        once per sighting added."""
        if self._own is None:
            self._own = self._colours_mean()
        return self._own

    def _colours_mean(self) -> tuple[float, float, float]:
        colours = self._colours
        sin = sum([c[4] for c in colours])
        cos = sum([c[3] for c in colours])
        return (math.degrees(math.atan2(sin, cos)) / 2 % 180, median_of([c[1] for c in colours]),
                max([c[2] for c in colours]))

    def _own_mask(self, roi: np.ndarray, hsv: np.ndarray) -> np.ndarray:
        """Pixels of the hue the marker has shown whose chroma (largest less smallest channel) is
        at least the share of its chroma that the brightness may drop to in a shadow (0.3 at the
        default tolerance): a shadow scales chroma with brightness, a dark grey-brown surround
        has little of it however its hue reads."""
        hue, _, chroma = self._own_colour()
        tol = self._bounds[0]
        turn = cv2.absdiff(hsv[:, :, 0], int(round(hue)) % 180)
        hue_ok = cv2.min(turn, cv2.subtract(180, turn)) <= tol
        b, g, r = cv2.split(roi)
        spread = cv2.subtract(cv2.max(cv2.max(b, g), r), cv2.min(cv2.min(b, g), r))
        return (hue_ok & (spread >= chroma * self._shadow_share())).view(np.uint8) * np.uint8(255)

    def _hue_bounds(self) -> tuple[int, int, int]:
        """Hue half-window (OpenCV's 8-bit hue: degrees / 2), least saturation, least brightness.

        --color-tol (default 80 of 255) scales them: the hue may turn 16 degrees at 80, a pixel
        may be paler down to 0.3 of the saturation (blur mixes in the background) and darker
        down to 0.3 of the brightness (a deep shadow)."""
        _, s, v = self._hsv
        share = min(self.tolerance / 80.0, 1.5)
        return (max(int(round(self.hue_tol_deg * share / 2)), 1), max(int(s * (1 - 0.7 * share)), 40),
                max(int(v * (1 - 0.7 * share)), 30))

    def _hue_mask(self, roi: np.ndarray, hsv: np.ndarray | None = None) -> np.ndarray:
        h = self._hsv[0]
        tol, s_min, v_min = self._bounds
        hsv = cv2.cvtColor(roi, cv2.COLOR_BGR2HSV) if hsv is None else hsv
        lo, hi = h - tol, h + tol
        mask = cv2.inRange(hsv, (max(lo, 0), s_min, v_min), (min(hi, 179), 255, 255))
        if lo < 0:
            mask |= cv2.inRange(hsv, (180 + lo, s_min, v_min), (179, 255, 255))
        if hi > 179:
            mask |= cv2.inRange(hsv, (0, s_min, v_min), (hi - 180, 255, 255))
        return mask

    def _blob_hs(self, roi: np.ndarray, blob: np.ndarray, x: int, y: int) -> tuple[int, int, int]:
        """Hue (OpenCV's 0-179), saturation and chroma (0-255) of the mean colour of ``blob`` at
        x, y in ``roi``."""
        h, w = blob.shape
        pixel = self._pixel
        pixel[0, 0] = cv2.mean(roi[y:y + h, x:x + w], blob)[:3]   # each channel truncated to 0-255
        bh, bs, bv = cv2.cvtColor(pixel, cv2.COLOR_BGR2HSV, dst=self._pixel_hsv)[0, 0].tolist()
        return bh, bs, bs * bv // 255

    def _has_own_colour(self, hs: tuple[int, int, int]) -> bool:
        """True if a blob's mean colour ``hs`` (``_blob_hs``) is the one the marker has shown (its round
        sightings): hue within the hue window of theirs, at least half their saturation (mostly
        sticker, as a blur streak the marker is found on still is) and at least the chroma a
        shadow leaves of theirs. A pick in shadow (dark: a brown hue passes its loose bounds)
        thus refuses grey-brown hair or skin. Before the first sighting the blob must have at
        least the chroma a shadow leaves of the given colour's (0.3 at the default --color-tol;
        paler *and* darker is a dim patch of that hue: a wire, a screen, not a sticker)."""
        if self._hsv is None:
            return True
        bh, bs, bc = hs
        if not self._colours:
            _, s, v = self._hsv
            return bc >= self._shadow_share() * (s * v // 255)
        hue, saturation, chroma = self._own_colour()
        turn = abs(bh - hue) % 180
        return (min(turn, 180 - turn) <= self._bounds[0] and bs >= 0.5 * saturation
                and bc >= self._shadow_share() * chroma)

    def _shadow_share(self) -> float:
        """The least share of its brightness (and so of its chroma) a shadow leaves the marker:
        0.3 at the default --color-tol."""
        return 1 - 0.7 * min(self.tolerance / 80.0, 1.5)

    def _has_hue(self, hs: tuple[int, int, int]) -> bool:
        """True if a blob's mean colour ``hs`` (``_blob_hs``) has the marker's hue."""
        bh, bs, _ = hs
        tol, s_min, _ = self._bounds
        return min(abs(bh - self._hsv[0]), 180 - abs(bh - self._hsv[0])) <= tol and bs >= s_min

    def _locate_in(self, image, box, centre, whole_inside: bool = False, tight: bool = False) -> Detection | None:
        """The marker in ``box``; ``whole_inside``: a blob cut by the box is refused; ``tight``:
        the box is a few radii around the prediction, where a lone blob of the RGB box, as
        usual, is the marker (``_as_usual``; a blob of the looser colour tests is judged)."""
        x0, y0, x1, y1 = box
        if x1 <= x0 or y1 <= y0:           # the prediction lies off the picture
            return None
        roi = image[y0:y1, x0:x1]          # a view: nothing outside the window is converted
        if self._lost and not self._may_hold(roi):
            return None
        for layer, (core, hue_checked) in enumerate(self._cores(roi)):
            det = self._locate_core(image, roi, core, box, centre, whole_inside, hue_checked, tight and layer == 0)
            if det is not None:
                return det
        return None

    def _locate_core(self, image, roi, core, box, centre, whole_inside: bool, hue_checked: bool,
                     tight: bool) -> Detection | None:
        """The marker among the blobs of ``core`` (one colour test over the window ``box``),
        tried nearest ``centre`` first; ``whole_inside``, ``tight``: as :meth:`_locate_in`."""
        x0, y0 = box[:2]
        n, blobs = labelled_blobs(core, (x0, y0), centre)
        for stat, mask, label in blobs:
            bx, by, bw, bh, area = stat
            if area < self.min_area_px:
                continue
            if touches_edge(stat, roi.shape, box, image.shape):
                if whole_inside:
                    return None
                det = self._look_again(image, box, stat)
            elif on_image_border(stat, box, image.shape):
                continue   # cut by the picture's edge: its centroid is not the marker's
            elif tight and n == 2 and hue_checked and self._as_usual(area, bw, bh):
                return self._as_before(roi, mask, stat, label, box)
            else:
                det = self._judged(roi, mask, stat, label, box, n == 2, hue_checked)
            if det is not None:
                return det
        return None

    def _look_again(self, image, box, stat) -> Detection | None:
        """The window cut the blob (the prediction was off): look again around what it saw; if
        that is not the marker, the other blobs in the window still may be (None)."""
        bx, by, bw, bh = stat[:4]
        seen_at = (box[0] + bx + bw / 2, box[1] + by + bh / 2)
        radius = math.sqrt(self._usual_area / math.pi) if self._areas else max(bw, bh)
        half = int(3 * radius + max(bw, bh) / 2) + 6
        return self._locate_in(image, window(seen_at, half, image.shape), seen_at, True)

    def _as_before(self, roi, mask, stat, label, box) -> Detection | None:
        """A blob alone in the tight window, as the marker has been seen (:meth:`_as_usual`):
        taken without judging its shape and colour, unless it lies on a look-alike."""
        bx, by, bw, bh = stat[:4]
        if self._near_distractor(box[0] + bx + bw / 2, box[1] + by + bh / 2):
            return None
        self._unjudged += 1
        return self._measure(roi, mask, stat, label, None, box[0], box[1], None, True)

    def _judged(self, roi, mask, stat, label, box, alone: bool, hue_checked: bool) -> Detection | None:
        """The blob, if its shape, its colour and its place say it is the marker; else None.
        ``alone``: ``mask`` is the colour mask itself, one blob in it."""
        bx, by, bw, bh, area = stat
        at = (box[0] + bx + bw / 2, box[1] + by + bh / 2)
        blob = mask[by:by + bh, bx:bx + bw]
        if not alone:   # with one blob the core is its mask
            blob = (blob == label).view(np.uint8)
        shape = blob_shape(blob, area)
        if not self._fits(shape, at):
            return None
        # the blob's mean colour (hue, saturation, chroma), for the checks and to learn from
        hs = self._blob_hs(roi, blob, bx, by) if self._hsv is not None else None
        if not (hue_checked or self._has_hue(hs)):
            return None
        if not self._has_own_colour(hs):
            return None   # taken only on a blob of the colour it has shown
        if self._near_distractor(*at):
            return None   # a look-alike seen at the start is never taken
        self._unjudged = 0
        return self._measure(roi, mask, stat, label, shape, box[0], box[1], hs, alone)

    def _as_usual(self, area: int, width: int, height: int) -> bool:
        """True if a blob, alone in the tight window around the prediction and within the RGB
        box of the marker's colour, is the marker just as it has been seen: 0.8 to 1.25 of its
        usual area, its box within 20 % (and a pixel) of its usual width both ways and filled
        as a disc fills its box (a streak lying diagonally fills half of it). Its shape and
        colour are then not judged again, which costs three OpenCV calls a frame; they are
        every ``JUDGE_EVERY``-th frame, so that what the marker looks like is still learned as
        the light and its distance change, and on every frame until as many sightings are
        learned as are kept (the shortcut must not slow the learning where it starts)."""
        if (self._unjudged >= JUDGE_EVERY - 1 or self._usual_width < 5.0
                or len(self._areas) < self._areas.maxlen):
            return False
        a, d = self._usual_area, self._usual_width
        slack = 0.2 * d + 1.0
        return (0.8 * a <= area <= 1.25 * a and abs(width - d) <= slack and abs(height - d) <= slack
                and area >= DISC_FILL * width * height)

    def _near_distractor(self, x: float, y: float) -> bool:
        """True if (x, y) lies on a look-alike's bounding box, grown by a marker radius."""
        if not self._distractors:
            return False
        return any(self._in_zone(box, x, y) for box in self._distractors)

    def _in_zone(self, box: tuple[int, int, int, int], x: float, y: float) -> bool:
        """True if (x, y) lies on ``box`` (x, y, w, h) grown by a marker radius."""
        bx, by, bw, bh = box
        r = 0.5 * self._usual_width + 1.0
        return bx - r <= x <= bx + bw + r and by - r <= y <= by + bh + r

    def _fits(self, shape: BlobShape, at: tuple[float, float]) -> bool:
        """Size and shape of the marker: learned from the round, whole sightings so far; the
        first sighting must be round and at least ``FIRST_SIGHTING_MIN_PX`` across. Motion blur
        may stretch it by up to the distance it moves in a frame, along its motion: the
        predicted one, or the way it went since it was last seen (a launch from rest is not
        predicted)."""
        if not self._areas:   # the first sighting: a round patch a sticker's centroid can be measured on
            return shape.minor_px >= max(0.6 * shape.major_px, FIRST_SIGHTING_MIN_PX)
        if shape.area_px < self.partial_fraction * self._usual_area:
            return False
        d = self._usual_width
        last = self.motion.last_point
        gap = self.motion.frames_lost(self._frame) + 1
        moved = ((at[0] - last[0]) / gap, (at[1] - last[1]) / gap)
        streak = 1.2 * max(self._speed, math.hypot(*moved)) + 2.0
        if shape.area_px > 1.6 * self._usual_area + d * streak:
            return False
        if d < 5.0:   # a few pixels across: too small to judge its shape
            return True
        if not (0.6 * d <= shape.minor_px <= 1.5 * d and shape.major_px <= 1.5 * d + streak):
            return False
        if shape.major_px > 1.4 * shape.minor_px:   # a blur streak lies along the motion
            if self._lost > self.motion.stretch:
                # lost for longer than the fit's own span: its extrapolated direction is a guess
                # (a few pixels of error in the curvature turn it by tens of degrees)
                return self._speed >= 0.3 * d
            return along(shape.angle_rad, self._velocity, d) or along(shape.angle_rad, moved, d)
        return True

    def _measure(self, roi, labels, stat, best: int, shape: BlobShape | None, x0: int, y0: int,
                 hs, alone: bool) -> Detection:
        """The blob's coverage centroid; a round, whole blob also teaches the marker's size
        (``shape``: None when it was not judged). ``alone``: ``labels`` is the colour mask
        itself (0/255, one blob in it), else OpenCV's labels with the blob as ``best``."""
        # the centroid needs the blob and four pixels around it (two dilations of 5x5)
        bx, by, bw, bh = stat[:4]
        cx0, cy0 = max(bx - RING_PX, 0), max(by - RING_PX, 0)
        cx1, cy1 = min(bx + bw + RING_PX, roi.shape[1]), min(by + bh + RING_PX, roi.shape[0])
        blob = labels[cy0:cy1, cx0:cx1]
        blob = blob.astype(bool) if alone else blob == best
        near = roi[cy0:cy1, cx0:cx1]
        px, py = coverage_centroid(near, blob)
        area = float(stat[4])
        score = area / self._usual_area if self._areas else 1.0
        if shape is not None and shape.minor_px >= 0.75 * shape.major_px:   # round and whole: learn its size
            self._areas.append(area)
            self._widths.append(shape.minor_px)
            self._usual_area = median_of(self._areas)
            self._usual_width = median_of(self._widths)
            if hs is not None:   # the blob's mean colour
                turn = math.radians(2 * hs[0])   # hue is an angle: its mean is the mean direction
                self._colours.append((*hs, math.cos(turn), math.sin(turn)))
                self._own = None
        return Detection(px + x0 + cx0, py + y0 + cy0, score, True)
