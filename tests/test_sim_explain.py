"""``locust sim --explain``: the tip-over's support and margin, the thresholds and the tornado,
each checked against a known truth: a robot built with its centre of mass a known distance
behind its feet, and the simulation itself at the values the explanation names."""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner

import locust
from locust.commands import cli
from locust.sim.explain import explain, tip_over
from locust.sim.model import build
from locust.sim.outcome import GOES_OVER
from locust.sim.run import run
from locust.sim.support import stance

SERVO_KG = 0.2          # each servo: the robot's mass is in them, where the test puts it
PLATE_KG = 0.001
BEHIND_M = (0.004, 0.010, 0.020)


def _chassis_quat(pitch_deg: float) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_euler2Quat(q, np.radians([180.0, pitch_deg, 180.0]), "xyz")
    return q


def _placed(robot, pitch_deg: float, behind_m: float):
    """The robot with its servos placed so that, posed level at ``pitch_deg`` with its feet on the
    floor, its centre of mass is ``behind_m`` behind its feet along the floor (the servos carry
    nearly all the mass: the links' 0.3 % moves it less than 0.1 mm); returns the model, its data
    posed, and the forward direction."""
    g = robot.geometry
    total = PLATE_KG + 2 * SERVO_KG
    r0 = robot.with_values({"geometry.servo_mass_kg": SERVO_KG, "geometry.body_mass_kg": PLATE_KG,
                            "geometry.link_density_kg_per_m3": 50.0})
    built = build(r0)
    model, data = built.model, mujoco.MjData(built.model)
    data.qpos[3:7] = _chassis_quat(pitch_deg)
    mujoco.mj_kinematics(model, data)
    rot = data.xmat[model.body("chassis").id].reshape(3, 3)
    centre = data.xpos[model.body("chassis").id].copy()
    foot = data.site("L_foot").xpos.copy()
    forward = 1.0 if data.site("nose").xpos[0] >= centre[0] else -1.0
    # the centre of mass in the chassis frame: the servos' centres (x: axis + body offset, z: below
    # the plate), the plate at the origin; along world x it is linear in the servos' x
    def com_world_x(body_x: float) -> float:
        servo_c = np.array([g.servo_axis_x_m + body_x, 0.0, g.servo_axis_below_plate_m])
        return float((centre + rot @ (2 * SERVO_KG * servo_c / total))[0])
    a, b = com_world_x(0.0), com_world_x(0.01)
    want = foot[0] - forward * behind_m
    body_x = 0.01 * (want - a) / (b - a)
    r1 = r0.with_values({"geometry.servo_body_x_m": body_x})
    built = build(r1)
    model, data = built.model, mujoco.MjData(built.model)
    data.qpos[3:7] = _chassis_quat(pitch_deg)
    mujoco.mj_kinematics(model, data)
    lowest = min(data.site(f"{s}_foot").xpos[2] for s in "LR")
    data.qpos[2] -= lowest - 0.0003     # the feet's capsules (0.5 mm radius) 0.2 mm into the floor
    mujoco.mj_forward(model, data)
    return built, data, forward


@pytest.mark.parametrize("behind_m", BEHIND_M)
def test_margin_of_a_robot_built_behind_its_feet(behind_m):
    """A robot posed on its feet alone with its centre of mass a known distance behind them: the
    explained margin is that distance within 1 mm, and it stands on its feet."""
    robot = locust.robot("small")
    pitch = _feet_only_pitch(robot)
    built, data, forward = _placed(robot, pitch, behind_m)
    st = stance(built, data, forward)
    assert set(st.parts) == {"left foot", "right foot"}
    assert st.com_behind_m == pytest.approx(behind_m, abs=0.001)


def _lowest_points(model, data) -> list[tuple[float, np.ndarray]]:
    """Every colliding geom's lowest point (z, point): a capsule's end sphere, a box's corner."""
    out = []
    for i in range(model.ngeom):
        if model.geom_contype[i] == 0 and model.geom_conaffinity[i] == 0 and model.geom_bodyid[i] != 0:
            # explicit floor pairs: a geom collides when a pair names it
            if not any(i in (model.pair_geom1[k], model.pair_geom2[k]) for k in range(model.npair)):
                continue
        if model.geom_bodyid[i] == 0:
            continue
        rot, centre, size = data.geom_xmat[i].reshape(3, 3), data.geom_xpos[i], model.geom_size[i]
        if model.geom_type[i] == mujoco.mjtGeom.mjGEOM_CAPSULE:
            ends = [centre + rot[:, 2] * size[1] * s for s in (-1, 1)]
            pts = [e - np.array([0, 0, size[0]]) for e in ends]
        elif model.geom_type[i] == mujoco.mjtGeom.mjGEOM_BOX:
            pts = [centre + rot @ (size * np.array(c)) for c in np.ndindex(2, 2, 2) for c in [np.array(c) * 2 - 1]]
        else:
            continue
        low = min(pts, key=lambda p: p[2])
        out.append((float(low[2]), low))
    return out


