"""Filmed hops -> the physics no bench experiment reaches: friction under impact, the folded
hinges in the real linkage, the servo's speed on the robot's own battery.

Each run is a ``locust hop --out`` folder: its ``run.json`` (the firmware's measured phase
times) and the track of its video (nose, and foot where it was tracked), up to
``REST_KEPT_S`` after the schedule's last phase ends. The simulation of a
run is driven by those measured phase times (settled on the floor first, as ``locust sim``
does), on the run's leg set built on the robot being fitted (:func:`locust.params.leg_set`,
the presets' rule: its links and its converged time step), so runs of different leg sets
are fitted together: their geometry differs, the physics named by ``--fit`` is shared.
Before the fit each run's step is checked at the start values: halved (at most
``MAX_HALVINGS`` times) while halving it moves the run's markers by more than
``STEP_TOLERANCE_M`` (RMS over the tracked frames), so the fitted model is the converged one.

Residual: the tracked markers against the same markers of the simulation, absolute (the
track's frame, the board's, against the world's, the standing pose included), moved by one
offset per run shared by every marker and frame (where the board stands: :func:`alignment`), put
on the schedule's clock by the rule the report uses (:mod:`locust.trials.measure`: the first
nose motion of more than 3 mm, the track's start placed where the simulation's is relative
to its first push) and then each run's clock offset fitted about it, for every candidate
(:func:`aligned_residual`). Every candidate of a solver iteration, the finite-difference
columns included, is simulated in one batched ``mujoco.rollout`` per run (in calls of
``CHUNK`` candidates, each set in a copy of the run's compiled model where the fitted values
allow: :mod:`.hopmodels`); the solver is ``mujoco.minimize.least_squares`` on the logarithm
of each positive parameter (a factor is what a friction or a stiffness is known to) and on
an angle in degrees (:func:`fit_parameters`: the stance keys). A fit whose runs straddle a threshold
between outcomes at the optimum (:func:`check_one_side`) is refused.
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
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy import optimize

from ..errors import CalibrationError, GeometryError, ParamsError, SimError, TrialError
from ..io.run_record import COMPLETE, CONFIG_FIX_HINT, DEFAULT_CONFIG, RunRecord
from ..params import Provenance, Robot, fittable_keys, value_type
from ..sim.gl import minimize  # MuJoCo's solver, as locust.sim imports MuJoCo (its OpenGL checked first)
from ..sim.hops import summarise
from ..sim.kinematics import geom_positions, marker_geoms, trace_rows
from ..sim.model import BuiltModel, build
from ..sim.outcome import classify
from ..sim.rollout import simulate_batch
from ..sim.samples import uncertain_values
from ..sim.schedule import ControlPlan
from ..trials.configs import configuration
from ..trials.measure import onset_time
from ..trials.measured import load_trial, read_track
from .fitparams import FitParameter, FitParameters
from .fitstats import Estimate, cluster_covariance, fixed_covariance, linear_shift
from .hopmodels import CandidateModels

DEFAULT_KEYS = ("contact.foot_friction", "compliance.hinge_stiffness_nm_per_rad", "servo.noload_speed_rad_per_s")
MARKERS = ("nose", "foot")
PROVENANCE_NAME = "hops"       # written as source fit:hops
TAIL_S = 0.5                   # simulated past the track's last frame (the alignment moves it)
REST_KEPT_S = 0.5              # frames kept after the schedule's last phase ends (the robot at rest)
BOUND_FACTOR = 5.0             # each value is searched within this factor of its start ...
ANGLE_BOUND_DEG = 30.0         # ... an angle (a key in deg: no factor, it may be 0 or negative) within this
ANGLE_UNIT_DEG = 10.0          # an angle's step in the solver's vector per unit (FD_STEP: 0.1 deg)
MAX_STD_DEG = 2.5              # an angle is identifiable with its 95% interval within about +-5 deg
FD_STEP = 1e-2                 # finite-difference step of the log values (1 %: over the contacts' jaggedness)
MU_FACTOR = 10 ** 0.5          # the solver's regulariser grows by this a rejected step (MuJoCo's default
                               # 10**0.1 took ~4 rejections, each a simulation of every run, an iteration)
STALL_STEP = 2e-3              # the solver has converged where a step under this (0.2 %, 0.02 deg) ...
STALL_REDUCTION = 1e-3         # ... lowers the cost by under this part of it (a fifth of FD_STEP; the 95 %
                               # intervals are +-8 % or wider, std_model alone being 4 %)
MAX_RELATIVE_STD = 0.25        # identifiable: 95% interval within about +-50%
FAILED_M = 0.1                 # residual of a candidate whose simulation failed (metres)
THREADS = 2
CHUNK = 16                     # candidates a rollout call simulates (progress is reported between calls)
STEP_TOLERANCE_M = 1e-4        # a run's step is converged when dt/2 moves its markers less (RMS) ...
MAX_HALVINGS = 3               # ... halved up to this many times until it is
SHIFT_SEARCH_S = 0.05          # each run's clock offset is fitted within this of the onset rule's ...
SHIFT_LEVELS = 101             # ... from the best of this many offsets, refined
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
# from where it stood; issue 33) gave the 4 %, kept as the upper figure; with absolute
# positions bench/hop_model_error.py measures the RMS of each value's error (bias and spread
# together) on other hidden truths, below it so far (docs/calibrate.md). Relative for a
# positive value; in degrees for an angle, where the 1 deg is an estimate not yet measured on
# the virtual robot. A key not listed takes the largest listed of its kind.
MODEL_ERROR_RELATIVE = {"contact.foot_friction": 0.04, "compliance.hinge_stiffness_nm_per_rad": 0.04,
                        "servo.noload_speed_rad_per_s": 0.04}
MODEL_ERROR_DEG = {"geometry.crank_start_deg": 1.0, "geometry.ground_angle_deg": 1.0}


@dataclass(frozen=True)
class MarkerTrack:
    """One tracked marker in the track's frame (the board's, or the world's for the virtual
    robot's camera.json): x forward, y up, metres."""

    t_s: np.ndarray          # camera clock
    x_m: np.ndarray
    y_m: np.ndarray


