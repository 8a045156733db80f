"""The servos' supply (locust.sim.supply, docs/servo.md "Power"): the source's current limit
as each servo's torque cap, the brown-out that leaves a stalled servo no drive, and the
stepped model against the static one and against hand-computed circuits."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from locust.params import preset, side_values
from locust.sim import supply
from locust.sim.live import LiveSim
from locust.sim.model import build
from locust.sim.rollout import simulate_batch
from locust.sim.run import run
from locust.sim.schedule import control_plan
from locust.sim.supply_rollout import supply_stepper

PUSH_RAD = math.radians(-30.0)


def robot_on(**power):
    """The robot as built (Small) on a supply of its own: ``power`` as power.KEY=value."""
    return preset("small").with_values({f"power.{k}": v for k, v in power.items()})


def stalled_drive(robot, command_rad=PUSH_RAD, speed_rad_per_s=0.0, built=None):
    """Both servos held at their rest angle (or turning at ``speed``) under ``command``: the
    stepper set for that step, then MuJoCo's own actuator force and the servo joint's damping
    force, per side [N·m], and the stepper."""
    built = built or build(robot)
    stepper = supply_stepper(built, 20)
    model = stepper.model
    data = mujoco.MjData(model)
    dofs = [int(model.jnt_dofadr[model.actuator_trnid[a, 0]]) for a in built.servo_actuators]
    for act, dof in zip(built.servo_actuators, dofs):
        data.ctrl[act] = command_rad
        data.qvel[dof] = speed_rad_per_s
    stepper.before_step(data, 0)
    mujoco.mj_forward(model, data)
    force = [float(data.actuator_force[a]) for a in built.servo_actuators]
    damper = [float(data.qfrc_damper[d]) for d in dofs]
    return force, damper, stepper


def test_the_current_limit_is_each_servos_torque_cap_at_stall():
    """0.8 A to two stalled SG90s (k_t = 0.15 N·m * 10 ohm / 5 V = 0.3 N·m/A), no source
    resistance, no board: each gives k_t * 0.8 / 2 = 0.12 N·m, its plug at 10 ohm * 0.4 A = 4 V."""
    robot = robot_on(source_resistance_ohm=0.0, current_limit_a=0.8, board_current_a=0.0)
    k_t = supply.torque_constant_nm_per_a(robot.servo)
    assert k_t == pytest.approx(0.3, rel=1e-12)
    cap = k_t * 0.8 / 2
    point = supply.stall_point(robot.servo, robot.power)
    assert point.current_limited and not point.browned_out
    assert (point.current_a, point.plug_v, point.torque_nm) == pytest.approx((0.4, 4.0, cap), rel=1e-12)
    assert supply.supply_limits(robot.servo, robot.power)
    # the static model's clamp is the cap ...
    built = build(robot)
    assert built.model.actuator("L_servo").forcerange[1] == pytest.approx(cap, rel=1e-12)
    assert built.supply is not None
    # ... and the stepped model gives it at stall: the rail at the limit, each servo k_t * I / 2
    force, damper, stepper = stalled_drive(robot, built=built)
    assert stepper.rail_v == pytest.approx(4.0, rel=1e-12) and not stepper.off
    assert force == pytest.approx([-cap, -cap], rel=1e-12)
    assert damper == [0.0, 0.0]
    assert supply.limit_note(robot.servo, robot.power).startswith(
        "the supply's current limit (0.8 A) holds each stalled servo to 0.400 A, 0.1200 N*m, its plug at 4.00 V")
    assert supply.limit_note(preset("small").servo, preset("small").power) is None
    # the board's own draw takes its share of the limit: k_t * (0.8 - 0.05) / 2
    board = robot_on(source_resistance_ohm=0.0, current_limit_a=0.8, board_current_a=0.05)
    assert stalled_drive(board)[0] == pytest.approx([-k_t * 0.75 / 2] * 2, rel=1e-12)


def test_a_supply_whose_stall_voltage_is_below_the_brownout_gives_no_drive_at_stall():
    """5 V through 5 ohm to two 10-ohm servos: stalled, the plug falls to 5 * 10 / 20 = 2.5 V,
    below their 3.5 V: no drive at stall, nor back-EMF braking, until a PWM pulse finds the
    rail above 3.5 V. A small step (1 deg: duty 0.044) draws little and drives."""
    robot = robot_on(source_resistance_ohm=5.0, current_limit_a=math.inf, brownout_v=3.5)
    point = supply.stall_point(robot.servo, robot.power)
    assert point.plug_v == pytest.approx(2.5, rel=1e-12) and point.browned_out and not point.current_limited
    force, damper, stepper = stalled_drive(robot, speed_rad_per_s=-1.0)
    assert stepper.off and force == [0.0, 0.0]
    # the folds' alone, at -1 rad/s: the servo fold's and the loop fold's (its tendon runs over the
    # servo joint: with the knee and ankle still, the loop fold turns as the crank does)
    folds = side_values(robot, "L").folds
    own = folds["servo"].damping_nms_per_rad + folds["loop"].damping_nms_per_rad
    assert damper == pytest.approx([own, own], rel=1e-9)
    small = math.radians(1.0)
    force, _, stepper = stalled_drive(robot, command_rad=small)
    u = robot.servo.kp_nm_per_rad * small / robot.servo.stall_torque_nm
    rail = 5.0 / (1 + 5.0 * 2 * u * u / 10.0)                 # V = V0 / (1 + Rs * sum(u^2) / R)
    assert not stepper.off and stepper.rail_v == pytest.approx(rail, rel=1e-12)
    assert force == pytest.approx([robot.servo.kp_nm_per_rad * small * rail / 5.0] * 2, rel=1e-12)
    # in a hop, the push never starts: the nose stays where it stood (the same robot on a
    # supply that holds goes over)
    browned = run(robot, cycles=1)
    assert browned.valid and browned.hops[0].nose_apex_m < 1e-4 and browned.outcome == "stays_low"
    assert any("falls to 2.50 V, under their 3.5 V" in n for n in browned.notes), browned.notes
    held = run(robot.with_values({"power.brownout_v": 0.0}), cycles=1)
    assert held.hops[0].nose_apex_m > 0.05


def test_the_static_model_is_the_circuit_at_full_duty_on_a_supply_that_does_not_limit():
    """The robot as built (5 V, 0.5 ohm, 1.5 A: not limiting): its compiled numbers are the
    stepped circuit's at full duty, at stall and at speed (torque and back-EMF together)."""
    robot = preset("small")
    assert not supply.supply_limits(robot.servo, robot.power)
    built = build(robot)
    assert built.supply is None
    forced = dataclasses.replace(built, supply=supply.ServoSupply((robot.servo,) * 2, robot.power))
    for speed in (0.0, -4.0):
        model, data = built.model, mujoco.MjData(built.model)
        dofs = [int(model.jnt_dofadr[model.actuator_trnid[a, 0]]) for a in built.servo_actuators]
        for act, dof in zip(built.servo_actuators, dofs):
            data.ctrl[act], data.qvel[dof] = PUSH_RAD, speed
        mujoco.mj_forward(model, data)
        static = [float(data.actuator_force[a] + data.qfrc_damper[d]) for a, d in zip(built.servo_actuators, dofs)]
        force, damper, _ = stalled_drive(robot, speed_rad_per_s=speed, built=forced)
        assert [f + b for f, b in zip(force, damper)] == pytest.approx(static, rel=1e-12, abs=1e-15)
    folds = side_values(robot, "L").folds   # the servo fold's damping and the loop fold's, whose tendon runs over it
    stall, hinge = 0.15 * 10 / 11, folds["servo"].damping_nms_per_rad + folds["loop"].damping_nms_per_rad
    assert -static[0] == pytest.approx(stall - (stall / 10.31 + hinge) * 4.0, rel=1e-12)


