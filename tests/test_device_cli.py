"""The acceptance runs, as a user types them: `locust flash/hop/virtual` in subprocesses."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import serial

from locust.device.link import Link
from locust.firmware import protocol

sys.path.insert(0, str(Path(__file__).resolve().parent / "firmware"))
from lcg import Lcg

from waiting import wait_for

LOCUST = [sys.executable, "-m", "locust.commands"]


def _run(args, env, timeout=90):
    return subprocess.run(LOCUST + args, capture_output=True, text=True, env=env, timeout=timeout)




def test_flash_then_hop_six_cycles_on_time(env, tmp_path, board_timing):
    proc = _run(["hop", "--port", "sim", "--cycles", "6", "--json", "--plant", "record",
                 "--out", str(tmp_path / "run")], env)
    assert proc.returncode == 0, proc.stderr
    rec = json.loads(proc.stdout)
    assert rec["status"] == "complete" and rec["firmware_version"] == protocol.VERSION
    assert len(rec["phases"]) == 12
    assert [(p["cycle"], p["phase"]) for p in rec["phases"][:2]] == [(1, "push"), (1, "wait")]
    assert rec["phases"][-1]["commanded_ms"] == 5 * 1300 + 300
    assert rec["jitter"]["max_abs_ms"] == pytest.approx(max(abs(p["measured_ms"] - p["commanded_ms"])
                                                            for p in rec["phases"]), abs=1e-3)
    assert rec["ticks_wrapped"]  # the virtual robot's 30-bit ticks wrap 7 s after its boot
    assert json.loads((tmp_path / "run" / "run.json").read_text()) == rec
    board_timing([(p["measured_ms"] - p["commanded_ms"]) * 1000 for p in rec["phases"]])


def test_hop_on_the_virtual_robot_lists_and_prints_its_simulated_hops(env, tmp_path):
    """`hop --port sim --preset small --cycles 2 --video --json`: two simulated hops, in the
    JSON and in the table on stderr, each within 0.1 mm of `locust sim`'s (the live model
    runs the firmware's commands; the rollout the schedule's)."""
    sim = json.loads(_run(["sim", "--preset", "small", "--cycles", "2", "--json"], env).stdout)
    proc = _run(["hop", "--port", "sim", "--preset", "small", "--cycles", "2", "--json", "--video",
                 str(tmp_path / "v.mp4"), "--fps", "10", "--out", str(tmp_path / "run")], env, timeout=240)
    assert proc.returncode == 0, proc.stderr
    simulated = json.loads(proc.stdout)["simulated"]
    assert simulated["valid"] and len(simulated["hops"]) == 2
    for live, planned in zip(simulated["hops"], sim["hops"], strict=True):
        assert live["distance_m"] == pytest.approx(planned["distance_m"], abs=1e-4)
    rows = [line.split() for line in proc.stderr.splitlines() if line.split()[:1] in (["1"], ["2"])]
    assert [float(r[1]) for r in rows] == pytest.approx([h["distance_m"] * 1000 for h in simulated["hops"]],
                                                        abs=0.006)


def test_locust_virtual_prints_each_hop_as_it_goes(env, tmp_path):
    """`locust virtual` (the live MuJoCo model) prints each hop's row while it runs, not only at
    exit: both hops of a two-cycle `hop` on its pty show while it is still running, each the
    distance the hop's own record of the simulation gives (within the printed 0.005 mm)."""
    import threading

    proc = subprocess.Popen(LOCUST + ["virtual", "--preset", "seed"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env)
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(iter(proc.stderr.readline, "")), daemon=True)
    try:
        device = proc.stdout.readline().strip()
        assert device.startswith("/dev/pts/"), device
        reader.start()
        hop = _run(["hop", "--port", device, "--preset", "seed", "--cycles", "2", "--out", str(tmp_path / "run")], env)
        assert hop.returncode == 0, hop.stderr
        def printed_rows():
            rows = [ln.split() for ln in list(lines) if ln.split()[:1] in (["1"], ["2"])]
            return rows if len(rows) >= 2 else None

        rows = wait_for(printed_rows, 30, "two rows printed", poll_s=0.1)
        assert proc.poll() is None               # still running: printed as it goes
        assert [r[0] for r in rows] == ["1", "2"], lines
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=60)
    final = [ln.split() for ln in lines if ln.split()[:1] in (["1"], ["2"])][-2:]
    assert [float(r[1]) for r in rows] == pytest.approx([float(r[1]) for r in final], abs=0.006)


