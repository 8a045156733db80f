"""What the recordings tell of the servo: the fit's covariance and intervals, which values they
identify, and the notes a user should read (misfits, convergence in the time step, the
fitted servo in plain words)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...params import Servo
from ...sim.gl import minimize
from ..fitstats import Estimate, cluster_covariance, covariance, linear_shift
from .layout import Layout
from .recording import Recording
from .rig import rig_model

if TYPE_CHECKING:
    from .fit import Residual

MAX_RELATIVE_STD = 0.25   # identifiable: 95% interval within about +-50% of the value
# The samples of one step share their errors (the model is not the servo, the command's
# PWM period moves each edge): with enough steps the covariance is cluster-robust, each
# step a cluster (fitstats.cluster_covariance); with fewer, s^2 (J^T J)^-1.
CLUSTERS_PER_PARAMETER = 2


def step_clusters(rec: Recording) -> np.ndarray:
    """The step each fitted sample belongs to.

    Parameters
    ----------
    rec : Recording
        The recording (checked).

    Returns
    -------
    numpy.ndarray of int
        Per fitted sample: 0, 1, ... (samples before the first edge: 0).
    """
    if rec.kind == "rate":
        return np.concatenate([np.full(end - first, k) for k, (_, first, end) in enumerate(rec.windows())])
    return np.maximum(np.searchsorted(rec.edges, np.arange(len(rec.t_s)), side="right") - 1, 0)


def fit_covariance(residual: Residual, x: np.ndarray, r: np.ndarray):
    """The covariance of the values (physical, then nuisance) at the solution ``x``: clustered
    by servo step when there are enough steps, with the time step's shift as a type-B part.

    Parameters
    ----------
    residual : Residual
        The fit's residual.
    x : numpy.ndarray
        The solution, in the solver's variables.
    r : numpy.ndarray
        The residual there.

    Returns
    -------
    locust.calibrate.fitstats.Covariance
        Of the free values, in the table's order.
    """
    recs, layout = residual.recs, residual.layout
    jac, _ = minimize.jacobian_fd(residual, x.reshape(-1, 1), r.reshape(-1, 1), np.float64(1e-6), 0,
                                  [b.reshape(-1, 1) for b in layout.bounds()])
    clusters = np.concatenate([step_clusters(rec) + 10_000 * k for k, rec in enumerate(recs)])
    jac_p = layout.params.to_values_jacobian(jac, x)      # d r / d p = (d r / d x) / (d p / d x)
    # the fit's time step: implicitfast is first order, so the values' distance to the dt -> 0
    # limit is about twice their shift when the step is halved (Richardson); a type-B part
    half = [rig_model(replace(rec.rig, timestep_s=rec.rig.timestep_s / 2)) for rec in recs]
    shift = 2.0 * linear_shift(jac_p, residual(x.reshape(-1, 1), half).ravel() - r)
    if len(np.unique(clusters)) > CLUSTERS_PER_PARAMETER * layout.size:
        return cluster_covariance(jac_p, r, clusters, shift=shift)
    return replace(covariance(jac_p, r), shift=shift)


def estimates_of(cov, values: np.ndarray, layout: Layout, held: dict[str, float | None], n_recs: int):
    """Estimates of the physical values (the held ones exact), the timing std per recording
    (delay, clock) and the gain estimate of each rate recording.

    Parameters
    ----------
    cov : locust.calibrate.fitstats.Covariance
        The fit's (:func:`fit_covariance`).
    values : numpy.ndarray
        The free values at the solution.
    layout : Layout
        The fit's table.
    held : dict of str to float or None
        Robot key -> the value held (None: fitted).
    n_recs : int
        Recordings fitted.

    Returns
    -------
    estimates : dict of str to Estimate
        By robot key.
    identifiable : dict of str to bool
        The held keys (True); :func:`mark_identifiable` adds the fitted ones.
    timing_std : list of list of float
        Per recording: (delay [s], clock ratio).
    gains : list of Estimate or None
        Per recording: its gyro gain (None for an angle one).
    """
    estimates, identifiable = {}, {}
    for i, key in enumerate(layout.fitted):
        estimates[key] = cov.parameter(values, i)
    for key, value in held.items():
        if value is not None:
            estimates[key] = Estimate(value, 0.0, value, value)
            identifiable[key] = True
    timing_std = [[0.0, 0.0] for _ in range(n_recs)]
    gain_est: list[Estimate | None] = [None] * n_recs
    for j, (k, what) in enumerate(layout.nuisance()):
        est = cov.parameter(values, len(layout.fitted) + j)
        if what == "gain":
            gain_est[k] = est
        else:
            timing_std[k][0 if what == "delay" else 1] = est.std
    return estimates, identifiable, timing_std, gain_est


def mark_identifiable(residual: Residual, x: np.ndarray, r: np.ndarray, estimates: dict[str, Estimate],
                      identifiable: dict[str, bool], notes: list[str]) -> None:
    """Mark each fitted value identifiable or not (interval, edge of its range, profile),
    with a note for each that is not.

    Parameters
    ----------
    residual : Residual
        The fit's residual.
    x, r : numpy.ndarray
        The solution and its residual.
    estimates : dict of str to Estimate
        The values by robot key (:func:`estimates_of`).
    identifiable : dict of str to bool
        Filled in, by robot key.
    notes : list of str
        Appended to.
    """
    fitted = residual.layout.fitted
    at_edge = residual.layout.params.near_bound(x, 1e-3)
    profile = profile_ok(residual, x, r, len(fitted))
    for i, key in enumerate(fitted):
        ok = bool(np.isfinite(estimates[key].std) and estimates[key].relative_std <= MAX_RELATIVE_STD)
        if at_edge[i]:
            ok = False
            notes.append(f"{key} ran to the edge of its range ({estimates[key].value:.3g}): the recordings do "
                         "not bound it")
        elif ok and not profile[i]:
            ok = False
            notes.append(f"{key} is not identifiable from these recordings: halving or doubling it changes the "
                         "fit by less than the noise")
        elif not ok:
            notes.append(f"{key} is not identifiable from these recordings (its 95% interval is wider than "
                         f"about +-{200 * MAX_RELATIVE_STD:.0f}%)")
        identifiable[key] = ok


def profile_ok(residual: Residual, x: np.ndarray, r: np.ndarray, nphys: int) -> list[bool]:
    """Whether halving *and* doubling each physical parameter (the others kept) worsens the
    fit by more than two standard errors would. The Jacobian alone can call a parameter
    determined at a point where it only just starts to act; this catches the one-sided cases.

    Parameters
    ----------
    residual : Residual
        The fit's residual.
    x, r : numpy.ndarray
        The solution and its residual.
    nphys : int
        The physical values fitted: the first of ``x``, each log-scaled.

    Returns
    -------
    list of bool
        One per physical value.
    """
    ssr = float(r @ r)
    s2 = ssr / max(len(r) - len(x), 1)
    trials = []
    for i in range(nphys):
        for factor in (0.5, 2.0):
            xi = x.copy()
            xi[i] += math.log(factor)
            trials.append(xi)
    rr = residual(np.array(trials).T)
    rise = np.sum(rr**2, axis=0) - ssr
    return [bool(min(rise[2 * i], rise[2 * i + 1]) > 4.0 * s2) for i in range(nphys)]


def misfit_notes(recs: list[Recording], per_rec: list[float], gains: list[float | None],
                 identifiable: dict[str, bool], notes: list[str]) -> dict[str, bool]:
    """A recording the model does not follow makes every value untrustworthy: the
    identifiable flags then, all False, with the note first.

    Parameters
    ----------
    recs : list of Recording
        The recordings.
    per_rec : list of float
        Each one's RMS residual, deg (angle) or rad/s (rate).
    gains : list of float or None
        Each one's gyro gain (None for an angle one).
    identifiable : dict of str to bool
        The flags so far.
    notes : list of str
        Inserted into.

    Returns
    -------
    dict of str to bool
        The flags.
    """
    for rec, rms, g in zip(recs, per_rec, gains):
        if rec.kind == "angle":
            bad = rms > max(3.0, 0.05 * float(np.ptp(rec.command_deg)))
        else:
            bad = rms > 0.15 * float(np.max(np.abs(rec.rate_units))) / abs(g)
        if bad:
            identifiable = dict.fromkeys(identifiable, False)
            unit = "deg" if rec.kind == "angle" else "rad/s"
            notes.insert(0, f"the model does not follow {Path(rec.source).name} (RMS {rms:.3g} {unit}): no value "
                            "is trustworthy; check --inertia-kgm2, --gravity-moment-nm and the command column")
    return identifiable


def convergence_notes(recs: list[Recording], per_rec: list[float], rms_half: list[float], notes: list[str]) -> None:
    """A note for each recording whose RMS moves by more than 5 % at half the time step.

    Parameters
    ----------
    recs : list of Recording
        The recordings.
    per_rec, rms_half : list of float
        Each one's RMS residual at its time step and at half of it.
    notes : list of str
        Appended to.
    """
    for rec, full, half in zip(recs, per_rec, rms_half):
        if abs(half - full) > 0.05 * full:
            notes.append(f"not converged in the time step: {Path(rec.source).name}'s RMS is {full:.3g} at "
                         f"{rec.rig.timestep_s:g} s and {half:.3g} at half of it")


def physics_notes(servo: Servo, recs: list[Recording], notes: list[str]) -> None:
    """Plain-language facts about the fitted servo that a user should check.

    Parameters
    ----------
    servo : locust.params.Servo
        The fitted servo.
    recs : list of Recording
        The recordings (the first one's load).
    notes : list of str
        Appended to.
    """
    linear_deg = math.degrees(servo.stall_torque_nm / servo.kp_nm_per_rad)
    j = recs[0].rig.inertia_kgm2
    tau_ms = 1000 * (j + servo.armature_kgm2) * servo.noload_speed_rad_per_s / servo.stall_torque_nm
    zeta = ((servo.kv_nms_per_rad + servo.stall_torque_nm / servo.noload_speed_rad_per_s)
            / (2 * math.sqrt(servo.kp_nm_per_rad * (j + servo.armature_kgm2))))
    notes.append(f"top speed {servo.noload_speed_rad_per_s:.3g} rad/s, reached with a time constant of "
                 f"{tau_ms:.3g} ms on this load; full torque until {linear_deg:.3g} deg from the command; "
                 f"damping ratio {zeta:.2g} inside that range")