def test_the_rail_and_the_meter_readings_by_hand():
    robot = preset("small")          # 5 V at rest, 0.5 ohm, 1.5 A, board 0.05 A, servos 10 ohm
    s, p = robot.servo, robot.power
    k = 5.0 / s.noload_speed_rad_per_s
    assert supply.backemf_v_s_per_rad(s) == pytest.approx(k, rel=1e-12)
    # one servo at full duty turning at 5 rad/s, the other at rest: V = (V0 + Rs*K*u*w/R) / (1 + Rs*u^2/R)
    assert supply.rail_voltage_v([s, s], p, [1.0, 0.0], [5.0, 0.0]) == pytest.approx(
        (5.0 + 0.5 * k * 5.0 / 10.0) / (1.0 + 0.05), rel=1e-12)
    assert supply.rail_voltage_v([s, s], p, [0.0, 0.0], [3.0, -3.0]) == 5.0
    # over the limit: both stalled on a 0.5 A source, 0.45 A left for them: V = R * 0.45 / 2
    weak = dataclasses.replace(p, current_limit_a=0.5)
    assert supply.rail_voltage_v([s, s], weak, [1.0, 1.0], [0.0, 0.0]) == pytest.approx(10.0 * 0.45 / 2, rel=1e-12)
    readings = supply.plug_readings(robot)
    assert (readings.rest_v, readings.stall_v, readings.stall_a) == pytest.approx((5.0, 50 / 11, 10 / 11), rel=1e-12)
    assert not readings.browned_out
    one = supply.stall_point(s, p, stalled=1)
    assert one.plug_v == pytest.approx(5.0 * 10 / 10.5, rel=1e-12)