def test_flash_refuses_a_pin_the_chip_cannot_drive_and_writes_nothing(env, tmp_path):
    """GPIO6 of a classic ESP32 is its SPI flash: refused with the usable pins as the hint, before
    any file is written; the firmware on the board is untouched and still hops."""
    flash_dir = Path(env["LOCUST_VIRTUAL_DIR"]) / "flash"
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in flash_dir.iterdir()}
    proc = _run(["flash", "--port", "sim", "--servo", "left.pin=6"], env)
    assert proc.returncode == 2, proc.stderr
    assert "error: --servo left.pin=6 refused for the ESP32" in proc.stderr and "SPI flash" in proc.stderr
    assert "hint: the ESP32's pins that can drive a servo: 4, 13, 14, 18, 19" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in flash_dir.iterdir()} == before
    hop = _run(["hop", "--port", "sim", "--cycles", "1", "--push-ms", "50", "--wait-ms", "50", "--plant", "record",
                "--out", str(tmp_path / "run")], env)
    assert hop.returncode == 0, hop.stderr


@pytest.fixture()
def flash_config(env):
    """The virtual board's config.json; put back as flashed after the test."""
    path = Path(env["LOCUST_VIRTUAL_DIR"]) / "flash" / "config.json"
    saved = path.read_bytes()
    yield path
    path.write_bytes(saved)


def test_flash_refuses_a_travel_beyond_the_trim_with_a_hint_about_the_two(env, flash_config):
    """A 2.5 deg trim leaves 87.5 deg of travel on a 180 deg pulse range: a travel of 90 is
    refused with the trim and travel in the hint (not the pins, which are fine), nothing is
    written; the trim set to 0 first in the same flash lets the travel go to 90."""
    flash_dir = flash_config.parent
    trimmed = _run(["config", "--port", "sim", "--set", "left.trim_deg=2.5"], env)
    assert trimmed.returncode == 0, trimmed.stderr
    before = {p.name: p.read_bytes() for p in flash_dir.iterdir()}
    proc = _run(["flash", "--port", "sim", "--servo", "left.travel_deg=90"], env)
    assert proc.returncode == 2, proc.stderr
    assert "error: --servo left.travel_deg=90 refused for the ESP32: left: travel plus trim exceed" in proc.stderr
    assert "hint: left has trim 2.5 deg and travel 45 deg; travel plus |trim| may be at most 90 deg" in proc.stderr
    assert "pins" not in proc.stderr and "Traceback" not in proc.stderr
    assert {p.name: p.read_bytes() for p in flash_dir.iterdir()} == before
    done = _run(["flash", "--port", "sim", "--servo", "left.trim_deg=0", "--servo", "left.travel_deg=90"], env)
    assert done.returncode == 0, done.stderr
    saved = json.loads(flash_config.read_text())["left"]
    assert (saved["trim_deg"], saved["travel_deg"]) == (0, 90)


