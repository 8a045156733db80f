"""The board's config read back and changed without flashing (``locust config``), recorded in
run.json with the robot and leg set hopped; a corrupt config.json is never a "complete" run.

Run against the virtual robot: the real firmware under MicroPython's unix port, its
config.json in the virtual flash folder."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from locust.firmware import config as fw_config
from locust.io import run_record
from locust.io.robot_toml import save_robot
from locust.params import preset
from locust.trials.measured import config_of
from probing import assert_refused_and_unchanged, tree

LOCUST = [sys.executable, "-m", "locust.commands"]
QUICK = ["--cycles", "1", "--push-ms", "50", "--wait-ms", "50", "--plant", "record"]


def _run(args, env, timeout=90, cwd=None):
    return subprocess.run(LOCUST + [str(a) for a in args], capture_output=True, text=True, env=env, timeout=timeout,
                          cwd=cwd)


@pytest.fixture()
def flash_config(env):
    """The virtual board's config.json; put back as flashed after the test."""
    path = Path(env["LOCUST_VIRTUAL_DIR"]) / "flash" / fw_config.FILE
    saved = path.read_bytes()
    yield path
    path.write_bytes(saved)


def test_config_reads_the_board_back_and_sets_a_trim_without_flashing(env, flash_config, tmp_path):
    flash = flash_config.parent
    firmware = {p.name: p.read_bytes() for p in flash.iterdir() if p.name != fw_config.FILE}
    shown = _run(["config", "--port", "sim", "--json"], env)
    assert shown.returncode == 0, shown.stderr
    board = run_record.board_config(json.loads(shown.stdout))
    assert (board.chip, board.left.pin, board.right.pin) == ("esp32", 18, 19)      # the ESP32's default pins
    assert (board.left.trim_deg, board.right.direction, board.problems) == (0.0, -1, ())

    changed = _run(["config", "--port", "sim", "--set", "right.trim_deg=-2.5", "--set", "left.trim_deg=1.25"], env)
    assert changed.returncode == 0, changed.stderr
    assert "set right.trim_deg = -2.5" in changed.stderr and "config.json: in use" in changed.stdout
    saved = json.loads(flash_config.read_text())
    assert (saved["left"]["trim_deg"], saved["right"]["trim_deg"]) == (1.25, -2.5)
    # only config.json changed: no firmware file was written
    assert {p.name: p.read_bytes() for p in flash.iterdir() if p.name != fw_config.FILE} == firmware

    # a hop records the pins and trims read from the board, and the robot and leg set hopped
    out = tmp_path / "run"            # a folder name that names no leg set
    hop = _run(["hop", "--port", "sim", *QUICK, "--preset", "seed", "--leg-set", "Large", "--out", out], env)
    assert hop.returncode == 0, hop.stderr
    rec = run_record.read_run_record(out / run_record.RECORD_NAME)
    assert rec.status == run_record.COMPLETE
    assert rec.robot == run_record.RobotSource(preset="seed", robot_file=None, leg_set="large")
    assert (rec.board.left.pin, rec.board.left.trim_deg, rec.board.right.trim_deg) == (18, 1.25, -2.5)
    # the report takes the configuration from the record, not the folder's name
    assert config_of(out) == ("large", "run record")
    assert config_of(out / run_record.RECORD_NAME) == ("large", "run record")


def test_a_preset_leg_set_is_recorded_and_a_contradicting_leg_set_refused(env, tmp_path):
    out = tmp_path / "trial-7"
    hop = _run(["hop", "--port", "sim", *QUICK, "--preset", "medium", "--out", out], env)
    assert hop.returncode == 0, hop.stderr
    assert run_record.read_run_record(out / run_record.RECORD_NAME).robot == run_record.RobotSource(
        "medium", None, "medium")
    assert config_of(out) == ("medium", "run record")
    assert_refused_and_unchanged(tmp_path, ["hop", "--port", "sim", "--preset", "small", "--leg-set", "large",
                                            "--out", tmp_path / "x"], "contradicts --preset small")
    assert_refused_and_unchanged(tmp_path, ["hop", "--port", "sim", "--leg-set", "big legs!",
                                            "--out", tmp_path / "x"], "not a plain name")


