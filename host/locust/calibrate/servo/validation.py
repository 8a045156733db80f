"""Validation: a fitted servo predicting recordings the fit never saw, each step's peak speed
measured and predicted."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from ...params import Servo
from ...sim.gl import minimize
from ..curves import Curves
from .layout import FD_STEP, Layout, clock_name, delay_name, values_of
from .recording import RATE_WINDOW_S, Recording, Timing, checked
from .rig import recording_curves, residuals, rig_model, simulate_deg, simulate_rate
from .starts import timing_guess


@dataclass(frozen=True)
class StepPeak:
    """One step's peak speed, measured and predicted.

    Attributes
    ----------
    step_deg : float
        The signed command change.
    peak_speed_measured_rad_per_s, peak_speed_predicted_rad_per_s : float
        The largest speed in the step's window; the prediction sampled at the recording's
        own sample times.
    """

    step_deg: float                            # the signed command change
    peak_speed_measured_rad_per_s: float
    peak_speed_predicted_rad_per_s: float      # sampled at the recording's own sample times

    @property
    def error(self) -> float:
        """Predicted over measured peak, minus one (dimensionless)."""
        return self.peak_speed_predicted_rad_per_s / self.peak_speed_measured_rad_per_s - 1.0


@dataclass(frozen=True)
class Validation:
    """A fitted servo predicting a recording it was not fitted to; only the recording's own
    timing (delay; clock ratio for an angle recording of three edges or more) is fitted to it,
    and a rate recording's gyro gain is the fitted recordings' (the same gyro) or, without
    one, its own integral over each step against the step.

    Attributes
    ----------
    source : str
        The recording's name.
    kind : str
        ``"angle"`` or ``"rate"``.
    rms : float
        RMS of prediction minus recording: deg (angle) or rad/s (rate).
    timing : Timing
        The recording's timing, fitted to it.
    gain : float or None
        The gyro gain used [gyro units per rad/s] (None for an angle recording).
    steps : list of StepPeak
        Each step's peak speed.
    curves : Curves
        The recording against the prediction.
    """

    source: str
    kind: str
    rms: float                                 # deg (angle) or rad/s (rate)
    timing: Timing
    gain: float | None
    steps: list[StepPeak]
    curves: Curves = field(repr=False)

    def summary(self) -> dict:
        """The validation for JSON output.

        Returns
        -------
        dict
            The fields (rms with its unit, the timing rounded, each step's peaks and error).
        """
        return {"source": self.source, "kind": self.kind, "rms": self.rms,
                "rms_unit": "deg" if self.kind == "angle" else "rad/s",
                "command_delay_s": round(self.timing.delay_s, 5),
                "command_clock_ratio": round(self.timing.clock_ratio, 6),
                "gyro_gain_units_per_rad_per_s": self.gain,
                "steps": [{"step_deg": p.step_deg,
                           "peak_speed_measured_rad_per_s": p.peak_speed_measured_rad_per_s,
                           "peak_speed_predicted_rad_per_s": p.peak_speed_predicted_rad_per_s,
                           "error": p.error} for p in self.steps]}


def step_windows(rec: Recording) -> list[tuple[int, int]]:
    """Each step's window: to the next edge, at most ``RATE_WINDOW_S``.

    Parameters
    ----------
    rec : Recording
        The recording.

    Returns
    -------
    list of tuple of int
        (edge, end) sample indices, ``end`` one past the last.
    """
    if rec.kind == "rate":
        return [(e, end) for e, _, end in rec.windows()]
    edges = list(rec.edges) + [len(rec.t_s)]
    return [(e, min(nxt, int(np.searchsorted(rec.t_s, rec.t_s[e] + RATE_WINDOW_S))))
            for e, nxt in itertools.pairwise(edges)]


def peak_speeds(rec: Recording, predicted: np.ndarray, gain: float | None) -> list[StepPeak]:
    """Each step's peak speed, measured and predicted (``predicted``: the model's angle [deg]
    at every sample of an angle recording, its speed [rad/s] at the fitted samples of a rate
    recording). An angle's speed is its change between samples over their interval.

    Parameters
    ----------
    rec : Recording
        The recording.
    predicted : numpy.ndarray
        The model's angle [deg] or speed [rad/s], as above.
    gain : float or None
        A rate recording's gyro gain [gyro units per rad/s] (unused for an angle one).

    Returns
    -------
    list of StepPeak
    """
    out = []
    if rec.kind == "rate":
        measured = rec.rate_units[rec.samples()] / gain
        k0 = 0
        for e, first, end in rec.windows():
            n = end - first
            sl = slice(k0 + (e - first), k0 + n)
            out.append(StepPeak(float(rec.command_deg[e] - rec.command_deg[e - 1]),
                                float(np.max(np.abs(measured[sl]))), float(np.max(np.abs(predicted[sl])))))
            k0 += n
        return out
    dt = np.diff(rec.t_s)
    meas = np.radians(np.diff(rec.angle_deg)) / dt
    pred = np.radians(np.diff(predicted)) / dt
    for e, end in step_windows(rec):
        sl = slice(e - 1, end - 1)
        out.append(StepPeak(float(rec.command_deg[e] - rec.command_deg[e - 1]),
                            float(np.max(np.abs(meas[sl]))), float(np.max(np.abs(pred[sl])))))
    return out


def _fitted_timing(servo: Servo, rec: Recording, gain: float | None, model) -> Timing:
    """The recording's own timing with the servo held: the best of a few delays around the
    data's guess, then least squares."""
    layout = Layout(values_of(servo), (rec.fits_clock,), (False,))

    def residual(x: np.ndarray) -> np.ndarray:
        xs = np.atleast_2d(np.asarray(x).T).reshape(-1, layout.size)
        cands = [(servo, layout.unpack(row)[1], [gain]) for row in xs]
        r = residuals([rec], [model], cands)[0].T
        return np.where(np.isfinite(r), r, 1e3)

    noload = servo.noload_speed_rad_per_s if math.isfinite(servo.noload_speed_rad_per_s) else 10.0
    delay_s, ratio = timing_guess(rec, noload)
    frame_s = float(np.median(np.diff(rec.t_s)))
    starts = [layout.params.as_vector({delay_name(0): delay_s + f * frame_s, clock_name(0): ratio - 1.0})
              for f in (-1.5, -1.0, -0.5, 0.0, 0.5)]
    bounds = layout.bounds()
    lo, hi = bounds
    xs = np.clip(np.array(starts), lo + 1e-6, hi - 1e-6)
    x0 = xs[int(np.argmin(np.sum(residual(xs.T) ** 2, axis=0)))]
    x, _ = minimize.least_squares(x0, residual, bounds=bounds, max_iter=40, verbose=0, eps=FD_STEP)
    return layout.unpack(np.asarray(x).ravel())[1][0]


