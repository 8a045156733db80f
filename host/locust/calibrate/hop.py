"""Filmed hops -> the physics no bench experiment reaches: friction under impact, the folded
hinges in the real linkage, the servo's speed on the robot's own battery.

Each run (:mod:`.hopruns`: a ``locust hop --out`` folder, its measured phase times and the
track of its video) is simulated on its leg set built on the robot being fitted
(:func:`locust.params.leg_set`, the presets' rule: its links and its converged time step), so
runs of different leg sets are fitted together: their geometry differs, the physics named by
``--fit`` is shared. The residual (:mod:`.hopresidual`) is every run's tracked markers against
the simulation's, absolute, on the schedule's clock; the solver is
``mujoco.minimize.least_squares`` (:func:`solve`), started from the best point of a
coarse-to-fine grid (:func:`grid_start`).
Uncertainties (:mod:`.fitstats`): the frames of one hop share its errors (tracking, and a
model that is not the robot: neighbouring residuals are correlated), so the covariance is
cluster-robust with each hop of each run a cluster, from a central-difference Jacobian at
the optimum with a step (``FD_STEP``) over the contacts' jaggedness, t on hops - 1 degrees
of freedom; the fit's own time step adds the parameters' shift when it is halved (to first
order, one more rollout per run), and so do the uncertainties of the values the fit holds
fixed (from the bench calibrations: the hinge damping, the servo's armature, kp and stall
torque), each carried through the fit's sensitivity to it (one batch per run, each held
value one standard uncertainty either side), and the model's error against the plant measured
on the virtual robot (:data:`MODEL_ERROR_RELATIVE`), in quadrature. A value is *identifiable* when
its 95% interval is within about +-50% and it did not run to the edge of its range (a factor
``BOUND_FACTOR`` either side of where it started).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..errors import CalibrationError, ParamsError
from ..params import PHYSICAL_SECTIONS, fittable_keys, value_type
from ..sim.gl import minimize  # MuJoCo's solver, as locust.sim imports MuJoCo (its OpenGL checked first)
from ..trials.measured import Trial
from .fitstats import Estimate, cluster_covariance
from .hopresidual import (
    ANGLE_BOUND_DEG,
    BOUND_FACTOR,
    FD_STEP,
    HopResidual,
    RunFit,
    held_covariance,
    held_uncertainties,
    is_angle,
    optimum_jacobian,
    run_fits,
)
from .hopruns import STEP_TOLERANCE_M, Tally, converged_step

DEFAULT_KEYS = ("contact.foot_friction", "compliance.hinge_stiffness_nm_per_rad", "servo.noload_speed_rad_per_s")
PROVENANCE_NAME = "hops"       # written as source fit:hops
MAX_STD_DEG = 2.5              # an angle is identifiable with its 95% interval within about +-5 deg
MU_FACTOR = 10 ** 0.5          # the solver's regulariser grows by this a rejected step (MuJoCo's default
                               # 10**0.1 took ~4 rejections, each a simulation of every run, an iteration)
STALL_STEP = 2e-3              # the solver has converged where a step under this (0.2 %, 0.02 deg) ...
STALL_REDUCTION = 1e-3         # ... lowers the cost by under this part of it (a fifth of FD_STEP; the 95 %
                               # intervals are +-8 % or wider, std_model alone being 4 %)
MAX_RELATIVE_STD = 0.25        # identifiable: 95% interval within about +-50%
GRID_FACTOR = 1.6              # the starting grid spans this factor either side of the start ...
GRID_LEVELS = {1: 9, 2: 7, 3: 3, 4: 3, 5: 3}   # ... in this many levels per fitted value
GRID_STAGES = 3                # ... refined about its best point this many times
GRID_COARSEN = 2               # ... and simulated at this many times the run's step (it only picks the start:
                               # its points 12-60 % apart, the step's change a few 0.01 mm)
# The model's error against the plant (std_model, one standard deviation, in quadrature): the
# rollout at the measured phase times is not the virtual robot (its firmware's ticks, the
# rendered and tracked marker faces), and the hops' own scatter does not show what that moves.
# Measured by fitting the virtual robot's own filmed hops at known truths: the demo's fit
# (friction +4.2 %, hinge stiffness +3.6 %, no-load speed within 1 %, each marker then taken
# from where it stood) gave the 4 %, kept as the upper figure; with absolute
# positions bench/hop_model_error.py measures the RMS of each value's error (bias and spread
# together) on other hidden truths, below it so far (docs/calibrate.md). Relative for a
# positive value; in degrees for an angle, where the 1 deg is an estimate not yet measured on
# the virtual robot. A key not listed takes the largest listed of its kind.
MODEL_ERROR_RELATIVE = {"contact.foot_friction": 0.04, "compliance.hinge_stiffness_nm_per_rad": 0.04,
                        "servo.noload_speed_rad_per_s": 0.04}
MODEL_ERROR_DEG = {"geometry.crank_start_deg": 1.0, "geometry.ground_angle_deg": 1.0}


@dataclass(frozen=True)
class HopFit:
    """The hop fit: the fitted values with their intervals, and how each run is followed.

    Attributes
    ----------
    keys : tuple of str
        The fitted robot parameters, by dotted name (the unit in the name).
    start : dict of str to float
        Each key's starting value, in its unit.
    estimates : dict of str to Estimate
        Each key's value, standard deviation (numerical, held-value and model-error parts
        included) and 95 % interval, in its unit.
    identifiable : dict of str to bool
        Whether the runs determine the key (its interval narrow enough).
    runs : list of RunFit
        Each run's residuals and curves.
    notes : list of str
        What a person should know about the fit.
    rms_m : float
        RMS residual over every run [m].
    iterations : int
        Solver iterations.
    simulations : int
        Simulations run.
    wall_s : float
        Wall time of the fit [s].
    interval : str
        What the intervals include.
    """

    keys: tuple[str, ...]
    start: dict[str, float]
    estimates: dict[str, Estimate]
    identifiable: dict[str, bool]
    runs: list[RunFit]
    notes: list[str]
    rms_m: float
    iterations: int
    simulations: int
    wall_s: float
    interval: str = ""                   # what the intervals include

    def summary(self) -> dict:
        """The fit as the JSON of ``locust calibrate hop --json``.

        Returns
        -------
        dict
            ``parameters`` (each key's estimate, identifiability and start), ``runs`` (their
            residuals [m] and steps [s]), the interval's wording, the RMS residual [m], the
            solver's iterations and simulations, the wall time [s] and the notes.
        """
        params = {k: {**self.estimates[k].as_dict(), "identifiable": self.identifiable[k], "start": self.start[k]}
                  for k in self.keys}
        return {"experiment": "hops", "source": "+".join(r.source for r in self.runs),
                "parameters": params,
                "runs": [{"source": r.source, "config": r.config, "rms_residual_m": r.rms_m,
                          "rms_residual_by_marker_m": r.rms_by_marker_m, "samples": r.samples,
                          "timestep_s": r.timestep_s, "step_change_at_half_m": r.step_change_m}
                         for r in self.runs],
                "interval": self.interval, "rms_residual_m": self.rms_m, "iterations": self.iterations,
                "simulations": self.simulations,
                "wall_s": round(self.wall_s, 2), "notes": self.notes}


# -- the fit ----------------------------------------------------------------------------
def check_fittable(keys: list[str]) -> None:
    """Fitted keys are named once each, and each is a real-valued physical robot parameter
    (:func:`locust.params.fittable_keys`): never the schedule or the solver."""
    if not keys:
        raise CalibrationError("no parameter to fit", f"e.g. --fit {','.join(DEFAULT_KEYS)}")
    if len(set(keys)) != len(keys):
        raise CalibrationError(f"--fit names a parameter twice ({','.join(keys)})", "name each once")
    for key in keys:
        try:
            value_type(key)
        except ParamsError as exc:
            raise CalibrationError(f"--fit: {exc.message}", exc.hint) from None
        if key not in fittable_keys():
            raise CalibrationError(f"--fit {key}: only the robot's real-valued physical parameters can be fitted "
                                   "(not the schedule it is given, nor how it is simulated)",
                                   "fit a real value of the sections " + ", ".join(PHYSICAL_SECTIONS)
                                   + " (`locust params` lists them), e.g. --fit " + ",".join(DEFAULT_KEYS))


def check_keys(keys: list[str], runs: list[Trial]) -> None:
    """Fitted keys are fittable (:func:`check_fittable`) and the same in every run's robot."""
    check_fittable(keys)
    for key in keys:
        values = {run.robot.get(key) for run in runs}
        if len(values) > 1:
            raise CalibrationError(f"--fit {key}: the runs' leg sets differ in it ({sorted(values)})",
                                   "fit the physics the leg sets share; their geometry is set by the leg set")
        value = values.pop()
        if not math.isfinite(value) or (not is_angle(key) and value <= 0):
            raise CalibrationError(f"--fit {key}: its starting value {value} is not a positive number",
                                   "the fit works on factors of a positive value (an angle's on degrees); "
                                   "set a start with --set")


