"""One error type per layer; the CLI turns any of them into one clear message.

Every error carries what was wrong (the message, naming the file, line, frame or
parameter) and, where there is one, what to do about it (the hint).
"""

from __future__ import annotations


class LocustError(Exception):
    """Base of every error a user can act on."""

    exit_code = 2

    def __init__(self, message: str, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.hint = hint

    def __str__(self) -> str:  # pragma: no cover - trivial
        return self.message if not self.hint else f"{self.message}\n  hint: {self.hint}"


class ParamsError(LocustError):
    """Robot parameters: unknown key, bad value, unreadable robot.toml."""


class GeometryError(LocustError):
    """A linkage that cannot be assembled (the four-bar does not close)."""


class SimError(LocustError):
    """The simulation could not be built or run."""


class DeviceError(LocustError):
    """Serial link, firmware, flashing, virtual robot."""


class TrackError(LocustError):
    """Video decoding and marker tracking."""


class TrialError(LocustError):
    """Filmed trials: finding and reading their tracks and run records, their configurations."""


class CalibrationError(LocustError):
    """Fitting the calibration experiments."""


class SweepError(LocustError):
    """Design sweeps and optimisation."""


class FabError(LocustError):
    """DXF reading and laminate generation."""


class ReportError(LocustError):
    """Building comparison reports."""


class MeasureError(LocustError):
    """Measuring the robot from photos: the board, the stickers, a pose the linkage cannot take."""


class WriteError(LocustError):
    """Writing a result: a read-only or non-regular target, a read-only folder, a full disk."""
