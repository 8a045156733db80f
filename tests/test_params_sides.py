"""The folds, left and right sections and servo.spline_teeth: inheritance, limits, the robot
file's round trip, --set and `locust params`, draws and sweeps of them."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import pytest
from click.testing import CliRunner

from locust import params
from locust.commands import cli
from locust.errors import ParamsError
from locust.io import robot_toml
from locust.sim.fourbar import fold_angles_deg
from locust.sim.samples import draw, uncertain_values
from locust.sweep.design import check_name, is_integer

ROOT = Path(__file__).resolve().parents[1]
HINGE_K, HINGE_B = "compliance.hinge_stiffness_nm_per_rad", "compliance.hinge_damping_nms_per_rad"


def test_every_inherited_key_takes_its_value_from_a_key_of_the_model():
    keys = set(params.all_keys())
    assert params.INHERITS and set(params.INHERITS.values()) <= keys
    # 8 fold stiffnesses and dampings, and per side 12 fold values and 5 servo values
    assert len(params.INHERITS) == 8 + 2 * (12 + 5)
    assert all(params.is_optional(k) for k in params.INHERITS)


def test_a_fold_inherits_the_film_hinge_and_a_side_the_folds_and_the_servo():
    robot = params.preset("small")
    k, b = robot.get(HINGE_K), robot.get(HINGE_B)
    assert (k, b) == (1.46e-4, 1.59e-6)
    for side in ("left", "right"):
        key = f"{side}.loop_stiffness_nm_per_rad"
        assert robot.get(key) == k and robot.own(key) is None
        assert robot.get(f"{side}.knee_damping_nms_per_rad") == b
        assert robot.get(f"{side}.servo_kp_nm_per_rad") == robot.servo.kp_nm_per_rad
    assert robot.inherits("left.loop_stiffness_nm_per_rad") == "folds.loop_stiffness_nm_per_rad"
    assert robot.inherits("folds.loop_stiffness_nm_per_rad") == HINGE_K
    # a value set on the way down is the one taken; the film hinge's still reaches the others
    changed = robot.with_values({"folds.loop_stiffness_nm_per_rad": 2e-4, HINGE_K: 3e-4})
    assert changed.get("right.loop_stiffness_nm_per_rad") == 2e-4
    assert changed.get("left.knee_stiffness_nm_per_rad") == 3e-4
    # "inherit" (or None) gives the value back to the key above, and its provenance with it
    back = changed.with_values({"folds.loop_stiffness_nm_per_rad": "inherit"})
    assert back.own("folds.loop_stiffness_nm_per_rad") is None and back.get("left.loop_stiffness_nm_per_rad") == 3e-4
    assert "folds.loop_stiffness_nm_per_rad" not in back.provenance


def test_side_values_resolve_each_leg():
    robot = params.preset("small").with_values({
        "left.crank_tooth": 1, "right.trim_deg": 2.5, "right.servo_kp_nm_per_rad": 0.5,
        "left.ankle_rest_offset_deg": 4.0, "folds.ankle_rest_offset_deg": -3.0,
        "folds.knee_stiffness_nm_per_rad": 1e-3})
    left, right = params.side_values(robot, "L"), params.side_values(robot, "R")
    assert robot.servo.spline_teeth == 21
    assert left.crank_start_deg == pytest.approx(-100.0 + 360.0 / 21, abs=1e-12)
    assert right.crank_start_deg == -100.0 and (left.trim_deg, right.trim_deg) == (0.0, 2.5)
    assert (left.servo.kp_nm_per_rad, right.servo.kp_nm_per_rad) == (0.377, 0.5)
    assert right.servo.stall_torque_nm == robot.servo.stall_torque_nm
    assert (left.folds["ankle"].rest_offset_deg, right.folds["ankle"].rest_offset_deg) == (4.0, -3.0)
    assert left.folds["knee"].stiffness_nm_per_rad == 1e-3 and left.folds["loop"].stiffness_nm_per_rad == 1.46e-4
    assert params.is_symmetric(params.preset("small"))
    assert not params.is_symmetric(robot)
    # a side holding the value it would inherit is still symmetric
    assert params.is_symmetric(params.preset("small").with_values({"left.servo_kp_nm_per_rad": 0.377}))
    with pytest.raises(ParamsError, match="unknown side"):
        params.side_values(robot, "left")


def test_the_fold_angles_of_a_square_linkage_are_a_quarter_turn_each():
    """Known truth: four 4 cm links with the crank straight down close as a square."""
    g = {f"geometry.{n}": 0.04 for n in ("ground_m", "crank_m", "coupler_m", "leg_m")}
    square = params.preset("small").with_values({**g, "geometry.crank_start_deg": -90.0})
    assert fold_angles_deg(square, "L") == pytest.approx({f: 90.0 for f in params.FOLDS}, abs=1e-9)
    # a tooth on: the servo fold turns by one tooth, and the four still make a whole turn
    moved = fold_angles_deg(square.with_values({"right.crank_tooth": 1}), "R")
    assert moved["servo"] == pytest.approx(90.0 + 360.0 / 21, abs=1e-9)
    assert sum(moved.values()) == pytest.approx(360.0, abs=1e-9)


@pytest.mark.parametrize("values, fragment", [
    ({"left.crank_tooth": 21}, "left.crank_tooth = 21 is a turn or more of the 21-tooth spline"),
    ({"right.trim_deg": 31.0}, "right.trim_deg = 31 must be >= -30 and <= 30"),
    ({"left.trim_deg": 20.0, "servo.travel_deg": 80.0}, "left.trim_deg = 20 with servo.travel_deg = 80 exceeds half"),
    ({"folds.loop_stiffness_nm_per_rad": -1e-4}, "folds.loop_stiffness_nm_per_rad = -0.0001 must be >= 0"),
    ({"right.knee_rest_offset_deg": 200.0}, "right.knee_rest_offset_deg = 200 must be >= -180"),
    ({"left.servo_stall_torque_nm": 0.0}, "left.servo_stall_torque_nm = 0 must be > 0"),
    ({"servo.spline_teeth": 4}, "servo.spline_teeth = 4 must be >= 8"),
])
def test_limits_of_the_new_values(values, fragment):
    with pytest.raises(ParamsError) as err:
        params.check_robot(params.preset("small").with_values(values))
    assert fragment in err.value.message


def test_an_inherited_value_out_of_its_limits_is_named_once():
    with pytest.raises(ParamsError) as err:
        params.check_robot(params.preset("small").with_values({HINGE_K: 20.0}))
    assert err.value.message.count("must be") == 1 and HINGE_K in err.value.message


def test_a_robot_file_round_trips_per_side_values_and_leaves_inherited_ones_out(tmp_path):
    fit = params.Provenance(source="fit:fold.csv", uncertainty=1e-5, date="2026-12-01")
    robot = params.preset("medium").with_values(
        {"left.crank_tooth": -1, "right.trim_deg": 1.5, "folds.knee_rest_offset_deg": -4.0,
         "right.servo_noload_speed_rad_per_s": math.inf}).with_values({"left.loop_stiffness_nm_per_rad": 2.2e-4}, fit)
    path = robot_toml.save_robot(robot, tmp_path / "robot.toml")
    doc = tomllib.loads(path.read_text())
    assert doc["left"]["crank_tooth"]["value"] == -1 and doc["left"]["loop_stiffness_nm_per_rad"]["value"] == 2.2e-4
    assert "servo_kp_nm_per_rad" not in doc["left"] and "loop_stiffness_nm_per_rad" not in doc["folds"]
    back = robot_toml.load_robot(path)
    assert all(back.own(k) == robot.own(k) for k in params.all_keys())
    assert back.source_of("left.loop_stiffness_nm_per_rad") == fit
    assert back.get("right.servo_noload_speed_rad_per_s") == math.inf
    # set back to inherit and written over the file: the key leaves it, the rest of it stays
    inherit = back.with_values({"left.loop_stiffness_nm_per_rad": "inherit"})
    robot_toml.save_robot(inherit, path, template=robot_toml.file_text(path))
    again = tomllib.loads(path.read_text())
    assert "loop_stiffness_nm_per_rad" not in again["left"] and again["left"]["crank_tooth"]["value"] == -1
    assert robot_toml.load_robot(path).get("left.loop_stiffness_nm_per_rad") == back.get(HINGE_K)


def test_todays_robot_file_loads_to_the_same_symmetric_robot(tmp_path):
    """A robot file written before these sections existed (the checkout's calibration/robot.toml
    without its folds, left and right tables and its spline count) loads to the robot as built."""
    text = (ROOT / "calibration" / "robot.toml").read_text()
    kept, skipping = [], False
    for line in text.splitlines():
        if line.startswith("["):
            skipping = line.strip() in ("[folds]", "[left]", "[right]")
        if not skipping and not line.startswith("spline_teeth"):
            kept.append(line)
    old = tmp_path / "robot.toml"
    old.write_text("\n".join(kept) + "\n")
    assert "[left]" not in old.read_text() and "spline_teeth" not in old.read_text()
    for path in (old, ROOT / "calibration" / "robot.toml"):
        robot = robot_toml.load_robot(path)
        assert params.is_symmetric(robot) and robot.flat() == params.preset("small").flat()
        assert all(robot.own(k) is None for k in params.INHERITS)


def test_set_a_crank_a_tooth_off_from_the_command_line():
    result = CliRunner().invoke(cli, ["params", "--preset", "small", "--set", "left.crank_tooth=1"])
    assert result.exit_code == 0, result.output
    lines = {line.split()[0]: line for line in result.output.splitlines() if line and not line.startswith("#")}
    assert lines["left.crank_tooth"].split()[1:] == ["1", "[override]"]
    assert lines["right.crank_tooth"].split()[1:] == ["0", "[default]"]
    assert lines["folds.loop_stiffness_nm_per_rad"].split()[1:] == ["0.000146", "[=", f"{HINGE_K}]"]
    out = CliRunner().invoke(cli, ["params", "--preset", "small", "--set", "left.crank_tooth=1", "--json"])
    values = json.loads(out.output[out.output.index("{"):])["values"]
    assert values["left.crank_tooth"] == {"value": 1, "source": "override"}
    assert values["left.loop_stiffness_nm_per_rad"] == {"value": 1.46e-4, "inherits": "folds.loop_stiffness_nm_per_rad"}
    bad = CliRunner().invoke(cli, ["params", "--preset", "small", "--set", "left.crank_tooth=0.5"])
    assert bad.exit_code == 2 and "not a whole number" in bad.output


def test_draws_move_what_carries_an_uncertainty_and_inherited_folds_with_their_hinge():
    robot = params.preset("small").with_values({"left.trim_deg": 0.0}, params.Provenance("estimate", uncertainty=1.0))
    sds = uncertain_values(robot)
    assert sds["left.trim_deg"] == 1.0 and "right.trim_deg" not in sds
    assert not any(k.startswith("folds.") for k in sds)
    drawn = draw(robot, 3, seed=1)
    trims = [d.left.trim_deg for d in drawn]
    assert len(set(trims)) == 3 and all(d.right.trim_deg == 0.0 for d in drawn)
    for d in drawn:   # the folds take the drawn film hinge: one spring, one draw
        assert d.get("folds.loop_stiffness_nm_per_rad") == d.get("left.knee_stiffness_nm_per_rad") == d.get(HINGE_K)
        assert d.get(HINGE_K) != robot.get(HINGE_K)
    assert {"left.trim_deg", "folds.loop_stiffness_nm_per_rad", "right.servo_kp_nm_per_rad"} <= set(params.real_keys())
    assert "left.crank_tooth" not in params.real_keys() and params.value_type("left.crank_tooth") == "int"


def test_a_sweep_may_vary_an_inherited_fold_and_a_crank_tooth():
    robot = params.preset("small")
    check_name("folds.loop_stiffness_nm_per_rad", robot)
    check_name("left.crank_tooth", robot)
    assert is_integer(robot, "left.crank_tooth") and not is_integer(robot, "folds.loop_stiffness_nm_per_rad")
