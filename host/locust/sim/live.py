"""The simulated robot driven live: servo commands arrive as the virtual robot runs.

The virtual robot (the firmware under the MicroPython unix port) sets horn angles as its
schedule runs; :class:`LiveSim` steps the same MuJoCo model ``locust sim`` uses
(``mj_step``, one physics step at a time, with ``data.ctrl`` holding the current commands)
up to each new time, and can render a video of it. Closing it audits the whole record
with :func:`.audit.audit` (non-finite state, loop closure, energy, MuJoCo warnings) and
summarises it with :func:`.hops.summarise`, so a live run is judged like any other.

Time: ``t_s = 0`` is the end of the settle phase (``solver.settle_s`` on the floor, servos
at rest), which runs when the model is made. Commands hold until the next one, exactly as
the rollout's control plan holds each 50 Hz tick, so driving it with the schedule at the
control rate reproduces ``run(robot)`` step for step.

Memory: every step's sensor row is kept for the audit (31 numbers, about 0.1 MB per
simulated second at dt = 2.5e-3 s, 5 MB at 5e-5 s).
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import asdict, dataclass, field, replace
from types import SimpleNamespace

import mujoco
import numpy as np

from ..errors import SimError
from ..params import Robot
from .audit import audit
from .camera import CAMERAS, frame_views
from .clip import ClipRecorder, check_video_path, validate_size
from .hops import summarise
from .model import build
from .outcome import classify
from .rollout import Trajectory, roll_out
from .schedule import ControlPlan, steps_per_tick
from .supply_rollout import supply_stepper

SIDES = ("left", "right")
# The fixed camera is framed on a batch rollout of the planned schedule; the live run's
# commands arrive a few ms off that plan, so its hops land a little apart from the
# rollout's: the frame holds this much more of the run's length on each side.
LIVE_SLACK_OF_RUN = 0.15
PREROLL_S = 0.5   # a video opens on the robot standing still this long before time 0


@dataclass(frozen=True)
class LiveResult:
    """What a live simulation has done so far.

    Attributes
    ----------
    distance_m : float
        Chassis x from the end of the settle phase to now [m].
    max_nose_height_m : float
        Highest nose point since the settle phase [m].
    sim_time_s : float
        Simulated time since the settle phase [s].
    valid : bool
        The run passed its audit.
    reasons : list of str
        Why not, when invalid.
    realtime_factor : float
        Simulated seconds per wall second spent stepping (and rendering).
    video_path : str or None
        The video written, if any.
    frames : int
        Frames in it.
    hops : list of dict
        Per push, :class:`locust.sim.hops.Hop`'s fields.
    outcome : str or None
        ``goes_over``, ``rears_and_returns`` or ``stays_low`` over the pushes (None: no push yet).
    """

    distance_m: float            # chassis x, end of the settle phase -> now
    max_nose_height_m: float     # highest nose point since the settle phase
    sim_time_s: float            # simulated time since the settle phase
    valid: bool
    reasons: list[str]
    realtime_factor: float       # simulated seconds per wall second spent stepping (and rendering)
    video_path: str | None = None
    frames: int = 0
    hops: list[dict] = field(default_factory=list)   # per push: Hop's fields (locust.sim.hops.Hop)
    outcome: str | None = None   # goes_over / rears_and_returns / stays_low over the pushes (None: none)

    def to_dict(self) -> dict:
        """The fields by name.

        Returns
        -------
        dict
            A shallow copy of the fields.
        """
        return dict(self.__dict__)


class LiveSim:
    """Step the robot's model in time with servo commands given as they happen.

    ``LiveSim(robot, video_path=None, fps=30)`` builds the model and settles it;
    ``set_servo_angles_deg(left, right)`` sets the horn angles (vs rest, the robot's frame:
    both -30 during a push) that hold from now on; ``advance_to(t_s)`` steps physics up to
    ``t_s`` seconds after the settle phase; ``close()`` finishes the video and returns the
    audited summary as a dict.

    The video's camera is ``fixed`` (default: it holds still where the planned run --
    ``robot.schedule``, ``cycles`` of it -- stays in view, so ``locust track`` turns the
    video into metres with its ``camera.json``) or ``track`` (follows the chassis).
    """

    def __init__(self, robot: Robot, video_path: str | None = None, fps: int = 30,
                 width: int = 640, height: int = 360, camera: str = "fixed", cycles: int | None = None):
        path = None
        if video_path is not None:
            if camera not in CAMERAS:
                raise SimError(f"camera {camera!r} is not known", f"choose one of {', '.join(CAMERAS)}")
            validate_size(fps, width, height)
            path = check_video_path(video_path)
        self.robot = robot
        # stepped uniformly in real time: at the finest step a simulation of it takes
        self.built = build(robot.with_values({"solver.timestep_s": robot.solver.finest_step_s}))
        # a supply that limits the servos is solved each step (docs/servo.md, "Power")
        self._stepper = supply_stepper(self.built, steps_per_tick(robot.solver.control_hz, robot.solver.finest_step_s))
        self.model = self.built.model if self._stepper is None else self._stepper.model
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        self.dt = float(self.model.opt.timestep)
        self._initial_sensordata = self.data.sensordata.copy()
        W = mujoco.mjtWarning
        self._divergence_warnings = [self.data.warning[int(w)]   # live views of the counters
                                     for w in (W.mjWARN_BADQACC, W.mjWARN_BADQVEL, W.mjWARN_BADQPOS)]
        self._chunks: list[np.ndarray] = []      # per-step sensor rows, in order
        self._ctrl_chunks: list[np.ndarray] = []  # per-step left command (rad), for the record's plan
        self._steps = 0
        self._stepping_wall_s = 0.0
        self._diverged = False
        self._result: LiveResult | None = None
        self._lock = threading.Lock()
        self._cancelled = threading.Event()   # set from another thread: stop stepping and rendering
        self._fps = fps
        self._recorder: ClipRecorder | None = None
        self._next_frame = 0

        # framed before the settle phase: the rollout must not see this model's own state
        fixed_view = self._planned_view(cycles, width / height) if path is not None and camera == "fixed" else None
        self._run_to(int(round(robot.solver.settle_s / self.dt)))
        self._video_start = self._steps
        if path is not None:
            # a clip starts with the robot standing, as a real one would: filmed, at rest,
            # before the first command can arrive (the report finds the first push by it)
            self._recorder = self._open_video(path, fps, width, height, fixed_view)
            try:
                self._run_to(self._steps + int(round(PREROLL_S / self.dt)))
            except BaseException:   # (a signal) no temporary video is left
                self._recorder.abort()
                raise
        self._settle_steps = self._steps

    # -- commands -------------------------------------------------------------------
    def set_servo_angles_deg(self, left_deg: float, right_deg: float) -> None:
        """Horn angles vs rest (push = -30 on both legs); they hold until the next call.

        Parameters
        ----------
        left_deg, right_deg : float
            The left and right horn angles from rest [deg].

        Raises
        ------
        SimError
            A command that is not a finite number, or a closed simulation.
        """
        for side, value in zip(SIDES, (left_deg, right_deg)):
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise SimError(f"servo command {side} = {value!r} deg is not a finite number",
                               "send horn angles in degrees, e.g. -30 for a push")
        with self._lock:
            self._check_open()
            for act, value in zip(self.built.servo_actuators, (left_deg, right_deg)):
                self.data.ctrl[act] = math.radians(float(value))

    def advance_to(self, t_s: float) -> None:
        """Step physics up to ``t_s`` seconds after the settle phase (an earlier time does nothing).

        Parameters
        ----------
        t_s : float
            Time since the end of the settle phase [s], finite and >= 0.

        Raises
        ------
        SimError
            A bad time, a closed or cancelled simulation.
        """
        if not isinstance(t_s, (int, float)) or not math.isfinite(t_s) or t_s < 0:
            raise SimError(f"advance_to({t_s!r}): time must be a finite number of seconds >= 0",
                           "pass the seconds since the virtual robot started")
        with self._lock:
            self._check_open()
            self._run_to(self._settle_steps + int(round(t_s / self.dt)))

    @property
    def sim_time_s(self) -> float:
        """Simulated time since the end of the settle phase [s]."""
        return (self._steps - getattr(self, "_settle_steps", self._steps)) * self.dt

    # -- stepping -------------------------------------------------------------------
    def _run_to(self, target_step: int) -> None:
        while self._steps < target_step and not self._diverged:
            if self._cancelled.is_set():
                raise SimError("the live simulation was cancelled (the command was interrupted)",
                               "run it again to have its video")
            stop = target_step
            if self._recorder is not None:
                frame_step = self._frame_step(self._next_frame)
                while frame_step == self._steps:  # the frame's time has come: draw it before moving on
                    self._render_frame()
                    frame_step = self._frame_step(self._next_frame)
                stop = min(stop, frame_step)
            self._step(stop - self._steps)

    def _step(self, n: int) -> None:
        m, d, bad = self.model, self.data, self._divergence_warnings
        rows = np.empty((n, m.nsensordata))
        t0 = time.perf_counter()
        stepper = self._stepper
        for i in range(n):
            if stepper is not None:
                stepper.before_step(d, self._steps + i)
            mujoco.mj_step(m, d)
            rows[i] = d.sensordata
            if bad[0].number or bad[1].number or bad[2].number:
                # MuJoCo flagged a diverging state: stop there, as mujoco.rollout does, and
                # leave the verdict to the audit (stepping on would only feed it NaNs)
                rows = rows[:i + 1]
                self._diverged = True
                break
        self._stepping_wall_s += time.perf_counter() - t0
        self._steps += len(rows)
        self._chunks.append(rows)
        self._ctrl_chunks.append(np.full(len(rows), d.ctrl[self.built.servo_actuators[0]]))
        if not (np.isfinite(rows[-1]).all() and np.isfinite(d.qpos).all()):
            self._diverged = True

    # -- video ----------------------------------------------------------------------
    def _frame_step(self, k: int) -> int:
        return self._video_start + int(round(k / (self._fps * self.dt)))

    def _planned_view(self, cycles: int | None, aspect: float):
        """The fixed view that holds the planned run: a batch rollout of the schedule, padded.

        The live run cannot know its future; the rollout of the same model, settings and
        schedule is what it will do when the commands arrive on time (they do, within a few
        ms on the virtual robot). Rows past a blow-up are left out.
        """
        s, g = self.built.sensors, self.robot.geometry
        traj = roll_out(self.robot, cycles=cycles, built=self.built)
        sd = traj.sensordata[np.isfinite(traj.sensordata).all(axis=1)]
        sd = np.vstack([self._initial_sensordata[None, :], sd])
        points = np.vstack([sd[:, s.nose_pos], sd[:, s.foot_pos], sd[:, s.chassis_pos], sd[:, s.com_pos]])
        slack = LIVE_SLACK_OF_RUN * float(np.ptp(points[:, 0])) + g.body_length_m / 2
        lo, hi = points[np.argmin(points[:, 0])], points[np.argmax(points[:, 0])]
        points = np.vstack([points, lo - [slack, 0.0, 0.0], hi + [slack, 0.0, 0.0]])
        fixed, _ = frame_views(points, points[:1, 0], g.body_length_m, 0.0, float(self.model.vis.global_.fovy), aspect)
        return fixed

    def _open_video(self, path, fps: int, width: int, height: int, fixed_view=None) -> ClipRecorder:
        """The fixed camera given, or a tracking camera framed on the settled robot with room above it to hop."""
        # no shadows: they would cost more than the physics and leave the run slower than real time
        if fixed_view is not None:
            return ClipRecorder(self.model, path, fps, width, height, "fixed", fixed_view,
                                robot_name=self.robot.name, shadows=False)
        s = self.built.sensors
        row = self._chunks[-1][-1] if self._chunks else self._initial_sensordata
        pose = np.vstack([row[s.nose_pos], row[s.foot_pos], row[s.chassis_pos], row[s.com_pos]])
        headroom = pose + [0.0, 0.0, self.robot.geometry.body_length_m]
        _, view = frame_views(np.vstack([pose, headroom]), pose[2:3, 0], self.robot.geometry.body_length_m, 0.0,
                              float(self.model.vis.global_.fovy), width / height)
        return ClipRecorder(self.model, path, fps, width, height, "track", view, robot_name=self.robot.name,
                            shadows=False)

    def _render_frame(self) -> None:
        t0 = time.perf_counter()
        self._recorder.add_frame(self.data.qpos, self._next_frame / self._fps)
        self._stepping_wall_s += time.perf_counter() - t0
        self._next_frame += 1

    # -- the end --------------------------------------------------------------------
    def _check_open(self) -> None:
        if self._result is not None:
            raise SimError("the live simulation is closed", "make a new LiveSim for another run")

    def close(self) -> dict:
        """Finish the video; audit and summarise the run. Calling it again returns the same.

        Returns
        -------
        dict
            :class:`LiveResult`'s fields.
        """
        with self._lock:
            if self._result is None:
                self._result = self._finish()
            return self._result.to_dict()

    def _finish(self) -> LiveResult:
        video_path, frames = None, 0
        if self._recorder is not None:
            if self._recorder.frames == 0:
                self._recorder.abort()
            else:
                info = self._recorder.finish()
                video_path, frames = str(info.video_path), info.frames
        traj = self.trajectory()
        sim_s = self.sim_time_s
        rtf = self._steps * self.dt / self._stepping_wall_s if self._stepping_wall_s > 0 else math.inf
        if traj.sensordata.shape[0] == 0:
            return LiveResult(0.0, float(self._initial_sensordata[self.built.sensors.nose_pos][2]), 0.0, True, [],
                              rtf, video_path, frames)
        verdict = audit(traj)
        nan = float("nan")
        if not verdict.valid:
            distance, nose = nan, nan
        elif self._steps > self._settle_steps:
            summary = summarise(traj)
            distance, nose = summary.distance_m, summary.max_nose_height_m
        else:  # nothing happened after the settle phase
            distance, nose = 0.0, float(traj.sensordata[-1, self.built.sensors.nose_pos][2])
        hops = _per_push(traj) if verdict.valid and self._steps > self._settle_steps else []
        outcome = classify([SimpleNamespace(**h) for h in hops]) if hops else None
        return LiveResult(distance, nose, sim_s, verdict.valid, verdict.reasons, rtf, video_path, frames, hops,
                          outcome)

    def finished_hops(self, rest_s: float) -> list[dict]:
        """The hops done so far, cut as :meth:`close` cuts them: a hop is done once the next push
        has started or the servos have been at rest ``rest_s`` since it (so the last hop of a
        schedule shows while the robot stays idle). Empty after a run that breaks its audit.

        Parameters
        ----------
        rest_s : float
            Time at rest after a push that ends its hop [s].

        Returns
        -------
        list of dict
            Per finished hop, :class:`locust.sim.hops.Hop`'s fields.
        """
        with self._lock:
            settle = getattr(self, "_settle_steps", self._steps)
            ctrl = np.concatenate(self._ctrl_chunks)[settle:] if self._ctrl_chunks else np.empty(0)
            pushing = ctrl != 0.0
            starts = np.flatnonzero(pushing & ~np.concatenate(([False], pushing[:-1])))
            if len(starts) == 0:
                return []
            last_push = int(np.flatnonzero(pushing)[-1])
            done = len(starts) - 1 + int(len(ctrl) - 1 - last_push >= round(rest_s / self.dt))
            if done == 0:
                return []
            traj = self.trajectory()
            if not audit(traj).valid:
                return []
            return _per_push(traj)[:done]

    def trajectory(self) -> Trajectory:
        """The record so far, in the rollout's form (one row per physics step, settle included).

        Returns
        -------
        Trajectory
            Sensor data and commands so far, no states kept.
        """
        nsd = self.model.nsensordata
        sd = np.concatenate(self._chunks) if self._chunks else np.empty((0, nsd))
        ctrl = np.concatenate(self._ctrl_chunks) if self._ctrl_chunks else np.empty(0)
        settle = getattr(self, "_settle_steps", self._steps)
        plan = ControlPlan(ctrl_rad=ctrl, timestep_s=self.dt, steps_per_tick=1, settle_steps=settle,
                           cycle_start_steps=np.array([settle, self._steps]))
        warnings = {mujoco.mjtWarning(i).name: int(self.data.warning[i].number)
                    for i in range(len(self.data.warning)) if self.data.warning[i].number}
        return Trajectory(built=self.built, plan=plan, initial_sensordata=self._initial_sensordata,
                          sensordata=sd, final_qpos=self.data.qpos.copy(), warnings=warnings,
                          wall_s=self._stepping_wall_s)

    def __enter__(self) -> LiveSim:
        return self

    def cancel(self) -> None:
        """Ask the thread stepping this simulation (and rendering its video) to stop soon: its
        next step or frame raises :class:`SimError`; it then calls :meth:`abort` itself. Any
        thread may call this; only the owner touches the renderer and the encoder."""
        self._cancelled.set()

    def abort(self) -> None:
        """End a failed run: its video is dropped (no half-written file), the result says aborted."""
        if self._result is None:
            if self._recorder is not None:
                self._recorder.abort()
            self._result = LiveResult(float("nan"), float("nan"), self.sim_time_s, False, ["aborted"], math.nan)

    def __exit__(self, *exc) -> None:
        if self._result is None and self._recorder is not None and exc[0] is not None:
            self.abort()   # a failed run leaves no half-written video
        elif self._result is None:
            self.close()


def _per_push(traj: Trajectory) -> list[dict]:
    """The run cut where each push starts (the left servo's command leaving rest), as the
    rollout's cycles are: per hop its distance, nose and CoM rise and flight (Hop's fields).
    The first hop starts at the end of the settle phase."""
    ctrl, settle = traj.plan.ctrl_rad, traj.plan.settle_steps
    pushing = ctrl[settle:] != 0.0
    starts = settle + np.flatnonzero(pushing & ~np.concatenate(([False], pushing[:-1])))
    if len(starts) == 0:
        return []
    cut = replace(traj, plan=replace(traj.plan, cycle_start_steps=np.array([settle, *starts[1:], len(ctrl)])))
    return [asdict(hop) for hop in summarise(cut).hops]


__all__ = ["LiveSim", "LiveResult"]
