"""Run the hop schedule on the model with ``mujoco.rollout`` (no Python per step).

``roll_out`` returns the raw per-step sensor record; :mod:`.audit` judges it and
:mod:`.hops` turns it into per-hop figures. :func:`run` does all three.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout as mj_rollout

from ..params import Robot, check_robot
from .batching import check_batch, rollout_chunked
from .model import BuiltModel, build
from .refine import check_refinement, refine_batch
from .schedule import ControlPlan, control_plan
from .supply_rollout import stepped_rollout


@dataclass
class Trajectory:
    """What one simulation recorded, one row per physics step.

    Sensor row i is evaluated in step i's forward pass, at t = i·dt before that step
    integrates (as ``mujoco.rollout`` records it); state row i is the state after step i.

    Attributes
    ----------
    built : BuiltModel
        The model simulated; its ``sensors`` name the columns of ``sensordata``.
    plan : ControlPlan
        The servo command of every step.
    initial_sensordata : ndarray
        ``(nsensordata,)`` sensors after ``mj_forward`` at t = 0 (SI units: m, J, N·m, rad/s).
    sensordata : ndarray
        ``(nstep, nsensordata)`` sensors of every step (SI units).
    final_qpos : ndarray
        ``(nq,)`` joint positions after the last step (free joint: m and quaternion; hinges: rad).
    warnings : dict of str to int
        MuJoCo's warning name -> count over the run.
    wall_s : float
        Wall-clock time of the rollout call [s] (of the whole batch it ran in).
    states : ndarray or None
        ``(nstep, nstate)`` full-physics states, kept on request (video, traces).
    model_steps : int
        Every step MuJoCo took (a refined run's coarse and fine ones, those taken again
        included): what the run cost; 0 where not counted.
    """

    built: BuiltModel
    plan: ControlPlan
    initial_sensordata: np.ndarray   # (nsensordata,) after mj_forward at t = 0
    sensordata: np.ndarray           # (nstep, nsensordata)
    final_qpos: np.ndarray
    warnings: dict[str, int]         # MuJoCo warning name -> count
    wall_s: float
    states: np.ndarray | None = None  # (nstep, nstate) FULLPHYSICS states, kept on request (video, traces)
    model_steps: int = 0              # every step MuJoCo took (the run's cost); 0: not counted

    @property
    def timestep_s(self) -> float:
        """The physics step of the run [s]."""
        return self.plan.timestep_s

    def column(self, s: slice) -> np.ndarray:
        """Columns ``s`` of the sensor record (a slice of :class:`SensorLayout`).

        Parameters
        ----------
        s : slice
            The columns, e.g. ``traj.built.sensors.nose_pos``.

        Returns
        -------
        ndarray
            ``(nstep, width)`` a view of those sensors at every step.
        """
        return self.sensordata[:, s]


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity), at least 1.

    Returns
    -------
    int
        The number of cores.
    """
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def rollout_threads(models: list[mujoco.MjModel], initial_state: np.ndarray, control: np.ndarray,
                    threads: int | None = None) -> tuple[np.ndarray, np.ndarray, list[mujoco.MjData]]:
    """One ``mujoco.rollout`` call over ``models`` (one per row of ``initial_state`` and
    ``control``) on ``threads`` threads (default: every core), none more than there are models.

    Parameters
    ----------
    models : list of mujoco.MjModel
        The models, all of one structure.
    initial_state : ndarray
        ``(n_models, nstate)`` full-physics start states.
    control : ndarray
        ``(n_models, nstep, nu)`` actuator commands for every step [rad].
    threads : int, optional
        Threads to run on.

    Returns
    -------
    state : ndarray
        ``(n_models, nstep, nstate)`` the state after each step.
    sensordata : ndarray
        ``(n_models, nstep, nsensordata)`` the sensors of each step.
    datas : list of mujoco.MjData
        The ``MjData`` of each thread (their warnings).
    """
    n = max(1, min(threads or available_cores(), len(models)))
    datas = [mujoco.MjData(models[0]) for _ in range(n)]
    state, sensordata = mj_rollout.rollout(models if len(models) > 1 else models[0],
                                           datas if n > 1 else datas[0], initial_state, control)
    return state, sensordata, datas


def initial_state(built: BuiltModel) -> tuple[np.ndarray, np.ndarray]:
    """The model's state and sensors at t = 0, after ``mj_forward`` in the assembled pose.

    Parameters
    ----------
    built : BuiltModel
        The model.

    Returns
    -------
    state : ndarray
        ``(nstate,)`` the full-physics state (``mjSTATE_FULLPHYSICS``).
    sensordata : ndarray
        ``(nsensordata,)`` the sensors (SI units).
    """
    model = built.model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    return state, data.sensordata.copy()