def _converged_steps(runs: list[Trial], tally: Tally | None = None) -> tuple[list[Trial], list[str], list[float]]:
    """Each run at the time step its markers converge in (:func:`converged_step`), with a note
    where that is not its leg set's step or where even the halved step moves them; returns
    (runs, notes, the RMS change of each run's markers at half its step)."""
    runs, step_notes, step_changes = list(runs), [], []
    for k, run in enumerate(runs):
        given = run.robot.solver.timestep_s
        runs[k], change = converged_step(run, tally=tally)
        step_changes.append(change)
        dt = runs[k].robot.solver.timestep_s
        if not change <= STEP_TOLERANCE_M:
            step_notes.append(f"{run.config} ({run.source.name}): at {dt * 1e3:g} ms, halving the step still moves the "
                              f"markers by {change * 1e3:.3g} mm RMS at the start values: the fit is not converged "
                              "in its step (std_numerical carries part of it)")
        elif dt != given:
            step_notes.append(f"{run.config} ({run.source.name}): fitted at {dt * 1e3:g} ms, not its leg set's "
                              f"{given * 1e3:g} ms (there halving the step moved the markers by more than "
                              f"{STEP_TOLERANCE_M * 1e3:g} mm RMS at the start values)")
    return runs, step_notes, step_changes


