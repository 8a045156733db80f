"""The hobby servo as MuJoCo elements: one definition for the robot model and the test rig.

An SG90-class servo is a DC motor behind a gearbox, driven by a proportional controller
whose drive saturates. At the output shaft (see docs/servo.md)::

    torque = clip(kp * (command - angle) - kv * velocity, -stall, +stall) - b * velocity
    b      = stall / noload_speed          (back-EMF and gear friction, outside the clamp)
    (J_load + armature) * acceleration = torque + load torques

so the horn cannot turn faster than the no-load speed however large the error, and the
rotor's inertia, reflected through the gearbox (gear ratio squared), slows every start.

MuJoCo does each part itself: a ``position`` actuator with a force range is the clamped
controller; the joint's ``damping`` is ``b`` and its ``armature`` the reflected rotor
inertia, both integrated implicitly by the ``implicitfast`` and ``implicit`` integrators.
``kv`` (velocity feedback inside the clamp) is 0 for a hobby servo; the notebook's model,
which had neither ``b`` nor armature, used it.

The supply (:func:`at_supply`): the drive is a DC motor, ``torque = eta*K*(u*V - K*w)/R`` at
the output shaft for a duty ``u`` in [-1, 1], terminal voltage ``V``, winding resistance
``R``, output-referred constant ``K`` and gearbox efficiency ``eta``: stall torque
``eta*K*V/R`` and no-load speed ``V/K`` both grow in proportion to ``V``, and the back-EMF
damping ``eta*K^2/R`` is their ratio. Two servos on one supply of resistance ``R_s`` drawing
the same current (the legs get the same command) see ``V = V_s - 2*R_s*I`` (``V_s`` the plug's
voltage at rest, the board's own draw in it): each acts as a motor on ``V_s`` behind
``R + 2*R_s``. So the servo's identified figures (at ``reference_voltage_v`` on its terminals)
become, on the supply::

    stall  = stall_ref * (V_s / V_ref) * R / (R + 2 R_s)
    noload = noload_ref * (V_s / V_ref)
    kp     = kp_ref * stall / stall_ref          (the controller's duty gain is fixed)

which are still a clamped position actuator plus joint damping: exact for the symmetric hop
at full duty and integrated by MuJoCo itself (rollouts included), no per-step callback. The
source's current limit caps the clamp (:func:`.supply.servo_torque_cap_nm`: exact at stall);
where it binds, or the servos brown out, the model is stepped instead (:mod:`.supply_rollout`).
"""

from __future__ import annotations

import copy
import dataclasses
import math

import mujoco

from ..params import Power, Servo
from .supply import SERVOS_ON_SUPPLY


def at_supply(servo: Servo, power: Power) -> Servo:
    """``servo`` as it acts on ``power``'s supply: stall torque, no-load speed and holding
    gain scaled from its reference voltage to the voltage its terminals see (module docstring).

    Parameters
    ----------
    servo : Servo
        The servo as identified at ``reference_voltage_v`` [V] on its terminals.
    power : Power
        The supply: its voltage at the servo plug at rest [V] and source resistance [ohm],
        shared by both servos (its current limit is :func:`.supply.servo_torque_cap_nm`'s).

    Returns
    -------
    Servo
        ``servo`` itself when the supply changes nothing; else a copy with stall torque [N·m],
        no-load speed [rad/s], ``kp`` [N·m/rad] and ``kv`` [N·m·s/rad] scaled.
    """
    volts = power.supply_voltage_v / servo.reference_voltage_v
    sag = servo.winding_resistance_ohm / (servo.winding_resistance_ohm
                                          + SERVOS_ON_SUPPLY * power.source_resistance_ohm)
    torque = volts * sag
    if volts == 1.0 and sag == 1.0:   # the servo as identified: its figures unchanged
        return servo
    return dataclasses.replace(servo, stall_torque_nm=servo.stall_torque_nm * torque,
                               noload_speed_rad_per_s=servo.noload_speed_rad_per_s * volts,
                               kp_nm_per_rad=servo.kp_nm_per_rad * torque,
                               kv_nms_per_rad=servo.kv_nms_per_rad * torque)


