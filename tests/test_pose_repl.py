"""`locust pose`, `locust repl` and mpremote's way into an idle robot, on the virtual robot.

The firmware's command loop lets Ctrl-C stop it while it idles (the REPL takes the console,
as on any MicroPython board) and ignores it while a hop runs. Everything runs the real
firmware on the MicroPython unix port behind a pseudo-terminal.
"""

from __future__ import annotations

import contextlib
import json
import os
import pty
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import serial
from click.testing import CliRunner

from locust.commands import cli
from locust.device.link import Link
from locust.device.plant import RecordingPlant
from locust.device.virtual import VirtualRobot
from locust.firmware import protocol
from waiting import wait_for

LOCUST = [sys.executable, "-m", "locust.commands"]
MPREMOTE = str(Path(sys.executable).with_name("mpremote"))


def _run(args, env, timeout=90):
    return subprocess.run(LOCUST + args, capture_output=True, text=True, env=env, timeout=timeout)


@contextlib.contextmanager
def _virtual(env, pwm_log=None, extra=()):
    """`locust virtual` in the background; yields its /dev/pts/N."""
    args = ["virtual", "--plant", "record", *extra] + (["--pwm-log", str(pwm_log)] if pwm_log else [])
    proc = subprocess.Popen(LOCUST + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        device = proc.stdout.readline().strip()
        assert device.startswith("/dev/pts/"), proc.stderr.read() if proc.poll() is not None else device
        yield device
    finally:
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=30)
    assert proc.returncode == 0


def _horn_angles(log: Path, n_writes: int, timeout_s: float = 5.0) -> dict[str, float]:
    """The last horn angle of each servo in a --pwm-log, once it holds n_writes rows."""
    def rows():
        found = [line.split(",") for line in log.read_text().splitlines()[2:]]
        return found if len(found) >= n_writes else None

    last = {}
    for row in wait_for(rows, timeout_s, f"{n_writes} PWM writes in {log}"):
        if row[3] and row[5]:
            last[row[3]] = float(row[5])
    return last


def _interact(args, env, steps, timeout_s=20.0):
    """Run `locust ARGS` in a pseudo-terminal; for each (send, expect): write, then read until expect.

    A step's ``send`` is repeated every second until ``expect`` shows: mpremote switches the
    terminal to raw mode just after its banner, and a Ctrl-C typed before that is lost.
    Returns (exit status, everything read).
    """
    master, slave = pty.openpty()
    proc = subprocess.Popen(LOCUST + args, stdin=slave, stdout=slave, stderr=slave, env=env, start_new_session=True)
    os.close(slave)
    seen = b""
    try:
        for send, expect in steps:
            deadline = time.monotonic() + timeout_s
            mark = len(seen)
            resend = 0.0
            while True:
                if send and time.monotonic() >= resend and (expect or not resend):
                    os.write(master, send)
                    resend = time.monotonic() + 1.0
                if not expect or expect in seen[mark:]:
                    break
                left = deadline - time.monotonic()
                assert left > 0, f"no {expect!r} after sending {send!r}: {seen[-2000:]!r}"
                if select.select([master], [], [], min(left, 0.2))[0]:
                    try:
                        seen += os.read(master, 4096)
                    except OSError:  # the command ended and closed the terminal
                        assert proc.poll() is not None
                        break
        code = proc.wait(timeout=timeout_s)
    finally:
        if proc.poll() is None:  # SIGTERM first: a --port sim virtual robot is stopped, not orphaned
            proc.terminate()
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        os.close(master)
    return code, seen


def _interpreters_in(flash_dir: Path) -> list[int]:
    """Pids of processes running in the virtual robot's flash folder (its interpreters)."""
    pids = []
    for proc in Path("/proc").iterdir():
        try:
            if proc.name.isdigit() and Path(os.readlink(proc / "cwd")) == flash_dir:
                pids.append(int(proc.name))
        except OSError:
            pass
    return pids