def planned_simulations(runs: int, keys: int, held: int, max_iter: int, grid_stages: int) -> int:
    """The simulations a fit plans (the solver's at ``max_iter``, its most): each run's dt/2
    check, the starting grid, the solver (the candidate and a forward difference a value each
    iteration), the optimum's curves, central differences and dt/2, the held values either side."""
    grid = GRID_LEVELS.get(keys, 0) ** keys * grid_stages
    return runs * (2 + grid + max_iter * (keys + 1) + 1 + 2 * keys + 2 + 2 * held)


def model_error(keys: tuple[str, ...], values: np.ndarray) -> np.ndarray:
    """Each fitted value's model error (std_model, its unit): :data:`MODEL_ERROR_RELATIVE`
    times the value, or :data:`MODEL_ERROR_DEG` for an angle; a key not listed takes the
    largest listed of its kind."""
    out = []
    for key, value in zip(keys, values):
        if is_angle(key):
            out.append(MODEL_ERROR_DEG.get(key, max(MODEL_ERROR_DEG.values())))
        else:
            out.append(abs(value) * MODEL_ERROR_RELATIVE.get(key, max(MODEL_ERROR_RELATIVE.values())))
    return np.array(out, dtype=float)


def _interval_text(hops: int, held: dict[str, float]) -> str:
    """How the intervals are made, in words."""
    return (f"cluster-robust over {hops} hops (CR1), t({max(hops - 1, 1)}), with the shift at half the time "
            "step (std_numerical)" + (f" and the uncertainties of the {len(held)} values held fixed "
                                      f"({', '.join(held)}: std_fixed)" if held else "")
            + " and the model's error against the plant (std_model, measured on the virtual robot's filmed "
            "hops: docs/calibrate.md) in quadrature, Welch-Satterthwaite degrees of freedom")


