"""Every writer of a robot.toml writes TOML that reads back, keeps the user's comments, and
loses no update when two processes write one file at once.

The strings written are generated: every control character, quotes, backslashes, newlines,
non-ASCII text and a file name's undecodable byte (a lone surrogate)."""

from __future__ import annotations

import os
import random
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from click.testing import CliRunner

from locust.bundled import bundled_recording
from locust.calibrate.fitstats import Estimate
from locust.calibrate.write import write_fitted
from locust.commands import cli
from locust.errors import WriteError
from locust.fileio import storable
from locust.io.robot_toml import load_robot, save_robot, update_robot
from locust.params import Provenance, parse_set_options, preset

ROOT = Path(__file__).resolve().parents[1]
RAMP = bundled_recording("synthetic_ramp.csv")
NASTY = [chr(c) for c in range(0x20)] + ["\x7f", '"', "'", "\\", '\\"', '"""', "'''", "\n\n", "\r\n", "é",
                                          "日本", "\u2028", "\ufeff", "\U0001f600", "\udcff", "\udc80", "#", "=",
                                          "[x]", "{", "}"]


def nasty_strings(seed: int, n: int = 8) -> list[str]:
    """Strings made of the characters TOML must escape and of plain text, mixed at random."""
    rng = random.Random(seed)
    return ["".join(rng.choice(NASTY + ["a", "b", " ", "1"]) for _ in range(rng.randint(1, 12))) for _ in range(n)]


def test_every_character_is_covered():
    # the generator reaches every control character, DEL and a lone surrogate
    seen = set("".join(s for seed in range(40) for s in nasty_strings(seed)))
    assert {chr(c) for c in range(0x20)} | {"\x7f", "\udcff", '"', "\\", "\n"} <= seen


@pytest.mark.parametrize("seed", range(40))
def test_save_robot_reads_back_every_string(tmp_path, seed):
    name, source, note, date, _, _, _, _ = nasty_strings(seed)
    robot = preset("small").renamed(name).with_values(
        {"servo.kp_nm_per_rad": 0.3, "solver.integrator": "rk4"},
        Provenance(source=source, uncertainty=0.01, date=date, note=note))
    path = save_robot(robot, tmp_path / "r.toml")
    back = load_robot(path)
    assert back.name == storable(name)
    assert back.flat() == robot.flat()
    for key in ("servo.kp_nm_per_rad", "solver.integrator"):
        assert back.source_of(key) == Provenance(storable(source), 0.01, storable(date), storable(note))


@pytest.mark.parametrize("seed", range(10))
def test_write_fitted_reads_back_every_recording_name(tmp_path, seed):
    path = tmp_path / "robot.toml"
    path.write_text('# my robot: keep this line\nname = "mine"  # and this one\n\n[contact]\n'
                    '# measured on the desk\nfoot_friction = { value = 1.1, source = "estimate:desk" }\n')
    for k, text in enumerate(nasty_strings(seed, 3)):
        write_fitted(path, {"contact.nose_friction": Estimate(0.5 + k / 10, 0.01, 0.48, 0.52)}, f"rec{text}.csv",
                     note=text)
        back = load_robot(path)
        assert back.get("contact.nose_friction") == 0.5 + k / 10
        assert back.source_of("contact.nose_friction").source == storable(f"fit:rec{text}.csv")
        assert back.get("contact.foot_friction") == 1.1
    kept = path.read_text()
    assert "# my robot: keep this line" in kept and "# and this one" in kept and "# measured on the desk" in kept


@pytest.mark.parametrize("seed", range(6))
def test_params_set_write_reads_back_every_string(tmp_path, seed):
    """`params --set solver.integrator=<text> --write`: the text reads back as it was typed."""
    for k, text in enumerate(nasty_strings(seed, 4)):
        out = tmp_path / f"new{k}.toml"
        res = CliRunner().invoke(cli, ["params", "--preset", "small", "--set", f"solver.integrator={text}",
                                       "--write", str(out)])
        assert res.exit_code == 0, res.output
        typed = parse_set_options([f"solver.integrator={text}"])["solver.integrator"]   # (spaces stripped)
        assert load_robot(out).get("solver.integrator") == storable(typed)