def test_the_default_robot_is_the_one_as_built_or_the_calibrated_one_here(env, tmp_path):
    """No --preset or --config: the robot as built (small) where the current folder has no
    calibration/robot.toml, that file where it has one; the line after the output folder says
    which, and the record names the leg set the robot carries (the file's own, not its name's)."""
    hop = _run(["hop", "--port", "sim", *QUICK, "--out", tmp_path / "a"], env, cwd=tmp_path)
    assert hop.returncode == 0, hop.stderr
    assert hop.stderr.splitlines()[0] == f"output folder: {tmp_path / 'a'}"   # then which robot
    assert hop.stderr.splitlines()[1].startswith("robot: small, the robot as built")
    assert run_record.read_run_record(tmp_path / "a" / run_record.RECORD_NAME).robot == run_record.RobotSource(
        "small", None, "small")
    (tmp_path / "calibration").mkdir()
    save_robot(preset("large").renamed("mine"), tmp_path / "calibration" / "robot.toml")
    hop = _run(["hop", "--port", "sim", *QUICK, "--out", tmp_path / "b"], env, cwd=tmp_path)
    assert hop.returncode == 0, hop.stderr
    assert hop.stderr.splitlines()[1].startswith("robot: calibration/robot.toml")
    assert run_record.read_run_record(tmp_path / "b" / run_record.RECORD_NAME).robot == run_record.RobotSource(
        None, "calibration/robot.toml", "large")
    sim = _run(["sim", "--cycles", "1", "--json"], env, cwd=tmp_path)
    assert sim.stderr.splitlines()[0].startswith("robot: calibration/robot.toml")
    assert json.loads(sim.stdout)["robot"] == "mine"


def test_a_missing_trial_folder_is_no_such_folder_not_an_unknown_configuration(tmp_path):
    assert_refused_and_unchanged(tmp_path, ["report", "--measured", tmp_path / "runs" / "small-1",
                                            "--out", tmp_path / "rep"], "runs/small-1: no such file or folder")
    assert_refused_and_unchanged(tmp_path, ["calibrate", "hop", tmp_path / "gone"], "gone: no such file or folder")


def test_a_value_the_board_refuses_changes_nothing(env, flash_config):
    before = tree(flash_config.parent)
    res = _run(["config", "--port", "sim", "--set", "left.trim_deg=40"], env)   # limits: -30..30
    assert res.returncode == 2 and "error:" in res.stderr and "hint:" in res.stderr and "Traceback" not in res.stderr
    assert "left.trim_deg=40.0 outside -30..30" in res.stderr
    assert tree(flash_config.parent) == before
    assert_refused_and_unchanged(flash_config.parent, ["config", "--port", "sim", "--set", "left.trim_deg=two"],
                                 "--set 'left.trim_deg=two' is not KEY=NUMBER")