def _feet_only_pitch(robot) -> float:
    """A plate pitch at which the feet are the robot's lowest points by 3 mm or more (only they
    touch the floor when it stands there)."""
    built = build(robot)
    model, data = built.model, mujoco.MjData(built.model)
    for pitch in np.arange(-40.0, 41.0, 1.0):
        data.qpos[3:7] = _chassis_quat(float(pitch))
        mujoco.mj_kinematics(model, data)
        feet = [data.site(f"{s}_foot").xpos for s in "LR"]
        lows = _lowest_points(model, data)
        lowest = min(z for z, _ in lows)
        near = [p for z, p in lows if z < lowest + 0.003]
        if all(min(np.linalg.norm(p - f) for f in feet) < 0.002 for p in near):
            return float(pitch)
    pytest.fail("no pitch stands the robot on its feet alone")


@pytest.fixture(scope="module")
def small_explained():
    robot = locust.robot("small")
    return robot, explain(robot, cycles=1)


def test_small_goes_over_from_its_knees(small_explained):
    """The robot as built (Small) goes over in its first push: on its knees (the crank tips) with
    its centre of mass behind them, then its feet, as the run's own states say."""
    robot, e = small_explained
    assert e.outcome == GOES_OVER
    tip = e.tip_over
    assert tip is not None and tip.cycle == 1
    assert set(tip.phases[0].parts) == {"left knee", "right knee"}
    assert 0.0 < tip.start_s < robot.schedule.push_s
    assert tip.com_behind_m > 0.005
    # the servo torque then is the run's own sensor at that instant
    res = run(robot, cycles=1, keep_states=True)
    again = tip_over(res.trajectory)
    assert again == tip
    assert e.words[0].startswith("goes over in push 1")


def test_thresholds_are_where_the_outcome_changes(small_explained):
    """Each threshold's two sides, simulated: the robot's own outcome on its near side, the named
    outcome on its far side."""
    robot, e = small_explained
    checked = 0
    for t in e.thresholds:
        for edge in (t.below, t.above):
            if edge is None or edge.outcome is None or t.key.startswith("schedule."):
                continue
            step = math.copysign(edge.resolution, edge.distance)
            near = run(robot.with_values({t.key: edge.value - step}), cycles=1)
            far = run(robot.with_values({t.key: edge.value + step}), cycles=1)
            assert near.outcome == e.outcome, t.key
            assert far.outcome == edge.outcome, t.key
            if t.sd:
                assert edge.distance_sd == pytest.approx(edge.distance / t.sd)
            checked += 1
        if checked >= 4:
            break
    assert checked >= 4


def test_tornado_ends_are_the_runs_at_two_sd(small_explained):
    """A tornado bar's figures are the robot's own run at -/+2 sd of that value, the others held."""
    robot, e = small_explained
    for bar in e.tornado[:3]:
        assert bar.high_value == pytest.approx(robot.get(bar.key) + 2 * bar.sd)
        res = run(robot.with_values({bar.key: bar.high_value}), cycles=1)
        assert bar.high.distance_m == pytest.approx(res.distance_m, abs=1e-12)
        assert bar.high.nose_rise_m == pytest.approx(res.hops[0].nose_apex_m, abs=1e-12)


def test_a_robot_that_stays_up_has_its_margin_to_going_over():
    """A robot that does not go over: how close its centre of mass came to being behind its
    supports, and the nearest value that would send it over, which does (simulated)."""
    robot = locust.robot("small").with_values({"geometry.crank_start_deg": -85.0})
    e = explain(robot, cycles=1)
    assert e.outcome != GOES_OVER and e.tip_over is None
    assert e.approach is not None and e.approach.support
    assert e.words[0].startswith("does not go over")
    over = [(t, edge) for t in e.thresholds for edge in (t.below, t.above)
            if edge is not None and edge.outcome == GOES_OVER and not t.key.startswith("schedule.")]
    assert over
    t, edge = over[0]
    far = run(robot.with_values({t.key: edge.value + math.copysign(edge.resolution, edge.distance)}), cycles=1)
    assert far.outcome == GOES_OVER


def test_sim_explain_json():
    """``locust sim --explain --json``: the tip-over's time, support, margin and servo torque; a
    threshold and a tornado bar per uncertain value."""
    out = CliRunner().invoke(cli, ["sim", "--preset", "small", "--cycles", "1", "--explain", "--json"])
    assert out.exit_code == 0, out.output
    doc = json.loads(out.stdout)
    ex = doc["explanation"]
    tip = ex["tip_over"]
    assert set(tip) >= {"start_s", "support", "com_behind_m", "servo_torque_nm", "duration_s"}
    uncertain = set(doc["explanation"]["tornado"][i]["key"] for i in range(len(ex["tornado"])))
    assert uncertain == set(locust.sim.samples.uncertain_values(locust.robot("small")))
    assert {t["key"] for t in ex["thresholds"]} >= uncertain
