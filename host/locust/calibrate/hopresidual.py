"""The hop fit's residual, every run's markers stacked, for the solver's candidate values; and
what the fit reads off it at the optimum (each run's fit, the Jacobian, the held values' part).

Every candidate of a solver iteration, the finite-difference columns included, is simulated in
one batched ``mujoco.rollout`` per run (in calls of ``CHUNK`` candidates, each set in a copy of
the run's compiled model where the fitted values allow: :mod:`.hopmodels`), the runs side by
side. The solver works on the logarithm of each positive parameter (a factor is what a friction
or a stiffness is known to) and on an angle in degrees (:func:`fit_parameters`: the stance
keys). A fit whose runs straddle a threshold between outcomes at the optimum
(:func:`check_one_side`) is refused.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field

import numpy as np

from ..errors import CalibrationError, GeometryError, SimError
from ..params import Robot
from ..sim.model import BuiltModel, build
from ..sim.samples import uncertain_values
from ..trials.measured import Trial
from .fitparams import FitParameter, FitParameters
from .fitstats import fixed_covariance, linear_shift
from .hopmodels import CandidateModels
from .hopruns import THREADS, Tally, aligned_residual, alignment, hop_index, simulate_markers

BOUND_FACTOR = 5.0             # each value is searched within this factor of its start ...
ANGLE_BOUND_DEG = 30.0         # ... an angle (a key in deg: no factor, it may be 0 or negative) within this
ANGLE_UNIT_DEG = 10.0          # an angle's step in the solver's vector per unit (FD_STEP: 0.1 deg)
FD_STEP = 1e-2                 # finite-difference step of the log values (1 %: over the contacts' jaggedness)
CHUNK = 16                     # candidates a rollout call simulates (progress is reported between calls)


@dataclass(frozen=True)
class RunFit:
    """How the fitted robot follows one run's tracked markers: the fit's result for one run
    (the run itself is a :class:`locust.trials.measured.Trial`).

    Attributes
    ----------
    source : str
        The run (its folder's name).
    config : str
        Its leg set or configuration.
    rms_m : float
        RMS residual over all its tracked coordinates [m].
    rms_by_marker_m : dict of str to float
        The same per marker [m].
    samples : int
        Tracked coordinates compared.
    curves : dict
        Marker -> (aligned time [s], tracked x, y [m], simulated time [s], simulated x, y [m]),
        for the plots.
    timestep_s : float
        The step the run was fitted at [s].
    step_change_m : float
        RMS move of its markers at half that step, at the start values [m].
    """

    source: str
    config: str
    rms_m: float                         # all tracked coordinates of the run
    rms_by_marker_m: dict[str, float]
    samples: int
    curves: dict = field(repr=False)     # marker -> (t aligned, tracked x, y, sim t, sim x, sim y)
    timestep_s: float = math.nan         # the step the run was fitted at
    step_change_m: float = math.nan      # RMS move of its markers at dt/2, at the start values


def is_angle(key: str) -> bool:
    """A key fitted on its own scale (degrees from its start), not on factors of it."""
    return key.endswith("_deg")


UNITS = (("_nms_per_rad", "N*m*s/rad"), ("_nm_per_rad", "N*m/rad"), ("_rad_per_s", "rad/s"), ("_kgm2", "kg*m^2"),
         ("_nm", "N*m"), ("_deg", "deg"), ("_kg", "kg"), ("_m", "m"), ("_s", "s"))


def unit_of(key: str) -> str:
    """The unit a robot key's name ends in ("1" for none: a friction coefficient)."""
    return next((unit for suffix, unit in UNITS if key.endswith(suffix)), "1")


def fit_parameters(runs: list[Trial], keys: tuple[str, ...]) -> FitParameters:
    """The fit's values (:class:`.fitparams.FitParameters`): each key free from the first run's
    value, a positive one on the logarithm of its factor from the start (a factor is what a
    friction or a stiffness is known to) within ``BOUND_FACTOR`` either way, an angle in
    steps of ``ANGLE_UNIT_DEG`` within ``ANGLE_BOUND_DEG``; then the values held fixed that
    carry an uncertainty (:func:`held_uncertainties`), with it and their source."""
    robot = runs[0].robot
    free = []
    for key in keys:
        start = robot.get(key)
        if is_angle(key):
            free.append(FitParameter(key, "deg", start, start - ANGLE_BOUND_DEG, start + ANGLE_BOUND_DEG, "linear",
                                     scale=ANGLE_UNIT_DEG, reference=start, source=robot.source_of(key).source))
        else:
            free.append(FitParameter(key, unit_of(key), start, start / BOUND_FACTOR, start * BOUND_FACTOR, "log",
                                     reference=start, source=robot.source_of(key).source))
    held = [FitParameter(key, unit_of(key), robot.get(key), held=True, std=sd, source=robot.source_of(key).source)
            for key, sd in held_uncertainties(runs, keys).items()]
    return FitParameters(free + held)


def held_uncertainties(runs: list[Trial], keys: tuple[str, ...]) -> dict[str, float]:
    """Values the fit holds fixed that carry an uncertainty (from earlier calibrations),
    the same in every run's robot -> that standard uncertainty."""
    held = {}
    for key, sd in uncertain_values(runs[0].robot).items():
        if key in keys:
            continue
        if all(run.robot.get(key) == runs[0].robot.get(key) and run.robot.source_of(key).uncertainty == sd
               for run in runs):
            held[key] = sd
    return held


class HopResidual:
    """The markers' residual of every run, stacked, for candidate vectors ``x`` (columns): the
    fitted values are ``params.free_values(x)`` (:func:`fit_parameters`); ``tally`` counts the
    simulations it ran and ``outcomes`` holds, per run, the outcome of each candidate of the
    last call."""

    def __init__(self, runs: list[Trial], keys: tuple[str, ...], tally: Tally | None = None):
        self.runs, self.keys = runs, keys
        self.params = fit_parameters(runs, keys)
        self.tally = tally or Tally()
        self.models: dict[tuple[int, int], CandidateModels] = {}    # per run and step: candidates, no compiler
        self.outcomes: list[list[str | None]] = []

    def values_at(self, xs: np.ndarray) -> list[dict[str, float]]:
        """The fitted values (key -> value) at each row of ``xs``."""
        return [dict(zip(self.keys, self.params.free_values(x).tolist())) for x in xs]

    def candidates(self, run: Trial, coarsen: int = 1) -> CandidateModels:
        """``run``'s compiled candidates (made at the first use), at its step times ``coarsen``."""
        key = (self.runs.index(run), coarsen)
        if key not in self.models:
            self.models[key] = CandidateModels(self.robot_of(run, coarsen), self.keys)
        return self.models[key]

    @staticmethod
    def robot_of(run: Trial, coarsen: int = 1) -> Robot:
        """``run``'s robot, its step times ``coarsen``."""
        if coarsen == 1:
            return run.robot
        return run.robot.with_values(run.robot.solver.steps_scaled(coarsen), "fit: starting grid")

    def robots_at(self, run: Trial, xs: np.ndarray, refine: int = 1) -> list[Robot]:
        """``run``'s robot at each row of ``xs`` (its step divided by ``refine``)."""
        robot = run.robot
        if refine > 1:
            robot = robot.with_values(robot.solver.steps_scaled(1 / refine), "fit: time step check")
        return [robot.with_values(values, "fit") for values in self.values_at(xs)]

    def residuals_of(self, robots: Callable[[Trial], list[Robot]],
                     builts: Callable[[Trial], list[BuiltModel]] | None = None) -> np.ndarray:
        """One residual column per robot ``robots(run)`` gives, runs stacked; ``builts(run)``:
        their compiled models, where the caller has them. The runs are simulated side by side,
        one thread each (``mujoco.rollout`` lets go of the interpreter), so that the solver's
        one candidate at a time still keeps every core busy; each run's batch in chunks of
        ``CHUNK``, progress after each."""
        workers = max(1, min(THREADS, len(self.runs)))
        threads = max(1, THREADS // workers)
        jobs = [(k, run, batch, builts(run) if builts else [_built_or_none(r) for r in batch])     # compiled here
                for k, run, batch in ((k, run, robots(run)) for k, run in enumerate(self.runs))]
        chunks = [(k, i) for k, _, batch, _ in jobs for i in range(0, len(batch), CHUNK)]

        def simulate_chunk(k: int, i: int) -> list:
            _, run, batch, models = jobs[k]
            part = [j for j in range(i, min(i + CHUNK, len(batch))) if models[j] is not None]
            out = dict.fromkeys(range(i, min(i + CHUNK, len(batch))))
            try:
                if part:
                    out.update(zip(part, simulate_markers(run, [batch[j] for j in part], [models[j] for j in part],
                                                          threads=threads)))
            except (GeometryError, SimError):
                pass
            return list(out.values())

        sims: dict[tuple[int, int], list] = {}
        with ThreadPoolExecutor(workers) as pool:
            futures = {pool.submit(simulate_chunk, k, i): (k, i) for k, i in chunks}
            for future in as_completed(futures):
                sims[futures[future]] = future.result()
                self.tally.add(len(sims[futures[future]]))
        cols, self.outcomes = [], []
        for k, run, batch, _ in jobs:
            done = [s for i in range(0, len(batch), CHUNK) for s in sims[(k, i)]]
            cols.append(np.stack([aligned_residual(run, s)[0] for s in done], axis=1))
            self.outcomes.append([None if s is None else s.outcome for s in done])
        return np.concatenate(cols, axis=0)

    def __call__(self, x: np.ndarray, refine: int = 1, coarsen: int = 1) -> np.ndarray:
        """The residual columns of the candidates ``x`` (one a column), runs stacked.

        Parameters
        ----------
        x : numpy.ndarray
            The solver's vectors, shape (values,) or (values, candidates).
        refine : int, default 1
            Each run's step divided by this (the values' shift at half the step).
        coarsen : int, default 1
            Each run's step times this (the starting grid's).

        Returns
        -------
        numpy.ndarray
            Shape (residuals, candidates) [m].
        """
        xs = np.atleast_2d(np.asarray(x, dtype=float).T).reshape(-1, len(self.keys))
        if refine > 1:
            return self.residuals_of(lambda run: self.robots_at(run, xs, refine))
        values = self.values_at(xs)
        return self.residuals_of(lambda run: [self.robot_of(run, coarsen)] * len(values),
                                 lambda run: [self.candidates(run, coarsen).built(v) for v in values])


def _built_or_none(robot: Robot) -> BuiltModel | None:
    """``robot`` compiled; None where its geometry cannot be built (a candidate that fails)."""
    try:
        return build(robot)
    except GeometryError:
        return None


def run_fits(residual: HopResidual, x: np.ndarray, step_changes: list[float]) -> tuple[list[RunFit], list]:
    """Each run at the optimum: its RMS (overall and per marker) and curves; and the hop each
    of its residual samples belongs to (the clusters of the interval)."""
    run_fits, clusters = [], []
    for k, run in enumerate(residual.runs):
        sim = simulate_markers(run, residual.robots_at(run, x[None, :]))[0]
        residual.tally.add(1)
        res, shift, offset = alignment(run, sim)
        clusters.append(k * 10_000 + hop_index(run, shift))
        by_marker, j = {}, 0
        curves = {}
        for m, tr in run.tracks.items():
            n = len(tr.t_s)
            by_marker[m] = float(np.sqrt(np.mean(res[j:j + 2 * n] ** 2)))
            j += 2 * n
            if sim is not None:      # the simulation where the track's frame puts it
                ts, xs, ys = sim[m]
                curves[m] = (tr.t_s - shift, tr.x_m, tr.y_m, ts, xs + offset[0], ys + offset[1])
        run_fits.append(RunFit(source=str(run.source), config=run.config, rms_m=float(np.sqrt(np.mean(res**2))),
                               rms_by_marker_m=by_marker, samples=len(res), curves=curves,
                               timestep_s=run.robot.solver.timestep_s, step_change_m=step_changes[k]))
    return run_fits, clusters


def optimum_jacobian(residual: HopResidual, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The residual at the optimum, its Jacobian in the values (central differences, one batch
    per run) and the values' shift at half the time step: (r, jac, numerical); refused where a
    run's outcome is not the same at every point (:func:`check_one_side`)."""
    low, high = residual.params.bounds()
    hi, lo = np.minimum(x + FD_STEP, high), np.maximum(x - FD_STEP, low)
    points = [x] + [np.where(np.arange(len(x)) == i, edge[i], x) for i in range(len(x)) for edge in (hi, lo)]
    rs = residual(np.array(points).T)
    check_one_side(residual, np.array(points))
    r = rs[:, 0]
    jac = residual.params.to_values_jacobian((rs[:, 1::2] - rs[:, 2::2]) / (hi - lo), x)   # d r / d value
    numerical = linear_shift(jac, residual(x.reshape(-1, 1), refine=2)[:, 0] - r)
    return r, jac, numerical


def check_one_side(residual: HopResidual, points: np.ndarray) -> None:
    """Refuse a fit whose runs straddle a threshold between outcomes (goes over / rears and
    returns / stays low, :func:`locust.sim.outcome.classify`) at the optimum: the outcomes of
    ``residual``'s last call, one per row of ``points`` (the optimum first), must agree in
    every run. Across the threshold the simulated markers jump (a robot on its back against
    one on its feet), so the least-squares optimum and its Jacobian there mean nothing."""
    for run, outcomes in zip(residual.runs, residual.outcomes):
        at = outcomes[0]
        for point, other in zip(points[1:], outcomes[1:]):
            if other == at or None in (other, at):      # a failed simulation is no outcome
                continue
            moved = {k: v for k, v, d in zip(residual.keys, residual.values_at(point[None, :])[0].values(),
                                              point - points[0]) if d}
            said = ", ".join(f"{k} = {v:.4g}" for k, v in moved.items())
            raise CalibrationError(
                f"{run.config} ({run.source.name}) straddles the threshold between outcomes: at the fitted values "
                f"its simulation {_said(at)}, at {said} it {_said(other)}; a least-squares fit across it is broken",
                "fit runs that stay on one side of it (measure the stance first, `locust measure stance`, and "
                "hold it; film a push that does not send the robot over), or fit fewer values")


def _said(outcome: str) -> str:
    return outcome.replace("_", " ")


def held_covariance(residual: HopResidual, x: np.ndarray, jac: np.ndarray) -> tuple[dict[str, float], object]:
    """The values held fixed that carry an uncertainty, and what it adds to the fitted values'
    covariance (None when there are none)."""
    runs = residual.runs
    held = residual.params.held_std()
    if not held:
        return held, None
    # each held value one standard uncertainty either side, at the optimum: one batch per run
    sds = np.array(list(held.values()))
    changes = [{key: runs[0].robot.get(key) + sign * sd} for key, sd in held.items() for sign in (1, -1)]
    rq = residual.residuals_of(lambda run: [residual.robots_at(run, x[None, :])[0].with_values(
        c, "fit: held value's uncertainty") for c in changes])
    return held, fixed_covariance(jac, (rq[:, 0::2] - rq[:, 1::2]) / (2 * sds), sds)

