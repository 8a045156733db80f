"""Where to look next: Tracker's constant-acceleration look-ahead.

Tracker's autotracker (``AutoTrackerCore.getPredictedMatchTarget``) predicts the next
position from the last four marked steps, per axis: from the acceleration
(``3 p0 - 3 p1 + p2``) when the jerk is small against the mean acceleration, else from
the velocity (``2 p0 - p1``) when the acceleration is small against the mean velocity,
else it stays at the last position. Without this a tossed ball leaves a +-40 px search
window within a frame or two.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from functools import lru_cache
from operator import mul

import numpy as np

Point = tuple[float, float]

LOOKBACK = 4  # Tracker's predictionLookback


def predict_next(history: Iterable[Point | None]) -> Point | None:
    """Predicted next position from ``history`` (oldest first, ``None`` = not found).

    Parameters
    ----------
    history : iterable of (tuple of float or None)
        Recent positions [px].

    Returns
    -------
    tuple of float or None
        (px, py) [px]; None when nothing recent was found.
    """
    prev = list(history)[-LOOKBACK:][::-1]  # prev[0] is the latest
    prev += [None] * (LOOKBACK - len(prev))
    if prev[0] is None:
        return None
    if prev[1] is None:
        return prev[0]
    return (_predict_axis([p[0] if p else None for p in prev]),
            _predict_axis([p[1] if p else None for p in prev]))


def _predict_axis(p: list[float | None]) -> float:
    """One axis; ``p[0]`` the latest position, ``p[1]`` known, older ones possibly ``None``.

    Tracker's rule, written out for the four-step lookback: the mean acceleration is over
    the two second differences the four steps hold, the mean velocity over the three first
    differences.
    """
    p0, p1, p2, p3 = p
    if p2 is None:          # two positions: constant velocity
        return 2 * p0 - p1
    if p3 is None:          # three: constant acceleration
        return 3 * p0 - 3 * p1 + p2
    acc0, acc1 = p0 - 2 * p1 + p2, p1 - 2 * p2 + p3
    if abs(p0 - 3 * p1 + 3 * p2 - p3) < abs((acc0 + acc1) / 2):      # jerk small against acceleration
        return 3 * p0 - 3 * p1 + p2
    if abs(acc0) < abs(((p0 - p1) + (p1 - p2) + (p2 - p3)) / 3):     # acceleration small against velocity
        return 2 * p0 - p1
    return p0


class MotionHistory:
    """The last few positions of one marker and the search centre they predict."""

    def __init__(self) -> None:
        self._points: deque[Point | None] = deque(maxlen=LOOKBACK)
        self.last_found: Point | None = None

    def add(self, point: Point | None) -> None:
        """Record the next frame's position.

        Parameters
        ----------
        point : tuple of float or None
            (px, py) [px]; None when not found.
        """
        self._points.append(point)
        if point is not None:
            self.last_found = point

    def search_centre(self) -> Point | None:
        """The look-ahead prediction, or the last position seen when there is none.

        Returns
        -------
        tuple of float or None
            (px, py) [px]; None before the first sighting.
        """
        return predict_next(self._points) or self.last_found


@lru_cache(maxsize=1024)
def _fit_matrix(offsets: tuple[int, ...]) -> list[list[float]]:
    """Least-squares polynomial through positions at frames ``offsets`` (the last one 0): a
    quadratic; a line through two, the point itself for one. Coefficients (highest power
    first) = matrix @ positions; a gap-free run of sightings, the usual case, is always the same."""
    return np.linalg.pinv(np.vander(np.array(offsets, float), min(len(offsets), 3))).tolist()


_NO_GAP = {n: tuple(range(1 - n, 1)) for n in range(1, 9)}


class MotionFit:
    """Where a marker should be on a given frame, also across frames it was not seen: the
    centre of the window it is searched in (not its track: only the last ``keep`` sightings).

    A least-squares constant-acceleration fit (per axis, over the frame number) to the last
    ``keep`` positions found; with two positions constant velocity, with one the position
    itself. While the marker is lost the fit is extrapolated, so a sticker that leaves the
    picture on a ballistic arc is looked for where it comes back.
    """

    def __init__(self, keep: int = 5) -> None:  # 3 <= keep <= 8
        self._found: deque[tuple[int, float, float]] = deque(maxlen=keep)
        self.max_speed_px: float = 0.0
        self._coef: list[tuple[float, float]] | None = None

    def add(self, frame: int, point: Point | None) -> None:
        """Record a position found; a frame not found (None) adds nothing.

        Parameters
        ----------
        frame : int
            The frame number.
        point : tuple of float or None
            (px, py) [px].
        """
        if point is None:
            return
        if self._found:
            f, x, y = self._found[-1]
            if frame - f == 1:
                self.max_speed_px = max(self.max_speed_px, ((point[0] - x) ** 2 + (point[1] - y) ** 2) ** 0.5)
        self._found.append((frame, point[0], point[1]))
        self._coef = None

    @property
    def sightings(self) -> int:
        """Positions held (at most ``keep``)."""
        return len(self._found)

    @property
    def last_frame(self) -> int | None:
        """The frame of the last sighting; None before the first."""
        return self._found[-1][0] if self._found else None

    def frames_lost(self, frame: int) -> int:
        """Frames since the last one found, not counting ``frame`` itself (0: found just before).

        Parameters
        ----------
        frame : int
            The frame being searched.

        Returns
        -------
        int
            Frames lost; 0 before the first sighting.
        """
        return frame - self._found[-1][0] - 1 if self._found else 0

    def _fit(self) -> list[tuple[float, float]] | None:
        """Polynomial coefficients (highest power first; columns x, y) in frames since the last
        sighting, computed once per sighting."""
        if self._coef is None and self._found:
            last, n = self._found[-1][0], len(self._found)
            if last - self._found[0][0] == n - 1:   # no gap, the usual case
                recent, offsets = self._found, _NO_GAP[n]
            else:
                recent = [p for p in self._found if p[0] >= last - 2 * n]   # one stretch of sightings
                offsets = tuple(p[0] - last for p in recent)
            xs, ys = [p[1] for p in recent], [p[2] for p in recent]
            self._coef = [(sum(map(mul, row, xs)), sum(map(mul, row, ys))) for row in _fit_matrix(offsets)]
        return self._coef

    def predict(self, frame: int) -> Point | None:
        """Where the fit puts the marker on ``frame``.

        Parameters
        ----------
        frame : int
            The frame number.

        Returns
        -------
        tuple of float or None
            (px, py) [px]; None before any sighting.
        """
        c = self._fit()
        if c is None:
            return None
        dt = frame - self._found[-1][0]
        x = y = 0.0
        for cx, cy in c:
            x, y = x * dt + cx, y * dt + cy
        return x, y

    def predict_motion(self, frame: int) -> tuple[Point, Point] | None:
        """``predict(frame)`` and the motion into it, ``predict(frame) - predict(frame - 1)``.

        Parameters
        ----------
        frame : int
            The frame being searched.

        Returns
        -------
        tuple of (tuple of float) or None
            The predicted position and motion [px, px/frame]; None before the first sighting.
        """
        c = self._fit()
        if c is None:
            return None
        dt = frame - self._found[-1][0]
        x = y = x1 = y1 = 0.0
        for cx, cy in c:
            x, y = x * dt + cx, y * dt + cy
            x1, y1 = x1 * (dt - 1) + cx, y1 * (dt - 1) + cy
        return (x, y), (x - x1, y - y1)

    @property
    def last_point(self) -> Point | None:
        """The last position found [px]; None before the first."""
        return (self._found[-1][1], self._found[-1][2]) if self._found else None

    @property
    def stretch(self) -> int:
        """Sightings the fit is made over: the last stretch of them (none older than twice their
        count before the last); 1 right after a re-acquisition, when there is no velocity yet."""
        if not self._found:
            return 0
        last = self._found[-1][0]
        return sum(1 for p in self._found if p[0] >= last - 2 * len(self._found))
