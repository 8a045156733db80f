"""The model's folds and sides: each fold's spring against k*(q - rest), the loop fold's tendon
against the bodies' own angles, a crank a tooth off, a trim, a side's own servo, and the
symmetric default against the model before the loop fold had a spring (its published figures)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from locust.params import preset, side_values
from locust.sim.fourbar import fold_angles_deg
from locust.sim.model import LOOP_FOLD_JOINTS, SIDES, build, loop_fold_coefficients
from locust.sim.rollout import simulate_built
from locust.sim.run import run
from locust.sim.schedule import control_plan
from locust.sim.servo import at_supply, back_emf_damping_nms_per_rad

# every fold of each side its own spring, so that a value taken from the wrong fold or side shows
FOLD_VALUES = {
    "left.servo_stiffness_nm_per_rad": 2e-4, "left.servo_damping_nms_per_rad": 2e-6, "left.servo_rest_offset_deg": 3.0,
    "left.knee_stiffness_nm_per_rad": 3e-4, "left.knee_damping_nms_per_rad": 3e-6, "left.knee_rest_offset_deg": -4.0,
    "left.ankle_stiffness_nm_per_rad": 5e-4, "left.ankle_damping_nms_per_rad": 5e-6, "left.ankle_rest_offset_deg": 6.0,
    "left.loop_stiffness_nm_per_rad": 7e-4, "left.loop_damping_nms_per_rad": 7e-6, "left.loop_rest_offset_deg": -8.0,
    "folds.knee_stiffness_nm_per_rad": 1.1e-3, "folds.loop_rest_offset_deg": 10.0,
    "folds.ankle_damping_nms_per_rad": 1.3e-5,
}


def _qadr(model: mujoco.MjModel, name: str) -> tuple[int, int]:
    joint = model.joint(name)
    return int(model.jnt_qposadr[joint.id]), int(model.jnt_dofadr[joint.id])


def _angle_about_y_deg(model, data, body_a: str, body_b: str) -> float:
    """Body b's turn from body a about their shared +y axis [deg] (the fourbar frame's sense)."""
    ra, rb = data.body(body_a).xmat.reshape(3, 3), data.body(body_b).xmat.reshape(3, 3)
    rel = ra.T @ rb
    assert abs(rel[1, 1] - 1.0) < 1e-9    # planar: the two share their y axis
    return math.degrees(math.atan2(rel[0, 2], rel[0, 0]))


def _wrap(deg: float) -> float:
    return (deg + 180.0) % 360.0 - 180.0


def test_each_folds_spring_and_damper_is_k_times_its_deflection_from_rest():
    """Known truth: in any pose and at any speed, a fold's torque is -k*(angle - rest) - b*rate;
    the loop fold's reaches the three joints through its tendon's coefficients."""
    robot = preset("small").with_values(FOLD_VALUES)
    built = build(robot)
    m, d = built.model, mujoco.MjData(built.model)
    rng = np.random.default_rng(3)
    d.qpos[:] = m.qpos0
    d.qvel[:] = 0.0
    coef = loop_fold_coefficients()
    for side in SIDES:
        for joint in LOOP_FOLD_JOINTS:
            qa, va = _qadr(m, f"{side}_{joint}")
            d.qpos[qa] = rng.uniform(-0.4, 0.4)
            d.qvel[va] = rng.uniform(-2.0, 2.0)
    mujoco.mj_forward(m, d)
    for side in SIDES:
        values = side_values(robot, side)
        folds = values.folds
        q = {j: d.qpos[_qadr(m, f"{side}_{j}")[0]] for j in LOOP_FOLD_JOINTS}
        qd = {j: d.qvel[_qadr(m, f"{side}_{j}")[1]] for j in LOOP_FOLD_JOINTS}
        loop = folds["loop"]
        length = sum(coef[j] * q[j] for j in LOOP_FOLD_JOINTS)
        rate = sum(coef[j] * qd[j] for j in LOOP_FOLD_JOINTS)
        loop_spring = -loop.stiffness_nm_per_rad * (length - math.radians(loop.rest_offset_deg))
        loop_damper = -loop.damping_nms_per_rad * rate
        emf = back_emf_damping_nms_per_rad(at_supply(values.servo, robot.power))
        for j in LOOP_FOLD_JOINTS:
            fold = folds[j]
            spring = -fold.stiffness_nm_per_rad * (q[j] - math.radians(fold.rest_offset_deg)) + coef[j] * loop_spring
            damper = -(fold.damping_nms_per_rad + (emf if j == "servo" else 0.0)) * qd[j] + coef[j] * loop_damper
            dof = _qadr(m, f"{side}_{j}")[1]
            assert d.qfrc_spring[dof] == pytest.approx(spring, rel=1e-12, abs=1e-15), (side, j)
            assert d.qfrc_damper[dof] == pytest.approx(damper, rel=1e-12, abs=1e-15), (side, j)
    # the values reached the fold they name: the left's own, the right's from the folds section
    assert side_values(robot, "L").folds["knee"].stiffness_nm_per_rad == 3e-4
    assert side_values(robot, "R").folds["knee"].stiffness_nm_per_rad == 1.1e-3
    assert side_values(robot, "R").folds["servo"].stiffness_nm_per_rad == 1.46e-4


def test_the_loop_tendon_is_the_loop_folds_deflection_read_off_the_bodies():
    """The loop fold's angle from the ground link's and the leg's orientations: as assembled it
    is the planar linkage's (fold_angles_deg), and through a push and its hop the tendon's
    length is its change from there."""
    robot = preset("medium").with_values({"right.crank_tooth": -1})
    built = build(robot)
    m = built.model
    plan = control_plan(robot.schedule, robot.solver, 1)
    traj = simulate_built(built, plan, keep_states=True)
    d = mujoco.MjData(m)
    deflections = []
    for side in SIDES:
        tendon = m.tendon(f"{side}_loop_fold").id
        planar = fold_angles_deg(robot, side)["loop"]
        for step in (0, plan.settle_steps, plan.settle_steps + 150, plan.settle_steps + 300, plan.nstep - 1):
            d.qpos[:] = traj.states[step, 1:1 + m.nq]
            mujoco.mj_kinematics(m, d)
            mujoco.mj_tendon(m, d)
            loop_deg = _wrap(180.0 - _angle_about_y_deg(m, d, f"{side}_ground", f"{side}_leg"))
            if step == 0:
                assert loop_deg == pytest.approx(planar, abs=1e-9)
            assert math.degrees(d.ten_length[tendon]) == pytest.approx(_wrap(loop_deg - planar), abs=1e-9)
            deflections.append(abs(math.degrees(d.ten_length[tendon])))
    assert max(deflections) > 10.0     # the push turned the fold: the comparison was not of zeros


def test_a_crank_a_tooth_off_starts_a_tooth_on():
    robot = preset("small").with_values({"left.crank_tooth": 1, "right.crank_tooth": -2})
    tooth = 360.0 / robot.servo.spline_teeth
    built = build(robot)
    d = mujoco.MjData(built.model)
    mujoco.mj_forward(built.model, d)
    start = robot.geometry.crank_start_deg
    for side, teeth in (("L", 1), ("R", -2)):
        assert _angle_about_y_deg(built.model, d, f"{side}_ground", f"{side}_crank") == pytest.approx(
            start + teeth * tooth, abs=1e-9)
        assert np.linalg.norm(d.site(f"{side}_loop_a").xpos - d.site(f"{side}_loop_b").xpos) < 1e-12
    assert built.assemblies["L"].crank_deg == pytest.approx(start + 17.142857142857, abs=1e-9)


def _settled_servo_deg(robot) -> dict[str, float]:
    built = build(robot)
    traj = simulate_built(built, control_plan(robot.schedule, robot.solver, 0), keep_states=True)
    q = traj.states[-1, 1:1 + built.model.nq]
    return {side: math.degrees(q[_qadr(built.model, f"{side}_servo")[0]]) for side in SIDES}


def test_a_trim_shifts_the_settled_servo_by_the_trim():
    """Standing at the 0 deg command: the trimmed servo rests a trim further on (its load
    changes a little with the pose: within 0.05 deg of 5), the other where it was."""
    base = preset("small")
    before = _settled_servo_deg(base)
    after = _settled_servo_deg(base.with_values({"right.trim_deg": -5.0}))
    assert after["R"] - before["R"] == pytest.approx(-5.0, abs=0.05)
    assert abs(after["L"] - before["L"]) < 0.05


def test_a_side_has_its_own_servo():
    robot = preset("small").with_values({"right.servo_kp_nm_per_rad": 0.5, "right.servo_stall_torque_nm": 0.2,
                                         "left.trim_deg": 2.0})
    m = build(robot).model
    for side in SIDES:
        s = at_supply(side_values(robot, side).servo, robot.power)
        act = m.actuator(f"{side}_servo").id
        assert m.actuator_gainprm[act, 0] == pytest.approx(s.kp_nm_per_rad, rel=1e-12)
        assert tuple(m.actuator_forcerange[act]) == pytest.approx((-s.stall_torque_nm, s.stall_torque_nm), rel=1e-12)
        trim = math.radians(side_values(robot, side).trim_deg)
        assert m.actuator_biasprm[act, 0] == pytest.approx(s.kp_nm_per_rad * trim, rel=1e-12, abs=0)
        travel = math.radians(robot.servo.travel_deg)
        assert tuple(m.jnt_range[m.joint(f"{side}_servo").id]) == pytest.approx((trim - travel, trim + travel))
    assert at_supply(side_values(robot, "R").servo, robot.power).kp_nm_per_rad != pytest.approx(
        at_supply(side_values(robot, "L").servo, robot.power).kp_nm_per_rad)


# Published reference: every hop of `small`, `medium` and `large` (3 cycles, run(preset(name),
# cycles=3)) as the model computed them at commit dcb7aa8 (main, before the folds had springs
# of their own and the loop fold any), run from that commit's checkout. Per hop: distance [m],
# nose apex [m], centre-of-mass apex [m], flight [s], plate's end turn [deg].
BEFORE_FOLDS = {
    "small": [(-0.07270096950410929, 0.11473084297727006, 0.0009052384592504806, 0.011, 91.37370473844972),
              (4.7494221800961633e-05, 0.11471217100994377, -0.009212156559344018, 0.0, 91.3737049511341),
              (4.946940971983782e-05, 0.11472206441037207, -0.009205830299473763, 0.0, 91.3737109966794)],
    "medium": [(-0.09845320057557376, 0.12737652327998594, 0.005199543036149508, 0.015, 99.13786973176227),
               (-0.0004946007031434024, 0.1273744370765751, -0.006601799188515695, 0.0, 99.1378702459725),
               (-0.0004930705946178393, 0.1273867435122801, -0.006591771542782877, 0.0, 99.13787281214563)],
    "large": [(-0.12187152563327829, 0.1405726139051178, 0.008216910439039216, 0.012, 106.53322286457487),
              (-0.0008339605399304284, 0.13918212275303699, -0.00571668924036927, 0.0, 106.53320689788772),
              (-0.0008359443663681076, 0.13919960711235216, -0.005704806010346626, 0.0, 106.5331996154234)],
}
LENGTH_TOL_M = 1e-5       # 0.01 mm
FLIGHT_TOL_S = 5e-4       # half a 1 ms step
TURN_TOL_DEG = 1e-4


def _figures(result) -> list[tuple[float, ...]]:
    return [(h.distance_m, h.nose_apex_m, h.com_apex_m, h.flight_s, h.end_turn_deg) for h in result.hops]


def _close(got, want) -> bool:
    tol = (LENGTH_TOL_M, LENGTH_TOL_M, LENGTH_TOL_M, FLIGHT_TOL_S, TURN_TOL_DEG)
    return all(abs(g - w) <= t for g, w, t in zip(got, want, tol))


@pytest.mark.parametrize("name", list(BEFORE_FOLDS))
def test_the_symmetric_default_without_the_loop_spring_is_the_model_before_it(name):
    robot = preset(name).with_values({"folds.loop_stiffness_nm_per_rad": 0.0, "folds.loop_damping_nms_per_rad": 0.0})
    got = _figures(run(robot, cycles=3))
    assert len(got) == 3
    for hop, want in zip(got, BEFORE_FOLDS[name]):
        assert _close(hop, want), (hop, want)
    # with its film spring the loop fold moves the figures, by a film hinge's little (< 0.1 mm)
    sprung = _figures(run(preset(name), cycles=3))
    assert sprung != got
    assert all(abs(a - b) < 1e-4 for hs, hg in zip(sprung, got) for a, b in list(zip(hs, hg))[:3])


def test_a_per_side_robot_is_itself_in_the_virtual_robot_the_stills_and_the_standing_load():
    """The live simulation (the virtual robot's plant), the stills and the statics build the
    same per-side model as `locust sim`: the live run's hop is the rollout's bit for bit, the
    still's crank angle is the left's own start, and the standing load is that of the robot
    settled with its trim."""
    from locust.sim.live import LiveSim
    from locust.sim.statics import standing_load
    from locust.sim.still import rest_pose

    robot = preset("small").with_values({"left.crank_tooth": 1, "right.trim_deg": -3.0,
                                         "right.knee_rest_offset_deg": 5.0})
    sim = LiveSim(robot)
    sch, hz = robot.schedule, robot.solver.control_hz
    for i in range(int((sch.push_s + sch.wait_s) * hz + 1e-9)):
        angle = sch.push_deg if i / hz < sch.push_s else 0.0
        sim.set_servo_angles_deg(angle, angle)
        sim.advance_to((i + 1) / hz)
    live, ref = sim.close(), run(robot, cycles=1)
    assert live["hops"] == [vars(hop) for hop in ref.hops]
    symmetric = run(preset("small"), cycles=1)
    assert abs(ref.hops[0].nose_apex_m - symmetric.hops[0].nose_apex_m) > 1e-4   # the sides changed the hop
    rest = rest_pose(robot)
    assert rest.crank_deg == pytest.approx(side_values(robot, "L").crank_start_deg + rest.servo_deg, abs=1e-12)
    assert rest.crank_deg == pytest.approx(-100.0 + 360.0 / 21, abs=1.0)        # a tooth on, less the servo's give
    assert standing_load(robot).nose_load_kg != standing_load(preset("small")).nose_load_kg
