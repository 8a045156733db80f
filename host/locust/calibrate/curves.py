"""What a fit plot shows: measured data, the fitted model, in one unit."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Curves:
    """Data and model on a common abscissa (time, or trial number for the ramp)."""

    x: np.ndarray
    data: np.ndarray
    model: np.ndarray
    x_label: str            # e.g. "t [s]"
    y_label: str            # e.g. "tip displacement [mm]"
    title: str
    model_x: np.ndarray | None = None      # a finer abscissa for the model line, if any
    model_fine: np.ndarray | None = None

    @property
    def residual(self) -> np.ndarray:
        return self.data - self.model
