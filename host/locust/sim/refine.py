"""Runs at a coarse step, refined where the floor contacts change (docs/performance.md).

Fixed-step rk4 is first order across a contact that arrives or leaves between two steps: on
the seed design nearly all of a coarse step's error is made in the touchdown after each
return stroke. :func:`refine_batch` steps each model at the plan's step in chunks of
:data:`CHUNK_STEPS`; where the number of floor contacts (the ``floor_contact`` sensor, a
count) changes from one row to the next, the step that changed it is taken again from the
state before it, and the plan's ``refine_window_s`` after it at its ``fine_timestep_s`` (a
whole number of fine steps per coarse one, the control held as the plan holds it). A change
of the servos' command is taken so too, for the plan's ``command_window_s``: the push and the
return each set off a train of touchdowns and foot bounces, contacts that last under a
coarse step and leave the count as it was from one coarse row to the next. Each
model is refined at its own contact changes: the models that step coarsely go in one
``mujoco.rollout`` call over every core, those in a fine window in another. The record stays
on the coarse grid (row i at t = i*dt, every ``dt/fine``-th fine row), so the audit and the
per-hop figures read it as any other trajectory.

The plan's refinement comes from ``solver.refine_timestep_s`` and ``solver.refine_window_s``
(:func:`.schedule.control_plan`); :func:`.rollout.simulate_batch` takes this route for every
refined plan whose models' supply holds their servos.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout as mj_rollout

from ..errors import SimError
from .batching import add_warnings
from .model import BuiltModel
from .schedule import ControlPlan

CHUNK_STEPS = 10    # coarse steps a rollout call: the work thrown away after a change found in it
MAX_CHUNK_STEPS = 80   # ... doubled after each chunk without a change, up to this (a robot at rest)


@dataclass
class Refined:
    """One model's refined rollout: its record on the coarse grid and what it cost.

    Attributes
    ----------
    sensordata : ndarray
        ``(nstep, nsensordata)`` the sensors of each coarse step.
    states : ndarray or None
        ``(nstep, nstate)`` the state after each coarse step, when kept.
    final_state : ndarray
        ``(nstate,)`` the state after the last step.
    warnings : dict of str to int
        MuJoCo's warnings of the calls it ran in (of every model in them: see
        :func:`refine_batch`).
    coarse_steps : int
        Coarse steps taken, those thrown away after a contact change found in a chunk included.
    fine_steps : int
        Fine steps taken in the windows after each contact change.
    """

    sensordata: np.ndarray
    states: np.ndarray | None
    final_state: np.ndarray
    warnings: dict[str, int]
    coarse_steps: int = 0
    fine_steps: int = 0

    @property
    def model_steps(self) -> int:
        """Every step MuJoCo took, coarse and fine (the cost of the run)."""
        return self.coarse_steps + self.fine_steps


def check_refinement(plan: ControlPlan) -> int:
    """Fine steps per coarse step of a refined ``plan``.

    Raises
    ------
    SimError
        The fine step does not divide the coarse one.
    """
    dt, fine = plan.timestep_s, plan.fine_timestep_s
    per_coarse = int(round(dt / fine))
    if per_coarse < 2 or abs(per_coarse * fine - dt) > 1e-9 * dt:
        raise SimError(f"a fine step of {fine:g} s does not divide the step {dt:g} s into whole steps",
                       "set solver.refine_timestep_s to solver.timestep_s over 2, 4, 8, ...")
    return per_coarse


def _padded(ctrl: np.ndarray, a: int, n: int) -> np.ndarray:
    """Rows ``a .. a+n`` of ``ctrl``, the last row repeated past its end."""
    rows = ctrl[a:a + n]
    if len(rows) < n:
        rows = np.concatenate([rows, np.repeat(ctrl[-1:], n - len(rows), axis=0)])
    return rows


def refine_batch(builts: list[BuiltModel], plan: ControlPlan, starts: np.ndarray, control: np.ndarray,
                 keep_states: bool = False, threads: int = 1) -> list[Refined]:
    """``plan`` on each of ``builts`` (one structure), each refined at its own contact changes
    (see the module docstring).

    Parameters
    ----------
    builts : list of BuiltModel
        The models; their supply holds the servos (no Python per step).
    plan : ControlPlan
        A refined plan (:attr:`.schedule.ControlPlan.refined`).
    starts : ndarray
        ``(n_models, nstate)`` full-physics start states.
    control : ndarray
        ``(n_models, nstep, nu)`` each model's commands at each coarse step [rad].
    keep_states : bool
        Keep the state after each coarse step.
    threads : int
        Threads of each ``mujoco.rollout`` call.

    Returns
    -------
    list of Refined
        One per model, in order. MuJoCo counts warnings per thread, not per model: each
        carries those of every call it was in.
    """
    per_coarse = check_refinement(plan)
    nstep, n = plan.nstep, len(builts)
    window = max(1, int(round(plan.refine_window_s / plan.timestep_s)))
    command_window = max(window, int(round(plan.command_window_s / plan.timestep_s)))
    windows = np.full(n, window)            # each model's next fine window [coarse steps]
    coarse_models = [b.model for b in builts]
    fine_models = []
    for m in coarse_models:
        f = copy.copy(m)
        f.opt.timestep = plan.fine_timestep_s
        fine_models.append(f)
    col = builts[0].sensors.floor_contact.start
    datas = [mujoco.MjData(coarse_models[0]) for _ in range(max(1, min(threads, n)))]
    out = [Refined(sensordata=np.empty((nstep, coarse_models[0].nsensordata)),
                   states=np.empty((nstep, starts.shape[1])) if keep_states else None,
                   final_state=starts[k].copy(), warnings={}) for k in range(n)]
    # the steps at which a servo's command changes (the push, the return): taken at the fine step
    command_changes = np.zeros(control.shape[:2], dtype=bool)
    command_changes[:, 1:] = (control[:, 1:] != control[:, :-1]).any(axis=2)
    commands = [np.flatnonzero(command_changes[k]) for k in range(n)]
    chunk = np.full(n, CHUNK_STEPS)          # each model's next coarse chunk [steps]
    at = np.zeros(n, dtype=int)             # each model's next coarse step
    fine_next = np.zeros(n, dtype=bool)     # whether it is to take its next steps fine
    warnings: dict[str, int] = {}

    def call(models: list[mujoco.MjModel], ks: list[int], ctrl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        use = datas[:min(len(datas), len(ks))]
        st, sd = mj_rollout.rollout([models[k] for k in ks], use, np.stack([out[k].final_state for k in ks]),
                                    ctrl, persistent_pool=len(use) > 1)
        for d in use:
            add_warnings(d, warnings)
        return st, sd

    def chunk_rows(k: int) -> int:
        """Model ``k``'s next coarse chunk: its size, ending at its next command change (whose
        step is then the one taken again) or the run's end."""
        i = int(at[k])
        upcoming = commands[k][np.searchsorted(commands[k], i, side="right"):]
        rows = min(int(chunk[k]), nstep - i)
        return min(rows, int(upcoming[0]) - i + 1) if upcoming.size else rows

    while (at < nstep).any():
        waiting = [k for k in range(n) if at[k] < nstep and not fine_next[k]]
        sizes = {k: chunk_rows(k) for k in waiting}
        # the models of one chunk size in one call: a model's chunks are its own, whatever the batch
        for size in sorted(set(sizes.values())):
            coarse = [k for k in waiting if sizes[k] == size]
            st, sd = call(coarse_models, coarse, np.stack([_padded(control[k], at[k], size) for k in coarse]))
            for j, k in enumerate(coarse):
                r, i = out[k], int(at[k])
                rows = size
                r.coarse_steps += rows
                # sensor row m is taken before step i+m: a count that differs from the row
                # before was changed by the step before it
                changed = np.flatnonzero(sd[j, 1:rows, col] != sd[j, :rows - 1, col])
                commanded = np.flatnonzero(command_changes[k, i:i + rows])
                if changed.size or commanded.size:
                    keep = min(int(a[0]) for a in (changed, commanded) if a.size)
                    windows[k] = command_window if commanded.size and commanded[0] == keep else window
                    fine_next[k] = True
                    chunk[k] = CHUNK_STEPS
                else:
                    chunk[k] = min(2 * int(chunk[k]), MAX_CHUNK_STEPS)
                    # every row but the last, whose step is taken again (a change in it is seen
                    # only from the row after it), unless the run ends there
                    keep = rows if i + rows == nstep else rows - 1
                r.sensordata[i:i + keep] = sd[j, :keep]
                if keep_states:
                    r.states[i:i + keep] = st[j, :keep]
                if keep:
                    r.final_state = st[j, keep - 1].copy()
                at[k] = i + keep
        fine = [k for k in range(n) if at[k] < nstep and fine_next[k]]
        if fine:
            # each model's commands held per_coarse fine steps each
            longest = int(max(windows[k] for k in fine))
            ctrl = np.stack([np.repeat(_padded(control[k], at[k], longest), per_coarse, axis=0) for k in fine])
            st, sd = call(fine_models, fine, ctrl)
            for j, k in enumerate(fine):
                r, i = out[k], int(at[k])
                w = min(int(windows[k]), nstep - i)
                r.fine_steps += w * per_coarse
                r.sensordata[i:i + w] = sd[j, :w * per_coarse:per_coarse]
                if keep_states:
                    r.states[i:i + w] = st[j, per_coarse - 1:w * per_coarse:per_coarse]
                r.final_state = st[j, w * per_coarse - 1].copy()
                at[k] = i + w
                fine_next[k] = False
    for r in out:
        r.warnings = dict(warnings)
    return out