def _hop_estimates(cov, values: np.ndarray, x: np.ndarray, keys: tuple[str, ...], start: np.ndarray,
                   edge: tuple[bool, ...], hops: int, notes: list[str]) -> tuple[dict[str, Estimate], dict[str, bool]]:
    """Each value's estimate and whether the hops bound it, with a note for each that is not
    (too few hops, the edge of its range, an interval too wide)."""
    estimates, identifiable = {}, {}
    if hops <= len(keys):
        notes.append(f"{hops} hops cannot bound {len(keys)} values (a cluster-robust interval needs at least one "
                     "hop more than the values fitted): film more hops, or fit fewer values")
    for i, key in enumerate(keys):
        est = cov.parameter(values, i)
        estimates[key] = est
        angle = is_angle(key)
        ok = bool(np.isfinite(est.std) and (est.std <= MAX_STD_DEG if angle else est.relative_std <= MAX_RELATIVE_STD))
        if edge[i]:
            ok = False
            span = f"{ANGLE_BOUND_DEG:g} deg" if angle else f"a factor {BOUND_FACTOR:g}"
            notes.append(f"{key} ran to the edge of its range ({est.value:.4g}, {span} from "
                         f"{start[i]:.4g}): the hops do not bound it")
        elif not ok and hops > len(keys):
            wide = f"+-{2 * MAX_STD_DEG:g} deg" if angle else f"+-{200 * MAX_RELATIVE_STD:.0f}%"
            notes.append(f"{key} is not identifiable from these hops (its 95% interval is wider than "
                         f"about {wide})")
        identifiable[key] = ok
    return estimates, identifiable


def fit_hops(runs: list[Trial], keys: list[str] | tuple[str, ...] = DEFAULT_KEYS, *, max_iter: int = 30,
             grid_stages: int = GRID_STAGES, progress: Callable[[int, int], None] | None = None) -> HopFit:
    """Fit ``keys`` (shared by all runs) to the tracked markers; see the module docstring.

    Parameters
    ----------
    runs : list of Trial
        The filmed runs (:func:`.hopruns.load_run`).
    keys : sequence of str
        The values fitted, shared by all runs.
    max_iter : int
        The solver's iterations, at most.
    grid_stages : int
        Stages of the starting grid (0: start at the robot's values).
    progress : callable, optional
        ``progress(done, planned)`` after each batch of simulations: those done so far and
        those the fit plans (:func:`planned_simulations`, replanned when the solver stops).

    Returns
    -------
    HopFit
    """
    t_start = time.perf_counter()
    keys = tuple(keys)
    if not runs:
        raise CalibrationError("no run given", "give the folders `locust hop --out` wrote")
    check_keys(list(keys), runs)
    start = np.array([runs[0].robot.get(k) for k in keys], dtype=float)
    held_count = len(held_uncertainties(runs, keys))
    tally = Tally(planned_simulations(len(runs), len(keys), held_count, max_iter, grid_stages), progress)
    runs, notes, step_changes = _converged_steps(runs, tally)
    residual = HopResidual(runs, keys, tally)
    bounds = list(residual.params.bounds())

    x, iterations = solve(residual, grid_start(residual, len(keys), grid_stages), bounds, max_iter)
    tally.planned = tally.done + len(runs) * (1 + 2 * len(keys) + 2 + 2 * held_count)   # what is left
    values = residual.params.free_values(x)
    followed, clusters = run_fits(residual, x, step_changes)
    # the optimum and its central differences in one batch per run, then the same at dt/2
    r, jac, numerical = optimum_jacobian(residual, x)
    held, fixed = held_covariance(residual, x, jac)
    cov = replace(cluster_covariance(jac, r, np.concatenate(clusters), numerical, fixed),
                  model=np.diag(model_error(keys, values) ** 2))
    hops = len(np.unique(np.concatenate(clusters)))
    estimates, identifiable = _hop_estimates(cov, values, x, keys, start, residual.params.near_bound(x), hops, notes)
    return HopFit(keys=keys, start=dict(zip(keys, start.tolist())), estimates=estimates, identifiable=identifiable,
                  runs=followed, notes=notes, rms_m=float(np.sqrt(np.mean(r**2))), iterations=iterations,
                  simulations=tally.done, wall_s=time.perf_counter() - t_start,
                  interval=_interval_text(hops, held))


