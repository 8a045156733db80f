"""`locust calibrate` end to end on the shipped synthetic recordings: fit, plot, --write,
--json, Tracker exports, and clear errors (naming the file) for bad input."""

from __future__ import annotations

import json
import math
import re
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from locust.bundled import bundled_recording, bundled_recordings
from locust.calibrate.recordings import read_table
from locust.commands import cli
from locust.io.robot_toml import load_robot, to_toml
from locust.params import all_keys, preset

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture()
def recs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)      # the fit plots' default folder is the current one
    for name in ("synthetic_beam.csv", "synthetic_beam_tracker.txt", "synthetic_servo.csv", "synthetic_servo_heavy.csv",
                 "synthetic_ramp.csv", "synthetic_ramp_track.csv"):
        shutil.copy(bundled_recording(name), tmp_path / name)
    return tmp_path


def run(*args):
    res = CliRunner().invoke(cli, list(map(str, args)))
    return res


def test_recordings_are_labelled_synthetic():
    names = [n for n in bundled_recordings() if n.startswith("synthetic_") and n.endswith(".csv")]
    assert "synthetic_beam.csv" in names
    for name in names:
        table = read_table(bundled_recording(name))
        assert table.comments and "SYNTHETIC" in table.comments[0]


def test_beam_json_and_write_then_ramp_and_servo(recs):
    toml = recs / "robot.toml"
    res = run("calibrate", "beam", recs / "synthetic_beam.csv", "--mass-kg", 0.01, "--length-m", 0.05,
              "--json", "--write", toml)
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    # header truth: the seed's stiffness and damping (zeta 0.237, so only ~3 cycles ring out);
    # this recording's noise puts the fit 2.4 sigma low, still inside the 3-sigma band
    for key, truth in (("natural_frequency_hz", 7.55777), ("damping_ratio", 0.237434), ("stiffness_n_per_m", 22.55)):
        assert abs(out[key]["value"] - truth) < 3 * out[key]["std"], key
        assert out[key]["value"] == pytest.approx(truth, rel=0.04), key
    assert Path(out["plot"]).stat().st_size > 10_000
    robot = load_robot(toml)
    k = robot.get("compliance.hinge_stiffness_nm_per_rad")
    assert k == pytest.approx(0.056375, rel=0.04)
    prov = robot.source_of("compliance.hinge_stiffness_nm_per_rad")
    assert prov.source == "fit:synthetic_beam.csv" and prov.uncertainty > 0 and prov.date
    # everything not fitted is the seed's, with the seed's provenance
    seed = preset("seed")
    assert robot.get("servo.kp_nm_per_rad") == seed.get("servo.kp_nm_per_rad")
    assert robot.source_of("servo.kp_nm_per_rad").source == "fit:sg90_aa_battery_step.csv+sg90_unloaded_gyro_steps.txt"

    res = run("calibrate", "ramp", recs / "synthetic_ramp.csv", "--write", toml, "--no-plot")
    assert res.exit_code == 0, res.output
    robot = load_robot(toml)
    angles = read_table(recs / "synthetic_ramp.csv").columns["angle_deg"]
    assert robot.get("contact.foot_friction") == pytest.approx(math.tan(math.radians(angles.mean())), rel=0.01)
    assert robot.get("compliance.hinge_stiffness_nm_per_rad") == k     # kept

    res = run("calibrate", "servo", recs / "synthetic_servo.csv", "--inertia-kgm2", 1.5e-5,
              "--stall-torque-nm", 0.15, "--write", toml, "--no-plot")
    assert res.exit_code == 0, res.output
    robot = load_robot(toml)
    # header truth: the AA swing's SG90 (noload 10.2 rad/s, armature 3.1e-4 kg*m^2, kp 0.26 N*m/rad)
    assert robot.get("servo.noload_speed_rad_per_s") == pytest.approx(10.2, rel=0.01)
    assert robot.get("servo.armature_kgm2") == pytest.approx(3.1e-4, rel=0.05)
    assert robot.get("servo.kp_nm_per_rad") == pytest.approx(0.26, rel=0.05)
    assert robot.source_of("servo.armature_kgm2").source == "fit:synthetic_servo.csv"
    assert robot.source_of("servo.stall_torque_nm").source == "datasheet:SG90"    # given, not fitted
    assert robot.get("contact.foot_friction") == pytest.approx(1.7, rel=0.03)   # kept


