"""A run at a coarse step, refined where the floor contacts change (docs/performance.md).

Fixed-step rk4 is first order across a contact that arrives or leaves between two steps: on
the seed design nearly all of a coarse step's error is made in the touchdown after each
return stroke. :func:`simulate_refined` steps the plan with ``mujoco.rollout`` at the plan's
step in chunks; where the number of floor contacts (the ``floor_contact`` sensor, a count)
changes from one row to the next, the step that changed it is taken again from the state
before it, and the ``window_s`` after it at ``fine_s`` (a whole number of fine steps per
coarse one, the control held as the plan holds it). The record stays on the coarse grid
(row i at t = i*dt, every ``dt/fine_s``-th fine row), so the audit and the per-hop figures
read it as any other trajectory.

Not a route of ``locust sim`` (its settings are not robot parameters), and not yet as true
as uniform rk4 at 1 ms on a design's draws: on medium's 32 it sends the draw nearest the
threshold over where every uniform step has it rear and come back (docs/performance.md,
``bench/draw_steps.py --refined``). Measured by ``bench/sim_speed.py`` and
``bench/draw_steps.py``.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout as mj_rollout

from ..errors import SimError
from .model import BuiltModel
from .rollout import Trajectory, initial_state
from .schedule import ControlPlan

CHUNK_STEPS = 25    # coarse steps a rollout call: the work thrown away after a change found in it


@dataclass(frozen=True)
class Refined:
    """A refined rollout: the record on the coarse grid and what it cost.

    Attributes
    ----------
    trajectory : Trajectory
        The record, one row per coarse step.
    coarse_steps : int
        Coarse steps taken, those thrown away after a contact change found in a chunk included.
    fine_steps : int
        Fine steps taken in the windows after each contact change.
    """

    trajectory: Trajectory
    coarse_steps: int    # coarse steps taken (those thrown away after a change included)
    fine_steps: int      # fine steps taken

    @property
    def model_steps(self) -> int:
        """Every step MuJoCo took, coarse and fine (the cost of the run)."""
        return self.coarse_steps + self.fine_steps


def _warnings(data: mujoco.MjData, into: dict[str, int]) -> None:
    for i in range(len(data.warning)):
        if data.warning[i].number:
            name = mujoco.mjtWarning(i).name
            into[name] = into.get(name, 0) + int(data.warning[i].number)


def simulate_refined(built: BuiltModel, plan: ControlPlan, fine_s: float, window_s: float,
                     keep_states: bool = False) -> Refined:
    """``plan`` on ``built`` at the plan's step, each contact change taken again at ``fine_s``
    for ``window_s`` (see the module docstring)."""
    if built.supply is not None:   # its servos follow the rail step by step (supply_rollout), not the rollout
        raise SimError("the refined step does not solve a supply that limits the servos (docs/servo.md, Power)",
                       "simulate it at one step (locust.sim.run), or on a supply that holds the servos' stall")
    dt = plan.timestep_s
    per_coarse = int(round(dt / fine_s))
    if per_coarse < 1 or abs(per_coarse * fine_s - dt) > 1e-12 * dt:
        raise SimError(f"a fine step of {fine_s:g} s does not divide the step {dt:g} s",
                       "choose a fine step of the step divided by a whole number")
    window = max(1, int(round(window_s / dt)))
    coarse_model = built.model
    fine_model = copy.copy(coarse_model)
    fine_model.opt.timestep = fine_s
    data = mujoco.MjData(coarse_model)
    col = built.sensors.floor_contact.start
    start, sensor0 = initial_state(built)
    ctrl = np.zeros((plan.nstep, coarse_model.nu))
    for act in built.servo_actuators:
        ctrl[:, act] = plan.ctrl_rad
    nstep = plan.nstep
    sensordata = np.empty((nstep, coarse_model.nsensordata))
    states = np.empty((nstep, start.size)) if keep_states else None
    warnings: dict[str, int] = {}
    coarse_steps = fine_steps = 0
    state, warm, i = start, None, 0
    t0 = time.perf_counter()
    while i < nstep:
        b = min(nstep, i + CHUNK_STEPS)
        st, sd = mj_rollout.rollout(coarse_model, data, state, ctrl[None, i:b], initial_warmstart=warm)
        st, sd = st[0], sd[0]
        _warnings(data, warnings)
        coarse_steps += b - i
        # row m is the state before step i+m: a count that differs from the row before was
        # changed by the step before it
        changed = np.flatnonzero(sd[1:, col] != sd[:-1, col])
        if changed.size == 0:
            # keep every row but the last: its step is taken again, so a change in it is seen
            keep = b - i if b == nstep else b - i - 1
            sensordata[i:i + keep] = sd[:keep]
            if keep_states:
                states[i:i + keep] = st[:keep]
            state = st[keep - 1] if keep else state
            warm = data.qacc_warmstart.copy()[None] if b == nstep else None
            i += keep
            continue
        c = int(changed[0])                     # step i+c changed the count
        sensordata[i:i + c] = sd[:c]
        if keep_states:
            states[i:i + c] = st[:c]
        state = st[c - 1] if c else state       # the state before step i+c
        i += c
        w = min(window, nstep - i)
        fine_ctrl = np.repeat(ctrl[i:i + w], per_coarse, axis=0)
        fst, fsd = mj_rollout.rollout(fine_model, data, state, fine_ctrl[None])
        fst, fsd = fst[0], fsd[0]
        _warnings(data, warnings)
        fine_steps += w * per_coarse
        sensordata[i:i + w] = fsd[::per_coarse]
        if keep_states:
            states[i:i + w] = fst[per_coarse - 1::per_coarse]
        state, warm = fst[-1], None
        i += w
    wall = time.perf_counter() - t0
    nq = coarse_model.nq
    traj = Trajectory(built=built, plan=plan, initial_sensordata=sensor0, sensordata=sensordata,
                      final_qpos=state[1:1 + nq].copy(), warnings=warnings, wall_s=wall, states=states)
    return Refined(trajectory=traj, coarse_steps=coarse_steps, fine_steps=fine_steps)
