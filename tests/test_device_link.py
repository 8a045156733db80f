"""End to end over a pseudo-terminal: mpremote flashes the virtual robot, the link drives it.

Everything here speaks the real wire format to the real firmware running in the real
MicroPython interpreter; only the servos are virtual (a recording plant).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import pty
import subprocess
import sys
import threading
import time

import pytest
import serial

from locust.device.flash import firmware_files, flash
from locust.device.hop import run_hop
from locust.device.link import Link
from locust.device.plant import RecordingPlant
from locust.device.pwm import PWM_PERIOD_S
from locust.device.virtual import TICKS_LEAD_S, VirtualRobot
from locust.errors import DeviceError
from locust.firmware import protocol
from locust.io import run_record
from waiting import wait_for


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    flash_dir = tmp_path_factory.mktemp("flash")
    plant = RecordingPlant()
    with VirtualRobot(flash_dir, plant) as vr:
        result = flash(vr.device_path)
        yield vr, plant, result


def test_flash_copies_verifies_and_shakes_hands(robot):
    vr, _, result = robot
    assert result.firmware_version == protocol.VERSION
    assert sorted(f.name for f in result.files) == sorted(p.name for p in firmware_files())
    for f in result.files:  # what landed in the flash folder is byte-identical
        assert hashlib.sha256((vr.flash_dir / f.name).read_bytes()).hexdigest() == f.sha256
    assert result.config_written and (vr.flash_dir / "config.json").exists()
    assert vr.boots >= 2  # the soft reset rebooted the interpreter into main.py


def test_hop_phases_on_time_and_servos_follow(robot, tmp_path, board_timing):
    vr, plant, _ = robot
    schedule = run_record.HopSchedule(cycles=2, push_deg=-30.0, push_ms=100, wait_ms=150)
    t_start = vr.now_s()
    with Link(vr.device_path) as link:
        rec = run_hop(link, schedule, tmp_path)
    assert rec.status == run_record.COMPLETE and len(rec.phases) == 4
    assert [p.commanded_us for p in rec.phases] == [0, 100_000, 250_000, 350_000]
    assert all(p.error_us >= 0 for p in rec.phases)     # never early
    pushes = [c for c in plant.commands if c.t_s > t_start and c.left_deg < -1]
    assert pushes and all(abs(c.left_deg + 30) < 0.01 for c in pushes)
    assert any(abs(c.right_deg + 30) < 0.01 for c in pushes)  # the mirrored leg, same horn angle
    writes = [w for w in vr.pwm_writes if w.t_written_s > t_start and w.servo]
    for w in writes:  # each duty change lands at the next 20 ms PWM period
        assert 0 <= w.t_effect_s - w.t_written_s <= PWM_PERIOD_S + 1e-9
    # one timer for both servos: the periods start together, so the left and right writes of
    # one command take effect at the same instant unless a period starts between the two
    starts = [w.t_effect_s for w in writes]
    periods = [(t - starts[0]) / PWM_PERIOD_S for t in starts]
    assert all(abs(k - round(k)) < 1e-6 for k in periods)     # one grid of period starts
    pairs = [(a, b) for a, b in zip(writes, writes[1:]) if (a.servo, b.servo) == ("left", "right")]
    assert len(pairs) >= 4
    for a, b in pairs:
        apart = math.ceil((b.t_written_s - starts[0]) / PWM_PERIOD_S - 1e-9) != \
            math.ceil((a.t_written_s - starts[0]) / PWM_PERIOD_S - 1e-9)
        assert b.t_effect_s - a.t_effect_s == pytest.approx(PWM_PERIOD_S if apart else 0.0, abs=1e-9)
    board_timing([p.error_us for p in rec.phases])


def test_silent_host_leaves_servos_at_rest_within_heartbeat(robot, board_timing):
    vr, _, _ = robot
    with Link(vr.device_path) as link:
        link.hello()
        reply = link.call("hop", cycles=3, push_ms=300, wait_ms=1000, heartbeat_ms=250)
        t_last_frame = vr.now_s()  # the host says nothing more
        done = None
        while done is None:
            ev = link.events.get(timeout=5)
            if ev.get("ev") == protocol.EV_DONE and ev.get("hop") == reply["id"]:
                done = ev
    assert done["status"] == protocol.HOP_HEARTBEAT and done["phases"] == 1
    def at_rest():   # the PWM writes reach the host through a FIFO, the events a pty
        last = [w for w in vr.pwm_writes if w.servo][-2:]
        return last if all(abs(w.horn_deg) < 1e-6 for w in last) else None

    last = wait_for(at_rest, 2, "both servos commanded to rest")
    assert {w.servo for w in last} == {"left", "right"}
    # rest commanded within the timeout: 250 ms, and 5 ms for the frame's way over the pty
    board_timing([(w.t_written_s - t_last_frame - 0.250) * 1e6 for w in last], bound_us=5000,
                 what="rest command after the heartbeat")


def test_errors_over_the_wire_and_busy(robot):
    vr, _, _ = robot
    with Link(vr.device_path) as link:
        assert link.request("pose", left_deg=80, right_deg=0)["error"] == protocol.E_RANGE
        assert link.request("warp")["error"] == protocol.E_UNKNOWN
        link.write(b"$not json*00000000\n")
        link.write(protocol.encode({"id": 77, "cmd": "ping"}).replace(b"ping", b"pong"))
        assert link.call("ping")["ok"]
        errors = [m["error"] for m in link.unsolicited]
        assert protocol.E_CHECKSUM in errors
        bad_id = link.request("pose", left_deg=10, right_deg=-10)
        assert bad_id["ok"] and (bad_id["left_deg"], bad_id["right_deg"]) == (10, -10)
        assert link.call("rest")["ok"]


def _reboot_into_firmware(link):
    """Soft-reset the robot (the firmware's `repl`, then Ctrl-D): its ticks start anew, TICKS_LEAD_S before a wrap."""
    link.call("repl")
    link.write(b"\x04")
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        if link.events.get(timeout=deadline - time.monotonic()).get("ev") == protocol.EV_BOOT:
            return
    raise AssertionError("no boot event")


def test_hop_across_a_ticks_wrap_stays_on_time(robot, tmp_path, board_timing):
    """A board's ticks_us wraps at 2**30 us; the virtual robot's do so TICKS_LEAD_S (7 s) after
    each boot, so a 7.8 s hop started right after one crosses the wrap. Phase times are the
    firmware's own (its clock), as on a board."""
    vr, _, _ = robot
    with Link(vr.device_path) as link:
        _reboot_into_firmware(link)
        before = link.call("ping")["t_us"]
        assert (1 << 30) - before < TICKS_LEAD_S * 1e6  # the wrap is ahead
        rec = run_hop(link, run_record.HopSchedule(cycles=6, push_ms=300, wait_ms=1000), tmp_path)
        after = link.call("ping")["t_us"]
    assert after < before  # wrapped during the hop
    start, end = rec.firmware_ticks_us
    assert before < start < (1 << 30) and end < after and rec.to_dict()["ticks_wrapped"]
    assert rec.status == run_record.COMPLETE and len(rec.phases) == 12
    assert [p.commanded_us for p in rec.phases][-1] == 5 * 1_300_000 + 300_000
    assert all(p.error_us >= 0 for p in rec.phases)     # never early
    board_timing([p.error_us for p in rec.phases])


def test_idle_robot_has_a_boards_ticks_and_soft_reset_leaves_servos_limp(robot):
    """mpremote exec on the idle robot: Ctrl-C stops the firmware (servos to rest), the raw
    REPL's soft reset stops every PWM output (a zero pulse on both servo pins), and the
    ticks are a board's 30-bit ones."""
    vr, _, _ = robot
    mpremote = [sys.executable, "-m", "mpremote", "connect", vr.device_path]
    n = len(vr.pwm_writes)
    proc = subprocess.run(mpremote + ["exec", "import time; print(time.ticks_add(0, -1))"],
                          capture_output=True, text=True, timeout=60)
    assert proc.stdout.strip() == "1073741823", proc.stdout + proc.stderr
    wait_for(lambda: any(w.pulse_us == 0 for w in list(vr.pwm_writes)[n:]), 5, "the pulses stopped")
    new = list(vr.pwm_writes)[n:]
    rest = [w for w in new if w.servo and w.pulse_us > 0]
    assert rest and all(abs(w.horn_deg) < 1e-6 for w in rest)  # Ctrl-C: to rest first
    assert {w.pin for w in new if w.pulse_us == 0} == {18, 19}  # then no pulse at all
    subprocess.run(mpremote + ["reset"], capture_output=True, timeout=60)  # main.py again
    with Link(vr.device_path) as link:
        assert link.hello(wait_s=8.0)["chip"] == "esp32"


def test_bad_saved_pins_fall_back_and_the_boot_escape_skips_the_firmware(robot):
    """A config.json with the flash pin 6 (written by hand) does not crash-loop the board: the
    firmware boots on the chip's default pins and says why; a `noboot` file leaves the REPL."""
    vr, _, _ = robot
    cfg_path = vr.flash_dir / "config.json"
    good = cfg_path.read_text()
    bad = json.loads(good)
    bad["left"]["pin"] = 6
    cfg_path.write_text(json.dumps(bad))
    try:
        with Link(vr.device_path) as link:
            _reboot_into_firmware(link)
            hello = link.hello()
            assert any("GPIO6" in p for p in hello["config_problems"]), hello
            assert link.call("config")["config"]["left"]["pin"] == 18
            assert link.call("pose", left_deg=-10, right_deg=-10)["ok"]
        (vr.flash_dir / "noboot").write_text("")
        with Link(vr.device_path) as link:
            link.call("repl")
            link.write(b"\x04")
            with pytest.raises(DeviceError, match="at the MicroPython REPL"):
                link.hello(wait_s=2.0)
    finally:
        cfg_path.write_text(good)
        (vr.flash_dir / "noboot").unlink(missing_ok=True)
    with Link(vr.device_path) as link:
        link.write(b"\x04")  # the friendly REPL's soft reset: main.py again
        assert link.hello(wait_s=8.0)["config_problems"] == []


def test_ctrl_c_interrupts_running_code_and_cancels_a_line_at_the_prompt(robot):
    """As on a board: Ctrl-C raises KeyboardInterrupt inside running code (here a sleep, not a
    read of the console), while at the >>> prompt it cancels the line being typed."""
    vr, _, _ = robot
    with Link(vr.device_path) as link:
        link.call("repl")
    port = serial.Serial(vr.device_path, timeout=0.2)
    try:
        def until(marker: bytes, data: bytes = b"") -> bytes:
            port.write(data)
            seen = b""
            deadline = time.monotonic() + 5
            while marker not in seen and time.monotonic() < deadline:
                seen += port.read(256)
            return seen
        until(b">>> ", b"\r")
        assert b"\n42\r\n" not in until(b">>> ", b"12\x03")        # the line "12" is dropped...
        assert b"\n42\r\n" in until(b">>> ", b"6*7\r")             # ...so this is 6*7, not 126*7
        # a loop that says once that it runs (its echo reads "loop" + "ing"), then sleeps
        until(b"... ", b"import time\rfor i in range(10**9): time.sleep_ms(5) if i else print('loop' + 'ing')\r")
        assert b"looping" in until(b"looping", b"\r")  # runs the loop: no prompt until it is interrupted
        assert b"KeyboardInterrupt" in until(b">>> ", b"\x03")
        port.write(b"\x04")  # soft reset: the firmware again
    finally:
        port.close()
    with Link(vr.device_path) as link:
        assert link.hello(wait_s=8.0)["name"] == "locust"


def test_flash_stops_a_running_hop_instead_of_calling_the_board_blank(robot):
    """A hop ignores Ctrl-C and answers `repl` with busy: flash stops it and gets in, rather than
    telling the user the board has no MicroPython."""
    vr, _, _ = robot
    with Link(vr.device_path) as link:
        link.hello()
        link.call("hop", cycles=20, push_ms=300, wait_ms=1000, heartbeat_ms=10000)
    # the hop runs on, silent host or not, for 10 s: past the 3 s the raw REPL is given
    result = flash(vr.device_path, repl_timeout_s=3.0)
    assert result.firmware_version == protocol.VERSION


def test_flash_on_a_port_without_micropython_names_the_installer():
    master, slave = pty.openpty()  # nothing answers on the other side
    try:
        with pytest.raises(DeviceError) as err:
            flash(os.ttyname(slave), repl_timeout_s=0.5)
        hint = err.value.hint
        # each chip's offset (the classic and S2 at 0x1000, the S3 and C3 at 0x0) and the guide
        assert "esptool" in hint and "0x1000" in hint and "0x0" in hint and "docs/hardware.md" in hint
    finally:
        os.close(master)
        os.close(slave)


def test_hop_without_firmware_is_a_clear_error(tmp_path):
    with VirtualRobot(tmp_path / "empty-flash") as vr, Link(vr.device_path) as link:
        t0 = time.monotonic()
        with pytest.raises(DeviceError, match="no locust firmware"):
            link.hello(wait_s=1.0)
        assert time.monotonic() - t0 < 3


class LaggingPlant(RecordingPlant):
    """A plant that falls behind the clock (as one rendering a video on a loaded machine does):
    its idle step blocks until the test releases it."""

    def __init__(self):
        super().__init__()
        self.busy, self.release = threading.Event(), threading.Event()
        self.closed_at_s: float | None = None

    def idle(self, t_s: float) -> None:
        self.busy.set()
        self.release.wait(timeout=30)

    def close(self, t_s: float) -> dict:
        self.closed_at_s = t_s
        return super().close(t_s)


def test_a_lagging_plant_ends_where_the_host_stopped_the_robot(tmp_path):
    # the plant's video ends when the host stops the robot, not when its thread catches up:
    # a second of lag used to add a second of the robot standing to the end of the video
    plant = LaggingPlant()
    vr = VirtualRobot(tmp_path / "flash", plant).start()
    wait_for(plant.busy.is_set, 10, "the plant thread to go idle")
    t_stop = vr.now_s()
    stopping = threading.Thread(target=vr.stop)
    stopping.start()
    wait_for(lambda: vr.now_s() > t_stop + 1.0, 10, "a second of the robot's clock after the stop")
    plant.release.set()
    stopping.join(timeout=30)
    assert not stopping.is_alive()
    assert t_stop <= plant.closed_at_s < t_stop + 0.3