def test_servo_two_loads_json(recs):
    res = run("calibrate", "servo", recs / "synthetic_servo.csv", recs / "synthetic_servo_heavy.csv",
              "--inertia-kgm2", 1.5e-5, "--inertia-kgm2", 1e-3, "--json", "--no-plot")
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    # header truth: stall 0.15 N*m, no-load 10.2 rad/s, delay 12 ms, clock ratio 1.002
    stall = out["servo.stall_torque_nm"]
    assert stall["value"] == pytest.approx(0.15, rel=0.02) and stall["identifiable"]
    assert out["servo.noload_speed_rad_per_s"]["value"] == pytest.approx(10.2, rel=0.01)
    assert out["command_delay_s"] == pytest.approx([0.012, 0.012], abs=0.002)
    assert out["command_clock_ratio"] == pytest.approx([1.002, 1.002], abs=3e-4)
    assert len(out["rms_per_recording"]) == 2 and out["rms_unit"] == ["deg", "deg"]

    res = run("calibrate", "servo", recs / "synthetic_servo.csv", "--inertia-kgm2", 1.5e-5, "--no-plot")
    assert res.exit_code != 0 and "stall torque is needed" in res.output
    res = run("calibrate", "servo", recs / "synthetic_servo.csv", recs / "synthetic_servo_heavy.csv",
              "--inertia-kgm2", 1.5e-5, "--inertia-kgm2", 1e-3, "--inertia-kgm2", 1e-3, "--no-plot")
    assert res.exit_code != 0 and "--inertia-kgm2 given 3 times for 2 recordings" in res.output


def test_tracker_export_gives_the_same_fit(recs):
    a = json.loads(run("calibrate", "beam", recs / "synthetic_beam.csv", "--mass-kg", 0.01, "--json",
                       "--no-plot").stdout)
    b = json.loads(run("calibrate", "beam", recs / "synthetic_beam_tracker.txt", "--mass-kg", 0.01, "--json",
                       "--no-plot").stdout)
    assert b["natural_frequency_hz"]["value"] == pytest.approx(a["natural_frequency_hz"]["value"], rel=2e-3)


def test_tracker_multi_export_with_decimal_commas(tmp_path):
    text = "#multi:\n\tcm A\t\tcm B\t\nt\tx\ty\tx\ty\n0,0\t1,5\t2,0\t3,0\t4,0\n0,1\t1,6\t\t3,1\t4,1\n"
    path = tmp_path / "multi.txt"
    path.write_text(text)
    table = read_table(path)
    assert table.markers() == ["cm_A", "cm_B"]
    x, y = table.marker("cm_A")
    assert list(x) == [1.5, 1.6] and y[0] == 2.0 and math.isnan(y[1])


def test_ramp_track_and_trials_together(recs):
    res = run("calibrate", "ramp", recs / "synthetic_ramp_track.csv", recs / "synthetic_ramp.csv", "--json",
              "--no-plot")
    out = json.loads(res.stdout)
    assert out["n_trials"] == 11
    assert out["angles_deg"][0] == pytest.approx(math.degrees(math.atan(1.7)), abs=0.6)


@pytest.mark.parametrize("content, args, message", [
    ("t_s,angle_deg\n0,1\n0.1,2\n", ["servo", "--inertia-kgm2", "1e-4"], "missing column command_deg"),
    ("frame,t_s,tip_x_m,tip_y_m\n0,0,0,0\n1,0.1,0,0.001\n", ["beam", "--mass-kg", "0.01"], "only 2 usable samples"),
    ("t_s,angle_deg,command_deg\n" + "".join(f"{i / 240},0.0,{0 if i < 10 else 90}\n" for i in range(100)),
     ["servo", "--inertia-kgm2", "1e-4"], "flat signal"),
    ("t_s,angle_deg,command_deg\n0,1,0\n0.1,abc,0\n", ["servo", "--inertia-kgm2", "1e-4"],
     "line 3: column 'angle_deg'"),
    ("trial,angle_deg\n1,59\n", ["ramp"], "need at least 2"),
])
def test_bad_input_names_the_file(tmp_path, content, args, message):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    toml = tmp_path / "robot.toml"
    res = run("calibrate", args[0], path, *args[1:], "--write", toml)
    assert res.exit_code == 2
    assert "error:" in res.output and message in res.output and "hint:" in res.output
    assert "bad.csv" in res.output   # every experiment's error names the file
    assert "Traceback" not in res.output
    assert not toml.exists()        # nothing half-written