@dataclass(frozen=True)
class HopRun:
    """One filmed run: what drives its simulation and what it is compared with."""

    source: Path
    config: str                  # leg set (small, medium, large, ...)
    robot: Robot                 # the leg set on the robot being fitted, the run's push angle
    phase_s: np.ndarray          # measured start of each phase, seconds from the first push
    pushing: np.ndarray          # per phase: a push (True) or a wait
    onset_s: float               # first nose motion on the camera clock
    tracks: dict[str, MarkerTrack]

    @property
    def end_s(self) -> float:
        """The last frame, seconds after the first nose motion."""
        return max(float(tr.t_s[-1]) for tr in self.tracks.values()) - self.onset_s


@dataclass(frozen=True)
class RunFit:
    """How the fitted robot follows one run's tracked markers.

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


# -- reading runs ------------------------------------------------------------------------
def load_run(path: Path, config: str, base: Robot) -> HopRun:
    """A ``locust hop --out`` folder (its run.json and tracks) as a :class:`HopRun` of ``config``."""
    trial = load_trial(Path(path), config, "nose")
    if trial.record is None or trial.track is None:
        raise CalibrationError(f"{path}: a hop fit needs the run's run.json and the track of its video",
                               "give the folder `locust hop --out` wrote, after `locust track` on its video")
    record = trial.record
    check_record(record, trial.run_path)
    phases = sorted(record.phases, key=lambda p: p.measured_us)
    pushes = [p for p in phases if p.phase == "push"]
    if not pushes:
        raise CalibrationError(f"{trial.run_path}: the record holds no push phase",
                               "a hop fit needs a run that pushed at least once; rerun the hop")
    t0_us = pushes[0].measured_us
    phases = [p for p in phases if p.measured_us >= t0_us]
    onset, _, _ = onset_time(trial.track.t_s, trial.track.x_m, trial.track.y_m, where=str(trial.track.path))
    tracks = {"nose": MarkerTrack(trial.track.t_s, trial.track.x_m, trial.track.y_m)}
    try:
        foot = read_track(trial.track.path, "foot")
    except TrialError:
        foot = None          # a track of the nose alone is fitted on the nose alone
    if foot is not None and (foot.t_s < onset).sum() >= 2:
        tracks["foot"] = MarkerTrack(foot.t_s, foot.x_m, foot.y_m)
    # the frames of the schedule's cycles and REST_KEPT_S after: a video that runs on while the
    # robot stands (the camera stopped late) adds rollout time and no information
    last = phases[-1]
    end_s = (last.measured_us - t0_us) * 1e-6 + (record.schedule.push_ms if last.phase == "push"
                                                  else record.schedule.wait_ms) * 1e-3
    tracks = {m: _until(tr, onset + end_s + REST_KEPT_S) for m, tr in tracks.items()}
    robot = configuration(base, config).robot
    if not math.isclose(robot.schedule.push_deg, record.schedule.push_deg):
        robot = robot.with_values({"schedule.push_deg": record.schedule.push_deg}, f"run:{trial.run_path}")
    return HopRun(source=Path(path), config=config, robot=robot,
                  phase_s=np.array([(p.measured_us - t0_us) * 1e-6 for p in phases]),
                  pushing=np.array([p.phase == "push" for p in phases]), onset_s=float(onset), tracks=tracks)


def check_record(record: RunRecord, path: Path) -> None:
    """Refuse a run record the fit cannot simulate truly: a run that did not finish its
    schedule (``incomplete``: a cable pulled, an interrupt; ``error``: refused by the board),
    one the board ran on its default config (the trims and pulse range the robot's angles rest
    on were not used), and one whose measured phase starts contradict the commanded order.

    Parameters
    ----------
    record : locust.io.run_record.RunRecord
    path : pathlib.Path
        Its ``run.json``, for the message.

    Raises
    ------
    locust.errors.CalibrationError
        Naming the run, what is wrong with it and what to do.
    """
    leave_out = f"rerun the hop, or leave {path.parent} out of the fit"
    if record.status == DEFAULT_CONFIG:
        raise CalibrationError(f"{path}: the board ran this hop on its default config, not its config.json "
                               f"({record.message}): the crank angles it made are not the ones simulated",
                               f"{CONFIG_FIX_HINT}; then {leave_out}")
    if record.status != COMPLETE:
        said = f" ({record.message})" if record.message else ""
        raise CalibrationError(f"{path}: the run is {record.status}{said}, {len(record.phases)} of "
                               f"{record.schedule.phases} phases recorded: a fit needs the whole schedule the "
                               "robot ran", leave_out)
    problem = record.order_problem()
    if problem:
        raise CalibrationError(f"{path}: {problem}: the record's phase times are not a hop's",
                               f"check the board's clock (`locust hop` again); {leave_out}")


def _until(track: MarkerTrack, last_s: float) -> MarkerTrack:
    """``track``'s frames up to camera time ``last_s``."""
    keep = track.t_s <= last_s
    return MarkerTrack(track.t_s[keep], track.x_m[keep], track.y_m[keep])