# -- locust pose -------------------------------------------------------------------------


def test_pose_moves_and_holds_the_horns_on_the_virtual_robot(env, tmp_path):
    log = tmp_path / "pwm.csv"
    with _virtual(env, pwm_log=log) as device:
        boot = 2  # the firmware starts both servos at rest: one write each
        assert _horn_angles(log, boot) == {"left": pytest.approx(0.0, abs=1e-3), "right": pytest.approx(0.0, abs=1e-3)}
        proc = _run(["pose", "--port", device, "-20", "10"], env)
        assert proc.returncode == 0, proc.stderr
        assert "left -20 deg, right 10 deg" in proc.stdout
        angles = _horn_angles(log, boot + 2)
        assert angles["left"] == pytest.approx(-20.0, abs=1e-3)
        assert angles["right"] == pytest.approx(10.0, abs=1e-3)  # the mirrored leg, same horn units

        far = _run(["pose", "--port", device, "60", "0"], env)  # beyond the servo travel (45)
        assert far.returncode == 2 and "error:" in far.stderr and "travel" in far.stderr
        assert "hint:" in far.stderr and "Traceback" not in far.stderr

        rest = _run(["pose", "--port", device, "--rest"], env)
        assert rest.returncode == 0, rest.stderr
        angles = _horn_angles(log, boot + 4)
        assert angles == {"left": pytest.approx(0.0, abs=1e-3), "right": pytest.approx(0.0, abs=1e-3)}
    rows = log.read_text().splitlines()[2:]
    assert len(rows) == boot + 4  # the refused pose moved nothing


def test_pose_port_sim(env, monkeypatch):
    """`--port sim`: the command's own virtual robot, whose plant shows the horn angles; it
    stops with the command, so the pose is said not to be held (it said "held")."""
    plant = RecordingPlant()
    monkeypatch.setenv("LOCUST_VIRTUAL_DIR", env["LOCUST_VIRTUAL_DIR"])
    monkeypatch.setattr("locust.device.session.make_plant", lambda *a, **k: plant)
    result = CliRunner().invoke(cli, ["pose", "--port", "sim", "-20", "10"])
    assert result.exit_code == 0, result.output
    assert "pose: left -20 deg, right 10 deg" in result.output
    assert "on sim; not held: this command's virtual robot stopped with it" in result.output
    assert "locust virtual" in result.output and "held until" not in result.output
    last = plant.commands[-1]
    assert (last.left_deg, last.right_deg) == (pytest.approx(-20.0, abs=1e-3), pytest.approx(10.0, abs=1e-3))


@pytest.mark.parametrize("args, message", [
    (["100", "0"], "error: bad pose: left 100"),
    (["0", "-90.5"], "error: bad pose: right -90.5"),
    (["nan", "0"], "error: bad pose: left nan"),
    (["--rest", "1", "2"], "or --rest, not both"),
    (["5"], "error: a pose needs both angles"),
])
def test_bad_pose_is_a_clear_error_before_any_port_opens(env, args, message):
    proc = _run(["pose", "--port", "sim", *args], env)
    assert proc.returncode == 2, proc.stderr
    assert message in proc.stderr and "error:" in proc.stderr and "hint:" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert "virtual robot on" not in proc.stderr  # refused before the virtual robot started


def test_pose_help_explains_assembly_and_trim():
    proc = _run(["pose", "--help"], dict(os.environ))
    assert proc.returncode == 0
    text = " ".join(proc.stdout.split())
    for words in ("assembly and trim", "--rest", "centre", "before the horns go on", "trim_deg", "travel_deg",
                  "-90..90", "locust pose -20 10"):
        assert words in text, words


# -- Ctrl-C, mpremote and the REPL ---------------------------------------------------------


