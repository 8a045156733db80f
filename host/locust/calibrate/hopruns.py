"""A filmed run as the hop fit takes it: loaded from its ``locust hop --out`` folder, simulated
on its measured phase times, and its tracked markers set against the simulation's.

Each run is a :class:`locust.trials.measured.Trial`: its ``run.json`` (the firmware's measured
phase times) and the track of its video (nose, and foot where it was tracked), up to
``REST_KEPT_S`` after the schedule's last phase ends (:func:`load_run`). The simulation of a
run is driven by those measured phase times (settled on the floor first, as ``locust sim``
does: :func:`measured_plan`), on the run's leg set built on the robot being fitted
(:func:`locust.params.leg_set`, the presets' rule: its links and its converged time step).
Before the fit each run's step is checked at the start values (:func:`converged_step`):
halved (at most ``MAX_HALVINGS`` times) while halving it moves the run's markers by more than
``STEP_TOLERANCE_M`` (RMS over the tracked frames), so the fitted model is the converged one.

Residual (:func:`alignment`): the tracked markers against the same markers of the simulation,
absolute (the track's frame, the board's, against the world's, the standing pose included),
moved by one offset per run shared by every marker and frame (where the board stands), put
on the schedule's clock by the rule the report uses (:mod:`locust.trials.measure`: the first
nose motion of more than 3 mm, the track's start placed where the simulation's is relative
to its first push) and then each run's clock offset fitted about it, for every candidate.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy import optimize

from ..errors import CalibrationError, GeometryError, SimError, TrialError
from ..io.run_record import COMPLETE, CONFIG_FIX_HINT, DEFAULT_CONFIG, RunRecord
from ..params import Provenance, Robot
from ..sim.hops import summarise
from ..sim.kinematics import geom_positions, marker_geoms, trace_rows
from ..sim.model import BuiltModel, build
from ..sim.outcome import classify
from ..sim.rollout import simulate_batch
from ..sim.schedule import ControlPlan
from ..trials.configs import configuration
from ..trials.measure import onset_time
from ..trials.measured import Trial, load_trial, read_track

TAIL_S = 0.5                   # simulated past the track's last frame (the alignment moves it)
REST_KEPT_S = 0.5              # frames kept after the schedule's last phase ends (the robot at rest)
FAILED_M = 0.1                 # residual of a candidate whose simulation failed (metres)
THREADS = 2
STEP_TOLERANCE_M = 1e-4        # a run's step is converged when dt/2 moves its markers less (RMS) ...
MAX_HALVINGS = 3               # ... halved up to this many times until it is
SHIFT_SEARCH_S = 0.05          # each run's clock offset is fitted within this of the onset rule's ...
SHIFT_LEVELS = 101             # ... from the best of this many offsets, refined


# -- reading runs ------------------------------------------------------------------------
def load_run(path: Path, config: str, robot: Robot) -> Trial:
    """A ``locust hop --out`` folder (its run.json and tracks) as the trial the fit simulates.

    Parameters
    ----------
    path : pathlib.Path
        The run folder.
    config : str
        Its leg set.
    robot : locust.params.Robot
        The robot being fitted, on which the leg set is built.

    Returns
    -------
    locust.trials.measured.Trial
        With its robot (the leg set on ``robot``, at the run's own push angle), its phase
        times from the first push, its nose's onset on the camera's clock, and its tracks
        (nose, and foot where it was tracked standing) up to ``REST_KEPT_S`` after the last phase.

    Raises
    ------
    locust.errors.CalibrationError
        No run record or no track, a record the fit cannot simulate truly
        (:func:`check_record`), or one without a push.
    """
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
    nose = trial.track
    onset, _, _ = onset_time(nose.t_s, nose.x_m, nose.y_m, where=str(nose.path))
    tracks = {"nose": nose}
    try:
        foot = read_track(nose.path, "foot")
    except TrialError:
        foot = None          # a track of the nose alone is fitted on the nose alone
    if foot is not None and (foot.t_s < onset).sum() >= 2:
        tracks["foot"] = foot
    # the frames of the schedule's cycles and REST_KEPT_S after: a video that runs on while the
    # robot stands (the camera stopped late) adds rollout time and no information
    last = phases[-1]
    end_s = (last.measured_us - t0_us) * 1e-6 + (record.schedule.push_ms if last.phase == "push"
                                                  else record.schedule.wait_ms) * 1e-3
    tracks = {m: tr.until(onset + end_s + REST_KEPT_S) for m, tr in tracks.items()}
    run_robot = configuration(robot, config).robot
    if not math.isclose(run_robot.schedule.push_deg, record.schedule.push_deg):
        run_robot = run_robot.with_values({"schedule.push_deg": record.schedule.push_deg}, f"run:{trial.run_path}")
    return replace(trial, source=Path(path), robot=run_robot, tracks=tracks,
                   phase_s=np.array([(p.measured_us - t0_us) * 1e-6 for p in phases]),
                   pushing=np.array([p.phase == "push" for p in phases]), onset_s=float(onset))


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


# -- simulating a run ------------------------------------------------------------------
def measured_plan(run: Trial, robot: Robot) -> ControlPlan:
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


def simulate_markers(run: Trial, robots: list[Robot], builts: list[BuiltModel] | None = None,
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


def aligned_residual(run: Trial, sim: dict[str, np.ndarray] | None) -> tuple[np.ndarray, float]:
    """Tracked minus simulated, every tracked coordinate of the run (x then y, marker by
    marker), and the track's shift onto the schedule's clock (nan when the simulation failed):
    :func:`alignment` without the board's offset."""
    res, shift, _ = alignment(run, sim)
    return res, shift


def alignment(run: Trial, sim: dict[str, np.ndarray] | None) -> tuple[np.ndarray, float, np.ndarray]:
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


def converged_step(run: Trial, robot: Robot | None = None, tally: Tally | None = None) -> tuple[Trial, float]:
    """``run`` at a step where halving it moves its markers by at most ``STEP_TOLERANCE_M``
    (RMS over the tracked frames, each simulation on the clock by its own onset) at ``robot``'s
    values (the run's own when None), halved at most ``MAX_HALVINGS`` times; and that last
    move (nan: a simulation failed, the step is kept)."""
    at = robot or run.robot
    scale = 1.0     # of every step of the run's solver
    change = math.nan
    for halvings in range(MAX_HALVINGS + 1):
        pair = []
        for f in (scale, scale / 2):
            try:
                robot_dt = at.with_values(run.robot.solver.steps_scaled(f), "fit: time step check")
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
        scale /= 2
    if scale != 1.0:
        note = f"halved until dt/2 moved the markers by at most {STEP_TOLERANCE_M * 1e3:g} mm (hop fit's check)"
        run = replace(run, robot=run.robot.with_values(run.robot.solver.steps_scaled(scale),
                                                       Provenance("fit: time step check", note=note)))
    return run, change


class Tally:
    """Simulations done and planned; ``progress(done, planned)`` after each batch."""

    def __init__(self, planned: int = 0, progress: Callable[[int, int], None] | None = None):
        self.done, self.planned, self.progress = 0, planned, progress

    def add(self, n: int) -> None:
        """``n`` more simulations done (the plan grows to them if they pass it).

        Parameters
        ----------
        n : int
            Simulations just run.
        """
        self.done += n
        self.planned = max(self.planned, self.done)
        if self.progress:
            self.progress(self.done, self.planned)


def hop_index(run: Trial, shift: float) -> np.ndarray:
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