# -- simulating a run ------------------------------------------------------------------
def measured_plan(run: HopRun, robot: Robot) -> ControlPlan:
    """Servo command per physics step: at rest while settling, then each phase from its
    measured start (held until the next), up to the track's end and ``TAIL_S`` more."""
    dt, settle_s = robot.solver.timestep_s, robot.solver.settle_s
    settle = int(round(settle_s / dt))
    nstep = settle + int(math.ceil((run.end_s + TAIL_S) / dt))
    t = (np.arange(nstep) - settle) * dt
    idx = np.searchsorted(run.phase_s, t + 1e-9, side="right") - 1
    push = (idx >= 0) & run.pushing[np.clip(idx, 0, None)]
    ctrl = np.where(push, math.radians(robot.schedule.push_deg), 0.0)
    starts = np.append(settle + np.rint(run.phase_s[run.pushing] / dt).astype(int), nstep)
    return ControlPlan(ctrl_rad=ctrl, timestep_s=dt, steps_per_tick=1, settle_steps=settle,
                       cycle_start_steps=starts)


def simulate_markers(run: HopRun, robots: list[Robot], builts: list[BuiltModel] | None = None,
                     threads: int = THREADS) -> list[dict[str, np.ndarray] | None]:
    """Each robot's simulated markers on the schedule's clock (one batched rollout): marker ->
    (3, n) rows t, x, y in the world (x forward along the floor, y up; the standing pose
    included); ``t`` = 0 at the first push; its ``outcome`` (:func:`locust.sim.outcome.classify`).
    None: it failed. ``builts``: the robots' compiled models where the caller has them
    (:mod:`.hopmodels`); ``threads``: those the batch runs on."""
    builts = builts or [build(r) for r in robots]
    plan = measured_plan(run, robots[0])
    trajs = simulate_batch(builts, plan, keep_states=True, threads=threads)
    dt, settle = plan.timestep_s, plan.settle_steps
    rows, _ = trace_rows(dt, settle, plan.nstep)
    t = (rows + 1 - settle) * dt
    names = list(run.tracks)
    geoms = marker_geoms(builts[0].model, names)
    if min(geoms) < 0:
        raise CalibrationError(f"the model carries no {names[geoms.index(-1)]!r} marker",
                               "track the markers the model has: nose and foot")
    out: list[SimMarkers | None] = []
    for traj in trajs:
        if not np.all(np.isfinite(traj.states)):
            out.append(None)
            continue
        pos = geom_positions(traj.built.model, traj.states, geoms, rows)
        out.append(SimMarkers({m: np.stack([t, pos[:, i, 0], pos[:, i, 2]]) for i, m in enumerate(names)},
                              classify(summarise(traj).hops)))
    return out


