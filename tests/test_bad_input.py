"""Bad input, faults and load, as a hostile new user tries them: every case is a clear
``error:`` with a ``hint:``, exit 2, no traceback, and no file changed (bytes and mode) or
left behind.

One parametrised case per probe class; the commands run in this process through the
``locust`` click group (as the console script does), in a fresh folder each. Faults that
need a process of their own (a full disk, kill -9, a killed hop) run in subprocesses.
"""

from __future__ import annotations

import json
import math
import os
import resource
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from locust.bundled import bundled_recording
from locust.fab.dxf_limits import MAX_ARC_SEGMENTS
from locust.io import run_record
from locust.params import LIMITS, MAX_SIM_STEPS, check_robot, preset, problems
from probing import assert_clear_error, assert_refused_and_unchanged, invoke, tree
from waiting import wait_for

LOCUST = [sys.executable, "-m", "locust.commands"]


# -- inputs the cases use ------------------------------------------------------------
def robot_toml(d: Path, text: str, name: str = "robot.toml") -> Path:
    p = d / name
    p.write_text(text)
    return p


def dxf(d: Path, name: str, body, holes=(), slits=()) -> Path:
    import ezdxf

    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4   # mm
    msp = doc.modelspace()
    msp.add_lwpolyline(body, close=True, dxfattribs={"layer": "plate"})
    for centre, r in holes:
        msp.add_circle(centre, r, dxfattribs={"layer": "holes"})
    for a, b in slits:
        msp.add_line(a, b, dxfattribs={"layer": "cuts"})
    doc.saveas(d / name)
    return d / name


RECT = [(0, 0), (50, 0), (50, 30), (0, 30)]
SERVO_CSV = bundled_recording("synthetic_servo.csv")
BEAM_CSV = bundled_recording("synthetic_beam.csv")


def trial(d: Path, status: str = run_record.COMPLETE, cycles: int = 2) -> Path:
    """A measured trial: a staircase nose track (synthetic) and its run record."""
    folder = d / "small-1"
    folder.mkdir()
    rows = ["frame,t_s,nose_x_m,nose_y_m"]
    for i in range(90):
        t = i / 30
        rows.append(f"{i},{t:.6f},{0.1 + 0.02 * min(int(t / 1.3), cycles):.6f},0.05")
    (folder / "hop.tracks.csv").write_text("\n".join(rows) + "\n")
    sched = run_record.HopSchedule(cycles=cycles, push_deg=-30.0, push_ms=300, wait_ms=1000)
    rec = run_record.RunRecord(schedule=sched, port="/dev/ttyUSB0", status=status,
                               message="out_of_range: push_deg" if status == run_record.ERROR else None)
    run_record.write(rec, folder)
    return folder


def copy_servo(d: Path) -> Path:
    p = d / "servo.csv"
    p.write_bytes(SERVO_CSV.read_bytes())
    return p


def copy_beam(d: Path) -> Path:
    p = d / "beam.csv"
    p.write_bytes(BEAM_CSV.read_bytes())
    return p


def readonly(d: Path, name: str = "robot.toml") -> Path:
    p = d / name
    p.write_text("# mine\n")
    p.chmod(0o444)
    return p


def user_trials(d: Path) -> Path:
    (d / "opt").mkdir()
    (d / "opt" / "trials.csv").write_text("trial,score\n1,0.5\n")
    return d / "opt"