def test_write_onto_a_robot_that_cannot_be_simulated_is_refused(recs):
    """The fit is shown, the file is left as it was (bytes), and the problem is named."""
    toml = recs / "robot.toml"
    text = to_toml(preset("seed").renamed("calibrated"))
    assert "timestep_s = {value = 0.001," in text
    toml.write_text(text.replace("timestep_s = {value = 0.001,", "timestep_s = {value = 0.5,"))
    before = toml.read_bytes()
    res = run("calibrate", "ramp", recs / "synthetic_ramp.csv", "--write", toml, "--no-plot")
    assert res.exit_code == 2, res.output
    assert "solver.timestep_s = 0.5 must be > 0 and <= 0.01" in res.output and "hint:" in res.output
    assert toml.read_bytes() == before


def test_missing_file_and_write_without_length(recs):
    res = run("calibrate", "beam", recs / "nope.csv", "--mass-kg", 0.01)
    assert res.exit_code == 2 and "nope.csv: no such file" in res.output
    res = run("calibrate", "beam", recs / "synthetic_beam.csv", "--mass-kg", 0.01, "--write", recs / "r.toml")
    assert res.exit_code == 2 and "--length-m" in res.output and not (recs / "r.toml").exists()


def test_sim_runs_with_the_written_robot(recs):
    """`locust sim --config <written robot.toml>` runs on the fitted values, on the robot every
    command runs on when told none (small, the robot as built), never the seed's design."""
    pytest.importorskip("locust.commands.sim", reason="the simulation command is not installed")
    toml = recs / "robot.toml"
    assert run("calibrate", "beam", recs / "synthetic_beam.csv", "--mass-kg", 0.01, "--length-m", 0.05,
               "--write", toml, "--no-plot").exit_code == 0
    res = run("sim", "--config", toml, "--cycles", 1, "--json")
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["robot"] == "small" and out["valid"] is True
    written, small = load_robot(toml), preset("small")
    assert written.leg_set == "small"
    # every value the robot file holds is small's but the fit's (the folds that take the film
    # hinge's values take the fitted ones with them: their own values, None, are small's)
    keys = [k for k in all_keys() if not k.startswith("compliance.")]
    assert {k: written.own(k) for k in keys} == {k: small.own(k) for k in keys}


def test_plot_never_lands_in_a_read_only_data_folder(recs, tmp_path, monkeypatch):
    """Someone else's data folder (mode r-x, as ../shared/data is) gets no file, even as root."""
    data = recs / "shared"
    data.mkdir()
    shutil.copy(recs / "synthetic_ramp.csv", data / "ramp.csv")
    data.chmod(0o555)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    try:
        res = run("calibrate", "ramp", data / "ramp.csv")
        assert res.exit_code == 0, res.output
        assert sorted(p.name for p in data.iterdir()) == ["ramp.csv"]
        assert (work / "ramp-ramp-fit.png").stat().st_size > 1000
    finally:
        data.chmod(0o755)


