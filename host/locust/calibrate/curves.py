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
        """Data minus model, in the data's unit."""
        return self.data - self.model

    @property
    def residual_label(self) -> str:
        """``residual [mm]``: data minus model, in the data's unit (``y_label``'s brackets);
        ``residual (no unit)`` for a pure number such as the ramp's tan(angle)."""
        unit = self.y_label[self.y_label.rfind("[") + 1:-1] if self.y_label.endswith("]") and "[" in self.y_label \
            else ""
        return f"residual [{unit}]" if unit else "residual (no unit)"