def roll_out(robot: Robot, cycles: int | None = None, timestep_s: float | None = None,
             built: BuiltModel | None = None, keep_states: bool = False) -> Trajectory:
    """Simulate settle + ``cycles`` hop cycles; the model is built unless given.

    Parameters
    ----------
    robot : Robot
        The robot and its hop schedule.
    cycles : int, optional
        Hop cycles instead of the schedule's.
    timestep_s : float, optional
        Physics step instead of the solver's [s].
    built : BuiltModel, optional
        ``robot``'s model, already built.
    keep_states : bool
        Keep every step's state in the trajectory (video, traces).

    Returns
    -------
    Trajectory
        The raw record, not yet audited.

    Raises
    ------
    ParamsError
        ``robot`` is outside the parameter limits or its run too long.
    GeometryError, SimError
        The model cannot be built, or its record would be over the memory limit.
    """
    if timestep_s is not None:
        robot = robot.with_values({"solver.timestep_s": timestep_s})
    check_robot(robot, cycles)  # before any allocation
    built = built or build(robot)
    plan = control_plan(robot.schedule, robot.solver, cycles)
    return simulate_built(built, plan, keep_states=keep_states)


def simulate_built(built: BuiltModel, plan: ControlPlan, keep_states: bool = False) -> Trajectory:
    """One built model run on ``plan`` (:func:`simulate_batch` of one).

    Parameters
    ----------
    built : BuiltModel
        The model.
    plan : ControlPlan
        The servo command of every step.
    keep_states : bool
        Keep every step's state in the trajectory.

    Returns
    -------
    Trajectory
        The raw record, not yet audited.

    Raises
    ------
    SimError
        The record would be over the memory limit.
    """
    return simulate_batch([built], plan, keep_states=keep_states)[0]


def servo_control(built: BuiltModel, plan: ControlPlan) -> np.ndarray:
    """The actuators' commands of every step of ``plan`` on ``built``.

    Parameters
    ----------
    built : BuiltModel
        The model.
    plan : ControlPlan
        The servo command of every step.

    Returns
    -------
    ndarray
        ``(nstep, nu)`` each actuator's command at each step [rad].
    """
    control = np.zeros((plan.nstep, built.model.nu))
    for act in built.servo_actuators:
        control[:, act] = plan.ctrl_rad
    return control


def simulate_batch(builts: list[BuiltModel], plan: ControlPlan, keep_states: bool = False,
                   threads: int | None = None) -> list[Trajectory]:
    """Several models of one structure (a fit's candidates, draws of the uncertain values) on
    one plan, in one ``mujoco.rollout`` call on ``threads`` threads (default: every core).
    MuJoCo counts its warnings per thread, not per model: when a batch raised any, each model
    is run again alone, so that every trajectory carries its own warnings for the audit.
    Models whose supply limits their servos are stepped in Python instead
    (:func:`.supply_rollout.stepped_rollout`), in a batch of their own.

    Parameters
    ----------
    builts : list of BuiltModel
        The models, all of one structure.
    plan : ControlPlan
        The servo command of every step, the same for all.
    keep_states : bool
        Keep every step's state in the trajectories.
    threads : int, optional
        Threads to run on.

    Returns
    -------
    list of Trajectory
        One raw record per model, in order, not yet audited.

    Raises
    ------
    SimError
        The batch's record would be over the memory limit.
    """
    stepped = [b.supply is not None for b in builts]
    if any(stepped) and not all(stepped):   # each kind in its own batch, the record in the given order
        out: dict[int, Trajectory] = {}
        for kind in (False, True):
            index = [i for i, s in enumerate(stepped) if s == kind]
            for i, traj in zip(index, simulate_batch([builts[i] for i in index], plan, keep_states, threads)):
                out[i] = traj
        return [out[i] for i in range(len(builts))]
    models = [b.model for b in builts]
    starts = [initial_state(b) for b in builts]
    control = np.stack([servo_control(b, plan) for b in builts])
    check_batch(models[0], len(models), plan.nstep, keep_states)
    t0 = time.perf_counter()
    costs = [plan.nstep] * len(models)
    if stepped[0]:   # the supply limits them: stepped in Python (docs/servo.md, "Power")
        # a refined plan's supply is stepped uniformly at its fine step
        substeps = check_refinement(plan) if plan.refined else 1
        states, sensordata, final, warnings = stepped_rollout(builts, np.array([s for s, _ in starts]), control,
                                                              keep_states, plan.steps_per_tick, substeps)
        costs = [plan.nstep * substeps] * len(models)
    elif plan.refined:   # each refined at its own contact changes (sim/refine.py)
        runs = refine_batch(builts, plan, np.array([s for s, _ in starts]), control, keep_states,
                            threads or available_cores())
        states = np.stack([r.states for r in runs]) if keep_states else None
        sensordata = np.stack([r.sensordata for r in runs])
        final = np.stack([r.final_state for r in runs])
        warnings = runs[0].warnings
        costs = [r.model_steps for r in runs]
    else:
        n_threads = max(1, min(threads or available_cores(), len(models)))
        datas = [mujoco.MjData(models[0]) for _ in range(n_threads)]
        states, sensordata, final, warnings = rollout_chunked(models, datas, np.array([s for s, _ in starts]),
                                                              control, keep_states)
    wall = time.perf_counter() - t0
    nq = models[0].nq
    if len(models) > 1 and warnings:
        return [simulate_batch([b], plan, keep_states=keep_states)[0] for b in builts]
    # FULLPHYSICS state starts with time, then qpos
    return [Trajectory(built=b, plan=plan, initial_sensordata=sensor0, sensordata=sensordata[k],
                       final_qpos=final[k, 1:1 + nq].copy(), warnings=dict(warnings), wall_s=wall,
                       states=states[k] if keep_states else None, model_steps=costs[k])
            for k, (b, (_, sensor0)) in enumerate(zip(builts, starts))]
