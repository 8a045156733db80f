"""The servo fit: every recording's residual against the rig model, minimised from the grid's
best starts with MuJoCo's least-squares solver, then the intervals and the notes
(:mod:`.intervals`)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from ...errors import CalibrationError
from ...params import Servo
from ...sim.gl import minimize, mujoco
from . import intervals
from .layout import FD_STEP, Layout
from .recording import Recording, Timing, checked
from .result import ServoFit
from .rig import recording_curves, residuals, rig_model, rms_in_unit
from .starts import STARTS, grid_starts

MAX_ITER = 60             # iterations of one solver run at most
EXPECTED_ITERATIONS = 15  # what a run takes, for progress until one has run (both SG90s: 43 in 3 runs)
# the solver's regularisation grows by this factor after each rejected step (MuJoCo's default
# 10**0.1): at the optimum, where every step is rejected, a run ends after a few dozen single
# simulations instead of about 140 (both SG90 recordings: the same values to 6 digits, 32 -> 21 s
# of CPU)
MU_FACTOR = 10 ** 0.5


class Residual:
    """The fit's residual vector for one or more candidate vectors ``x`` (columns), each
    recording's part in units of its noise (``scales``), so that recordings of different
    kinds weigh by their information: a first guess (1 deg; a gyro unit), then each one's
    own RMS (:meth:`weigh_by_own_noise`).

    Parameters
    ----------
    recs : list of Recording
        The recordings (checked).
    layout : Layout
        The fit's table.
    """

    def __init__(self, recs: list[Recording], layout: Layout):
        self.recs, self.layout = recs, layout
        self.models = [rig_model(r.rig) for r in recs]
        self.scales = [math.radians(1.0) if r.kind == "angle" else 1.0 for r in recs]

    def __call__(self, x: np.ndarray, on: list[mujoco.MjModel] | None = None) -> np.ndarray:
        """The residual of each candidate.

        Parameters
        ----------
        x : numpy.ndarray
            One solver vector, or several as columns.
        on : list of mujoco.MjModel, optional
            The rig models to simulate on (default: each recording's at its time step).

        Returns
        -------
        numpy.ndarray, shape (samples, candidates)
            In units of each recording's noise; a candidate that diverged reads 1e3.
        """
        xs = np.atleast_2d(np.asarray(x).T).reshape(-1, self.layout.size)
        parts = residuals(self.recs, on or self.models, [self.layout.unpack(row) for row in xs])
        r = np.concatenate([p / sc for p, sc in zip(parts, self.scales)], axis=1).T
        return np.where(np.isfinite(r), r, 1e3)

    def weigh_by_own_noise(self, x: np.ndarray) -> None:
        """Scale each recording's part by its own RMS at ``x``.

        Parameters
        ----------
        x : numpy.ndarray
            A solver vector (the best start's solution).
        """
        parts = residuals(self.recs, self.models, [self.layout.unpack(x)])
        self.scales = [max(float(np.sqrt(np.mean(p ** 2))), 1e-12) for p in parts]


class _Shown:
    """Progress of the solver runs: each run is max_iter steps, an iteration worth max_iter /
    (the iterations the run before took; EXPECTED_ITERATIONS for the first), never past its
    run's end until it ends; a run that ends early fills its share then. A bar's rate is then
    about a run's time, and its time left the runs still to go (tests/test_calibrate_servo.py)."""

    def __init__(self, max_iter: int, progress: Callable[[int], None] | None):
        self.max_iter, self.progress = max_iter, progress
        self.shown, self.last = 0, EXPECTED_ITERATIONS   # steps shown in this run, iterations the last run took

    def on_iter(self, trace) -> None:
        if self.progress:
            step = min(max(1, round(self.max_iter / self.last)), self.max_iter - 1 - self.shown)
            if step > 0:
                self.shown += step
                self.progress(step)

    def run_ended(self, iterations: int) -> None:
        if self.progress:
            self.progress(self.max_iter - self.shown)
        self.shown, self.last = 0, max(iterations, 1)


def _solve(residual: Residual, max_iter: int, progress: Callable[[int], None] | None) -> tuple[np.ndarray, int]:
    """Least squares from each grid start, the best kept; with several recordings, each then
    weighed by its own noise and the best polished. Returns (x, iterations)."""
    shown = _Shown(max_iter, progress)
    bounds = residual.layout.bounds()

    def least_squares(x0):
        x, trace = minimize.least_squares(x0, residual, bounds=bounds, max_iter=max_iter, verbose=0,
                                          iter_callback=shown.on_iter, eps=FD_STEP, xtol=1e-8, gtol=1e-10,
                                          mu_factor=MU_FACTOR)
        shown.run_ended(len(trace))
        return np.asarray(x).ravel(), len(trace)

    best, best_cost, iterations = None, math.inf, 0
    starts = grid_starts(residual.recs, residual.layout, residual, bounds)
    if progress and len(starts) < STARTS:   # fewer distinct starts than planned
        progress(max_iter * (STARTS - len(starts)))
    for x0 in starts:
        x, n = least_squares(x0)
        iterations += n
        cost = float(np.sum(residual(x.reshape(-1, 1)) ** 2))
        if cost < best_cost:
            best, best_cost = x, cost
    x = best
    if len(residual.recs) > 1:   # weigh each recording by its own noise, and polish
        residual.weigh_by_own_noise(x)
        x, n = least_squares(x)
        iterations += n
    return x, iterations


def progress_steps(n_recordings: int, max_iter: int = MAX_ITER) -> int:
    """Steps that :func:`fit_servo`'s ``progress`` reports in all: ``max_iter`` per solver run,
    one per start and a polish with several recordings (see ``_solve``).

    Parameters
    ----------
    n_recordings : int
        Recordings to fit.
    max_iter : int
        Iterations of one solver run at most.

    Returns
    -------
    int
        The steps' total.
    """
    return (STARTS + (n_recordings > 1)) * max_iter


def _checked_inputs(recordings: list[Recording], stall_torque_nm: float | None,
                    kv_nms_per_rad: float | None) -> list[Recording]:
    """The recordings, checked, and the held values refused where they cannot be used."""
    if not recordings:
        raise CalibrationError("no recording given", "give the CSV of a servo step")
    recs = [checked(r) for r in recordings]
    if stall_torque_nm is not None and not (stall_torque_nm > 0 and math.isfinite(stall_torque_nm)):
        raise CalibrationError(f"--stall-torque-nm must be positive (got {stall_torque_nm})",
                               "the SG90's datasheet gives about 0.15 N*m")
    if stall_torque_nm is None and len({r.rig.inertia_kgm2 for r in recs}) < 2 \
            and not any(r.rig.gravity_moment_nm for r in recs):
        raise CalibrationError(
            "one load gives only ratios (speed, armature/stall, kp/stall): the stall torque is needed to split them",
            "give --stall-torque-nm (stall test or datasheet: about 0.15 N*m for an SG90), or a second recording "
            "with another load")
    if kv_nms_per_rad is not None and not (kv_nms_per_rad >= 0 and math.isfinite(kv_nms_per_rad)):
        raise CalibrationError(f"--kv-nms-per-rad must be 0 or more (got {kv_nms_per_rad})",
                               "0 holds the servo without velocity feedback inside its drive")
    return recs


def _rms_half_step(recs: list[Recording], servo: Servo, timings: list[Timing],
                   gains: list[float | None]) -> list[float]:
    """Each recording's RMS residual (its unit) with the fitted servo simulated at half the step."""
    models = [rig_model(replace(rec.rig, timestep_s=rec.rig.timestep_s / 2)) for rec in recs]
    parts = residuals(recs, models, [(servo, timings, gains)])
    return [rms_in_unit(rec, p[0], g) for rec, p, g in zip(recs, parts, gains)]


def fit_servo(recordings: list[Recording], stall_torque_nm: float | None = None, *,
              kv_nms_per_rad: float | None = None, max_iter: int = MAX_ITER,
              progress: Callable[[int], None] | None = None) -> ServoFit:
    """Identify the servo from one or more recordings (angle or rate); see :mod:`locust.calibrate.servo`.
    ``stall_torque_nm`` and ``kv_nms_per_rad``, when given, are held at that value.

    Parameters
    ----------
    recordings : list of Recording
        Angle and rate recordings, fitted together.
    stall_torque_nm : float, optional
        The stall torque [N*m], held (a stall test, the datasheet); fitted when not given.
    kv_nms_per_rad : float, optional
        The servo law's velocity gain [N*m*s/rad], held; fitted when not given.
    max_iter : int
        Iterations of one solver run at most.
    progress : callable, optional
        Called with the number of steps done since its last call; they add up to
        :func:`progress_steps`.

    Returns
    -------
    ServoFit
        Its values by their robot keys (``servo.*``).

    Raises
    ------
    CalibrationError
        No recording; a stall torque not positive or a negative kv; one load only (one
        inertia, no weight to lift) without a stall torque; or a recording too short, without
        a step, or with a flat signal.
    """
    t_start = time.perf_counter()
    recs = _checked_inputs(recordings, stall_torque_nm, kv_nms_per_rad)
    held = {"servo.stall_torque_nm": stall_torque_nm, "servo.kv_nms_per_rad": kv_nms_per_rad}
    layout = Layout(held, tuple(r.fits_clock for r in recs), tuple(r.kind == "rate" for r in recs),
                    tuple(r.gain_sign if r.kind == "rate" else 1.0 for r in recs))
    residual = Residual(recs, layout)
    x, iterations = _solve(residual, max_iter, progress)
    r = residual(x.reshape(-1, 1)).ravel()
    servo, timings, gains = layout.unpack(x)
    cov = intervals.fit_covariance(residual, x, r)
    estimates, identifiable, timing_std, gain_est = intervals.estimates_of(cov, layout.params.free_values(x), layout,
                                                                           held, len(recs))

    parts = residuals(recs, residual.models, [(servo, timings, gains)])
    per_rec = [rms_in_unit(rec, p[0], g) for rec, p, g in zip(recs, parts, gains)]
    angle_rms = [(rms, len(rec.t_s)) for rec, rms in zip(recs, per_rec) if rec.kind == "angle"]
    rms_deg = (math.sqrt(sum(rms ** 2 * n for rms, n in angle_rms) / sum(n for _, n in angle_rms))
               if angle_rms else None)
    notes: list[str] = []
    intervals.mark_identifiable(residual, x, r, estimates, identifiable, notes)
    intervals.physics_notes(servo, recs, notes)
    identifiable = intervals.misfit_notes(recs, per_rec, gains, identifiable, notes)
    rms_half = _rms_half_step(recs, servo, timings, gains)
    intervals.convergence_notes(recs, per_rec, rms_half, notes)
    curves = [recording_curves(model, servo, timing, gain, rec)
              for model, rec, timing, gain in zip(residual.models, recs, timings, gains)]
    source = recs[0].source if len(recs) == 1 else "+".join(Path(rec.source).name for rec in recs)
    given = tuple(key for key, v in held.items() if v is not None)
    return ServoFit(source=source, recordings=recs, estimates=estimates, given=given,
                    timings=timings, timing_std=[tuple(ts) for ts in timing_std], gains=gain_est,
                    identifiable=identifiable, notes=notes, rms_residual_deg=rms_deg, rms_per_recording=per_rec,
                    timestep_s=recs[0].rig.timestep_s, rms_half_step=rms_half,
                    n_samples=int(sum(p.shape[1] for p in parts)), iterations=iterations,
                    wall_s=time.perf_counter() - t_start, interval=cov.method, curves=curves)