# (id, setup(d) -> args, words the error must hold)
S = "--set"
CASES = [
    # parameter edges: nothing unsimulatable reaches MuJoCo, nothing absurd is simulated as valid
    ("timestep-0", lambda d: ["sim", S, "solver.timestep_s=0"], ["solver.timestep_s"]),
    ("timestep-negative", lambda d: ["sim", S, "solver.timestep_s=-1e-3"], ["solver.timestep_s"]),
    ("timestep-huge", lambda d: ["sim", S, "solver.timestep_s=1"], ["solver.timestep_s"]),
    ("timestep-nan", lambda d: ["sim", S, "solver.timestep_s=nan"], ["solver.timestep_s"]),
    ("control-hz-0", lambda d: ["sim", S, "solver.control_hz=0"], ["solver.control_hz"]),
    ("control-hz-beyond-step", lambda d: ["sim", S, "solver.control_hz=1e6"], ["faster than one command"]),
    ("wait-negative", lambda d: ["sim", S, "schedule.wait_s=-1"], ["schedule.wait_s"]),
    ("settle-negative", lambda d: ["sim", S, "solver.settle_s=-1"], ["solver.settle_s"]),
    ("cycles-0", lambda d: ["sim", S, "schedule.cycles=0"], ["schedule.cycles"]),
    ("cycles-fraction", lambda d: ["sim", S, "schedule.cycles=1.5"], ["schedule.cycles"]),
    ("push-s-1e9", lambda d: ["sim", S, "schedule.push_s=1e9"], ["schedule.push_s"]),
    ("push-deg-beyond-firmware", lambda d: ["sim", S, "schedule.push_deg=-120"], ["schedule.push_deg", "-90"]),
    ("push-deg-beyond-travel", lambda d: ["sim", S, "schedule.push_deg=-60"], ["servo travel"]),
    ("foot-friction-negative", lambda d: ["sim", S, "contact.foot_friction=-1"], ["contact.foot_friction"]),
    ("nose-friction-negative", lambda d: ["sim", S, "contact.nose_friction=-0.1"], ["contact.nose_friction"]),
    ("kp-negative", lambda d: ["sim", S, "servo.kp_nm_per_rad=-1"], ["servo.kp_nm_per_rad"]),
    ("kv-negative", lambda d: ["sim", S, "servo.kv_nms_per_rad=-1"], ["servo.kv_nms_per_rad"]),
    ("stall-torque-0", lambda d: ["sim", S, "servo.stall_torque_nm=0"], ["servo.stall_torque_nm"]),
    ("iterations-0", lambda d: ["sim", S, "solver.iterations=0"], ["solver.iterations"]),
    ("leg-length-0", lambda d: ["sim", S, "geometry.leg_m=0"], ["geometry.leg_m"]),
    ("body-mass-negative", lambda d: ["sim", S, "geometry.body_mass_kg=-0.05"], ["geometry.body_mass_kg"]),
    ("loop-impedance-1", lambda d: ["sim", S, "solver.loop_dmin=1"], ["solver.loop_dmin"]),
    ("pulses-swapped", lambda d: ["sim", S, "servo.pulse_min_us=2600"], ["pulse_min_us"]),
    ("step-budget", lambda d: ["sim", S, "schedule.wait_s=60", "--cycles", "1000"], ["physics steps"]),
    ("config-file-bad-value", lambda d: ["sim", "--config", robot_toml(d, "[schedule]\nwait_s = -1\n")],
     ["schedule.wait_s"]),
    ("sweep-base-bad", lambda d: ["sweep", S, "schedule.push_s=1e9", "--vary", "scale=0:0.01:2", "--out", d / "sw"],
     ["schedule.push_s"]),
    ("params-write-refuses-what-sim-refuses",
     lambda d: ["params", S, "solver.timestep_s=0", "--write", d / "new.toml"], ["solver.timestep_s"]),
    ("params-unknown-key", lambda d: ["params", S, "solver.timestep=0.001"], ["unknown robot parameter"]),
    # writes never destroy
    ("write-read-only-file", lambda d: ["params", "--write", readonly(d), "--force"], ["read-only"]),
    ("write-existing-file", lambda d: ["params", "--write", robot_toml(d, "# mine\n")], ["exists"]),
    # (a pipe stands in for a device: a regression must not replace the machine's /dev/null)
    ("write-pipe", lambda d: ["params", "--write", os.mkfifo(d / "pipe") or d / "pipe", "--force"],
     ["not a regular file"]),
    ("write-onto-folder", lambda d: ["params", "--write", (d / "folder").mkdir() or d / "folder", "--force"],
     ["directory"]),
    # sweeps and optimisation
    ("sweep-grid-too-large",
     lambda d: ["sweep", "--vary", "scale=0:0.05:1000000", "--vary", "geometry.leg_m=0.05:0.09:1000000",
                "--out", d / "sw"], ["1,000,000,000,000 designs"]),
    ("sweep-n-0", lambda d: ["sweep", "--vary", "scale=0:0.05:0", "--out", d / "sw"], ["N = 0"]),
    ("sweep-not-a-number", lambda d: ["sweep", "--vary", "scale=0:x:3", "--out", d / "sw"], ["not a number"]),
    ("sweep-foreign-folder", lambda d: ["sweep", "--vary", "scale=0:0.01:2", "--out", user_trials(d)],
     ["not a sweep folder"]),
    ("optimize-user-trials-csv", lambda d: ["optimize", "--vary", "geometry.leg_m=0.05:0.07", "--trials", "1",
                                            "--out", user_trials(d)], ["did not write", "trials.csv"]),
    ("optimize-bogus-storage", lambda d: ["optimize", "--vary", "geometry.leg_m=0.05:0.07", "--trials", "1",
                                          "--out", d / "o", "--storage", "bogus://x"], ["bogus://x"]),
    ("optimize-integer-without-integer", lambda d: ["optimize", "--vary", "solver.iterations=1.2:1.8", "--trials",
                                                    "1", "--out", d / "o"], ["no whole number"]),
    # fabrication
    ("fab-jig-diameter-0", lambda d: ["fab", "--from-robot", "seed", "--jig-diameter-mm", "0"], ["jig_diameter_mm"]),
    ("fab-jig-spacing-inf", lambda d: ["fab", "--from-robot", "seed", "--jig-spacing-mm", "inf"], ["finite"]),
    ("fab-kerf-nan", lambda d: ["fab", "--from-robot", "seed", "--kerf-mm", "nan"], ["finite"]),
    ("fab-kerf-negative", lambda d: ["fab", "--from-robot", "seed", "--kerf-mm", "-1"], ["kerf_mm"]),
    ("fab-kerf-wide-no-out", lambda d: ["fab", "--from-robot", "seed", "--kerf-mm", "5"], ["kerf"]),
    ("fab-kerf-wide-out", lambda d: ["fab", "--from-robot", "seed", "--kerf-mm", "5", "--out", d / "cut"], ["kerf"]),
    ("fab-unclosable-robot", lambda d: ["fab", "--from-robot", robot_toml(d, "[geometry]\ncoupler_m = 0.5\n")],
     ["cannot close"]),
    ("fab-part-over-10m", lambda d: ["fab", "--from-robot", robot_toml(
        d, "[geometry]\nground_m = 4\ncrank_m = 4\ncoupler_m = 3\nleg_m = 4\n")], ["10 m"]),
    ("fab-part-under-0.01mm", lambda d: ["fab", dxf(d, "tiny.dxf", [(0, 0), (0.001, 0), (0.001, 0.001), (0, 0.001)])],
     ["0.01 mm"]),
    ("fab-drawing-over-10m", lambda d: ["fab", dxf(d, "huge.dxf", [(0, 0), (20000, 0), (20000, 30), (0, 30)])],
     ["10 m"]),
    ("fab-nan-vertex", lambda d: ["fab", dxf(d, "nan.dxf", [(0, 0), (50, 0), (math.nan, 30), (0, 30)])],
     ["not a finite number"]),
    ("fab-hole-outside-body", lambda d: ["fab", dxf(d, "hole.dxf", RECT, holes=[((200, 200), 2)])],
     ["outside the body"]),
    ("fab-slit-outside-body", lambda d: ["fab", dxf(d, "slit.dxf", RECT, slits=[((100, 100), (120, 100))])],
     ["outside the body"]),
    # tracking options
    ("track-angle-nan", lambda d: ["track", d / "v.mp4", "--angle", "nan"], ["--angle"]),
    ("track-accept-nan", lambda d: ["track", d / "v.mp4", "--accept", "nan"], ["--accept"]),
    ("track-fps-0", lambda d: ["track", d / "v.mp4", "--fps", "0"], ["--fps"]),
    # calibration: bad numbers, and fits off by a unit are not written
    ("servo-gravity-moment-inf", lambda d: ["calibrate", "servo", copy_servo(d), "--inertia-kgm2", "1.5e-5",
                                            "--gravity-moment-nm", "inf", "--no-plot"], ["finite"]),
    ("servo-inertia-nan", lambda d: ["calibrate", "servo", copy_servo(d), "--inertia-kgm2", "nan", "--no-plot"],
     ["finite"]),
    ("servo-inertia-0", lambda d: ["calibrate", "servo", copy_servo(d), "--inertia-kgm2", "0", "--no-plot"],
     ["above 0"]),
    ("beam-mass-negative", lambda d: ["calibrate", "beam", copy_beam(d), "--mass-kg", "-0.01", "--no-plot"],
     ["above 0"]),
    ("beam-length-in-mm", lambda d: ["calibrate", "beam", copy_beam(d), "--mass-kg", "0.01", "--length-m", "50",
                                     "--write", d / "cal.toml", "--no-plot"], ["plausible", "not written"]),
    ("ramp-angles-in-radians", lambda d: ["calibrate", "ramp", robot_toml(d, "trial,angle_deg\n1,1.04\n2,1.05\n",
                                                                          "ramp.csv"),
                                          "--write", d / "cal.toml", "--no-plot"], ["contact.foot_friction"]),
    # report
    ("report-cycles-beyond-record", lambda d: ["report", "--measured", f"small={trial(d)}", "--cycles", "5",
                                               "--out", d / "rep"], ["recorded only 2 cycles"]),
    ("report-refused-hop", lambda d: ["report", "--measured", f"small={trial(d, run_record.ERROR)}",
                                      "--out", d / "rep"], ["refused by the robot"]),
    # the robot's command line
    ("hop-heartbeat-0", lambda d: ["hop", "--port", "sim", "--heartbeat-ms", "0", "--out", d / "run"],
     ["--heartbeat-ms"]),
    ("hop-push-ms-5", lambda d: ["hop", "--port", "sim", "--push-ms", "5", "--out", d / "run"], ["--push-ms"]),
    ("hop-no-such-port", lambda d: ["hop", "--port", d / "ttyNONE", "--out", d / "runs" / "one"],
     ["cannot open serial port"]),
    ("pose-nan", lambda d: ["pose", "nan", "0", "--port", "sim"], ["error"]),
    ("unknown-option", lambda d: ["sim", "--bogus"], ["--bogus"]),
]