class _Stalled(Exception):
    """The solver's candidates no longer move the values by more than ``STALL_STEP``."""


class _StallWatch:
    """The residual as the solver sees it, stopping the solver where it stalls: a candidate
    within ``STALL_STEP`` of the best point so far that lowers its cost by under
    ``STALL_REDUCTION``. Levenberg-Marquardt meets such a candidate by growing its
    regulariser one factor at a time, each growth a simulation of every run, until a step too
    small to matter passes its sufficient-reduction test; there the fit has converged."""

    def __init__(self, residual: HopResidual):
        self.residual = residual
        self.best_cost, self.best_x = math.inf, None
        self.jacobians = 0

    def __call__(self, x: np.ndarray) -> np.ndarray:
        r = self.residual(x)
        if x.shape[1] > 1:           # the finite-difference points about the solver's point
            self.jacobians += 1
            return r
        cost = float(np.sum(r ** 2))
        stalled = (self.best_x is not None and np.linalg.norm(x[:, 0] - self.best_x) < STALL_STEP
                   and cost > self.best_cost * (1 - STALL_REDUCTION))
        if cost < self.best_cost:
            self.best_cost, self.best_x = cost, x[:, 0].copy()
        if stalled:
            raise _Stalled
        return r


def solve(residual: HopResidual, x0: np.ndarray, bounds: list[np.ndarray], max_iter: int) -> tuple[np.ndarray, int]:
    """The least-squares optimum from ``x0`` (``mujoco.minimize.least_squares``, its Jacobian
    by forward differences of ``FD_STEP``, each simulated as one batch), stopped where it
    stalls (:class:`_StallWatch`): (the solver vector, its iterations)."""
    watch = _StallWatch(residual)
    try:
        x, trace = minimize.least_squares(x0, watch, bounds=bounds, eps=FD_STEP, max_iter=max_iter, verbose=0,
                                          xtol=1e-6, gtol=1e-8, mu_factor=MU_FACTOR)
    except _Stalled:
        return watch.best_x, watch.jacobians
    return np.asarray(x, dtype=float).ravel(), len(trace)


def grid_start(residual, n: int, stages: int = GRID_STAGES) -> np.ndarray:
    """The best point of a coarse-to-fine grid of factors about the start, each stage's grid
    simulated in one batch about the best point so far, its span halved (in log) each time:
    a hop sits near thresholds (a foot slipping or not, a crank tip touching the floor), so
    the fit's landscape has local minima that a solver started at the robot file's values,
    or at a coarse grid's best point, stops in. The grid only chooses where the solver
    starts, so it is simulated at ``GRID_COARSEN`` times each run's step (half the cost);
    every value the fit reports is simulated at the run's converged step."""
    levels = GRID_LEVELS.get(n)
    best, best_cost = np.zeros(n), math.inf
    if levels is None:
        return best
    for stage in range(stages):
        half = math.log(GRID_FACTOR) / 2 ** stage
        axis = np.linspace(-half, half, levels)
        xs = best[:, None] + np.array(np.meshgrid(*[axis] * n, indexing="ij")).reshape(n, -1)
        cost = np.sum(residual(xs, coarsen=GRID_COARSEN) ** 2, axis=0)
        k = int(np.argmin(cost))
        if cost[k] < best_cost:
            best, best_cost = xs[:, k].copy(), float(cost[k])
    return best