class SimMarkers(dict):
    """One simulation's markers (marker -> rows t, x, y) and its ``outcome``."""

    def __init__(self, markers: dict[str, np.ndarray], outcome: str):
        super().__init__(markers)
        self.outcome = outcome


def aligned_residual(run: HopRun, sim: dict[str, np.ndarray] | None) -> tuple[np.ndarray, float]:
    """Tracked minus simulated, every tracked coordinate of the run (x then y, marker by
    marker), and the track's shift onto the schedule's clock (nan when the simulation failed):
    :func:`alignment` without the board's offset."""
    res, shift, _ = alignment(run, sim)
    return res, shift


def alignment(run: HopRun, sim: dict[str, np.ndarray] | None) -> tuple[np.ndarray, float, np.ndarray]:
    """Tracked minus simulated, every tracked coordinate of the run (x then y, marker by
    marker), absolute positions: the simulation's world positions (the standing pose
    included) moved by one offset (x, y) shared by every marker and frame of the run, where
    the track's frame (the board's) stands in the world, fitted in closed form (the mean
    difference): the robot's pose and every marker's place on it stay in the residual; the
    track's shift onto the schedule's clock (nan when the simulation failed): the report's
    rule (the first nose motion of 3 mm in both) places it, then the shift that fits the run
    best within ``SHIFT_SEARCH_S`` of it (a clock offset fitted per run and candidate: the
    rule on a 30 frames/s track is off by up to a few milliseconds, which the fitted values
    would otherwise bend to make up for); and the offset (m)."""
    n = sum(2 * len(tr.t_s) for tr in run.tracks.values())
    if sim is None:
        return np.full(n, FAILED_M), math.nan, np.full(2, math.nan)
    nose = sim["nose"]
    try:
        latency, _, _ = onset_time(nose[0], nose[1], nose[2], where="simulation")
    except TrialError:
        return np.full(n, FAILED_M), math.nan, np.full(2, math.nan)

    def residual_at(shift: float) -> tuple[np.ndarray, np.ndarray]:     # shift: camera time of the first push
        dx, dy = [], []
        for m, tr in run.tracks.items():
            ts, xs, ys = sim[m]
            t = tr.t_s - shift
            # before the simulation's kept lead the robot stands where it stood then
            dx.append(tr.x_m - np.interp(t, ts, xs))
            dy.append(tr.y_m - np.interp(t, ts, ys))
        offset = np.array([np.mean(np.concatenate(dx)), np.mean(np.concatenate(dy))])
        return np.concatenate([part for pair in zip(dx, dy) for part in (pair[0] - offset[0],
                                                                      pair[1] - offset[1])]), offset

    def cost(shift: float) -> float:
        return float(np.sum(residual_at(shift)[0] ** 2))

    rule = run.onset_s - latency
    grid = rule + np.linspace(-SHIFT_SEARCH_S, SHIFT_SEARCH_S, SHIFT_LEVELS)
    costs = [cost(s) for s in grid]
    k = int(np.argmin(costs))
    half = grid[1] - grid[0]
    best = optimize.minimize_scalar(cost, method="bounded", bounds=(grid[k] - half, grid[k] + half),
                                    options={"xatol": 1e-6}).x
    shift = float(best) if cost(best) <= costs[k] else float(grid[k])
    res, offset = residual_at(shift)
    return res, shift, offset


