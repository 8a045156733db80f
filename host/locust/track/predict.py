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
from typing import Iterable, Optional

Point = tuple[float, float]

LOOKBACK = 4  # Tracker's predictionLookback


def predict_next(history: Iterable[Optional[Point]]) -> Optional[Point]:
    """Predicted next position from ``history`` (oldest first, ``None`` = not found)."""
    prev = list(history)[-LOOKBACK:][::-1]  # prev[0] is the latest
    prev += [None] * (LOOKBACK - len(prev))
    if prev[0] is None:
        return None
    if prev[1] is None:
        return prev[0]
    return (_predict_axis([p[0] if p else None for p in prev]),
            _predict_axis([p[1] if p else None for p in prev]))


def _diffs(values: list[Optional[float]], order: int) -> list[Optional[float]]:
    out = []
    for i in range(LOOKBACK):
        window = values[i:i + order + 1]
        if len(window) < order + 1 or any(v is None for v in window):
            out.append(None)
            continue
        coeffs = {1: (1, -1), 2: (1, -2, 1), 3: (1, -3, 3, -1)}[order]
        out.append(sum(c * v for c, v in zip(coeffs, window)))
    return out


def _mean_abs(values: list[Optional[float]]) -> float:
    present = [v for v in values if v is not None]
    return abs(sum(present) / len(present)) if present else 0.0


def _predict_axis(p: list[Optional[float]]) -> float:
    vel, acc, jerk = _diffs(p, 1), _diffs(p, 2), _diffs(p, 3)
    accel_valid = p[2] is not None and (p[3] is None or abs(jerk[0]) < _mean_abs(acc))
    veloc_valid = p[2] is None or abs(acc[0]) < _mean_abs(vel)
    if accel_valid:
        return 3 * p[0] - 3 * p[1] + p[2]
    if veloc_valid:
        return 2 * p[0] - p[1]
    return p[0]


class MotionHistory:
    """The last few positions of one marker and the search centre they predict."""

    def __init__(self) -> None:
        self._points: deque[Optional[Point]] = deque(maxlen=LOOKBACK)
        self.last_found: Optional[Point] = None

    def add(self, point: Optional[Point]) -> None:
        self._points.append(point)
        if point is not None:
            self.last_found = point

    def has_velocity(self) -> bool:
        """True when the last two positions are both known."""
        return len(self._points) >= 2 and self._points[-1] is not None and self._points[-2] is not None

    def search_centre(self) -> Optional[Point]:
        """The look-ahead prediction, or the last position seen when there is none."""
        return predict_next(self._points) or self.last_found