def test_mpremote_exec_on_an_idle_robot_then_flash_and_hop(env, tmp_path):
    with _virtual(env) as device:
        with Link(device) as link:    # the firmware booted: it answers, then idles waiting for frames
            link.hello(wait_s=8)
        t0 = time.monotonic()
        proc = subprocess.run([MPREMOTE, "connect", device, "exec", "print(6*7)"],
                              capture_output=True, text=True, timeout=30)
        assert proc.returncode == 0, proc.stdout + proc.stderr
        assert proc.stdout.strip() == "42"
        assert time.monotonic() - t0 < 10

        # the board is at the REPL now: a command that needs the firmware says so
        stuck = _run(["pose", "--port", device, "--rest"], env)
        assert stuck.returncode == 2 and "MicroPython REPL" in stuck.stderr and "Ctrl-D" in stuck.stderr

        # `hop` soft-resets a board it finds at the REPL (as mpremote does) and goes on
        hop = _run(["hop", "--port", device, "--cycles", "1", "--json", "--out", str(tmp_path / "run0")], env)
        assert hop.returncode == 0, hop.stderr
        rec = json.loads(hop.stdout)
        assert rec["status"] == "complete" and len(rec["phases"]) == 2

        # `locust flash` gets in from the REPL and restarts the command loop; `hop` works again
        mp = subprocess.run([MPREMOTE, "connect", device, "exec", "print(6*7)"], capture_output=True, text=True,
                            timeout=30)
        assert mp.stdout.strip() == "42", mp.stdout + mp.stderr
        flashed = _run(["flash", "--port", device], env)
        assert flashed.returncode == 0, flashed.stderr
        hop = _run(["hop", "--port", device, "--cycles", "1", "--json", "--out", str(tmp_path / "run")], env)
        assert hop.returncode == 0, hop.stderr
        rec = json.loads(hop.stdout)
        assert rec["status"] == "complete" and len(rec["phases"]) == 2


def test_mpremote_sees_a_boards_line_ends_and_file_sizes_on_the_virtual_robot(env):
    """mpremote on the virtual robot as on a board: `exec` output ends its lines CR LF (bare LF
    before: a staircase in a terminal), `fs ls` gives each flashed file its size in bytes (0
    before: the unix port's ilistdir has no size), and the firmware's frames still end in a
    bare LF, as a board sends them through sys.stdout.buffer."""
    flash_dir = Path(env["LOCUST_VIRTUAL_DIR"]) / "flash"
    with _virtual(env) as device:
        with serial.Serial(device, timeout=0.2) as port:
            port.write(protocol.encode({"id": 7, "cmd": "ping"}))
            seen = b""
            deadline = time.monotonic() + 10
            while not (b'"id":7' in seen and seen.endswith(b"\n")) and time.monotonic() < deadline:
                seen += port.read(256)
        at = seen.find(b'"id":7')
        start, end = seen.rfind(b"$", 0, at), seen.find(b"\n", at)
        reply = seen[start:end + 1]
        assert protocol.decode(reply[:-1])["id"] == 7 and reply[-2:-1] != b"\r", seen

        out = subprocess.run([MPREMOTE, "connect", device, "exec", "print(1); print(2)"], capture_output=True,
                             timeout=30)
        assert out.returncode == 0, out.stderr
        assert out.stdout == b"1\r\n2\r\n"

        ls = subprocess.run([MPREMOTE, "connect", device, "fs", "ls"], capture_output=True, text=True, timeout=30)
        assert ls.returncode == 0, ls.stderr
        listed = {name: int(size) for size, name in (line.split() for line in ls.stdout.splitlines()[1:])}
        assert listed == {p.name: p.stat().st_size for p in flash_dir.iterdir() if p.is_file()}
        assert min(listed.values()) > 0


