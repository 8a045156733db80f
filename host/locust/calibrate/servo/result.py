"""What a servo fit found: :class:`ServoFit`, its values by their robot keys."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...params import Servo
from ..curves import Curves
from ..fitstats import Estimate
from .layout import KEYS, servo_of
from .recording import Recording, Timing


@dataclass(frozen=True)
class ServoFit:
    """The result of :func:`~.fit.fit_servo`: the servo's values with their intervals, each
    recording's timing (and gyro gain), and how well the recordings fit.

    Attributes
    ----------
    source : str
        The recordings' names.
    recordings : list of Recording
        The recordings fitted (checked).
    estimates : dict of str to Estimate
        Each of ``KEYS`` by its robot key (units in the names); a held (given) one has std 0.
    given : tuple of str
        The ``KEYS`` held at a given value, not fitted.
    timings : list of Timing
        Each recording's fitted timing.
    timing_std : list of tuple of float
        Their standard uncertainties: (delay [s], clock ratio).
    gains : list of Estimate or None
        Per recording: a rate recording's gyro gain [gyro units per rad/s] (None for an angle one).
    identifiable : dict of str to bool
        Whether the data tell each value (see :mod:`locust.calibrate.servo`), by its robot key.
    notes : list of str
        Why a value is not identifiable, misfits, convergence in the time step.
    rms_residual_deg : float or None
        RMS residual over the angle recordings (None: there are none).
    rms_per_recording : list of float
        Each recording's RMS residual in its unit: deg (angle), rad/s (rate).
    timestep_s : float
        The rig model's physics step.
    rms_half_step : list of float
        The same RMS at half the step: convergence.
    n_samples : int
        Samples fitted.
    iterations : int
        Solver iterations, all runs.
    wall_s : float
        Wall time the fit took.
    interval : str
        How the intervals were computed.
    curves : list of Curves
        Each recording against the model, for the plots.
    """

    source: str
    recordings: list[Recording] = field(repr=False)
    estimates: dict[str, Estimate]           # KEYS -> value; a held one (given) has std 0
    given: tuple[str, ...]                   # the KEYS held at a given value, not fitted
    timings: list[Timing]
    timing_std: list[tuple[float, float]]
    gains: list[Estimate | None]             # per recording: the gyro gain [units per rad/s] of a rate recording
    identifiable: dict[str, bool]
    notes: list[str]
    rms_residual_deg: float | None           # over the angle recordings (None: there are none)
    rms_per_recording: list[float]           # in each recording's unit: deg (angle), rad/s (rate)
    timestep_s: float
    rms_half_step: list[float]               # the same at half the step: convergence
    n_samples: int
    iterations: int
    wall_s: float
    interval: str = "s^2 (J^T J)^-1, t(n-p)"
    curves: list[Curves] = field(default_factory=list, repr=False)

    @property
    def servo(self) -> Servo:
        """The fitted servo (other fields at their defaults)."""
        return servo_of({key: self.estimates[key].value for key in KEYS})

    @property
    def rms_residual_rad_per_s(self) -> float | None:
        """RMS residual over the rate recordings [rad/s] (None: there are none)."""
        rates = [r for rec, r in zip(self.recordings, self.rms_per_recording) if rec.kind == "rate"]
        return float(np.sqrt(np.mean(np.square(rates)))) if rates else None

    @property
    def rate_gain(self) -> float | None:
        """The gyro's gain of the fitted rate recordings [gyro units per rad/s] (their mean; None without one)."""
        gains = [g.value for g in self.gains if g is not None]
        return float(np.mean(gains)) if gains else None

    def summary(self) -> dict:
        """The fit for JSON output.

        Returns
        -------
        dict
            ``experiment`` ("servo"), each recording's kind and rig, each of ``KEYS`` (by its
            robot key) as its :meth:`~.fitstats.Estimate.as_dict` with ``identifiable`` (a
            given one without interval), the timings and gains per recording, and the fit's
            figures.
        """
        out = {"experiment": "servo", "source": self.source,
               "kind": [r.kind for r in self.recordings],
               "inertia_kgm2": [r.rig.inertia_kgm2 for r in self.recordings],
               "gravity_moment_nm": [r.rig.gravity_moment_nm for r in self.recordings]}
        for key in KEYS:
            est = self.estimates[key]
            entry = {**est.as_dict(), "identifiable": self.identifiable[key]}
            if key in self.given:
                entry = {"value": est.value, "std": None, "ci95": [None, None], "identifiable": True,
                         "given": True}
            out[key] = entry
        out["interval"] = self.interval
        out["command_delay_s"] = [round(t.delay_s, 5) for t in self.timings]
        out["command_delay_std_s"] = [round(s[0], 5) for s in self.timing_std]
        out["command_clock_ratio"] = [round(t.clock_ratio, 6) for t in self.timings]
        out["command_clock_ratio_std"] = [round(s[1], 6) for s in self.timing_std]
        out["gyro_gain_units_per_rad_per_s"] = [g.as_dict() if g is not None else None for g in self.gains]
        out.update(rms_residual_deg=self.rms_residual_deg, rms_residual_rad_per_s=self.rms_residual_rad_per_s,
                   rms_per_recording=self.rms_per_recording,
                   rms_unit=["deg" if r.kind == "angle" else "rad/s" for r in self.recordings],
                   timestep_s=self.timestep_s, rms_half_step=self.rms_half_step,
                   n_samples=self.n_samples, iterations=self.iterations, wall_s=round(self.wall_s, 2),
                   notes=self.notes)
        return out