def validate(servo: Servo, rec: Recording, gain: float | None = None) -> Validation:
    """Predict a recording with a fitted servo; see :class:`Validation`.

    Parameters
    ----------
    servo : Servo
        The fitted servo.
    rec : Recording
        A recording it was not fitted to.
    gain : float, optional
        The gyro's gain [gyro units per rad/s] (its sign is taken from the data); by default
        the recording's own.

    Returns
    -------
    Validation

    Raises
    ------
    CalibrationError
        A recording too short, without a step, or with a flat signal.
    """
    rec = checked(rec)
    if rec.kind == "rate" and gain is None:
        gain = rec.gain_sign * rec.gain_guess()
    elif rec.kind == "rate":
        gain = rec.gain_sign * abs(gain)
    model = rig_model(rec.rig)
    timing = _fitted_timing(servo, rec, gain, model)
    if rec.kind == "angle":
        predicted = simulate_deg(model, [servo], [timing], rec, float(rec.angle_deg[0]))[0]
        rms = float(np.sqrt(np.mean((predicted - rec.angle_deg) ** 2)))
    else:
        predicted = simulate_rate(model, [servo], [timing.delay_s], rec)[0]
        rms = float(np.sqrt(np.mean((predicted - rec.rate_units[rec.samples()] / gain) ** 2)))
    return Validation(rec.source, rec.kind, rms, timing, gain, peak_speeds(rec, predicted, gain),
                      recording_curves(model, servo, timing, gain, rec, label="predicted: "))