def converged_step(run: HopRun, robot: Robot | None = None, tally: _Tally | None = None) -> tuple[HopRun, float]:
    """``run`` at a step where halving it moves its markers by at most ``STEP_TOLERANCE_M``
    (RMS over the tracked frames, each simulation on the clock by its own onset) at ``robot``'s
    values (the run's own when None), halved at most ``MAX_HALVINGS`` times; and that last
    move (nan: a simulation failed, the step is kept)."""
    at = robot or run.robot
    step = run.robot.solver.timestep_s
    change = math.nan
    for halvings in range(MAX_HALVINGS + 1):
        pair = []
        for dt in (step, step / 2):
            try:
                robot_dt = at.with_values({"solver.timestep_s": dt}, "fit: time step check")
                pair.append(simulate_markers(run, [robot_dt])[0])
                if tally:
                    tally.add(1)
            except (GeometryError, SimError):
                pair.append(None)
        if any(sim is None for sim in pair):
            return run, math.nan
        change = float(np.sqrt(np.mean((aligned_residual(run, pair[0])[0] - aligned_residual(run, pair[1])[0]) ** 2)))
        if change <= STEP_TOLERANCE_M or halvings == MAX_HALVINGS:
            break
        step /= 2
    if step != run.robot.solver.timestep_s:
        note = f"halved until dt/2 moved the markers by at most {STEP_TOLERANCE_M * 1e3:g} mm (hop fit's check)"
        run = replace(run, robot=run.robot.with_values({"solver.timestep_s": step}, Provenance("fit: time step check",
                                                                                                note=note)))
    return run, change


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
                                   "fit any of " + ", ".join(fittable_keys()))


def check_keys(keys: list[str], runs: list[HopRun]) -> None:
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


def is_angle(key: str) -> bool:
    """A key fitted on its own scale (degrees from its start), not on factors of it."""
    return key.endswith("_deg")


UNITS = (("_nms_per_rad", "N*m*s/rad"), ("_nm_per_rad", "N*m/rad"), ("_rad_per_s", "rad/s"), ("_kgm2", "kg*m^2"),
         ("_nm", "N*m"), ("_deg", "deg"), ("_kg", "kg"), ("_m", "m"), ("_s", "s"))


def unit_of(key: str) -> str:
    """The unit a robot key's name ends in ("1" for none: a friction coefficient)."""
    return next((unit for suffix, unit in UNITS if key.endswith(suffix)), "1")


def fit_parameters(runs: list[HopRun], keys: tuple[str, ...]) -> FitParameters:
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


def _converged_steps(runs: list[HopRun], tally: _Tally | None = None) -> tuple[list[HopRun], list[str], list[float]]:
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


class _Tally:
    """Simulations done and planned; ``progress(done, planned)`` after each batch."""

    def __init__(self, planned: int = 0, progress: Callable[[int, int], None] | None = None):
        self.done, self.planned, self.progress = 0, planned, progress

    def add(self, n: int) -> None:
        self.done += n
        self.planned = max(self.planned, self.done)
        if self.progress:
            self.progress(self.done, self.planned)