def test_a_hop_on_locust_virtual_records_the_robot_it_simulates(env, tmp_path):
    """`locust virtual --preset medium`, then `hop --port /dev/pts/N`: run.json records medium
    (the virtual robot's), not the hop's own default."""
    with _virtual(env, extra=("--preset", "medium")) as device:
        hop = _run(["hop", "--port", device, "--cycles", "1", "--push-ms", "50", "--wait-ms", "50",
                    "--out", str(tmp_path / "run")], env)
        assert hop.returncode == 0, hop.stderr
        first, second = hop.stderr.splitlines()[:2]
        assert first == f"output folder: {tmp_path / 'run'}"        # where the record goes, first
        assert second == f"robot: medium, the one the virtual robot on {device} simulates"
    robot = json.loads((tmp_path / "run" / "run.json").read_text())["robot"]
    assert (robot["preset"], robot["leg_set"]) == ("medium", "medium"), robot


def test_a_virtual_robot_with_nothing_flashed_says_so(tmp_path):
    """`hop --port sim` before any `locust flash --port sim`: which command flashes it, and no
    virtual robot started for nothing (no pty named, no run folder)."""
    env = dict(os.environ, LOCUST_VIRTUAL_DIR=str(tmp_path / "virtual"))
    res = _run(["hop", "--port", "sim", "--cycles", "1", "--out", str(tmp_path / "run")], env)
    assert res.returncode == 2, res.stderr
    assert "error: nothing flashed: run `locust flash --port sim`" in res.stderr
    assert "/dev/pts" not in res.stderr and "REPL" not in res.stderr
    assert not (tmp_path / "run").exists()


def test_a_hop_the_board_never_answered_leaves_no_run_folder(tmp_path):
    """A port with no firmware behind it (a bare pty: nothing answers the handshake): the
    error, and no data/runs/<timestamp>/ in the current folder (run.json is written only
    once the board has answered)."""
    master, slave = pty.openpty()
    try:
        res = subprocess.run(LOCUST + ["hop", "--port", os.ttyname(slave), "--cycles", "1"], cwd=tmp_path,
                             capture_output=True, text=True, timeout=60)
    finally:
        os.close(master)
        os.close(slave)
    assert res.returncode == 2, res.stderr
    first = res.stderr.splitlines()[0]
    assert first.startswith("output folder: data/runs/"), res.stderr
    assert "error: no locust firmware answered" in res.stderr
    # the error says what became of the folder the first line named (it said nothing of it)
    assert f"no run record was written, so {first.split(': ', 1)[1]} was not kept" in res.stderr
    assert list(tmp_path.iterdir()) == []      # not data/, not data/runs/, not the timestamp folder


def test_ctrl_c_stops_the_idle_loop_not_a_hop_and_ctrl_d_resumes(env):
    flash_dir = Path(env["LOCUST_VIRTUAL_DIR"]) / "flash"
    with VirtualRobot(flash_dir, RecordingPlant()) as vr, Link(vr.device_path) as link:
        link.hello(wait_s=8)
        link.start_heartbeat(0.05)
        writes = len(vr.pwm_writes)
        hop = link.call("hop", cycles=2, push_ms=100, wait_ms=150, heartbeat_ms=500)
        wait_for(lambda: any(w.servo and abs(w.horn_deg) > 1 for w in list(vr.pwm_writes)[writes:]), 5,
                 "the hop's first push")
        link.write(b"\r\x03\n")  # mid-hop: a stray Ctrl-C is a byte of a bad frame
        done = None
        while done is None:
            ev = link.events.get(timeout=5)
            if ev.get("ev") == protocol.EV_DONE and ev.get("hop") == hop["id"]:
                done = ev
        link.stop_heartbeat()
        assert done["status"] == protocol.HOP_COMPLETE and done["phases"] == 4
        assert protocol.E_FRAME in [m.get("error") for m in link.unsolicited]

        assert link.call("pose", left_deg=10, right_deg=10)["ok"]
        t_ctrl_c = vr.now_s()
        link.write(b"\r\x03")  # idle: the loop stops, the servos rest, the REPL has the console
        wait_for(lambda: link.write(b"\r\n") or link.repl_seen, 5, "the REPL's prompt after Ctrl-C", poll_s=0.1)

        def rest_writes():   # the PWM writes reach the host through a FIFO
            rest = [w for w in vr.pwm_writes if w.servo and w.t_written_s > t_ctrl_c]
            return rest if len(rest) >= 2 else None

        rest = wait_for(rest_writes, 5, "the servos' rest after Ctrl-C")
        assert {w.servo for w in rest} == {"left", "right"}
        assert all(abs(w.horn_deg) < 1e-6 for w in rest)

        boots = vr.boots
        link.write(b"\x04")  # Ctrl-D at the >>> prompt: soft reset, main.py runs the loop again
        assert link.hello(wait_s=8)["ok"]
        assert vr.boots == boots + 1
        assert link.call("ping")["ok"]


