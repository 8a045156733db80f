"""What every marker model returns for one frame."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np


@dataclass(frozen=True)
class Detection:
    """A marker's position in one frame, in pixels (OpenCV convention).

    ``score`` is the model's own confidence (see each model); ``ok`` is false when the
    marker was not found, and then ``px``/``py`` are NaN -- never a guess.
    """

    px: float
    py: float
    score: float
    ok: bool

    @staticmethod
    def missing(score: float = math.nan) -> Detection:
        """A detection of a marker that was not found.

        Parameters
        ----------
        score : float
            The model's score for the frame.

        Returns
        -------
        Detection
            ``ok`` False, ``px`` and ``py`` nan.
        """
        return Detection(math.nan, math.nan, score, False)

    def point(self) -> tuple[float, float] | None:
        """The position, or None when not found.

        Returns
        -------
        tuple of float or None
            (px, py) [px].
        """
        return (self.px, self.py) if self.ok else None


class MarkerModel(Protocol):
    """One tracked marker. ``locate`` is called once per frame, in frame order."""

    name: str
    spec: str

    def locate(self, frame: int, image_bgr: np.ndarray) -> Detection:
        """Find the marker in one frame.

        Parameters
        ----------
        frame : int
            The frame number.
        image_bgr : ndarray
            The frame, BGR.

        Returns
        -------
        Detection
            Where it is [px], or not found.
        """


def window(centre: tuple[float, float], half_px: int, shape: tuple[int, ...]) -> tuple[int, int, int, int]:
    """Integer window ``(x0, y0, x1, y1)`` (exclusive end) of half-size ``half_px`` around
    ``centre``, clipped to an image of ``shape``.

    Parameters
    ----------
    centre : tuple of float
        (x, y) [px].
    half_px : int
        Half-size [px].
    shape : tuple of int
        The image's shape (height, width, ...).

    Returns
    -------
    tuple of int
        (x0, y0, x1, y1) [px].
    """
    cx, cy = int(round(centre[0])), int(round(centre[1]))
    h, w = shape[:2]
    return max(cx - half_px, 0), max(cy - half_px, 0), min(cx + half_px + 1, w), min(cy + half_px + 1, h)