def test_ctrl_c_keeps_an_incomplete_record(env, tmp_path):
    out = tmp_path / "D"
    proc = subprocess.Popen(LOCUST + ["hop", "--port", "sim", "--cycles", "6", "--plant", "record", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    wait_for(lambda: len(json.loads((out / "run.json").read_text())["phases"]) >= 3, 30, "three phases in run.json")
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=30)
    assert proc.returncode == 2, stderr
    assert "interrupted" in stderr and "Traceback" not in stderr
    rec = json.loads((out / "run.json").read_text())
    assert rec["status"] == "incomplete"
    assert 3 <= len(rec["phases"]) < 12
    assert [p["commanded_ms"] for p in rec["phases"]] == [0, 300, 1300, 1600, 2600, 2900][:len(rec["phases"])]


def test_bad_input_is_a_clear_error_and_nothing_is_lost(env, tmp_path):
    out = tmp_path / "bad"
    proc = _run(["hop", "--port", "sim", "--push-deg", "-80", "--plant", "record", "--out", str(out)], env)
    assert proc.returncode == 2 and "error:" in proc.stderr and "out_of_range" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert json.loads((out / "run.json").read_text())["status"] == "error"
    again = _run(["hop", "--port", "sim", "--plant", "record", "--out", str(out)], env)
    assert again.returncode == 2 and "never overwritten" in again.stderr
    assert json.loads((out / "run.json").read_text())["status"] == "error"  # untouched


def test_two_hops_into_one_folder_never_share_it(env, tmp_path):
    """Two `hop --out same` at once: one runs, the other is refused before it starts (the folder
    is locked for the run), and the record that is kept is the first's, whole."""
    out = tmp_path / "same"
    args = ["hop", "--port", "sim", "--cycles", "1", "--push-ms", "50", "--wait-ms", "50", "--plant", "record",
            "--json", "--out", str(out)]
    procs = [subprocess.Popen(LOCUST + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
             for _ in range(2)]
    results = [(p.wait(timeout=90), *p.communicate()) for p in procs]
    codes = sorted(rc for rc, _, _ in results)
    assert codes == [0, 2], results
    winner = next(o for rc, o, _ in results if rc == 0)
    loser = next(e for rc, _, e in results if rc == 2)
    assert "error:" in loser and "hint:" in loser and "Traceback" not in loser
    assert ("another process is writing in" in loser) or ("never overwritten" in loser)
    assert json.loads((out / "run.json").read_text()) == json.loads(winner)


def _filmed_hop(env, folder: Path, fps: int = 60) -> subprocess.Popen:
    return subprocess.Popen(LOCUST + ["hop", "--port", "sim", "--cycles", "1", "--push-ms", "100", "--wait-ms", "100",
                                      "--video", str(folder / "v.mp4"), "--fps", str(fps), "--out", str(folder / "r")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def _check_what_was_kept(proc: subprocess.Popen, folder: Path) -> tuple[int, dict | None]:
    """After a TERM: no crash, no temporary video, and a record that says whether the video was kept."""
    try:
        _, stderr = proc.communicate(timeout=150)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGABRT)
        _, stderr = proc.communicate(timeout=10)
        raise AssertionError("hung: " + stderr[-6000:]) from None
    assert proc.returncode not in (-11, -6, 134, 139), stderr   # no segfault, no abort
    assert "Fatal Python error" not in stderr and "Traceback" not in stderr, stderr
    assert not [p.name for p in folder.iterdir() if p.name.startswith(".v.mp4")]   # no temporary left
    record = folder / "r" / "run.json"
    if not record.exists():
        assert not (folder / "v.mp4").exists()
        return proc.returncode, None
    rec = json.loads(record.read_text())
    if (folder / "v.mp4").exists():   # (a TERM during the hop: the robot to rest, the video of it finished)
        assert "video was not kept" not in (rec["message"] or "")
    else:   # the record must not say complete about a run whose video was dropped
        assert rec["status"] != "complete" and "the video was not kept" in rec["message"], rec
    return proc.returncode, rec


def test_term_while_the_video_is_finished_keeps_a_true_record(env, tmp_path):
    """TERM once the hop is done and its video is still being rendered: exit 2 with error:/hint:,
    the record keeps both phases and says the video was not kept (it said complete, and the
    interpreter crashed, before). A TERM that lands as the hop returns is the hop's: the video
    is finished and kept, and the record says the hop was interrupted."""
    proc = _filmed_hop(env, tmp_path, fps=120)
    wait_for(lambda: proc.poll() is not None
             or json.loads((tmp_path / "r" / "run.json").read_text())["status"] == "complete", 90,
             "the record to say complete")
    proc.send_signal(signal.SIGTERM)
    rc, rec = _check_what_was_kept(proc, tmp_path)
    assert rec is not None and len(rec["phases"]) == 2
    if rc != 0:   # (a machine fast enough had the video written already: rc 0, video kept, record complete)
        assert rc == 2
        # the TERM came as the video was being finished: dropped, the record incomplete; or
        # too late to drop it, the video kept beside a record the TERM changed nothing in
        assert (rec["status"] == "incomplete" and rec["message"]) or \
            (rec["status"] == "complete" and (tmp_path / "v.mp4").exists()), rec


def test_a_term_once_the_video_is_finished_leaves_the_record_as_the_video_is(env, tmp_path, monkeypatch):
    """The TERM lands after the live simulation's close has written the video (its last frames,
    its index and read-back take a while, and look at no cancel): the video is kept, so the
    record stays complete and does not say it was dropped; the command exits 2 saying the video
    was kept (it said "the video was not kept" beside a whole v.mp4). The moment is pinned: the
    plant signals the command's main thread once its video is in place, then waits for the
    cancel the signal brings."""
    import threading

    import cv2
    from click.testing import CliRunner

    from locust.commands import cli
    from locust.device.plant import MujocoPlant

    class TermOnceFilmed(MujocoPlant):
        def __init__(self, *args):
            super().__init__(*args)
            self.cancelled = threading.Event()

        def close(self, t_s):
            summary = super().close(t_s)     # the video written, read back and in place
            signal.pthread_kill(threading.main_thread().ident, signal.SIGTERM)
            assert self.cancelled.wait(timeout=30)
            return summary

        def cancel(self):
            self.cancelled.set()
            super().cancel()

    monkeypatch.setenv("LOCUST_VIRTUAL_DIR", env["LOCUST_VIRTUAL_DIR"])
    monkeypatch.setattr("locust.device.session.make_plant", lambda kind, robot, video, fps: TermOnceFilmed(robot, video,
                                                                                                          fps))
    video = tmp_path / "v.mp4"
    res = CliRunner().invoke(cli, ["hop", "--port", "sim", "--cycles", "1", "--push-ms", "100", "--wait-ms", "100",
                                   "--video", str(video), "--fps", "10", "--out", str(tmp_path / "r")])
    assert res.exit_code == 2, res.output
    assert "error: interrupted as the virtual robot stopped, once its video was finished: the video was kept" \
        in res.output and "hint:" in res.output and "not kept" not in res.output
    rec = json.loads((tmp_path / "r" / "run.json").read_text())
    assert rec["status"] == "complete" and rec["message"] is None and len(rec["phases"]) == 2
    capture = cv2.VideoCapture(str(video))
    frames = 0
    while capture.read()[0]:
        frames += 1
    capture.release()
    truth = video.with_name("v.truth.csv").read_text().splitlines()[2:]   # one row a frame, after two header lines
    assert frames == len(truth) > 0


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
def test_term_at_a_random_moment_of_a_filmed_hop(env, tmp_path, seed):
    """A TERM anywhere from start-up to the video's end (about 40 s in all)."""
    import random

    proc = _filmed_hop(env, tmp_path)
    time.sleep(random.Random(seed).uniform(0.5, 9.0))
    proc.send_signal(signal.SIGTERM)
    _check_what_was_kept(proc, tmp_path)


def test_video_frames_are_bounded_before_anything_starts(env, tmp_path):
    proc = _run(["hop", "--port", "sim", "--cycles", "100", "--video", str(tmp_path / "v.mp4"), "--fps", "1000",
                 "--out", str(tmp_path / "r")], env)
    assert proc.returncode == 2 and "130500 frames, over the 10000" in proc.stderr and "hint:" in proc.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args, message", [
    (["hop", "--push-deg", "1e308"], "'1e308' is above 90"),
    (["hop", "--push-deg", "nan"], "'nan' is not a finite number"),
    (["config", "--set", "left.trim_deg=nan"], "nan is not a finite number; nothing was sent"),
])
def test_a_wrong_value_is_refused_before_it_is_sent(env, tmp_path, args, message):
    proc = _run([*args, "--port", "sim", *(["--out", str(tmp_path / "r")] if args[0] == "hop" else [])], env)
    assert proc.returncode == 2 and message in proc.stderr and "hint:" in proc.stderr, proc.stderr
    assert "virtual robot on" not in proc.stderr   # refused before the (virtual) board was opened
    assert list(tmp_path.iterdir()) == []


def _fuzz_frames(n, seed=4):
    """n lines, each answered by exactly one reply: random, corrupted and out-of-range frames.

    No 0x03: Ctrl-C stops the idle command loop by design, as on any MicroPython board
    (tests/test_pose_repl.py checks that, and that a hop ignores it).
    """
    rng = Lcg(seed)
    frames = []
    for i in range(n):
        kind = i % 8
        if kind == 0:
            line = rng.bytes(1 + rng.below(200))
        elif kind == 1:  # a valid frame with one flipped bit
            good = bytearray(protocol.encode({"id": i, "cmd": "pose", "left_deg": 1, "right_deg": 1})[:-1])
            good[1 + rng.below(len(good) - 2)] ^= 1 << rng.below(7)
            line = bytes(good)
        elif kind == 2:
            body = rng.bytes(rng.below(80))
            line = b"$" + body + b"*" + protocol.crc_hex(body).encode()
        elif kind == 3:
            line = b"$" + rng.bytes(300 + rng.below(2000))
        elif kind == 4:
            line = protocol.encode({"id": i, "cmd": "pose", "left_deg": rng.below(400) - 200,
                                    "right_deg": rng.below(400) - 200})[:-1]
        elif kind == 5:
            line = protocol.encode({"id": i, "cmd": ["hop", "fly", "config", "report"][rng.below(4)],
                                    "cycles": rng.below(5) - 1, "key": "left.travel_deg", "value": 200})[:-1]
        elif kind == 6:
            line = protocol.encode({"id": rng.next(), "cmd": "pose", "left_deg": 1e308 * 10, "right_deg": "x"})[:-1]
        else:
            line = bytes([4, 1, 2, 5, 0x1B]) + rng.bytes(8)  # the REPL's other control characters
        line = line.replace(b"\n", b"").replace(b"\r", b"").replace(b"\x03", b"?") or b"?"
        frames.append(line + b"\n")
    return frames


def test_fuzzed_virtual_robot_survives_and_then_hops(env, tmp_path, board_timing):
    log = tmp_path / "pwm.csv"
    vproc = subprocess.Popen(LOCUST + ["virtual", "--plant", "record", "--pwm-log", str(log)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        device = vproc.stdout.readline().strip()
        assert device.startswith("/dev/pts/")
        frames = _fuzz_frames(3000)
        replies = []
        with Link(device) as link:   # the firmware booted: it answers, then idles waiting for frames
            link.hello(wait_s=8)
        with serial.Serial(device, timeout=2) as port:
            port.reset_input_buffer()
            reader = protocol.LineReader(limit=1 << 16)
            for start in range(0, len(frames), 20):
                batch = frames[start:start + 20]
                port.write(b"".join(batch))
                while len(replies) < start + len(batch):
                    data = port.read(max(1, port.in_waiting))
                    assert data, f"no reply after {len(replies)} of {len(frames)} frames"
                    replies += [protocol.decode(line) for line in reader.feed(data) if line]
        assert len(replies) == len(frames)  # one reply each: nothing crashed, nothing dropped
        assert not [r for r in replies if r.get("error") == protocol.E_INTERNAL]
        assert sum(r.get("error") == protocol.E_CHECKSUM for r in replies) >= 375
        assert sum(r.get("error") == protocol.E_TOO_LONG for r in replies) == 375
        moved = sum(1 for r in replies if r.get("ok") and "left_deg" in r)
        assert moved > 0
        hop = _run(["hop", "--port", device, "--cycles", "1", "--json", "--out", str(tmp_path / "after")], env)
        assert hop.returncode == 0, hop.stderr
        rec = json.loads(hop.stdout)
        assert rec["status"] == "complete" and len(rec["phases"]) == 2
        errors_us = [p["error_ms"] * 1000 for p in rec["phases"]]
    finally:
        vproc.send_signal(signal.SIGTERM)
        vproc.communicate(timeout=30)
    assert vproc.returncode == 0
    board_timing(errors_us)
    rows = [line.split(",") for line in log.read_text().splitlines()[2:]]
    angles = [float(r[5]) for r in rows if r[5]]
    assert len(angles) > 2 * moved
    assert max(abs(a) for a in angles) <= 45.0 + 1e-3  # never outside the servo travel


@pytest.mark.slow
def test_thousand_cycle_hop_runs_in_a_boards_heap(env, tmp_path):
    """1000 cycles (2000 phases, 40 s) on the virtual robot's 224 kB heap: the phases are
    computed when due, not listed up front (the two lists of 2000 tuples alone do not fit)."""
    proc = _run(["hop", "--port", "sim", "--cycles", "1000", "--push-ms", "20", "--wait-ms", "20", "--json",
                 "--plant", "record", "--out", str(tmp_path / "run")], env, timeout=300)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr[-3000:]
    rec = json.loads(proc.stdout)
    assert rec["status"] == "complete" and len(rec["phases"]) == 2000
    assert rec["phases"][-1]["commanded_ms"] == 999 * 40 + 20