def test_locust_repl_in_a_terminal(env):
    with _virtual(env) as device:
        code, seen = _interact(["repl", "--port", device], env, [
            (b"", b"exit this shell"),  # mpremote's banner
            (b"\x03", b">>> "),  # Ctrl-C: out of the command loop
            (b"print(6*7)\r", b"42\r\n>>> "),    # a board's line end: no staircase in the terminal
            (b"\x1d", b""),  # Ctrl-]: leave
        ])
        assert code == 0, seen[-2000:]
        # Ctrl-D restarts the firmware: the robot answers again
        with serial.Serial(device) as port:
            port.write(b"\x04")
        with Link(device) as link:
            assert link.hello(wait_s=8)["ok"]


def test_locust_repl_port_sim_starts_a_virtual_robot(env):
    code, seen = _interact(["repl", "--port", "sim"], env, [
        (b"", b"exit this shell"),
        (b"\x03", b">>> "),
        (b"import sys; print(sys.implementation.name)\r", b"micropython"),
        (b"\x18", b""),  # Ctrl-X: leave
    ])
    assert code == 0, seen[-2000:]
    assert b"virtual robot on /dev/pts/" in seen


@pytest.mark.parametrize("sig", [signal.SIGHUP, signal.SIGTERM], ids=["SIGHUP", "SIGTERM"])
def test_locust_repl_port_sim_closed_terminal_leaves_no_interpreter(env, sig):
    flash_dir = (Path(env["LOCUST_VIRTUAL_DIR"]) / "flash").resolve()
    assert not _interpreters_in(flash_dir)
    master, slave = pty.openpty()
    proc = subprocess.Popen(LOCUST + ["repl", "--port", "sim"], stdin=slave, stdout=slave, stderr=slave, env=env,
                            start_new_session=True)
    os.close(slave)
    try:
        seen = b""
        deadline = time.monotonic() + 20
        while b"exit this shell" not in seen and time.monotonic() < deadline:
            if select.select([master], [], [], 0.2)[0]:
                seen += os.read(master, 4096)
        assert b"exit this shell" in seen, seen
        assert _interpreters_in(flash_dir)
        proc.send_signal(sig)
        proc.wait(timeout=15)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
    wait_for(lambda: not _interpreters_in(flash_dir), 5, "the MicroPython interpreters to end with the shell")


def test_repl_help_and_no_terminal(env):
    text = " ".join(_run(["repl", "--help"], env).stdout.split())
    for words in ("Ctrl-] or Ctrl-X", "Ctrl-C", "Ctrl-D", "mpremote connect PORT repl", "locust virtual"):
        assert words in text, words
    proc = subprocess.run(LOCUST + ["repl", "--port", "sim"], stdin=subprocess.DEVNULL, capture_output=True,
                          text=True, env=env, timeout=30)
    assert proc.returncode == 2 and "needs a terminal" in proc.stderr and "hint:" in proc.stderr
    assert "virtual robot on" not in proc.stderr and "Traceback" not in proc.stderr