def planned_simulations(runs: int, keys: int, held: int, max_iter: int, grid_stages: int) -> int:
    """The simulations a fit plans (the solver's at ``max_iter``, its most): each run's dt/2
    check, the starting grid, the solver (the candidate and a forward difference a value each
    iteration), the optimum's curves, central differences and dt/2, the held values either side."""
    grid = GRID_LEVELS.get(keys, 0) ** keys * grid_stages
    return runs * (2 + grid + max_iter * (keys + 1) + 1 + 2 * keys + 2 + 2 * held)


class _HopResidual:
    """The markers' residual of every run, stacked, for candidate vectors ``x`` (columns): the
    fitted values are ``params.free_values(x)`` (:func:`fit_parameters`); ``tally`` counts the
    simulations it ran and ``outcomes`` holds, per run, the outcome of each candidate of the
    last call."""

    def __init__(self, runs: list[HopRun], keys: tuple[str, ...], tally: _Tally | None = None):
        self.runs, self.keys = runs, keys
        self.params = fit_parameters(runs, keys)
        self.tally = tally or _Tally()
        self.models: dict[tuple[int, int], CandidateModels] = {}    # per run and step: candidates, no compiler
        self.outcomes: list[list[str | None]] = []

    def values_at(self, xs: np.ndarray) -> list[dict[str, float]]:
        """The fitted values (key -> value) at each row of ``xs``."""
        return [dict(zip(self.keys, self.params.free_values(x).tolist())) for x in xs]

    def candidates(self, run: HopRun, coarsen: int = 1) -> CandidateModels:
        """``run``'s compiled candidates (made at the first use), at its step times ``coarsen``."""
        key = (self.runs.index(run), coarsen)
        if key not in self.models:
            self.models[key] = CandidateModels(self.robot_of(run, coarsen), self.keys)
        return self.models[key]

    @staticmethod
    def robot_of(run: HopRun, coarsen: int = 1) -> Robot:
        """``run``'s robot, its step times ``coarsen``."""
        if coarsen == 1:
            return run.robot
        return run.robot.with_values({"solver.timestep_s": run.robot.solver.timestep_s * coarsen},
                                     "fit: starting grid")

    def robots_at(self, run: HopRun, xs: np.ndarray, refine: int = 1) -> list[Robot]:
        """``run``'s robot at each row of ``xs`` (its step divided by ``refine``)."""
        robot = run.robot
        if refine > 1:
            robot = robot.with_values({"solver.timestep_s": robot.solver.timestep_s / refine}, "fit: time step check")
        return [robot.with_values(values, "fit") for values in self.values_at(xs)]

    def residuals_of(self, robots: Callable[[HopRun], list[Robot]],
                     builts: Callable[[HopRun], list[BuiltModel]] | None = None) -> np.ndarray:
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


def _run_fits(residual: _HopResidual, x: np.ndarray, step_changes: list[float]) -> tuple[list[RunFit], list]:
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


