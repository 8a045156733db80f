"""The firmware compiles with mpy-cross, and its unit tests pass under the MicroPython unix port."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from locust.device.flash import firmware_files, mpy_version
from locust.device.virtual import SHIM_DIR, _raise_priority, micropython_executable

ROOT = Path(__file__).resolve().parents[1]
UNIT_DIR = ROOT / "tests" / "firmware"
MODULES = ["test_protocol", "test_config", "test_schedule", "test_controller"]


@pytest.mark.parametrize("src", firmware_files(), ids=lambda p: p.name)
def test_compiles_with_mpy_cross(src, tmp_path):
    out = tmp_path / (src.stem + ".mpy")
    proc = subprocess.run([sys.executable, "-m", "mpy_cross", "-o", str(out), str(src)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert mpy_version(out.read_bytes()[:4]) == 6  # the format of MicroPython >= 1.22


def test_unit_tests_pass_under_micropython(board_timing):
    expected = sum(len(re.findall(r"^def test_", (UNIT_DIR / f"{m}.py").read_text(), re.M)) for m in MODULES)
    env = dict(os.environ, MICROPYPATH=f"{ROOT / 'firmware'}:{UNIT_DIR}:{SHIM_DIR}")
    proc = subprocess.run([micropython_executable(), str(UNIT_DIR / "mp_run.py"), *MODULES],
                          capture_output=True, text=True, timeout=120, env=env, cwd=UNIT_DIR,
                          preexec_fn=_raise_priority)
    assert "MicroPython" in subprocess.run([micropython_executable(), "-c", "import sys; print(sys.version)"],
                                           capture_output=True, text=True).stdout
    last = proc.stdout.strip().splitlines()[-1]
    assert last == f"RESULT {expected} 0", proc.stdout[-3000:] + proc.stderr[-2000:]
    # the hop's phases started within the board's 2 ms (test_controller prints how late each was)
    timing = [line.split()[1] for line in proc.stdout.splitlines() if line.startswith("TIMING ")]
    assert len(timing) == 1, proc.stdout[-3000:]
    board_timing([int(e) for e in timing[0].split(",")])


def test_firmware_fallback_servo_config_is_the_robot_parameters():
    """The board's built-in config (used until config.json exists) keeps a copy of the pulse
    range and travel, as it cannot import the host; the host writes them from params.Servo."""
    from locust.device.flash import servo_config
    from locust.firmware import config as fw_config
    from locust.params import Servo

    keys = ("pulse_min_us", "pulse_max_us", "range_deg", "travel_deg")
    written = servo_config(Servo())
    assert fw_config.problems(written) == []
    for name in fw_config.SERVOS:
        assert {k: fw_config.default()[name][k] for k in keys} == {k: getattr(Servo(), k) for k in keys}
        assert {k: written[name][k] for k in keys} == {k: getattr(Servo(), k) for k in keys}
    narrow = servo_config(Servo(pulse_min_us=600.0, pulse_max_us=2400.0, travel_deg=40.0))
    assert narrow["right"]["pulse_min_us"] == 600.0 and narrow["left"]["travel_deg"] == 40.0


def _micropython(script: str, stdin: bytes = b"") -> str:
    """Run a script under the MicroPython unix port with the firmware and its unit tests on the path."""
    env = dict(os.environ, MICROPYPATH=f"{ROOT / 'firmware'}:{UNIT_DIR}:{SHIM_DIR}")
    proc = subprocess.run([micropython_executable(), "-c", script], input=stdin, capture_output=True,
                          timeout=60, env=env, cwd=UNIT_DIR)
    assert proc.returncode == 0, (proc.stdout + proc.stderr).decode(errors="replace")[-3000:]
    return proc.stdout.decode().strip().splitlines()[-1]


def test_console_ctrl_c_stops_the_loop_only_while_allowed():
    """Where 0x03 reaches stdin as a byte (the virtual robot), the console raises KeyboardInterrupt
    at it, leaving what follows for the REPL; switched off (a hop), 0x03 is an ordinary byte."""
    script = """
import sys, robot
c = robot.Console()
out = []
try:
    c.read(1000)
except KeyboardInterrupt:
    out.append("interrupt")