def test_a_batch_of_both_kinds_is_each_run_as_alone():
    """Draws on a limiting supply are stepped, the others rolled out: in the batch's order,
    each as its own run."""
    limited = robot_on(current_limit_a=0.8)
    builts = [build(preset("small")), build(limited)]
    plan = control_plan(limited.schedule, limited.solver, 1)
    both = simulate_batch(builts, plan)
    for b, traj in zip(builts, both):
        alone = simulate_batch([b], plan)[0]
        assert traj.built is b
        np.testing.assert_array_equal(traj.sensordata, alone.sensordata)
    assert not np.array_equal(both[0].sensordata, both[1].sensordata)


def test_the_live_robot_on_a_limiting_supply_is_the_rollout():
    robot = robot_on(current_limit_a=0.8)
    sim = LiveSim(robot)
    sch, hz = robot.schedule, robot.solver.control_hz
    for i in range(int((sch.push_s + sch.wait_s) * hz + 1e-9)):
        angle = sch.push_deg if (i / hz) < sch.push_s else 0.0
        sim.set_servo_angles_deg(angle, angle)
        sim.advance_to((i + 1) / hz)
    live = sim.close()
    ref = run(robot, cycles=1)
    assert live["valid"] and ref.valid
    assert live["max_nose_height_m"] == ref.max_nose_height_m and live["distance_m"] == ref.distance_m


def test_the_stepper_scales_the_actuator_as_compiled_a_trims_bias_too():
    """The stepped servo is the compiled actuator on the rail: a trim compiled into its bias
    (kp * trim) moves its target, so a command of minus the trim at the rest angle asks nothing."""
    robot = robot_on(current_limit_a=0.8)
    built = build(robot)
    model = built.model
    for act in built.servo_actuators:
        model.actuator_biasprm[act, 0] = model.actuator_gainprm[act, 0] * 0.1     # a 0.1 rad trim
    force, _, stepper = stalled_drive(robot, command_rad=-0.1, built=built)
    assert force == [0.0, 0.0] and stepper.rail_v == robot.power.supply_voltage_v
    force, _, stepper = stalled_drive(robot, command_rad=PUSH_RAD - 0.1, built=built)
    assert force == pytest.approx([-supply.servo_torque_cap_nm(robot.servo, robot.power)] * 2, rel=1e-12)