def _jacobian(residual: _HopResidual, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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


def check_one_side(residual: _HopResidual, points: np.ndarray) -> None:
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


def _held_covariance(residual: _HopResidual, x: np.ndarray, jac: np.ndarray) -> tuple[dict[str, float], object]:
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


def fit_hops(runs: list[HopRun], keys: list[str] | tuple[str, ...] = DEFAULT_KEYS, *, max_iter: int = 30,
             grid_stages: int = GRID_STAGES, progress: Callable[[int, int], None] | None = None) -> HopFit:
    """Fit ``keys`` (shared by all runs) to the tracked markers; see the module docstring.

    Parameters
    ----------
    runs : list of HopRun
        The filmed runs (:func:`load_run`).
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
    tally = _Tally(planned_simulations(len(runs), len(keys), held_count, max_iter, grid_stages), progress)
    runs, notes, step_changes = _converged_steps(runs, tally)
    residual = _HopResidual(runs, keys, tally)
    bounds = list(residual.params.bounds())

    x, iterations = solve(residual, grid_start(residual, len(keys), grid_stages), bounds, max_iter)
    tally.planned = tally.done + len(runs) * (1 + 2 * len(keys) + 2 + 2 * held_count)   # what is left
    values = residual.params.free_values(x)
    run_fits, clusters = _run_fits(residual, x, step_changes)
    # the optimum and its central differences in one batch per run, then the same at dt/2
    r, jac, numerical = _jacobian(residual, x)
    held, fixed = _held_covariance(residual, x, jac)
    cov = replace(cluster_covariance(jac, r, np.concatenate(clusters), numerical, fixed),
                  model=np.diag(model_error(keys, values) ** 2))
    hops = len(np.unique(np.concatenate(clusters)))
    estimates, identifiable = _hop_estimates(cov, values, x, keys, start, residual.params.near_bound(x), hops, notes)
    return HopFit(keys=keys, start=dict(zip(keys, start.tolist())), estimates=estimates, identifiable=identifiable,
                  runs=run_fits, notes=notes, rms_m=float(np.sqrt(np.mean(r**2))), iterations=iterations,
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

    def __init__(self, residual: _HopResidual):
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


def solve(residual: _HopResidual, x0: np.ndarray, bounds: list[np.ndarray], max_iter: int) -> tuple[np.ndarray, int]:
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


def held_uncertainties(runs: list[HopRun], keys: tuple[str, ...]) -> dict[str, float]:
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


def hop_index(run: HopRun, shift: float) -> np.ndarray:
    """Per residual entry of :func:`aligned_residual` (x then y, marker by marker): the hop
    its frame belongs to, counted from the push it follows (frames before the first push go
    with the first hop); ``shift``: the track's shift onto the schedule's clock."""
    starts = run.phase_s[run.pushing]
    if not math.isfinite(shift):
        shift = run.onset_s
    parts = []
    for tr in run.tracks.values():
        hop = np.clip(np.searchsorted(starts, tr.t_s - shift, side="right") - 1, 0, None)
        parts += [hop, hop]
    return np.concatenate(parts)


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


# -- the plot ---------------------------------------------------------------------------
def plot_run(fit: RunFit, path: Path, subtitle: str = "") -> Path:
    """Tracked markers against the fitted simulation, x and y of each, on the schedule's clock."""
    from ..plotting import save_png

    return save_png(run_figure(fit, subtitle), path, dpi=110)


def run_figure(fit: RunFit, subtitle: str = ""):
    """The figure :func:`plot_run` writes (a ``matplotlib.figure.Figure``, no display needed)."""
    from matplotlib.figure import Figure

    markers = list(fit.curves)
    fig = Figure(figsize=(5.2 * max(len(markers), 1), 5.5))
    axes = fig.subplots(2, max(len(markers), 1), squeeze=False, sharex=True)
    for col, m in enumerate(markers):
        t, x, y, ts, xs, ys = fit.curves[m]
        lo, hi = float(t[0]), float(t[-1])
        keep = (ts >= lo) & (ts <= hi)
        for row, (data, model, label) in enumerate(((x, xs, "x forward"), (y, ys, "y up"))):
            ax = axes[row, col]
            ax.plot(t, 1000 * data, ".", ms=3, color="#1f77b4", label="tracked")
            ax.plot(ts[keep], 1000 * model[keep], "-", lw=1.2, color="#d62728", label="fitted simulation")
            ax.set_ylabel(f"{m} {label} [mm]")
            ax.grid(alpha=0.3)
        axes[0, col].set_title(f"{m}: RMS {1000 * fit.rms_by_marker_m[m]:.2f} mm", fontsize=10)
        axes[1, col].set_xlabel("t from the first push [s]")
    axes[0, 0].legend(loc="best", fontsize=8)
    fig.suptitle(f"{fit.config}: {Path(fit.source).name}" + (f"\n{subtitle}" if subtitle else ""), fontsize=10)
    fig.tight_layout()
    return fig
