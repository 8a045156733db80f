"""The robot's serial port: one program at a time, a heartbeat that has stopped before the port
closes, and a port that goes away (a pulled cable) named as such.

A second program on the port (mpremote's REPL, a serial monitor, another locust command) takes
pieces of the board's replies; each command refuses a port another program holds, naming it.
The runs use the virtual robot (the real firmware behind a pseudo-terminal) and, where the
cable must go at one chosen message, a SYNTHETIC board double on a pty that speaks the real
wire format and closes its end there.
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
import threading
import tty
from pathlib import Path

import serial.serialposix as SP
from serial.serialutil import to_bytes

from locust.device.link import Link
from locust.firmware import config as fw_config
from locust.firmware import protocol
from waiting import wait_for

LOCUST = [sys.executable, "-m", "locust.commands"]
SHORT_HOP = ["--cycles", "1", "--push-ms", "50", "--wait-ms", "50"]
# a serial monitor that takes no lock (screen, cat, minicom): it opens the port and reads
MONITOR = ("import serial, sys\nport = serial.Serial(sys.argv[1], timeout=0.05)\n"
           "while True:\n    port.read(100)\n")


def _run(args, env, timeout=90):
    return subprocess.run(LOCUST + args, capture_output=True, text=True, env=env, timeout=timeout)


@contextlib.contextmanager
def _virtual(env, *extra):
    """`locust virtual` in the background; yields (its /dev/pts/N, its process)."""
    proc = subprocess.Popen(LOCUST + ["virtual", "--plant", "record", *extra], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)
    try:
        device = proc.stdout.readline().strip()
        assert device.startswith("/dev/pts/"), proc.stderr.read() if proc.poll() is not None else device
        yield device, proc
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=30)


def _has_open(pid: int, device: str) -> bool:
    fds = Path(f"/proc/{pid}/fd")
    return any(os.readlink(fd) == device for fd in fds.iterdir())


@contextlib.contextmanager
def _second_program(kind: str, device: str):
    """Another program with the port open, once it has it: mpremote's REPL (which locks the
    port, as locust does) in a terminal of its own, or a monitor that takes no lock."""
    master = None
    if kind == "mpremote":
        master, slave = pty.openpty()
        proc = subprocess.Popen([sys.executable, "-m", "mpremote", "connect", device, "repl"], stdin=slave,
                                stdout=slave, stderr=slave, start_new_session=True)
        os.close(slave)
    else:
        proc = subprocess.Popen([sys.executable, "-c", MONITOR, device], stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE)
    try:
        wait_for(lambda: proc.poll() is None and _has_open(proc.pid, device), 30, f"{kind} to open {device}")
        yield proc
    finally:
        proc.terminate()
        proc.wait(timeout=15)
        if master is not None:
            os.close(master)


def _hop_completes(env, device, folder):
    hop = _run(["hop", "--port", device, *SHORT_HOP, "--json", "--out", str(folder)], env)
    assert hop.returncode == 0, hop.stderr
    rec = json.loads(hop.stdout)
    assert rec["status"] == "complete" and len(rec["phases"]) == 2


# -- one program at a time ------------------------------------------------------------------


def test_hop_config_and_pose_refuse_a_port_mpremote_or_a_monitor_holds(env, tmp_path):
    """mpremote's REPL, then a serial monitor, on the virtual robot's pty: `hop`, `config` and
    `pose` each stop at once with "port in use by another program" naming that program's pid
    (never the virtual robot's own), exit 2, and a hop leaves no run folder (it said "no
    reply ... run `locust flash`" and "no locust firmware answered" before). Once the other
    program has gone, the same hop completes: the board was well all along."""
    with _virtual(env) as (device, robot):
        for kind in ("mpremote", "monitor"):
            with _second_program(kind, device) as other:
                for args in (["hop", *SHORT_HOP, "--out", str(tmp_path / kind)], ["config"], ["pose", "0", "0"]):
                    res = _run([args[0], "--port", device, *args[1:]], env)
                    assert res.returncode == 2, (kind, args, res.stderr)
                    said = f"error: port in use by another program: {device} is open in pid {other.pid} ("
                    assert said in res.stderr, (kind, args, res.stderr)
                    assert f"pid {robot.pid}" not in res.stderr                # the board end is not "another program"
                    assert "hint: one program at a time talks to the robot" in res.stderr
                    assert "Traceback" not in res.stderr
                assert not (tmp_path / kind).exists()
            _hop_completes(env, device, tmp_path / f"after-{kind}")


def test_a_second_locust_command_is_refused_while_a_hop_runs_and_the_hop_completes(env, tmp_path):
    """A `locust config` while a hop runs on the same port is refused, naming the hop's
    process (pyserial's lock, which mpremote takes too); the hop, undisturbed, records every
    phase as complete (a config that shared the port took the hop's events: incomplete)."""
    out = tmp_path / "run"
    with _virtual(env) as (device, _):
        hop = subprocess.Popen(LOCUST + ["hop", "--port", device, "--cycles", "8", "--push-ms", "100",
                                         "--wait-ms", "1000", "--json", "--out", str(out)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        try:
            wait_for(lambda: json.loads((out / "run.json").read_text())["phases"], 60, "the hop's first phase")
            config = _run(["config", "--port", device], env)
            assert hop.poll() is None, "the hop ended before `locust config` ran: the test proves nothing"
            stdout, stderr = hop.communicate(timeout=60)
        finally:
            if hop.poll() is None:
                hop.kill()
                hop.communicate()
    assert config.returncode == 2, config.stderr
    assert f"error: port in use by another program: {device} is open in pid {hop.pid} (" in config.stderr
    assert "hop --port" in config.stderr and "Traceback" not in config.stderr
    assert hop.returncode == 0, stderr
    rec = json.loads(stdout)
    assert rec["status"] == "complete" and len(rec["phases"]) == 16


# -- the heartbeat and the port's close -------------------------------------------------------


def test_no_heartbeat_write_is_in_progress_when_the_port_closes(monkeypatch):
    """A ping already past pyserial's is-open check (its thread preempted there) when the link
    closes: close() waits for it, so the port never closes under a write (Ctrl-C in a long
    `hop --port sim` printed the heartbeat thread's TypeError from pyserial's write, the port
    closed under it, before the clean error)."""
    ping = protocol.encode({"id": 0, "cmd": "ping"})
    inside = threading.Event()       # the held ping is inside pyserial's write
    closing = threading.Event()
    writing = []                     # writes in progress
    seen = {"closed_during_write": False}
    errors = []
    monkeypatch.setattr(threading, "excepthook", lambda args: errors.append(args.exc_value))

    def held(data):      # pyserial's write calls this right after its is_open check
        if bytes(data) == ping and not inside.is_set():
            inside.set()
            closing.wait(timeout=0.2)   # preempted here until the port starts to close (or 0.2 s)
        return to_bytes(data)

    real_write, real_close = SP.Serial.write, SP.Serial.close

    def write(self, data):
        writing.append(data)
        try:
            return real_write(self, data)
        finally:
            writing.remove(data)

    def close(self):
        seen["closed_during_write"] = seen["closed_during_write"] or bool(writing)
        closing.set()
        real_close(self)

    monkeypatch.setattr(SP, "to_bytes", held)
    monkeypatch.setattr(SP.Serial, "write", write)
    monkeypatch.setattr(SP.Serial, "close", close)
    master, slave = pty.openpty()
    try:
        link = Link(os.ttyname(slave))
        link.start_heartbeat(0.005)
        assert inside.wait(5)
        link.close()
        beats = [t for t in threading.enumerate() if t.name == "locust-link-heartbeat"]
        assert not [t for t in beats if t.is_alive()]          # it had ended before close() returned
    finally:
        os.close(master)
        os.close(slave)
    assert not seen["closed_during_write"]
    assert errors == []


# -- a port that goes away ------------------------------------------------------------------


class PulledBoard:
    """A board double on a pty whose cable is pulled right after it sends the message named
    ``pull`` (``pose`` before its reply: the request arrived; ``phase``: the hop's first phase)."""

    def __init__(self, pull: str):
        self.master, self.slave = pty.openpty()
        tty.setraw(self.slave)
        self.port = os.ttyname(self.slave)
        self.pull = pull
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _answer(self, req: dict) -> bool:
        """Answer ``req``; True when the cable goes now."""
        cmd, rid = req.get("cmd"), req.get("id")
        if cmd == self.pull:
            return True
        if cmd == "hello":
            msg = protocol.reply(rid, name=protocol.NAME, version=protocol.VERSION, protocol=protocol.PROTOCOL,
                                 platform="esp32", micropython=[1, 26, 0], machine="ESP32 module", chip="esp32",
                                 reset="power_on", config_problems=[], hopping=False)
        elif cmd == "config":
            msg = protocol.reply(rid, config=fw_config.default("esp32"))
        elif cmd == "hop":
            os.write(self.master, protocol.encode(protocol.reply(rid)))
            msg = protocol.event(protocol.EV_PHASE, hop=rid, i=0, cycle=1, phase="push", commanded_us=0,
                                 measured_us=150)
            if self.pull == "phase":
                os.write(self.master, protocol.encode(msg))
                return True
        else:
            msg = protocol.reply(rid)
        os.write(self.master, protocol.encode(msg))
        return False

    def _serve(self) -> None:
        lines = protocol.LineReader()
        while True:
            if not select.select([self.master], [], [], 30)[0]:
                break
            pulled = False
            for line in lines.feed(os.read(self.master, 4096)):
                try:
                    pulled = pulled or self._answer(protocol.decode(line))
                except (protocol.ProtocolError, TypeError):
                    continue
            if pulled:
                break
        os.close(self.slave)     # the device goes: no one is left holding it
        os.close(self.master)


def test_a_pulled_cable_says_what_the_robot_does_now(tmp_path):
    """The cable goes as a `pose` request reaches the board: lost port, and the hint says the
    servos keep the last pose (a pose has no heartbeat; it said the robot returns to rest).
    The cable goes during a hop: the same error, and there the robot does return to rest on
    its own (the hop's heartbeat), and the record says the port was lost."""
    board = PulledBoard("pose")
    pose = _run(["pose", "--port", board.port, "10", "10"], dict(os.environ))
    assert pose.returncode == 2, pose.stderr
    assert f"error: lost the serial port {board.port}" in pose.stderr and "Traceback" not in pose.stderr
    hint = pose.stderr.split("hint:", 1)[1]
    assert "re-plug the board" in hint
    assert "the servos keep the last pose they were given until the board is reset or powered off" in hint
    assert "returns to rest" not in pose.stderr

    board = PulledBoard("phase")
    out = tmp_path / "run"
    hop = _run(["hop", "--port", board.port, "--cycles", "2", "--out", str(out)], dict(os.environ))
    assert hop.returncode == 2, hop.stderr
    assert f"error: lost the serial port {board.port}" in hop.stderr and "Traceback" not in hop.stderr
    assert "the robot returns to rest on its own once the host has been silent" in hop.stderr.split("hint:", 1)[1]
    rec = json.loads((out / "run.json").read_text())
    # (the phase is the host's only if it read it before the pty's hangup flushed the line)
    assert rec["status"] == "incomplete" and len(rec["phases"]) <= 1
    assert rec["message"].startswith(f"lost the serial port {board.port}")


def test_a_cable_pulled_during_flash_is_named_as_such(tmp_path):
    """The virtual robot killed (its pty gone, as a pulled USB cable takes the port) while
    `locust flash` copies the firmware: "lost the serial port ... while flashing", the cable,
    the port and re-plugging in the hint; it said "Input/output error" and "check ... that
    the disk has space"."""
    env = dict(os.environ, LOCUST_VIRTUAL_DIR=str(tmp_path / "virtual"))
    with _virtual(env, "--flash-dir", str(tmp_path / "flash")) as (device, robot):
        flash = subprocess.Popen(LOCUST + ["flash", "--port", device], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, env=env)
        lines = []
        for line in flash.stderr:
            lines.append(line)
            if line.strip().startswith("copying "):
                robot.kill()
                break
        _, rest = flash.communicate(timeout=60)
    stderr = "".join(lines) + rest
    assert any(line.strip().startswith("copying ") for line in lines), stderr
    assert flash.returncode == 2, stderr
    assert f"error: lost the serial port {device} while flashing (" in stderr
    hint = stderr.split("hint:", 1)[1]
    assert "check the USB cable and the port" in hint and "re-plug the board" in hint
    assert "disk" not in stderr and "Traceback" not in stderr
