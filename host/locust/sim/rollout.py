"""Run the hop schedule on the model with ``mujoco.rollout`` (no Python per step).

``simulate`` returns the raw per-step sensor record; :mod:`.audit` judges it and
:mod:`.hops` turns it into per-hop figures. :func:`run` does all three.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout as mj_rollout

from ..params import Robot, check_robot
from .model import BuiltModel, build
from .schedule import ControlPlan, control_plan


@dataclass
class Trajectory:
    """What one simulation recorded, one row per physics step (after the step)."""

    built: BuiltModel
    plan: ControlPlan
    initial_sensordata: np.ndarray   # (nsensordata,) after mj_forward at t = 0
    sensordata: np.ndarray           # (nstep, nsensordata)
    final_qpos: np.ndarray
    warnings: dict[str, int]         # MuJoCo warning name -> count
    wall_s: float
    states: np.ndarray | None = None  # (nstep, nstate) FULLPHYSICS states, kept on request (video, traces)

    @property
    def timestep_s(self) -> float:
        return self.plan.timestep_s

    def column(self, s: slice) -> np.ndarray:
        return self.sensordata[:, s]


def initial_state(built: BuiltModel) -> tuple[np.ndarray, np.ndarray]:
    model = built.model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    return state, data.sensordata.copy()


def simulate(robot: Robot, cycles: int | None = None, timestep_s: float | None = None,
             built: BuiltModel | None = None, keep_states: bool = False) -> Trajectory:
    """Simulate settle + ``cycles`` hop cycles; the model is built unless given."""
    if timestep_s is not None:
        robot = robot.with_values({"solver.timestep_s": timestep_s})
    check_robot(robot, cycles)  # before any allocation
    built = built or build(robot)
    plan = control_plan(robot.schedule, robot.solver, cycles)
    return simulate_built(built, plan, keep_states=keep_states)


def simulate_built(built: BuiltModel, plan: ControlPlan, keep_states: bool = False) -> Trajectory:
    model = built.model
    state0, sensor0 = initial_state(built)
    control = np.zeros((1, plan.nstep, model.nu))
    for act in built.servo_actuators:
        control[0, :, act] = plan.ctrl_rad
    data = mujoco.MjData(model)
    t0 = time.perf_counter()
    state, sensordata = mj_rollout.rollout(model, data, state0[None, :], control)
    wall = time.perf_counter() - t0
    nq = model.nq
    final_qpos = state[0, -1, 1:1 + nq].copy()  # FULLPHYSICS state starts with time, then qpos
    warnings = {
        mujoco.mjtWarning(i).name: int(data.warning[i].number)
        for i in range(len(data.warning)) if data.warning[i].number
    }
    return Trajectory(built=built, plan=plan, initial_sensordata=sensor0,
                      sensordata=sensordata[0], final_qpos=final_qpos, warnings=warnings, wall_s=wall,
                      states=state[0] if keep_states else None)
