"""The bang-bang hop schedule as a per-step control sequence.

Servo commands change at a fixed control rate (a hobby servo takes a new pulse each 20 ms
PWM period; the notebook used 60 Hz video frames). Each control tick lasts
``floor(1 / (hz * dt))`` physics steps, the notebook's rule (with float round-off forgiven,
so 50 Hz at dt = 1e-4 s is 200 steps, not 199).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..params import Schedule, Solver


@dataclass(frozen=True)
class ControlPlan:
    """The servo command at every physics step of a run.

    Attributes
    ----------
    ctrl_rad : ndarray
        ``(nstep,)`` servo command for every physics step [rad].
    timestep_s : float
        The physics step [s].
    steps_per_tick : int
        Physics steps per control tick.
    settle_steps : int
        Steps before the first push.
    cycle_start_steps : ndarray
        ``(cycles + 1,)`` step index where each cycle starts; the last is the end.
    fine_timestep_s : float
        Where the floor contacts change, the step taken again at this one [s]; 0: uniform
        steps (``solver.refine_timestep_s``, :mod:`.refine`).
    refine_window_s : float
        How long the fine step runs after a contact change [s].
    command_window_s : float
        How long it runs after a change of the command [s].
    """

    ctrl_rad: np.ndarray          # (nstep,) servo command for every physics step, radians
    timestep_s: float
    steps_per_tick: int
    settle_steps: int             # steps before the first push
    cycle_start_steps: np.ndarray  # (cycles + 1,) step index where each cycle starts; last = end
    fine_timestep_s: float = 0.0   # the step where the floor contacts change; 0: uniform
    refine_window_s: float = 0.0   # how long it runs after a contact change
    command_window_s: float = 0.0  # ... and after a change of the command

    @property
    def refined(self) -> bool:
        """Whether the run refines its step where the floor contacts change."""
        return 0.0 < self.fine_timestep_s < self.timestep_s

    @property
    def nstep(self) -> int:
        """Number of physics steps."""
        return int(self.ctrl_rad.shape[0])

    @property
    def duration_s(self) -> float:
        """The run's length, settle phase included [s]."""
        return self.nstep * self.timestep_s


def steps_per_tick(control_hz: float, timestep_s: float) -> int:
    """Physics steps per control tick: ``floor(1 / (hz * dt))``, round-off forgiven, at least 1.

    Parameters
    ----------
    control_hz : float
        The control rate [Hz].
    timestep_s : float
        The physics step [s].

    Returns
    -------
    int
        Steps per tick.
    """
    return max(1, int(math.floor(1.0 / (control_hz * timestep_s) + 1e-6)))


def control_plan(schedule: Schedule, solver: Solver, cycles: int | None = None,
                 timestep_s: float | None = None) -> ControlPlan:
    """The schedule as a per-step command: a settle phase at rest, then each cycle's push (at
    ``push_deg``) and wait (at 0), changing only on control ticks.

    Parameters
    ----------
    schedule : Schedule
        Push angle [deg], push and wait times [s] and cycles.
    solver : Solver
        Timestep [s], control rate [Hz] and settle time [s].
    cycles : int, optional
        Cycles instead of the schedule's.
    timestep_s : float, optional
        Physics step instead of the solver's [s].

    Returns
    -------
    ControlPlan
        The command at every step.
    """
    dt = solver.timestep_s if timestep_s is None else timestep_s
    n_cycles = schedule.cycles if cycles is None else cycles
    hz = solver.control_hz
    per_tick = steps_per_tick(hz, dt)
    cycle_s = schedule.push_s + schedule.wait_s
    push_rad = math.radians(schedule.push_deg)

    settle_ticks = int(round(solver.settle_s * hz))
    hop_ticks = int(n_cycles * cycle_s * hz + 1e-9)
    tick_ctrl = np.zeros(settle_ticks + hop_ticks)
    for i in range(hop_ticks):
        # the notebook's expression, kept so its schedule is reproduced tick for tick
        if (i / hz) % cycle_s < schedule.push_s:
            tick_ctrl[settle_ticks + i] = push_rad
    ctrl = np.repeat(tick_ctrl, per_tick)
    starts = [settle_ticks + int(round(c * cycle_s * hz)) for c in range(n_cycles)]
    starts.append(settle_ticks + hop_ticks)
    # the solver's refinement, with its own step (an explicit step steps uniformly)
    fine = solver.refine_timestep_s if timestep_s is None and solver.refined else 0.0
    return ControlPlan(
        ctrl_rad=ctrl, timestep_s=dt, steps_per_tick=per_tick, settle_steps=settle_ticks * per_tick,
        cycle_start_steps=np.asarray(starts) * per_tick, fine_timestep_s=fine,
        refine_window_s=solver.refine_window_s if fine else 0.0,
        command_window_s=solver.refine_command_window_s if fine else 0.0,
    )