def test_plots_go_to_the_out_folder_named_first_never_beside_the_data(recs, tmp_path, monkeypatch):
    """A writable data folder gets no file either: the fit plot goes to --out (made), or to the
    current folder, and the first line (stderr) names that folder."""
    data = recs / "data"
    data.mkdir()
    shutil.copy(recs / "synthetic_beam.csv", data / "beam.csv")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    res = CliRunner().invoke(cli, ["calibrate", "beam", str(data / "beam.csv"), "--mass-kg", "0.01",
                                   "--out", "results/beam"])
    assert res.exit_code == 0, res.output
    assert res.stderr.splitlines()[0] == f"output folder: {work / 'results' / 'beam'}"
    assert sorted(p.name for p in data.iterdir()) == ["beam.csv"]
    assert (work / "results" / "beam" / "beam-beam-fit.png").stat().st_size > 1000
    assert f"plot: {Path('results/beam/beam-beam-fit.png')}" in res.stdout
    res = CliRunner().invoke(cli, ["calibrate", "ramp", str(recs / "synthetic_ramp.csv"), "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["plot"] == "synthetic_ramp-ramp-fit.png"     # the current folder
    assert (work / "synthetic_ramp-ramp-fit.png").is_file() and not (recs / "synthetic_ramp-ramp-fit.png").exists()


# -- calibrate hop starts from the robot its runs record ---------------------------------------
def _recorded_run(folder, preset_name=None, robot_file=None, leg=None):
    """A run.json (no track) recording which robot was hopped, as `locust hop` writes it."""
    from locust.io import run_record

    rec = run_record.RunRecord(schedule=run_record.HopSchedule(cycles=1, push_deg=-30, push_ms=300, wait_ms=1000),
                               port="sim", status=run_record.COMPLETE,
                               robot=run_record.RobotSource(preset=preset_name, robot_file=robot_file, leg_set=leg))
    folder.mkdir(parents=True)
    run_record.write(rec, folder)
    return folder


def test_calibrate_hop_starts_from_the_robot_its_runs_record(tmp_path):
    """Runs hopped with --preset small and --preset medium share the robot as built (the
    small preset, +0 cm): that is the start, said on the first line, not the seed."""
    from locust.api.calibration import robot_of_runs
    from locust.params import preset

    s = _recorded_run(tmp_path / "small-1", "small", leg="small")
    m = _recorded_run(tmp_path / "medium-1", "medium", leg="medium")
    robot, said = robot_of_runs([f"small={s}", f"medium={m}"])
    assert robot.flat() == preset("small").flat() and robot.flat() != preset("seed").flat()
    assert said.startswith("robot: small (the robot as built")
    res = CliRunner().invoke(cli, ["calibrate", "hop", f"small={s}", f"medium={m}", "--no-plot"])
    assert res.exit_code == 2
    assert res.stderr.splitlines()[0] == said            # then: no track to fit
    seed_robot, _ = robot_of_runs([f"small={_recorded_run(tmp_path / 'seed-1', 'seed', leg='small')}"])
    assert seed_robot.flat() == preset("seed").flat()


def test_calibrate_hop_refuses_runs_on_different_robots_unless_told(tmp_path):
    s = _recorded_run(tmp_path / "small-1", "small", leg="small")
    seed = _recorded_run(tmp_path / "large-1", "seed", leg="large")
    res = CliRunner().invoke(cli, ["calibrate", "hop", f"small={s}", f"large={seed}", "--no-plot"])
    assert res.exit_code == 2 and "the runs record different robots" in res.stderr, res.output
    assert "--config" in res.stderr
    told = CliRunner().invoke(cli, ["calibrate", "hop", f"small={s}", f"large={seed}", "--no-plot",
                                    "--config", str(_robot_file(tmp_path))])
    assert told.exit_code == 2 and "different robots" not in told.stderr      # on to the runs: no track
    assert told.stderr.splitlines()[0] == f"robot: {tmp_path / 'robot.toml'}"


def _robot_file(folder):
    from locust.io.robot_toml import save_robot
    from locust.params import preset

    return save_robot(preset("small"), folder / "robot.toml")


# -- what `locust calibrate` prints for a person -----------------------------------------------
def test_fitted_values_print_with_units_and_four_figures():
    """`k  5.587e-2  N·m/rad  ± 1.0 %  (95 %: ... … ...)`: the JSON's own value to 4 figures, its
    unit in a column (N·m, never nm), one sd as a share of the value, the 95 % interval; no
    Python lists or 12-digit floats."""
    args = ["calibrate", "beam", str(bundled_recording("synthetic_beam.csv")), "--mass-kg", "0.01",
            "--length-m", "0.05", "--no-plot"]
    text = CliRunner().invoke(cli, args).stdout
    fit = json.loads(CliRunner().invoke(cli, [*args, "--json"]).stdout)
    for key, unit in (("compliance.hinge_stiffness_nm_per_rad", "N·m/rad"),
                      ("compliance.hinge_damping_nms_per_rad", "N·m·s/rad"), ("natural_frequency_hz", "Hz")):
        v = fit[key]
        line = next(ln for ln in text.splitlines() if ln.split()[0] == key.split("_n")[0].split("_hz")[0])
        m = re.fullmatch(r"(\S+)\s+(\S+)\s+(\S+)\s+± (\S+) %\s+\(95 %: (\S+) … (\S+)\)", line)
        assert m, line
        assert m.group(3) == unit
        assert float(m.group(2)) == pytest.approx(v["value"], rel=5e-4)
        assert float(m.group(4)) == pytest.approx(100 * v["std"] / v["value"], abs=0.051)
        assert [float(m.group(5)), float(m.group(6))] == pytest.approx(v["ci95"], rel=5e-4)
    assert "[" not in text and "'" not in text and not re.search(r"\d\.\d{6,}", text)


def test_the_hinge_interval_is_flagged_where_its_residual_is_model_error(shared_data):
    """docs/calibrate.md: on Damping_test.trk the residual (0.8 mm RMS) is model error, so the
    intervals computed for independent errors are too narrow: the printed line says so."""
    res = CliRunner().invoke(cli, ["calibrate", "hinge", str(shared_data / "hinge" / "Damping_test.trk"),
                                   "--inertia-kgm2", "8.5e-7", "--gravity", "out-of-plane", "--coulomb", "off",
                                   "--no-plot"])
    assert res.exit_code == 0, res.output
    flagged = [ln for ln in res.stdout.splitlines() if "TOO NARROW" in ln]
    assert [ln.split()[0] for ln in flagged] == ["compliance.hinge_stiffness", "compliance.hinge_damping"]
    assert "0.79 mm RMS" in flagged[0]


def test_two_experiments_on_one_recording_keep_both_plots(shared_data, tmp_path, monkeypatch):
    """The rubber pendulum fitted as a beam, then as a hinge (both fit it): each experiment
    draws its own `<recording>-<experiment>-fit.png`, and the hinge fit leaves the beam's plot as
    it was (both were `<recording>-fit.png`: the second replaced the first)."""
    monkeypatch.chdir(tmp_path)
    rec = shared_data / "hinge" / "pendulum_rubber_60fps_m.csv"
    beam = CliRunner().invoke(cli, ["calibrate", "beam", str(rec), "--mass-kg", "0.0295", "--json"])
    assert beam.exit_code == 0, beam.output
    assert json.loads(beam.stdout)["plot"] == "pendulum_rubber_60fps_m-beam-fit.png"
    drawn = (tmp_path / "pendulum_rubber_60fps_m-beam-fit.png").read_bytes()
    hinge = CliRunner().invoke(cli, ["calibrate", "hinge", str(rec), "--inertia-kgm2", "1e-4", "--gravity",
                                     "out-of-plane", "--json"])
    assert hinge.exit_code == 0, hinge.output
    assert json.loads(hinge.stdout)["plot"] == "pendulum_rubber_60fps_m-hinge-fit.png"
    assert (tmp_path / "pendulum_rubber_60fps_m-beam-fit.png").read_bytes() == drawn
    assert (tmp_path / "pendulum_rubber_60fps_m-hinge-fit.png").stat().st_size > 10_000


# -- one job behind both doors ------------------------------------------------------------------
def test_the_command_and_the_api_run_the_same_job(recs, monkeypatch):
    """Each experiment's work is one function of locust.calibrate.jobs, which `locust calibrate`
    and locust.calibrate_* both call: each door calls it once, and both give the same figures
    (the beam's hinge stiffness within 4 % of its header's 0.056375 N*m/rad, the ramp's interval
    holding its header's friction 1.7); a hop fit's empty run folder is refused in it for both."""
    import locust
    from locust.calibrate import jobs
    from locust.errors import LocustError

    calls = []

    def counted(name):
        job = getattr(jobs, name)
        return lambda *args, **kwargs: calls.append(name) or job(*args, **kwargs)

    for name in ("beam", "ramp", "hops"):
        monkeypatch.setattr(jobs, name, counted(name))
    key = "compliance.hinge_stiffness_nm_per_rad"
    cli_beam = json.loads(run("calibrate", "beam", recs / "synthetic_beam.csv", "--mass-kg", 0.01, "--length-m", 0.05,
                              "--json", "--no-plot").stdout)[key]
    api_beam = locust.calibrate_beam(recs / "synthetic_beam.csv", 0.01, length_m=0.05).parameters[key]
    assert (cli_beam["value"], cli_beam["std"], cli_beam["ci95"]) == (api_beam.value, api_beam.std, list(api_beam.ci95))
    assert api_beam.value == pytest.approx(0.056375, rel=0.04)
    key = "contact.foot_friction"
    cli_ramp = json.loads(run("calibrate", "ramp", recs / "synthetic_ramp.csv", "--json", "--no-plot").stdout)[key]
    api_ramp = locust.calibrate_ramp(recs / "synthetic_ramp.csv").parameters[key]
    assert (cli_ramp["value"], cli_ramp["ci95"]) == (api_ramp.value, list(api_ramp.ci95))
    assert api_ramp.ci95[0] <= 1.7 <= api_ramp.ci95[1]
    (recs / "small-1").mkdir()
    refused = run("calibrate", "hop", "small=small-1", "--no-plot")
    assert refused.exit_code == 2 and "no run.json" in refused.output
    with pytest.raises(LocustError, match="no run.json"):
        locust.calibrate_hops(locust.robot("seed"), {"small": recs / "small-1"})
    assert calls == ["beam", "beam", "ramp", "ramp", "hops", "hops"]