@pytest.mark.parametrize("setup, words", [pytest.param(s, w, id=i) for i, s, w in CASES])
def test_bad_input_is_a_clear_error_and_nothing_changes(tmp_path, monkeypatch, setup, words):
    monkeypatch.chdir(tmp_path)
    args = setup(tmp_path)
    before = tree(tmp_path)
    res = invoke(args)
    assert_clear_error(res, *words)
    assert tree(tmp_path) == before   # no input changed, nothing lost, nothing half-written left


def test_there_are_enough_probe_classes():
    assert len(CASES) >= 60


# -- the parameter edge, in one place -------------------------------------------------
def test_every_preset_is_within_the_limits():
    from locust.params import PRESETS

    for name in PRESETS:
        assert problems(preset(name)) == [], name


def test_schedule_limits_are_the_firmwares():
    from locust.firmware.protocol import COMMANDS

    hop = COMMANDS["hop"]
    assert LIMITS["schedule.push_s"][:2] == (hop["push_ms"][1] / 1000, hop["push_ms"][2] / 1000)
    assert LIMITS["schedule.wait_s"][:2] == (hop["wait_ms"][1] / 1000, hop["wait_ms"][2] / 1000)
    assert LIMITS["schedule.push_deg"][:2] == (hop["push_deg"][1], hop["push_deg"][2])
    assert LIMITS["schedule.cycles"][:2] == (hop["cycles"][1], hop["cycles"][2])


def test_step_budget_is_checked_before_any_allocation():
    # 1000 cycles of 70 s at 0.1 ms would be 7e8 steps; refused by arithmetic, not by a MemoryError
    robot = preset("seed").with_values({"schedule.push_s": 10, "schedule.wait_s": 60, "solver.timestep_s": 1e-4})
    found = problems(robot, cycles=1000)
    assert len(found) == 1 and f"{(0.5 + 1000 * 70) / 1e-4:.3g}" in found[0] and f"{MAX_SIM_STEPS:g}" in found[0]
    check_robot(robot, cycles=2)   # 2 cycles are 1.405e6 steps: within the budget


def test_an_unsimulatable_design_is_an_invalid_row_of_the_sweep(tmp_path):
    from locust.sweep.design import parse_axis
    from locust.sweep.run import run_sweep

    # each value within its limits, the push beyond the servo's travel together: a row, not a run
    base = preset("seed")
    axes = [parse_axis("schedule.push_deg=-60:-30:2", base)]
    s = run_sweep(base, axes, cycles=1, out=tmp_path / "sw", jobs=1, plots=False)
    assert [r["valid"] for r in s.rows] == [False, True]
    assert "schedule.push_deg = -60 is beyond the servo travel of +-45 deg" in s.rows[0]["reason"]
    assert s.best["design"] == 1


# -- writes ---------------------------------------------------------------------------
def test_write_onto_a_symlink_updates_its_target_and_keeps_the_link(tmp_path):
    target = tmp_path / "real.toml"
    target.write_text("# old\n")
    target.chmod(0o640)
    link = tmp_path / "link.toml"
    link.symlink_to("real.toml")
    res = invoke(["params", "--write", link, "--force"])
    assert res.exit_code == 0, res.output
    assert link.is_symlink() and os.readlink(link) == "real.toml"
    assert target.read_text().startswith("# locust robot parameters")
    assert stat.S_IMODE(target.stat().st_mode) == 0o640   # the mode is the file's own