def test_params_write_keeps_comments_of_the_config(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text('# the robot on my desk\nbase = "small"\nname = "desk"\n\n[servo]\n'
                    'kp_nm_per_rad = { value = 0.3, source = "override" }   # tuned by hand\n')
    res = CliRunner().invoke(cli, ["params", "--config", str(path), "--set", "servo.kv_nms_per_rad=0.002",
                                   "--write", str(path), "--force"])
    assert res.exit_code == 0, res.output
    text = path.read_text()
    assert "# the robot on my desk" in text and "# tuned by hand" in text
    back = load_robot(path)
    assert back.get("servo.kv_nms_per_rad") == 0.002 and back.get("servo.kp_nm_per_rad") == 0.3


def test_calibrate_write_after_a_robot_file_with_escapes_reads_back(tmp_path):
    """A note with a newline escape, then `calibrate ramp --write`: the file reads back."""
    path = tmp_path / "r.toml"
    path.write_text('# mine\nname = "r"\n[geometry]\n'
                    'leg_m = { value = 0.06, source = "seed", note = "x\\ny\\u0001\\u007f" }\n')
    res = CliRunner().invoke(cli, ["calibrate", "ramp", str(RAMP), "--write", str(path), "--no-plot"])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(cli, ["params", "--config", str(path), "--json"])
    assert res.exit_code == 0, res.output
    assert load_robot(path).source_of("geometry.leg_m").note == "x\ny\x01\x7f"
    assert "# mine" in path.read_text()


def test_a_write_that_does_not_read_back_keeps_the_old_file(tmp_path, monkeypatch):
    import locust.io.robot_toml as robot_toml

    path = tmp_path / "r.toml"
    save_robot(preset("seed"), path)
    before = path.read_bytes()
    monkeypatch.setattr(robot_toml, "to_toml", lambda robot, template=None: 'name = "x\n"\n')   # not TOML
    with pytest.raises(robot_toml.ParamsError, match="does not read back"):
        save_robot(preset("small"), path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["r.toml"]   # no temporary left


def test_a_new_file_is_created_exclusively(tmp_path):
    path = tmp_path / "new.toml"
    save_robot(preset("seed"), path, exclusive=True)
    before = path.read_bytes()
    with pytest.raises(WriteError, match="exists"):
        save_robot(preset("small"), path, exclusive=True)
    assert path.read_bytes() == before


COUNTER = textwrap.dedent("""
    import sys
    from locust.params import Provenance
    from locust.io.robot_toml import update_robot
    path, who = sys.argv[1], sys.argv[2]

    def bump(robot):   # a read-modify-write: a lost update loses a count
        prov = robot.source_of("geometry.leg_m")
        n = int(prov.note) if prov.source == "estimate:count" else 0
        robot = robot.with_values({"geometry.leg_m": robot.get("geometry.leg_m")},
                                  Provenance("estimate:count", note=str(n + 1)))
        return robot.with_values({f"contact.{who}_friction": 1.0 + n / 100}, Provenance(f"estimate:{who}"))

    for _ in range(20):
        update_robot(path, bump)
""")


def test_two_processes_updating_one_file_lose_no_update(tmp_path):
    path = tmp_path / "robot.toml"
    save_robot(preset("seed"), path)
    procs = [subprocess.Popen([sys.executable, "-c", COUNTER, str(path), who]) for who in ("foot", "nose")]
    assert [p.wait(timeout=120) for p in procs] == [0, 0]
    robot = load_robot(path)
    assert robot.source_of("geometry.leg_m").note == "40"   # 20 + 20 updates, none lost
    assert robot.source_of("contact.foot_friction").source == "estimate:foot"
    assert robot.source_of("contact.nose_friction").source == "estimate:nose"


def test_update_robot_waits_for_the_lock_then_says_who_holds_it(tmp_path):
    from locust.fileio import locked

    path = tmp_path / "robot.toml"
    save_robot(preset("seed"), path)
    with locked(path):
        with pytest.raises(WriteError, match="being updated by another process"):
            update_robot(path, lambda r: r, wait_s=0.3)


@pytest.mark.slow
def test_two_concurrent_calibrate_writes_both_land_20_of_20(tmp_path):
    """Two writers at once, 20 times: `calibrate ramp --into foot` and `--into nose` onto
    one file at once; both fitted values are in it every time (about 90 s)."""
    landed = 0
    for k in range(20):
        path = tmp_path / f"same{k}.toml"
        procs = [subprocess.Popen([sys.executable, "-c", "from locust.commands import main; main()",
                                   "calibrate", "ramp",
                                   str(RAMP), "--into", into, "--write", str(path), "--no-plot"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) for into in ("foot", "nose")]
        assert [p.wait(timeout=120) for p in procs] == [0, 0]
        robot = load_robot(path)
        landed += all(robot.source_of(f"contact.{x}_friction").source == "fit:synthetic_ramp.csv"
                      for x in ("foot", "nose"))
    assert landed == 20


def test_a_recording_named_with_an_undecodable_byte_is_written_and_plotted(tmp_path):
    """`ramp\\xff.csv`: --write raised UnicodeEncodeError, and the default plot a matplotlib traceback."""
    name = os.fsdecode(b"ramp\xff.csv")
    shutil.copy(RAMP, tmp_path / name)
    res = subprocess.run([sys.executable, "-c", "from locust.commands import main; main()", "calibrate", "ramp",
                          str(tmp_path / name), "--write", str(tmp_path / "r.toml"), "--out", str(tmp_path)],
                         capture_output=True, timeout=120)
    assert res.returncode == 0 and b"Traceback" not in res.stderr, res.stderr[-3000:]
    assert (tmp_path / os.fsdecode(b"ramp\xff-ramp-fit.png")).stat().st_size > 10_000
    assert load_robot(tmp_path / "r.toml").source_of("contact.foot_friction").source == "fit:ramp\\udcff.csv"