def test_a_corrupt_board_config_is_recorded_and_never_complete(env, flash_config, tmp_path):
    """The firmware falls back to its defaults and says why (hello's config_problems); the hop
    records that, its status is default_config, the command exits 2 and says how to fix it;
    `locust config --set` writes a valid config.json and the next hop is complete."""
    flash_config.write_text('{"left": {"pin": 18, "trim')          # torn mid-write
    out = tmp_path / "small-1"
    hop = _run(["hop", "--port", "sim", *QUICK, "--out", out], env)
    assert hop.returncode == 2, hop.stderr
    assert "error: every phase ran, but the board ran on its default config" in hop.stderr
    assert "hint:" in hop.stderr and "locust config --port PORT --set" in hop.stderr and "Traceback" not in hop.stderr
    rec = run_record.read_run_record(out / run_record.RECORD_NAME)
    assert rec.status == run_record.DEFAULT_CONFIG and len(rec.phases) == 2
    assert rec.board.problems == ("config.json is not valid JSON; using defaults",)

    reflashed = _run(["flash", "--port", "sim"], env)        # keeps the board's config.json, and says it is unused
    assert reflashed.returncode == 0, reflashed.stderr
    assert "warning: the board runs on its default config: config.json is not valid JSON" in reflashed.stderr
    assert "fix: write a valid config: `locust config --port PORT --set" in reflashed.stderr
    shown = _run(["config", "--port", "sim"], env)
    assert shown.returncode == 0 and "NOT in use" in shown.stdout and "not valid JSON" in shown.stderr
    fixed = _run(["config", "--port", "sim", "--set", "left.trim_deg=0"], env)
    assert fixed.returncode == 0 and "config.json: in use" in fixed.stdout, fixed.stderr
    assert fw_config.problems(json.loads(flash_config.read_text()), "esp32") == []
    again = _run(["hop", "--port", "sim", *QUICK, "--out", tmp_path / "small-2"], env)
    assert again.returncode == 0, again.stderr
    assert run_record.read_run_record(tmp_path / "small-2" / run_record.RECORD_NAME).status == run_record.COMPLETE


def test_robot_and_board_read_back_equal_and_a_damaged_board_entry_is_named(tmp_path):
    servo = dict(fw_config.default()["left"], trim_deg=2.5)
    board = run_record.board_config({"chip": "s3", "machine": "Generic ESP32S3 module with ESP32S3", "left": servo,
                                     "right": fw_config.default()["right"],
                                     "config_problems": ["config.json is not valid JSON"]})
    rec = run_record.RunRecord(schedule=run_record.HopSchedule(cycles=1), port="/dev/ttyACM0",
                               status=run_record.DEFAULT_CONFIG,
                               robot=run_record.RobotSource(None, "calibration/robot.toml", "v2"), board=board)
    path = run_record.write(rec, tmp_path)
    assert run_record.read_run_record(path) == rec and run_record.read_run_record(path).board.on_defaults
    doc = json.loads(path.read_text())
    doc["board"]["left"]["pin"] = "eighteen"
    path.write_text(json.dumps(doc))
    with pytest.raises(run_record.DeviceError, match="board left.pin is missing or not a number"):
        run_record.read_run_record(path)
    del doc["board"], doc["robot"]                # a record from before they were recorded
    path.write_text(json.dumps(doc))
    back = run_record.read_run_record(path)
    assert back.robot == run_record.RobotSource() and back.board is None


def test_every_torn_or_out_of_limits_config_is_reported_and_never_used(tmp_path):
    """The firmware's own loader (the host imports the same file): every prefix of a valid
    config.json (a write torn at any byte), every key pushed past its limit either way and
    every key given a boolean or a string is refused with a reason naming it, and the board
    runs on the chip's default config; the valid file itself is used as it is."""
    path = tmp_path / fw_config.FILE
    good = dict(fw_config.default("esp32"), left=dict(fw_config.default("esp32")["left"], trim_deg=2.5))
    text = json.dumps(good)
    path.write_text(text)
    assert fw_config.load(str(path), "esp32") == (good, [])
    for cut in range(len(text)):
        path.write_text(text[:cut])
        cfg, problems = fw_config.load(str(path), "esp32")
        assert cfg == fw_config.default("esp32") and problems, cut
    cases = 0
    for name in fw_config.SERVOS:
        for key, (lo, hi, whole) in fw_config.LIMITS.items():
            step = 1 if whole else 0.5
            for bad in (lo - step, hi + step, True, "1"):
                path.write_text(json.dumps(dict(good, **{name: dict(good[name], **{key: bad})})))
                cfg, problems = fw_config.load(str(path), "esp32")
                assert cfg == fw_config.default("esp32"), (name, key, bad)
                assert any(f"{name}.{key}" in p for p in problems), (name, key, bad, problems)
                cases += 1
    assert cases == 2 * len(fw_config.LIMITS) * 4
