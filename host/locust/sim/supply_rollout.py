"""The servos on a supply that limits them, stepped: the rail solved before each physics step.

Where the supply's current limit or the servos' brown-out binds (:func:`.supply.supply_limits`),
no fixed set of actuator numbers is the servo: its torque follows the rail, and the rail both
servos' draw. :class:`SupplyStepper` takes each physics step's start: each servo's duty ``u``
(what its compiled actuator would ask, unclamped, over its stall torque on the supply: the
controller's torque over its stall torque, trim and gains as compiled) and speed, the rail
from both (:func:`.supply.rail_voltage_v`: the source's resistance, or its current limit),
and sets each servo to its motor on that rail for the step::

    gain and bias  the compiled ones scaled by V / (the rail they were compiled for)
    clamp          stall_ref * V / reference voltage      (the duty saturates)
    damping        the motor's own back-EMF, stall_ref / noload_ref (the source acts through V)

so MuJoCo's clamped position actuator and the joint's damping give ``k_t*(u*V - K*w)/R``
within the step. A rail below ``power.brownout_v`` turns both servos off (no drive, no
back-EMF braking: their bridges open) until a PWM pulse (a control tick) finds it above again
with them driving. :func:`stepped_rollout` runs models so, one ``mj_step`` at a time, and
returns what ``mujoco.rollout`` would (:func:`.batching.rollout_chunked`).
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from .batching import add_warnings
from .model import BuiltModel
from .servo import at_supply, back_emf_damping_nms_per_rad
from .supply import rail_voltage_v

# MuJoCo's warnings that end a trajectory (mujoco.rollout stops there too, and repeats its last row)
STOPPING_WARNINGS = (mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADQVEL,
                     mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADCTRL)


class SupplyStepper:
    """The servos of ``built`` on its limiting supply, set before each physics step.

    Parameters
    ----------
    built : BuiltModel
        A model whose ``supply`` is set (the supply limits its servos).
    steps_per_tick : int
        Physics steps per PWM period: a browned-out servo restarts on a tick.

    Attributes
    ----------
    model : mujoco.MjModel
        The stepper's own copy of the model, the one to step (its servo numbers change).
    off : bool
        The servos are browned out (until the next tick).
    rail_v : float
        The rail at the last step's start [V].
    """

    def __init__(self, built: BuiltModel, steps_per_tick: int):
        if built.supply is None:
            raise ValueError("the model's supply does not limit its servos: nothing to step")
        self.servos, self.power = built.supply.servos, built.supply.power
        self.model = copy.copy(built.model)
        m = self.model
        self.acts = list(built.servo_actuators)
        joints = [int(m.actuator_trnid[a, 0]) for a in self.acts]
        self.dofs = [int(m.jnt_dofadr[j]) for j in joints]
        self.qadr = [int(m.jnt_qposadr[j]) for j in joints]
        self.ctrl_range = [tuple(float(x) for x in m.actuator_ctrlrange[a]) for a in self.acts]
        # the numbers compiled: each servo on the supply's rail at rest, through its resistance
        statics = [at_supply(s, self.power) for s in self.servos]
        self.static_stall = [s.stall_torque_nm for s in statics]
        self.static_volts = [s.reference_voltage_v * st.stall_torque_nm / s.stall_torque_nm
                             for s, st in zip(self.servos, statics)]
        self.gain = [float(m.actuator_gainprm[a, 0]) for a in self.acts]
        self.bias = [[float(x) for x in m.actuator_biasprm[a, :3]] for a in self.acts]
        self.own_damping = [float(m.dof_damping[d]) - back_emf_damping_nms_per_rad(st)   # the joint's own (its hinge)
                            for d, st in zip(self.dofs, statics)]
        self.back_emf = [back_emf_damping_nms_per_rad(s) for s in self.servos]
        self.stall_per_volt = [s.stall_torque_nm / s.reference_voltage_v for s in self.servos]
        self.per_tick = max(1, int(steps_per_tick))
        self.off = False
        self.rail_v = self.power.supply_voltage_v

    def duties(self, data: mujoco.MjData) -> tuple[list[float], list[float]]:
        """Each servo's duty (-1 to 1) and speed [rad/s] in ``data``'s state and command."""
        duties, speeds = [], []
        for i, (act, dof, adr, (lo, hi)) in enumerate(zip(self.acts, self.dofs, self.qadr, self.ctrl_range)):
            command = min(max(float(data.ctrl[act]), lo), hi)
            w = float(data.qvel[dof])
            b0, b1, b2 = self.bias[i]
            ask = self.gain[i] * command + b0 + b1 * float(data.qpos[adr]) + b2 * w   # unclamped
            duties.append(min(max(ask / self.static_stall[i], -1.0), 1.0))
            speeds.append(w)
        return duties, speeds

    def before_step(self, data: mujoco.MjData, step: int) -> None:
        """Set the servos for the physics step that starts at ``data``'s state.

        Parameters
        ----------
        data : mujoco.MjData
            The state about to be stepped (its command in ``ctrl``).
        step : int
            The step's index from the run's start (a multiple of ``steps_per_tick`` is a PWM pulse).
        """
        if self.off and step % self.per_tick == 0:
            self.off = False          # the pulse restarts them: they drive, if the rail holds
        if not self.off:
            duties, speeds = self.duties(data)
            self.rail_v = rail_voltage_v(self.servos, self.power, duties, speeds)
            self.off = self.rail_v < self.power.brownout_v
        else:
            self.rail_v = self.power.supply_voltage_v   # nothing drawn: the rail at rest
        self._set(0.0 if self.off else self.rail_v)

    def _set(self, volts: float) -> None:
        """Each servo as its motor on a rail of ``volts`` (0: off, no drive and no back-EMF)."""
        m = self.model
        for i, (act, dof) in enumerate(zip(self.acts, self.dofs)):
            scale = volts / self.static_volts[i]
            m.actuator_gainprm[act, 0] = self.gain[i] * scale
            for k in range(3):
                m.actuator_biasprm[act, k] = self.bias[i][k] * scale
            stall = self.stall_per_volt[i] * volts
            m.actuator_forcerange[act, 0] = -stall
            m.actuator_forcerange[act, 1] = stall
            m.dof_damping[dof] = self.own_damping[i] + (self.back_emf[i] if volts > 0.0 else 0.0)


def supply_stepper(built: BuiltModel, steps_per_tick: int) -> SupplyStepper | None:
    """A :class:`SupplyStepper` for ``built``, or None where its supply does not limit it.

    Parameters
    ----------
    built : BuiltModel
    steps_per_tick : int
        Physics steps per PWM period.

    Returns
    -------
    SupplyStepper or None
    """
    return None if built.supply is None else SupplyStepper(built, steps_per_tick)


def stepped_rollout(builts: list[BuiltModel], initial_state: np.ndarray, control: np.ndarray, keep_states: bool,
                    steps_per_tick: int, substeps: int = 1
                    ) -> tuple[np.ndarray | None, np.ndarray, np.ndarray, dict[str, int]]:
    """:func:`.batching.rollout_chunked`'s record, each model stepped on its supply in Python.

    With ``substeps`` > 1 each row of ``control`` is that many steps of the model's step over
    ``substeps`` (a refined plan's fine step, taken uniformly: :mod:`.refine` does not step a
    supply), recorded on the rows' grid.

    Parameters
    ----------
    builts : list of BuiltModel
        Models whose supply limits their servos, all of one structure.
    initial_state : ndarray
        ``(n_models, nstate)`` full-physics start states.
    control : ndarray
        ``(n_models, nstep, nu)`` actuator commands for every step [rad].
    keep_states : bool
        Whether every step's state is returned.
    steps_per_tick : int
        Rows per PWM period.
    substeps : int
        Physics steps a row.

    Returns
    -------
    states : ndarray or None
        ``(n_models, nstep, nstate)`` the state after each row, or None without ``keep_states``.
    sensordata : ndarray
        ``(n_models, nstep, nsensordata)`` the sensors of each row (evaluated at its start).
    final : ndarray
        ``(n_models, nstate)`` the state after the last step.
    warnings : dict of str to int
        MuJoCo's warning name -> count, over all models.
    """
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    n, nstep = control.shape[0], control.shape[1]
    model0 = builts[0].model
    nstate = mujoco.mj_stateSize(model0, spec)
    sensordata = np.empty((n, nstep, model0.nsensordata))
    states = np.empty((n, nstep, nstate)) if keep_states else None
    final = np.empty((n, nstate))
    warnings: dict[str, int] = {}
    for k, built in enumerate(builts):
        stepper = SupplyStepper(built, steps_per_tick * substeps)
        m = stepper.model
        m.opt.timestep = built.model.opt.timestep / substeps
        d = mujoco.MjData(m)
        mujoco.mj_setState(m, d, initial_state[k], spec)
        row = np.empty(nstate)
        stop = nstep
        for i in range(nstep):
            d.ctrl[:] = control[k, i]
            for j in range(substeps):
                stepper.before_step(d, i * substeps + j)
                mujoco.mj_step(m, d)
                if j == 0:
                    sensordata[k, i] = d.sensordata
            if keep_states:
                mujoco.mj_getState(m, d, states[k, i], spec)
            if any(d.warning[int(w)].number for w in STOPPING_WARNINGS):
                stop = i + 1
                break
        if stop < nstep:   # as mujoco.rollout: the last row repeated past a diverged step
            sensordata[k, stop:] = sensordata[k, stop - 1]
            if keep_states:
                states[k, stop:] = states[k, stop - 1]
        mujoco.mj_getState(m, d, row, spec)
        final[k] = row
        add_warnings(d, warnings)
    return states, sensordata, final, warnings


__all__ = ["SupplyStepper", "stepped_rollout", "supply_stepper"]