def back_emf_damping_nms_per_rad(servo: Servo) -> float:
    """``b = stall / no-load speed``; 0 for a servo with no speed limit (``inf``).

    Parameters
    ----------
    servo : Servo
        Its stall torque [N·m] and no-load speed [rad/s].

    Returns
    -------
    float
        The back-EMF damping at the output shaft [N·m·s/rad].
    """
    if math.isinf(servo.noload_speed_rad_per_s):
        return 0.0
    return servo.stall_torque_nm / servo.noload_speed_rad_per_s


def configure(joint: mujoco.MjsJoint, actuator: mujoco.MjsActuator, servo: Servo,
              joint_damping_nms_per_rad: float = 0.0, trim_rad: float = 0.0,
              torque_cap_nm: float = math.inf) -> None:
    """Make ``actuator`` (on ``joint``) the servo, in place on the spec.

    Sets the joint's linear damping and armature and the actuator's position gains and
    force range (the clamp at the stall torque, or at ``torque_cap_nm`` below it). A trim is
    added to every command inside the controller: the position actuator's bias
    ``kp * (trim - q)``, so the servo's target is the command (clamped to the control range)
    plus the trim, as the firmware's is.

    Parameters
    ----------
    joint : mujoco.MjsJoint
        The servo's hinge joint.
    actuator : mujoco.MjsActuator
        The actuator on ``joint``.
    servo : Servo
        The servo's figures (on the supply: :func:`at_supply`).
    joint_damping_nms_per_rad : float
        The joint's own damping (a flexure hinge in parallel with the servo), added to the
        servo's back-EMF damping [N·m·s/rad].
    trim_rad : float
        The trim added to every command [rad].
    torque_cap_nm : float
        The drive's cap from the supply's current limit [N·m] (inf: none); the back-EMF damping
        stays outside it.
    """
    damping = list(joint.damping)   # [linear, higher-order terms]
    damping[0] = joint_damping_nms_per_rad + back_emf_damping_nms_per_rad(servo)
    joint.damping = damping
    joint.armature = servo.armature_kgm2
    actuator.set_to_position(kp=servo.kp_nm_per_rad, kv=servo.kv_nms_per_rad)
    bias = list(actuator.biasprm)   # [0, -kp, -kv, ...]: force = kp*ctrl + bias . (1, q, qdot)
    bias[0] = servo.kp_nm_per_rad * trim_rad
    actuator.biasprm = bias
    # the drive saturates: a hobby servo never exceeds its stall torque
    actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    clamp = min(servo.stall_torque_nm, torque_cap_nm)
    actuator.forcerange = [-clamp, clamp]


def with_servo(model: mujoco.MjModel, servo: Servo, joint_damping_nms_per_rad: float = 0.0,
               dof: int = 0, actuator: int = 0, scratch: mujoco.MjData | None = None) -> mujoco.MjModel:
    """A copy of a compiled ``model`` whose servo (``actuator`` on ``dof``) is ``servo``:
    the same numbers :func:`configure` gives, without recompiling (for batched fits).

    Parameters
    ----------
    model : mujoco.MjModel
        The compiled model; left unchanged.
    servo : Servo
        The servo's figures.
    joint_damping_nms_per_rad : float
        The joint's own damping, added to the servo's [N·m·s/rad].
    dof : int
        The servo joint's degree of freedom.
    actuator : int
        The servo's actuator id.
    scratch : mujoco.MjData, optional
        An ``MjData`` of ``model`` to work in (making one costs 4 times the rest).

    Returns
    -------
    mujoco.MjModel
        The copy, its constant mass-matrix terms recomputed for the new armature.
    """
    m = copy.copy(model)
    kp, kv = servo.kp_nm_per_rad, servo.kv_nms_per_rad
    m.actuator_gainprm[actuator, 0] = kp
    m.actuator_biasprm[actuator, :3] = (0.0, -kp, -kv)
    m.actuator_forcerange[actuator] = (-servo.stall_torque_nm, servo.stall_torque_nm)
    m.dof_damping[dof] = joint_damping_nms_per_rad + back_emf_damping_nms_per_rad(servo)
    m.dof_armature[dof] = servo.armature_kgm2
    # armature enters the constant mass-matrix terms
    mujoco.mj_setConst(m, scratch if scratch is not None else mujoco.MjData(m))
    return m
