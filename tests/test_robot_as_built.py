"""The seed team's robot as built (params.AS_BUILT): sources, the supply's DC-motor physics,
the contact softness, and what the leg sets do against the filmed robots (docs/servo.md)."""

from __future__ import annotations

import math

import pytest

from locust import params
from locust.sim import servo as sim_servo
from locust.sim.model import build, contact_solref
from locust.sim.run import run


def test_every_as_built_value_names_a_measurement_and_none_a_hop_fit():
    for name in ("small", "medium", "large"):
        robot = params.preset(name)
        for key in params.AS_BUILT:
            source = robot.source_of(key).source
            # a bench recording's fit (fit:<recording>) is a measurement; a hop fit is not
            assert source.split(":")[0] in {"photo", "cut_file", "datasheet", "data", "estimate", "preset",
                                            "fit"}, key
        assert not [k for k in params.all_keys() if "hop" in robot.source_of(k).source], name
    # the leg sets' lengths are the cut file's plus the notebook's added centimetres
    assert params.preset("large").link_lengths_m() == pytest.approx((0.06, 0.06, 0.04, 0.08), abs=1e-12)


# what a photo of the robot from above can show: lengths in the plate's plane
IN_PLANE = {"geometry.body_length_m", "geometry.body_width_m", "geometry.nose_x_m", "geometry.servo_axis_x_m",
            "geometry.leg_mount_y_m", "geometry.servo_body_x_m", "geometry.servo_body_y_m"}


def test_params_json_has_no_photo_source_a_photo_cannot_show():
    """``locust params --preset medium --json``: every photo is a top view or a loose part, so
    an angle or height in the legs' plane (crank at rest, ground link, axis below the plate,
    pitch), a mass or a voltage never names a photo; no value comes from a hop fit."""
    import json

    from click.testing import CliRunner

    from locust.commands import cli

    res = CliRunner().invoke(cli, ["params", "--preset", "medium", "--json"])
    assert res.exit_code == 0, res.output
    values = json.loads(res.stdout)["values"]
    photo = {k for k, v in values.items() if v.get("source", "").startswith("photo:")}
    assert photo and photo <= IN_PLANE, sorted(photo - IN_PLANE)
    for key in ("geometry.crank_start_deg", "geometry.ground_angle_deg"):
        assert values[key]["source"] == "estimate" and values[key]["uncertainty"] > 0, key
    assert not [k for k, v in values.items() if "hop" in v.get("source", "")]
    # the servo axis scaled from the SG90s in the top view: 32 mm from the 6 cm half-plate's edge
    axis = values["geometry.servo_axis_x_m"]
    assert (axis["value"], axis["uncertainty"]) == (0.028, 0.003) and "px/mm" in axis["note"]


def test_the_supply_scales_the_servo_as_a_dc_motor():
    """4.2 V through 0.5 ohm to two servos of 10 ohm: stall torque 0.15 * 4.2/5 * 10/11, no-load
    speed 10.2 * 4.2/5 (no current at no load, no sag), the holding gain with the torque."""
    robot = params.preset("medium").with_values({"power.supply_voltage_v": 4.2, "power.source_resistance_ohm": 0.5})
    s = sim_servo.at_supply(robot.servo, robot.power)
    torque = 4.2 / 5.0 * 10.0 / 11.0
    stall, noload, kp = robot.servo.stall_torque_nm, robot.servo.noload_speed_rad_per_s, robot.servo.kp_nm_per_rad
    assert robot.servo.reference_voltage_v == 5.0 and robot.servo.winding_resistance_ohm == 10.0
    assert s.stall_torque_nm == pytest.approx(stall * torque, rel=1e-12)
    assert s.noload_speed_rad_per_s == pytest.approx(noload * 4.2 / 5.0, rel=1e-12)
    assert s.kp_nm_per_rad == pytest.approx(kp * torque, rel=1e-12)
    # and that is what MuJoCo runs: the actuator's clamp and gain, the crank's back-EMF damping
    model = build(robot).model
    act = model.actuator("L_servo")
    assert act.forcerange[1] == pytest.approx(stall * torque, rel=1e-12)
    assert act.gainprm[0] == pytest.approx(kp * torque, rel=1e-12)
    dof = model.joint("L_servo").dofadr[0]
    back_emf = (stall * torque) / (noload * 4.2 / 5.0)
    hinge = robot.compliance.hinge_damping_nms_per_rad
    assert model.dof_damping[dof] == pytest.approx(hinge + back_emf, rel=1e-12)
    # on the voltage it was identified at, with no source resistance, the servo is unchanged
    bare = params.preset("medium").with_values({"power.source_resistance_ohm": 0.0})
    assert sim_servo.at_supply(bare.servo, bare.power) is bare.servo


@pytest.mark.parametrize("restitution", [0.0, 0.2, 0.5, 0.9])
def test_contact_softness_gives_the_drop_tests_restitution(restitution):
    contact = params.Contact(timeconst_s=0.01, restitution=restitution)
    timeconst, zeta = contact_solref(contact)
    assert timeconst == 0.01
    bounce = 0.0 if zeta >= 1.0 else math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta**2))
    assert bounce == pytest.approx(restitution, abs=1e-12)
    # restitution 0 is MuJoCo's default contact (critically damped)
    assert contact_solref(params.Contact()) == [0.02, 1.0]


@pytest.fixture(scope="module")
def leg_sets():
    return {name: run(params.preset(name), cycles=6) for name in ("small", "medium", "large")}


def test_as_built_leg_sets_rear_onto_their_legs_and_stay(leg_sets):
    """The presets as built (docs/servo.md, "The robot as built against the filmed robots"):
    the first push pitches each robot over its legs onto its back, 7.3 / 9.9 / 12.2 cm toward
    the leg end, and it stays there; every later hop's "nose rise" is the nose's resting
    height, and the run says so. The filmed robots instead fell back and moved on each hop:
    this is the model's honest miss, pinned at the values reached (1 mm) so that a change to
    the presets or the model shows up here."""
    first = {"small": (-0.0727, 0.1147), "medium": (-0.0985, 0.1274), "large": (-0.1219, 0.1406)}
    for name, r in leg_sets.items():
        assert r.valid, (name, r.reasons)
        hop1 = r.hops[0]
        assert (hop1.distance_m, hop1.nose_apex_m) == pytest.approx(first[name], abs=1e-3), name
        # then it lies still: under 1 mm a hop, the nose at its first apex within 5 mm
        assert all(abs(h.distance_m) < 1e-3 for h in r.hops[1:]), name
        assert all(abs(h.nose_apex_m - hop1.nose_apex_m) < 5e-3 for h in r.hops[1:]), name
        assert any(n.startswith("did not come back down") for n in r.notes), (name, r.notes)


def test_large_falls_back_each_hop_one_sigma_away():
    """The behaviour sits on a threshold that the estimates' own uncertainties straddle:
    Large with its crank at -90 deg at rest instead of -100 (the estimate's one standard
    deviation, 10 deg) pitches its nose up 9-12 cm and falls back every hop, moving 7.4-8.2 mm
    toward its nose each time (docs/servo.md has the table)."""
    r = run(params.preset("large").with_values({"geometry.crank_start_deg": -90.0}), cycles=6)
    assert r.valid, r.reasons
    assert all(0.007 < h.distance_m < 0.0085 for h in r.hops), [h.distance_m for h in r.hops]
    assert all(0.09 < h.nose_apex_m < 0.12 for h in r.hops), [h.nose_apex_m for h in r.hops]
    assert not any(n.startswith("did not come back down") for n in r.notes), r.notes
    assert r.outcome == "rears_and_returns"
