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
    ctrl_rad: np.ndarray          # (nstep,) servo command for every physics step, radians
    timestep_s: float
    steps_per_tick: int
    settle_steps: int             # steps before the first push
    cycle_start_steps: np.ndarray  # (cycles + 1,) step index where each cycle starts; last = end

    @property
    def nstep(self) -> int:
        return int(self.ctrl_rad.shape[0])

    @property
    def duration_s(self) -> float:
        return self.nstep * self.timestep_s


def steps_per_tick(control_hz: float, timestep_s: float) -> int:
    return max(1, int(math.floor(1.0 / (control_hz * timestep_s) + 1e-6)))


def control_plan(schedule: Schedule, solver: Solver, cycles: int | None = None,
                 timestep_s: float | None = None) -> ControlPlan:
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
    return ControlPlan(
        ctrl_rad=ctrl, timestep_s=dt, steps_per_tick=per_tick, settle_steps=settle_ticks * per_tick,
        cycle_start_steps=np.asarray(starts) * per_tick,
    )