out.append(sys.stdin.buffer.read(3))
c.ctrl_c(False)
out.append(c.read(1000))
c.ctrl_c(True)
print(repr(out), c.interruptible)
"""
    assert _micropython(script, stdin=b"ab\x03\r\x01Z\x03ef") == "['interrupt', b'\\r\\x01Z', b'\\x03ef'] True"


def test_hop_switches_ctrl_c_off_and_back_on():
    script = """
import config, robot
import test_controller as T

class Port(T.ScriptedPort):
    def __init__(self):
        super().__init__()
        self.calls = []
        self.during = []

    def ctrl_c(self, on):
        self.calls.append(on)

    def write(self, data):
        self.during.append(self.calls[-1] if self.calls else None)
        super().write(data)

port = Port()
ctl = robot.Controller(port, T.RecordingServos, config.default(), (), "/tmp/locust_fw_ctrl_c.json")
ctl.handle_line(T._req(1, "hop", cycles=1, push_ms=20, wait_ms=20, heartbeat_ms=5000)[:-1])
ctl.step(0)
events = [m.get("ev") for m in port.messages()]
print(port.calls, port.during, events)
"""
    # the reply goes out before the hop starts, the phase events with Ctrl-C off, `done` once it is back on
    assert _micropython(script) == "[False, True] [None, False, False, True] [None, 'phase', 'phase', 'done']"


def _board(script: str, chip: str, stdin: bytes = b"") -> str:
    """Run a script under the unix port with the virtual robot's shims for ``chip``."""
    from locust.device.virtual import chip_env

    env = dict(os.environ, MICROPYPATH=str(SHIM_DIR), **chip_env(chip))
    proc = subprocess.run([micropython_executable(), "-c", script], input=stdin, capture_output=True,
                          timeout=60, env=env)
    assert proc.returncode == 0, (proc.stdout + proc.stderr).decode(errors="replace")[-3000:]
    return proc.stdout.decode().strip().splitlines()[-1]


PIN_PROBE = """
import machine, os
out = [os.uname().machine]
for pin in PINS:
    try:
        p = machine.PWM(machine.Pin(pin), freq=50, duty_ns=1500000)
        out.append("ok")
    except ValueError as e:
        out.append(str(e))
p.deinit()
try:
    p.duty_ns(1000000)
except RuntimeError as e:
    out.append(str(e))
print(out)
"""


def test_virtual_pins_refuse_what_the_chip_refuses():
    """As the ESP32 port's machine.Pin/PWM: a GPIO the chip lacks is "invalid pin", an input-only
    one cannot be a PWM, and a PWM used after deinit() raises."""
    esp32 = _board("PINS = (20, 34, 18)\n" + PIN_PROBE, "esp32")
    assert esp32 == ("['Generic ESP32 module with ESP32', 'invalid pin', 'pin can only be input', 'ok', "
                     "'PWM is inactive']")
    c3 = _board("PINS = (18, 19, 4)\n" + PIN_PROBE, "c3")  # the C3's USB-Serial-JTAG lines
    assert c3 == "['ESP32C3 module with ESP32C3', 'invalid pin', 'invalid pin', 'ok', 'PWM is inactive']"


def test_virtual_poll_timeout_ends_on_a_10_ms_tick():
    """select.poll(3) on a board sleeps to the next FreeRTOS tick: it never returns before the
    first 10 ms boundary after its timeout (a lower bound: no race on the machine's load)."""
    script = """
import select, sys, time, utime
p = select.poll()
p.register(sys.stdin, select.POLLIN)
short = []
for timeout in (1, 3, 7, 12):
    start = utime.ticks_ms()
    p.poll(timeout)
    end = utime.ticks_ms()
    grid = start + timeout + (-(start + timeout)) % 10
    short.append(end < grid)
print(short)
"""
    r, w = os.pipe()  # an open, silent stdin
    try:
        env = dict(os.environ, MICROPYPATH=str(SHIM_DIR))
        proc = subprocess.run([micropython_executable(), "-c", script], stdin=r, capture_output=True,
                              timeout=60, env=env)
    finally:
        os.close(r)
        os.close(w)
    assert proc.stdout.decode().strip() == "[False, False, False, False]", proc.stderr
