"""One robot through every door: the resolution rule, the leg set as part of the robot, a
calibration written to a new file, and the seed notebook's reproduction from the command line
and the API (README, "What the presets are"; docs/architecture.md, "Robot parameters")."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import locust
from locust.errors import ParamsError
from locust.io.robot_toml import ROBOT_FILE, default_robot, load_robot, save_robot
from locust.params import LEG_SETS, leg_set, preset

ROOT = Path(__file__).resolve().parents[1]
GEOMETRY = [k for k in preset("small").flat() if k.startswith("geometry.")]
SERVO_FITTED = ("servo.noload_speed_rad_per_s", "servo.armature_kgm2", "servo.kp_nm_per_rad")


def locust_cli(*args, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "locust.commands", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, "PYTHONUNBUFFERED": "1"})


def test_the_seed_notebook_is_reproduced_through_the_command_line_and_the_api(tmp_path):
    """README: 60.29 cm and 7.04 cm over 6 hops, within 0.5 %, as a user asks for them (the
    standing load's own settling must not refuse a robot dropped with its schedule running)."""
    cli = locust_cli("sim", "--preset", "seed-notebook", "--json", cwd=tmp_path)
    assert cli.returncode == 0, cli.stderr
    out = json.loads(cli.stdout)
    api = locust.simulate(locust.robot("seed-notebook"))
    for distance_m, nose_m in ((out["distance_m"], out["max_nose_height_m"]),
                               (api.distance_m, api.max_nose_height_m)):
        assert distance_m == pytest.approx(0.6029, rel=0.005)
        assert nose_m == pytest.approx(0.0704, rel=0.005)
    assert api.distance_m == out["distance_m"]
    assert api.nose_load_kg > 0       # it stands on its nose when settled: 27.3 g of its 60.6 g


def test_the_checkouts_robot_file_is_the_robot_as_built():
    """calibration/robot.toml (what `locust params` reads from the checkout's root) is small,
    the robot as built with the real recordings' fits: every value and source alike."""
    here, small = load_robot(ROOT / ROBOT_FILE), preset("small")
    assert here.leg_set == small.leg_set == "small"
    assert here.flat() == small.flat()
    assert {k: here.source_of(k) for k in small.flat()} == {k: small.source_of(k) for k in small.flat()}


def test_the_leg_set_is_written_read_back_and_never_derived_from_the_name(tmp_path):
    large = preset("large").renamed("my robot")
    path = save_robot(large, tmp_path / "mine.toml")
    back = load_robot(path)
    assert back.name == "my robot" and back.leg_set == "large"
    # a leg set goes in place of the one the robot carries: Medium on Large is +10 mm, not +30
    medium = leg_set(back, "medium")
    assert medium.geometry.leg_m == pytest.approx(preset("small").geometry.leg_m + LEG_SETS["medium"].added_m,
                                                  abs=1e-12)
    assert medium.link_lengths_m() == pytest.approx(preset("medium").link_lengths_m(), abs=1e-12)
    # the name says nothing: a robot named "large" carrying small's legs stays small's
    assert leg_set(preset("small").renamed("large"), "large").geometry.leg_m == pytest.approx(0.08, abs=1e-12)


def test_a_robot_file_without_a_leg_set_or_values_starts_from_the_robot_as_built(tmp_path):
    path = tmp_path / "partial.toml"
    path.write_text('name = "partial"\n[geometry]\nbody_mass_kg = 0.006\n')
    robot = load_robot(path)
    assert robot.leg_set == "small"
    assert robot.geometry.body_mass_kg == 0.006
    assert robot.geometry.crank_start_deg == preset("small").geometry.crank_start_deg == -100.0
    path.write_text('name = "bad"\nleg_set = "huge"\n')
    with pytest.raises(ParamsError, match="leg_set = 'huge' is not a leg set"):
        load_robot(path)


def test_the_api_follows_the_one_rule(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert default_robot().preset == "small" and locust.robot() == preset("small")
    (tmp_path / "calibration").mkdir()
    save_robot(preset("medium").renamed("calibrated here"), tmp_path / ROBOT_FILE)
    assert default_robot().robot_file == ROBOT_FILE
    here = locust.robot()
    assert here.name == "calibrated here" and here.leg_set == "medium"


@pytest.mark.parametrize("where", ["empty folder", "checkout"])
def test_a_calibration_written_to_a_new_file_is_the_default_robot_with_the_fit(shared_data, tmp_path, where):
    """params, sim, calibrate servo (both real SG90 recordings) --write new.toml, params --config
    new.toml: the default robot's geometry and leg set, the fitted servo values in place."""
    cwd = tmp_path if where == "empty folder" else ROOT
    new = tmp_path / "new.toml"
    params = locust_cli("params", "--json", cwd=cwd)
    assert params.returncode == 0, params.stderr
    default = json.loads(params.stdout)
    expected = "robot: small, the robot as built" if where == "empty folder" else f"robot: {ROBOT_FILE}"
    assert params.stderr.splitlines()[0].startswith(expected)
    sim = locust_cli("sim", "--cycles", "1", "--json", cwd=cwd)
    assert sim.returncode == 0 and json.loads(sim.stdout)["robot"] == "small"
    servo = shared_data / "servo"
    fit = locust_cli("calibrate", "servo", servo / "sg90_aa_battery_step.csv", servo / "sg90_unloaded_gyro_steps.txt",
                     "--inertia-kgm2", "3.3e-6", "--inertia-kgm2", "1e-6", "--stall-torque-nm", "0.15",
                     "--write", new, "--no-plot", "--json", cwd=cwd, timeout=600)
    assert fit.returncode == 0, fit.stderr
    assert fit.stderr.splitlines()[0].startswith(expected)
    assert fit.stderr.splitlines()[0].endswith(f"the new {new} starts from it")
    fitted = json.loads(fit.stdout)
    back = locust_cli("params", "--config", new, "--json", cwd=cwd)
    assert back.returncode == 0, back.stderr
    written = json.loads(back.stdout)
    assert written["leg_set"] == default["leg_set"] == "small"
    assert {k: written["values"][k]["value"] for k in GEOMETRY} == {k: default["values"][k]["value"] for k in GEOMETRY}
    for key in SERVO_FITTED:
        assert written["values"][key]["value"] == fitted[key]["value"]
        assert written["values"][key]["source"].startswith("fit:sg90_aa_battery_step.csv")
    # the real recordings' fit (docs/servo.md): no-load speed 10.31 rad/s, kp 0.377 N*m/rad
    assert written["values"]["servo.noload_speed_rad_per_s"]["value"] == pytest.approx(10.31, abs=0.05)
    assert written["values"]["servo.kp_nm_per_rad"]["value"] == pytest.approx(0.377, abs=0.005)


@pytest.mark.parametrize("named", [[], ["--preset", "medium"]])
def test_a_command_writing_a_robot_file_says_first_which_robot_it_starts_from(tmp_path, named):
    for args in (["params", *named, "--write", "a.toml"],
                 ["measure", "nose-load", "4.2" if named else "7.4", *named, "--write", "b.toml"]):
        done = locust_cli(*args, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        first = done.stderr.splitlines()[0]
        assert first == (f"robot: medium; {args[-1]} is written from it" if named else
                         "robot: small, the robot as built (no calibration/robot.toml here; --preset or --config to "
                         "choose another)"), first
        written = load_robot(tmp_path / args[-1])
        assert written.leg_set == ("medium" if named else "small")