def test_a_full_disk_is_an_error_and_leaves_nothing_behind(tmp_path):
    """A file-size limit stands in for a full disk: the write fails part way (EFBIG, as ENOSPC)."""
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (1000, 1000))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)

    proc = subprocess.run(LOCUST + ["params", "--write", "robot.toml"], cwd=tmp_path, preexec_fn=limit,
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    assert "error:" in proc.stderr and "hint:" in proc.stderr and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []   # no robot.toml, no temporary file


@pytest.mark.parametrize("args", [
    ["params", "--write", "ro/robot.toml"],
    ["sweep", "--vary", "scale=0.3:0.4:2", "--cycles", "1", "--out", "ro/sweep"],
], ids=["params-write", "sweep-out"])
def test_a_read_only_folder_is_an_error_and_gets_nothing(tmp_path, monkeypatch, args):
    """Refused by the folder's mode, so the check holds even for root (who may write anyway)."""
    monkeypatch.chdir(tmp_path)
    ro = tmp_path / "ro"
    ro.mkdir()
    (ro / "data.csv").write_text("t_s,x_m\n0,0\n")
    ro.chmod(0o555)
    try:
        before = tree(ro)
        assert_clear_error(invoke(args), "read-only")
        assert tree(ro) == before
    finally:
        ro.chmod(0o755)


def test_track_out_never_lands_on_the_videos_sidecars(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = invoke(["sim", "--cycles", "1", "--video", "hop.mp4", "--camera", "fixed",
                  S, "solver.settle_s=0.3", S, "schedule.wait_s=0.2"])
    assert res.exit_code == 0, res.output
    before = tree(tmp_path)
    for out in ("hop.camera.csv", "hop.camera", "hop.truth.csv"):
        for force in ([], ["--force"]):
            res = invoke(["track", "hop.mp4", "--out", out, "--overlay", "none", *force])
            assert_clear_error(res, "sidecar")
    assert tree(tmp_path) == before


# -- processes ------------------------------------------------------------------------
def _children(pid: int) -> list[int]:
    out = []
    for status in Path("/proc").glob("[0-9]*/status"):
        try:
            text = status.read_text()
        except OSError:
            continue
        if f"\nPPid:\t{pid}\n" in text:
            out.append(int(status.parent.name))
    return out


def _alive(pid: int) -> bool:
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    return "\nState:\tZ" not in text


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc (Linux)")
def test_kill_9_of_a_sweep_leaves_no_worker_and_no_lock_and_resumes(tmp_path):
    args = LOCUST + ["sweep", "--vary", "scale=0:0.03:40", "--cycles", "1", "--jobs", "2", "--out", "sw"]
    proc = subprocess.Popen(args, cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    results = tmp_path / "sw" / "results.csv"
    wait_for(lambda: len(results.read_text().splitlines()) >= 3, 60, "two rows in the sweep's results.csv")
    workers = _children(proc.pid)
    assert workers, "the sweep had no worker processes"
    proc.kill()
    proc.wait()
    wait_for(lambda: not [w for w in workers if _alive(w)], 10, "the workers to end with the killed sweep")
    done = len(results.read_text().splitlines()) - 1
    assert 2 <= done < 40
    again = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    rows = results.read_text().splitlines()[1:]
    assert len(rows) == 40 and [int(r.split(",")[0]) for r in rows] == list(range(40))
    assert json.loads((tmp_path / "sw" / "sweep.json").read_text())["finished"] is True


def _wait_for_the_first_phase(run: Path, timeout_s: float = 60.0) -> Path:
    """``run`` (a run.json) once it records a phase: the hop is under way."""
    wait_for(lambda: '"phase"' in run.read_text(), timeout_s, f"a phase recorded in {run}")
    return run


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc (Linux)")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_a_killed_hop_leaves_no_interpreter_running(env, tmp_path, sig):
    proc = subprocess.Popen(LOCUST + ["hop", "--port", "sim", "--plant", "record", "--cycles", "20",
                                      "--out", str(tmp_path / "run")],
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    run = _wait_for_the_first_phase(tmp_path / "run" / "run.json")
    interpreters = [c for c in _children(proc.pid) if "micropython" in Path(f"/proc/{c}/comm").read_text()]
    assert len(interpreters) == 1
    proc.send_signal(sig)
    _, stderr = proc.communicate(timeout=30)
    wait_for(lambda: not _alive(interpreters[0]), 5, "the MicroPython interpreter to end with the host")
    rec = json.loads(run.read_text())
    assert rec["status"] in ("incomplete", "running")
    if sig == signal.SIGTERM:
        assert proc.returncode == 2 and "Traceback" not in stderr and "hint:" in stderr
        assert rec["status"] == "incomplete" and "interrupted" in rec["message"]


# -- load -----------------------------------------------------------------------------
def test_the_heartbeat_keeps_its_clock_beside_a_busy_thread():
    """Pings from the heartbeat's own thread stay on time while another thread of the host
    computes in Python (holding the GIL whenever it can): no gap near the firmware's timeout."""
    import pty
    import select
    import threading

    from locust.device.link import Link
    from locust.firmware import protocol

    master, slave = pty.openpty()
    interval_s = protocol.COMMANDS["hop"]["heartbeat_ms"][3] / 8000.0
    stop = threading.Event()

    def busy():
        x = 0
        while not stop.is_set():
            x = (x * 31 + 7) % 1_000_003

    arrivals = []
    link = Link(os.ttyname(slave))
    worker = threading.Thread(target=busy, daemon=True)
    try:
        worker.start()
        link.start_heartbeat(interval_s)
        t_end = time.monotonic() + 2.0
        while time.monotonic() < t_end:
            ready, _, _ = select.select([master], [], [], 0.05)
            if ready:
                data = os.read(master, 4096)
                arrivals += [time.monotonic()] * data.count(b'"cmd":"ping"')
    finally:
        stop.set()
        link.close()
        os.close(master)
        os.close(slave)
    gaps = [b - a for a, b in zip(arrivals, arrivals[1:])]
    if len(arrivals) < 0.8 * 2.0 / interval_s or max(gaps) >= 2 * interval_s:
        # a host that stops this process for long (a busy shared machine) cannot judge the
        # heartbeat's clock; probed now, one that does not stop it can, and the beat was late
        from host_probe import STALL_LIMIT_US, spin_probe_us

        again_us = spin_probe_us()
        if again_us > STALL_LIMIT_US:
            pytest.skip(f"worst gap between beats {max(gaps, default=0) * 1000:.0f} ms, and the host stopped a "
                        f"spinning process for {again_us / 1000:.2f} ms: the heartbeat's clock cannot be judged here")
    assert len(arrivals) >= 0.8 * 2.0 / interval_s
    # a beat may be late by a few scheduler slices, never by a good part of the timeout
    assert max(gaps) < 2 * interval_s, gaps


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc (Linux)")
def test_ctrl_c_during_a_filmed_hop_finishes_the_video_and_says_so(env, tmp_path):
    proc = subprocess.Popen(LOCUST + ["hop", "--port", "sim", "--cycles", "4", "--video", "hop.mp4", "--out", "run"],
                            cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    run = _wait_for_the_first_phase(tmp_path / "run" / "run.json")
    # a phase filmed in full (the video's frames follow the simulation), so the video has frames
    wait_for(lambda: len(json.loads(run.read_text())["phases"]) >= 2, 60, "two phases in run.json")
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 2 and "interrupted" in stderr and "hint:" in stderr and "Traceback" not in stderr
    rec = json.loads(run.read_text())
    assert rec["status"] == "incomplete" and "interrupted" in rec["message"] and 1 <= len(rec["phases"]) < 8
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["hop.camera.json", "hop.mp4", "hop.truth.csv", "run"]   # no hidden temporary file
    from locust.track.video import probe

    assert probe(tmp_path / "hop.mp4").frame_count >= 10   # a playable video of what was filmed


# -- the property-style probe: many generated inputs per class ------------------------
# Each class draws its inputs from a seeded generator (the same cases every run, a new seed
# a new set): every one must be a clear error (exit 2, error:/hint:, no traceback) that
# leaves every file as it was and creates none.
DRAWS = 20


def _draws(seed: int, n: int = DRAWS):
    import random

    rng = random.Random(seed)
    return [(k, rng) for k in range(n)]


def _beyond(key: str, rng) -> str:
    """A value of ``key`` outside its limits: past either end (the end itself where that end is
    open), as far as 1e300 past, or not finite."""
    from locust.params import value_type

    low, high, low_ok, high_ok, _ = LIMITS[key]
    whole = value_type(key) == "int"
    sides = [s for s, end in (("low", low), ("high", high)) if math.isfinite(end)]
    side = rng.choice(sides + ["nan"])
    if side == "nan":
        return "nan"
    end, ok, sign = (low, low_ok, -1) if side == "low" else (high, high_ok, 1)
    if not ok and rng.random() < 0.3:
        return repr(end)
    step = 10 ** rng.uniform(-3, 300 if not whole else 6) * max(abs(end), 1e-3)
    value = end + sign * step
    return str(int(math.floor(value) if sign < 0 else math.ceil(value) + (value == math.ceil(value)))) \
        if whole else repr(value)


def _robot_bytes(rng) -> bytes:
    """A valid robot.toml with a byte that is not UTF-8 somewhere in it."""
    text = b'name = "mine"\n[geometry]\nleg_m = 0.06\n# measured with a ruler\n[servo]\nkp_nm_per_rad = 0.4\n'
    at = rng.randrange(len(text))
    bad = bytes([rng.choice([0x80, 0x9F, 0xC0, 0xC1, 0xF5, 0xFE, 0xFF])])
    return text[:at] + bad + text[at:]


NUMBER_KEYS = sorted(LIMITS)


@pytest.mark.parametrize("k, rng", _draws(1))
def test_probe_out_of_limit_values_are_refused_with_their_reason(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    key = rng.choice(NUMBER_KEYS)
    value = _beyond(key, rng)
    (tmp_path / "mine.toml").write_text("# mine\n")
    section, name = key.split(".")
    robot = robot_toml(tmp_path, f"[{section}]\n{name} = {value}\n")
    for args in (["params", S, f"{key}={value}"], ["sim", "--cycles", "1", "--config", robot],
                 ["params", "--config", robot, "--write", tmp_path / "new.toml"]):
        before = tree(tmp_path)
        res = invoke(args)
        assert_clear_error(res, key)
        if value != "nan":
            assert f"({LIMITS[key].reason})" in res.stderr or "takes a" in res.stderr, res.stderr
        assert tree(tmp_path) == before


def test_every_parameter_has_limits_with_a_reason():
    from locust.params import PRESETS, all_keys, value_type

    numbers = [k for k in all_keys() if value_type(k) in ("float", "int")]   # the cycles, a crank's tooth too
    assert sorted(numbers) == sorted(LIMITS)
    assert all(len(limit.reason) > 10 for limit in LIMITS.values())
    # the toolkit's robots: a gram to a kilogram, millimetres to tens of centimetres, hobby servos
    assert LIMITS["geometry.body_mass_kg"][:2] == (0.001, 1.0)
    assert LIMITS["geometry.leg_m"][:2] == (0.001, 0.5)
    assert LIMITS["servo.stall_torque_nm"][1] == 5.0
    for name in PRESETS:
        assert problems(preset(name)) == [], name


@pytest.mark.parametrize("k, rng", _draws(2))
def test_probe_robot_files_that_are_not_utf8_in_every_reader(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    robot = tmp_path / "robot.toml"
    robot.write_bytes(_robot_bytes(rng))
    ramp = robot_toml(tmp_path, "trial,angle_deg\n1,30\n2,31\n3,29\n", "ramp.csv")
    commands = [["params", "--config", robot], ["sim", "--cycles", "1", "--config", robot],
                ["hop", "--port", "sim", "--config", robot, "--out", tmp_path / "run"],
                ["fab", "--from-robot", robot],
                ["report", "--before", robot, "--measured", f"small={trial(tmp_path)}", "--out", tmp_path / "rep"],
                ["calibrate", "ramp", ramp, "--write", robot, "--no-plot"]]
    assert_refused_and_unchanged(tmp_path, commands[k % len(commands)], "robot.toml", "not UTF-8")


@pytest.mark.parametrize("k, rng", _draws(3))
def test_probe_booleans_are_not_numbers_in_a_robot_file(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    key = rng.choice(NUMBER_KEYS)
    section, name = key.split(".")
    robot = robot_toml(tmp_path, f"[{section}]\n{name} = {rng.choice(['true', 'false'])}\n")
    assert_refused_and_unchanged(tmp_path, ["params", "--config", robot], key, "not a number")


def _corrupt_cell(path: Path, rng, columns: list[str]) -> None:
    """One data cell of ``columns`` replaced by a value no recording holds."""
    lines = path.read_text().splitlines()
    header = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    names = lines[header].split(",")
    row = rng.randrange(header + 1, len(lines))
    cells = lines[row].split(",")
    cells[names.index(rng.choice(columns))] = rng.choice(["inf", "-inf", "1e308", "-1e305", "Infinity"]) \
        if rng.random() < 0.6 else repr(rng.choice([-1, 1]) * 10 ** rng.uniform(12, 300))
    lines[row] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("k, rng", _draws(4))
def test_probe_non_finite_and_absurd_values_in_recordings(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    if k % 2:
        rec = copy_beam(tmp_path)
        _corrupt_cell(rec, rng, ["t_s", "tip_x_m", "tip_y_m"])
        args = ["calibrate", "beam", rec, "--mass-kg", "0.01", "--no-plot"]
    else:
        rec = copy_servo(tmp_path)
        _corrupt_cell(rec, rng, ["t_s", "angle_deg", "command_deg"])
        args = ["calibrate", "servo", rec, "--inertia-kgm2", "1.5e-5", "--no-plot"]
    assert_refused_and_unchanged(tmp_path, args, "data row")


@pytest.mark.parametrize("k, rng", _draws(5))
def test_probe_times_not_in_seconds(tmp_path, monkeypatch, k, rng):
    """Times of a 60 frames/s recording written in ms (or any unit 100 to 100000 times too
    long): refused, with --time-scale in the hint, before any simulation."""
    monkeypatch.chdir(tmp_path)
    factor = 10 ** rng.uniform(2, 5)
    lines = SERVO_CSV.read_text().splitlines()
    out = []
    for ln in lines:
        if ln[:1].isdigit() or ln[:1] == "-":
            t, rest = ln.split(",", 1)
            ln = f"{float(t) * factor:.6f},{rest}"
        out.append(ln)
    rec = robot_toml(tmp_path, "\n".join(out) + "\n", "servo_ms.csv")
    assert_refused_and_unchanged(tmp_path, ["calibrate", "servo", rec, "--inertia-kgm2", "1.5e-5", "--no-plot"],
                                 "not in seconds", "--time-scale 0.001")


def _plot_collision(d: Path, rng, inputs: list[Path]) -> tuple[list, str]:
    """--plot / --write paths that would destroy something: (extra args, a word of the error)."""
    target = rng.choice(inputs)
    spellings = [target, Path(os.path.relpath(target, d)), d / "." / target.name,
                 d / "sub" / ".." / target.name]
    (d / "sub").mkdir(exist_ok=True)
    choice = rng.randrange(5)
    if choice == 0:   # an input, spelt some way
        return ["--plot", rng.choice(spellings)], "an input"
    if choice == 1:   # an input reached through a link
        link = d / "link.png"
        link.symlink_to(target)
        return ["--plot", link], "an input"
    if choice == 2:   # a path that is not an image
        name = rng.choice(["notes.txt", "fit.csv", "robot.toml", "fit", "fit.png.bak"])
        if rng.random() < 0.5:
            (d / name).write_text("mine\n")
        return ["--plot", d / name], "must end in"
    if choice == 3:   # a user's picture
        (d / "photo.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(rng.randrange(256) for _ in range(64)))
        return ["--plot", d / "photo.png"], "not a figure this toolkit wrote"
    same = d / rng.choice(["out.png", "out.toml"])   # two outputs on one file
    return ["--plot", same, "--write", rng.choice([same, Path(os.path.relpath(same, d))])], "same file"


@pytest.mark.parametrize("k, rng", _draws(6, 30))
def test_probe_plot_paths_never_replace_inputs_or_user_files(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    kind = ["beam", "servo", "ramp", "hinge"][k % 4]
    if kind == "beam":
        rec = copy_beam(tmp_path)
        base = ["calibrate", "beam", rec, "--mass-kg", "0.01", "--length-m", "0.05"]
    elif kind == "servo":
        rec = copy_servo(tmp_path)
        base = ["calibrate", "servo", rec, "--inertia-kgm2", "1.5e-5"]
    elif kind == "ramp":
        rec = robot_toml(tmp_path, "trial,angle_deg\n1,30\n2,31\n3,29\n", "ramp.csv")
        base = ["calibrate", "ramp", rec]
    else:
        rec = copy_beam(tmp_path)
        base = ["calibrate", "hinge", rec, "--inertia-kgm2", "8.5e-7", "--gravity", "out-of-plane"]
    extra, word = _plot_collision(tmp_path, rng, [rec])
    assert_refused_and_unchanged(tmp_path, base + extra, word)


@pytest.mark.parametrize("k, rng", _draws(7))
def test_probe_sweep_ranges_beyond_the_limits(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    key = rng.choice(NUMBER_KEYS + ["scale"] * 5)
    if key == "scale":   # centimetres typed for metres
        a, b = 0.0, rng.choice([1, 2, 5, 10, 30, 100])
        words = ["scale", "units"]
    else:
        inside = preset("seed").get(key)
        a, b = sorted([float(inside), float(_beyond(key, rng).replace("nan", "inf"))])
        if not math.isfinite(a) or not math.isfinite(b):
            a, b = (inside, LIMITS[key].high * 10 + 1) if math.isfinite(LIMITS[key].high) else \
                (LIMITS[key].low - 1, inside)
        words = [key] if key != "schedule.cycles" else ["--cycles"]
    cmd = rng.choice(["sweep", "optimize"])
    args = [cmd, "--vary", f"{key}={a!r}:{b!r}" + (":3" if cmd == "sweep" else ""), "--cycles", "1",
            "--out", tmp_path / "out"]
    assert_refused_and_unchanged(tmp_path, args, *words)


@pytest.mark.parametrize("k, rng", _draws(8))
def test_probe_hop_fits_take_each_run_once_and_only_physics(tmp_path, monkeypatch, k, rng):
    from locust.params import all_keys, fittable_keys

    monkeypatch.chdir(tmp_path)
    run = trial(tmp_path)
    if k % 2:
        spelt = rng.choice([run, Path("small-1"), Path("./small-1"), tmp_path / "x" / ".." / "small-1"])
        (tmp_path / "x").mkdir()
        args = ["calibrate", "hop", f"small={run}", f"{rng.choice(['small', 'large'])}={spelt}", "--no-plot"]
        word = "given twice"
    else:
        key = rng.choice([key for key in all_keys() if key not in fittable_keys()])
        args = ["calibrate", "hop", f"small={run}", "--fit", key, "--no-plot"]
        word = "physical parameters"
    assert_refused_and_unchanged(tmp_path, args, word)


def test_a_bare_write_names_its_file_and_makes_no_calibration_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ramp = robot_toml(tmp_path, "trial,angle_deg\n1,30\n2,31\n3,29\n", "ramp.csv")
    assert_refused_and_unchanged(tmp_path, ["calibrate", "ramp", ramp, "--write", "--no-plot"],
                                 str(tmp_path / "calibration"), "--write PATH")
    (tmp_path / "calibration").mkdir()
    res = invoke(["calibrate", "ramp", ramp, "--write", "--no-plot"])
    assert res.exit_code == 0, res.output
    assert f"to {tmp_path / 'calibration' / 'robot.toml'}" in res.output
    assert (tmp_path / "calibration" / "robot.toml").is_file()


def test_a_plot_replaces_only_its_own_figure(tmp_path, monkeypatch):
    from locust.plotting import is_own_figure

    monkeypatch.chdir(tmp_path)
    ramp = robot_toml(tmp_path, "trial,angle_deg\n1,30\n2,31\n3,29\n", "ramp.csv")
    for suffix in (".png", ".svg", ".pdf"):
        for _ in range(2):   # the second run replaces the first one's figure
            res = invoke(["calibrate", "ramp", ramp, "--plot", f"fit{suffix}"])
            assert res.exit_code == 0, res.output
        assert is_own_figure(tmp_path / f"fit{suffix}")
    (tmp_path / "mine.png").write_bytes((tmp_path / "fit.png").read_bytes().replace(b"locust", b"gimp!!"))
    assert not is_own_figure(tmp_path / "mine.png")
    assert_refused_and_unchanged(tmp_path, ["calibrate", "ramp", ramp, "--plot", "mine.png"], "--force")
    assert invoke(["calibrate", "ramp", ramp, "--plot", "mine.png", "--force"]).exit_code == 0
    assert is_own_figure(tmp_path / "mine.png")


def test_an_unstable_simulation_leaves_no_mujoco_log(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = invoke(["sim", "--cycles", "1", S, "solver.timestep_s=0.01", S, "solver.integrator=euler",
                  S, "servo.kp_nm_per_rad=100", S, "servo.armature_kgm2=0",
                  S, "compliance.hinge_stiffness_nm_per_rad=10", S, "schedule.wait_s=0.2", S, "solver.settle_s=0.1"])
    assert "INVALID" in res.output and "MuJoCo warnings: BADQACC" in res.output, res.output
    assert list(tmp_path.iterdir()) == []


def test_a_two_million_row_recording_is_refused_before_it_is_parsed(tmp_path, monkeypatch):
    from locust.calibrate.recordings import MAX_ROWS

    monkeypatch.chdir(tmp_path)
    rec = tmp_path / "long.csv"
    rows = "\n".join(f"{i / 1000:.3f},{0.1 + 0.01 * math.sin(i / 50):.6f},0.05" for i in range(MAX_ROWS + 1))
    rec.write_text("t,x,y\n" + rows + "\n")
    assert_refused_and_unchanged(tmp_path, ["calibrate", "beam", rec, "--mass-kg", "0.01", "--no-plot"],
                                 f"{MAX_ROWS + 2:,} lines", "cut the recording")


def _robot_structure(d: Path, rng) -> tuple[Path, str]:
    """A robot file whose structure no robot.toml has: (its path, a word of the error)."""
    key = rng.choice(NUMBER_KEYS)
    section, name = key.split(".")
    depth = rng.randrange(500, 3000)
    kind = rng.choice(["overflow", "list", "table", "deep-inline", "deep-list", "base", "name", "section",
                       "not-a-file"])
    if kind == "overflow":   # an integer no float holds, plain or as {value = ...}
        big = rng.choice(["", "-"]) + "1" + "0" * rng.randrange(309, 2000)
        text = f"{name} = {big}" if rng.random() < 0.5 else f"{name} = {{value = {big}}}"
        return robot_toml(d, f"[{section}]\n{text}\n"), "too large for a number"
    if kind == "list":
        return robot_toml(d, f"[{section}]\n{name} = [{rng.uniform(0, 1)}, 2]\n"), "a list, where a number"
    if kind == "table":
        inner = rng.choice([f"{{value = {{a = {rng.random()}}}}}", f"{{value = [{rng.random()}]}}"])
        return robot_toml(d, f"[{section}]\n{name} = {inner}\n"), "where a number"
    if kind == "deep-inline":
        return robot_toml(d, f"[{section}]\n{name} = " + "{a = " * depth + "1" + "}" * depth + "\n"), "too deep"
    if kind == "deep-list":
        where = rng.choice([f"[{section}]\n{name} = ", "name = ", "base = "])
        return robot_toml(d, where + "[" * depth + "]" * depth + "\n"), "too deep"
    if kind == "base":
        return robot_toml(d, rng.choice(['base = ["seed"]\n', "base = {a = 1}\n", "base = 3\n"])), "not a preset"
    if kind == "name":
        return robot_toml(d, rng.choice(['name = ["mine"]\n', "name = {a = 1}\n", "name = 3\n"])), "not a string"
    if kind == "section":
        return robot_toml(d, f"{section} = {rng.choice(['1', '[1]', 'true'])}\n"), f"section [{section}]"
    choice = rng.randrange(3)
    if choice == 0:
        os.mkfifo(d / "fifo.toml")
        return d / "fifo.toml", "not a regular file"
    if choice == 1:
        (d / "folder.toml").mkdir()
        return d / "folder.toml", "not a regular file"
    return Path(rng.choice(["/dev/zero", "/dev/urandom"])), "not a regular file"


@pytest.mark.timeout(60)   # a pipe read as a robot.toml blocked for ever
@pytest.mark.parametrize("k, rng", _draws(9, 30))
def test_probe_robot_files_whose_structure_is_no_robot_s(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    robot, word = _robot_structure(tmp_path, rng)
    ramp = robot_toml(tmp_path, "trial,angle_deg\n1,30\n2,31\n3,29\n", "ramp.csv")
    commands = [["params", "--config", robot], ["sim", "--cycles", "1", "--config", robot],
                ["fab", "--from-robot", robot],
                ["report", "--before", robot, "--measured", f"small={trial(tmp_path)}", "--out", tmp_path / "rep"],
                ["calibrate", "ramp", ramp, "--write", robot, "--no-plot"]]
    t0 = time.monotonic()
    assert_refused_and_unchanged(tmp_path, commands[k % len(commands)], str(robot.name), word)
    assert time.monotonic() - t0 < 10


def _calibration_input(d: Path, rng) -> tuple[list, list[str]]:
    """A calibration command given a recording that is not a file, or a load no servo holds."""
    if rng.random() < 0.3:
        moment = rng.choice([-1, 1]) * 10 ** rng.uniform(math.log10(5.001), 300)
        return (["calibrate", "servo", copy_servo(d), "--inertia-kgm2", "1.5e-5", "--gravity-moment-nm",
                 repr(moment), "--no-plot"], ["--gravity-moment-nm", "5 N*m"])
    choice, word = rng.randrange(4), "not a regular file"
    if choice == 0:
        os.mkfifo(d / "fifo.csv")
        rec = d / "fifo.csv"
    elif choice == 1:
        (d / "folder.csv").mkdir()
        rec, word = d / "folder.csv", "is a directory"
    else:
        rec = Path(rng.choice(["/dev/zero", "/dev/urandom"]))
    kind = rng.choice(["beam", "ramp", "hinge", "servo"])
    extra = {"beam": ["--mass-kg", "0.01"], "ramp": [], "servo": ["--inertia-kgm2", "1.5e-5"],
             "hinge": ["--inertia-kgm2", "8.5e-7", "--gravity", "out-of-plane"]}[kind]
    return ["calibrate", kind, rec, *extra, "--no-plot"], [rec.name, word]


@pytest.mark.timeout(60)   # a pipe read as a recording blocked for ever, /dev/zero filled the memory
@pytest.mark.parametrize("k, rng", _draws(10))
def test_probe_calibration_recordings_that_are_not_files_and_loads_no_servo_holds(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    args, words = _calibration_input(tmp_path, rng)
    t0 = time.monotonic()
    assert_refused_and_unchanged(tmp_path, args, *words)
    assert time.monotonic() - t0 < 10


def _hostile_dxf(d: Path, rng) -> tuple[list, list[str]]:
    """A body outline with one entity no laser cuts: a number not finite, an arc of a radius or
    bulge that flattens into millions of chords; or a gap tolerance that is no distance."""
    import ezdxf

    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    plate = {"layer": "plate"}
    kind = rng.choice(["not-finite", "radius", "bulge", "gap"])
    if kind == "gap":
        msp.add_lwpolyline(RECT, close=True, dxfattribs=plate)
        doc.saveas(d / "part.dxf")
        gap = rng.choice([0.0, -1.0, -1e300, 10.5, 1e300, -10 ** rng.uniform(-6, 3)])
        return ["fab", d / "part.dxf", "--gap-tol-mm", repr(gap)], ["--gap-tol-mm"]
    bad = rng.choice([math.inf, -math.inf, math.nan])
    if kind == "not-finite":
        where = rng.randrange(4)
        if where == 0:
            msp.add_lwpolyline([(0, 0), (50, 0), (50, bad), (0, 30)], close=True, dxfattribs=plate)
        elif where == 1:
            msp.add_lwpolyline([(0, 0, 0), (50, 0, bad), (50, 30, 0), (0, 30, 0)], format="xyb", close=True,
                               dxfattribs=plate)
        else:
            msp.add_lwpolyline(RECT, close=True, dxfattribs=plate)
            if where == 2:   # its centre, or (infinite) its radius
                centre, radius = ((10, 10), abs(bad)) if math.isinf(bad) and rng.random() < 0.5 else ((bad, 10), 2)
                msp.add_circle(centre, radius, dxfattribs=plate)
            else:
                msp.add_line((0, 0), (bad, 5), dxfattribs=plate)
        words = ["not a finite number"]
    elif kind == "radius":
        msp.add_lwpolyline(RECT, close=True, dxfattribs=plate)
        radius = 10 ** rng.uniform(9, 300)
        (msp.add_arc((10, 10), radius, 0, 90, dxfattribs=plate) if rng.random() < 0.5
         else msp.add_circle((10, 10), radius, dxfattribs=plate))
        words = ["chords", f"{MAX_ARC_SEGMENTS:,}"]
    else:
        bulge = rng.choice([-1, 1]) * 10 ** rng.uniform(9, 300)
        msp.add_lwpolyline([(0, 0, 0), (50, 0, bulge), (50, 30, 0), (0, 30, 0)], format="xyb", close=True,
                           dxfattribs=plate)
        words = ["chords", f"{MAX_ARC_SEGMENTS:,}"]
    doc.saveas(d / "part.dxf")
    return ["fab", d / "part.dxf"], ["part.dxf", *words]


@pytest.mark.timeout(60)   # an arc of radius 1e12 mm flattened for ever
@pytest.mark.parametrize("k, rng", _draws(11))
def test_probe_drawings_with_numbers_no_laser_cuts(tmp_path, monkeypatch, k, rng):
    monkeypatch.chdir(tmp_path)
    args, words = _hostile_dxf(tmp_path, rng)
    t0 = time.monotonic()
    assert_refused_and_unchanged(tmp_path, args, *words)
    assert time.monotonic() - t0 < 10


# -- long simulations: refused by their memory, ended by a signal within a second or two --
@pytest.mark.parametrize("samples", [64, 512, 4096])
def test_a_batch_over_the_memory_limit_is_refused_before_any_simulation(tmp_path, monkeypatch, samples):
    from locust.sim.batching import MAX_BATCH_BYTES

    monkeypatch.chdir(tmp_path)
    t0 = time.monotonic()
    assert_refused_and_unchanged(tmp_path, ["sim", "--samples", samples, "--cycles", "1000"],
                                 f"{samples} simulation(s)", f"{MAX_BATCH_BYTES / 2**30:g} GiB")
    assert time.monotonic() - t0 < 10   # the 1000-cycle run alone takes minutes


def test_a_chunked_rollout_is_the_one_call_record_bit_for_bit(monkeypatch):
    import mujoco
    from mujoco import rollout as mj_rollout

    from locust.sim import batching
    from locust.sim.model import build
    from locust.sim.rollout import initial_state
    from locust.sim.schedule import control_plan

    robot = preset("seed")
    built, plan = build(robot), control_plan(robot.schedule, robot.solver, 1)
    control = np.zeros((1, plan.nstep, built.model.nu))
    control[0][:, list(built.servo_actuators)] = plan.ctrl_rad[:, None]
    start = initial_state(built)[0][None]
    whole_state, whole_sensors = mj_rollout.rollout(built.model, mujoco.MjData(built.model), start, control)
    monkeypatch.setattr(batching, "CHUNK_MODEL_STEPS", 397)   # a prime: chunks end anywhere in a phase
    assert len(batching.chunk_bounds(plan.nstep, 1)) > 2
    states, sensors, final, _ = batching.rollout_chunked([built.model], [mujoco.MjData(built.model)], start,
                                                         control, keep_states=True)
    assert np.array_equal(sensors, whole_sensors) and np.array_equal(states, whole_state)
    assert np.array_equal(final, whole_state[:, -1])


def _cpu_s(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


@pytest.mark.skipif(not Path("/proc").is_dir(), reason="needs /proc (Linux)")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_ends_a_long_simulation_within_two_seconds(tmp_path, sig):
    """1000 cycles are minutes of mujoco.rollout: the signal is taken between two chunks."""
    proc = subprocess.Popen(LOCUST + ["sim", "--cycles", "1000"], cwd=tmp_path, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    # the CPU time it has used: past the imports and the build, into the rollout
    wait_for(lambda: proc.poll() is not None or _cpu_s(proc.pid) >= 4.0, 60, "4 s of CPU in the simulation")
    assert proc.poll() is None, proc.stderr.read()
    t0 = time.monotonic()
    proc.send_signal(sig)
    try:
        _, stderr = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:   # the signal was not taken: no simulation left running
            proc.kill()
            proc.wait()
    seconds = time.monotonic() - t0
    assert seconds < 2.0, seconds
    assert proc.returncode != 0 and "Traceback" not in stderr, stderr
    assert list(tmp_path.iterdir()) == []
