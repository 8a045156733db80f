# The command loop with a scripted console and recording servos (MicroPython only: it
# needs time.ticks_us). The wire format is the real one: frames built by protocol.py.
import json
import time

import config
import protocol as P
import robot
from lcg import Lcg


class ScriptedPort:
    """Input: a list of (at_ms, bytes) delivered once their time has come; output: frames."""

    def __init__(self, script=()):
        self.t0 = time.ticks_ms()
        self.script = list(script)
        self.out = bytearray()

    def read(self, timeout_ms):
        now = time.ticks_diff(time.ticks_ms(), self.t0)
        if self.script and self.script[0][0] <= now:
            return self.script.pop(0)[1]
        time.sleep_ms(min(timeout_ms, 2))
        return b""

    def write(self, data):
        self.out += data

    def messages(self):
        out = []
        for line in bytes(self.out).split(b"\n"):
            if line:
                out.append(P.decode(line))
        return out


class RecordingServos:
    def __init__(self, cfg):
        self.cfg = cfg
        self.log = []  # (ticks_us, left_deg, right_deg) as commanded, after the clamp

    def set(self, left, right):
        t = config.clamp
        travel_l = self.cfg["left"]["travel_deg"]
        travel_r = self.cfg["right"]["travel_deg"]
        left = t(left, -travel_l, travel_l)
        right = t(right, -travel_r, travel_r)
        self.log.append((time.ticks_us(), left, right))
        return left, right

    def rest(self):
        return self.set(0.0, 0.0)

    def deinit(self):
        pass


def _controller(script=()):
    port = ScriptedPort(script)
    ctl = robot.Controller(port, RecordingServos, config.default(), (), "/tmp/locust_fw_ctl.json")
    return ctl, port


def _req(i, cmd, **args):
    args["id"] = i
    args["cmd"] = cmd
    return P.encode(args)


def test_hello_and_errors():
    ctl, port = _controller()
    for line in (_req(1, "hello"), b"garbage\n", _req(2, "pose", left_deg=60, right_deg=0),
                 _req(3, "fly"), b"$" + b"x" * 400 + b"\n"):
        for item in ctl.reader.feed(line):
            ctl.handle_line(item)
    msgs = port.messages()
    assert msgs[0]["ok"] and msgs[0]["version"] == P.VERSION and msgs[0]["id"] == 1
    assert [m.get("error") for m in msgs[1:]] == [P.E_FRAME, P.E_RANGE, P.E_UNKNOWN, P.E_TOO_LONG]
    assert [m["id"] for m in msgs[1:]] == [None, 2, 3, None]
    assert ctl.servos.log == []  # the out-of-range pose moved nothing


def test_hop_timing_and_events():
    ctl, port = _controller()
    ctl.handle_line(_req(7, "hop", cycles=2, push_deg=-30, push_ms=40, wait_ms=60, heartbeat_ms=5000)[:-1])
    ctl.step(0)
    msgs = port.messages()
    assert msgs[0] == {"id": 7, "ok": True, "phases": 4, "duration_us": 200000}
    phases = [m for m in msgs if m.get("ev") == P.EV_PHASE]
    assert [(m["cycle"], m["phase"], m["commanded_us"]) for m in phases] == [
        (1, "push", 0), (1, "wait", 40000), (2, "push", 100000), (2, "wait", 140000)]
    for m in phases:
        assert m["measured_us"] >= m["commanded_us"], m   # never early
    # how late each phase started: the host judges it against the board's 2 ms (or says it
    # cannot, on a host that stalls a spinning process longer: tests/conftest.py board_timing)
    print("TIMING", ",".join(str(m["measured_us"] - m["commanded_us"]) for m in phases))
    done = msgs[-1]
    assert done["ev"] == P.EV_DONE and done["status"] == P.HOP_COMPLETE and done["phases"] == 4
    assert 200000 <= done["rest_us"] < 210000
    assert [a for _, a, _ in ctl.servos.log] == [-30, 0, -30, 0, 0]


def test_stop_mid_hop():
    ctl, port = _controller([(70, _req(8, "stop"))])
    ctl.handle_line(_req(7, "hop", cycles=3, push_ms=40, wait_ms=60, heartbeat_ms=5000)[:-1])
    ctl.step(0)
    msgs = port.messages()
    done = msgs[-1]
    assert done["status"] == P.HOP_STOPPED and done["phases"] == 2
    assert {"id": 8, "ok": True, "stopped": True} in msgs
    assert ctl.servos.log[-1][1:] == (0.0, 0.0)


def test_heartbeat_loss_rests_within_timeout():
    ctl, port = _controller()
    ctl.handle_line(_req(7, "hop", cycles=3, push_ms=300, wait_ms=1000, heartbeat_ms=150)[:-1])
    start = time.ticks_us()
    ctl.step(0)
    done = port.messages()[-1]
    assert done["status"] == P.HOP_HEARTBEAT
    t_rest, left, right = ctl.servos.log[-1]
    assert (left, right) == (0.0, 0.0)
    late = time.ticks_diff(t_rest, start) - 150000
    assert 0 <= late < 3000, late


def test_busy_during_hop():
    ctl, port = _controller([(10, _req(2, "pose", left_deg=1, right_deg=1)), (20, _req(3, "ping"))])
    ctl.handle_line(_req(1, "hop", cycles=1, push_ms=30, wait_ms=30, heartbeat_ms=5000)[:-1])
    ctl.step(0)
    msgs = port.messages()
    assert {"id": 2, "ok": False, "error": P.E_BUSY, "detail": "pose is not allowed during a hop"} in msgs
    assert [m for m in msgs if m.get("id") == 3][0]["ok"]


def test_fuzz_never_raises_or_leaves_travel():
    rng = Lcg(2024)
    ctl, port = _controller()
    lines = 0
    for n in range(600):
        k = rng.below(5)
        if k == 0:
            line = rng.bytes(rng.below(120))
        elif k == 1:
            body = json.dumps({"id": rng.below(100), "cmd": "pose",
                               "left_deg": rng.below(400) - 200, "right_deg": rng.below(400) - 200})
            line = b"$" + body.encode() + b"*" + P.crc_hex(body.encode()).encode()
        elif k == 2:
            body = rng.bytes(rng.below(60))
            line = b"$" + body + b"*" + P.crc_hex(body).encode()
        elif k == 3:
            line = P.encode({"id": n, "cmd": "config", "key": "left.travel_deg", "value": rng.below(200)})[:-1]
        else:
            line = _req(n, "hop", cycles=rng.below(3), push_deg=rng.below(200) - 100)[:-1]
        line = line.replace(b"\n", b"").replace(b"\r", b"")
        lines += 1 if line else 0
        for item in ctl.reader.feed(line + b"\n"):
            ctl.handle_line(item)
        ctl.pending_hop = None  # accepted hops are not run here
    msgs = port.messages()
    assert len(msgs) == lines  # one reply to every non-empty line, no more, no less
    internal = [m for m in msgs if m.get("error") == P.E_INTERNAL]
    assert not internal, internal[:3]
    for _, left, right in ctl.servos.log:
        assert abs(left) <= 45 and abs(right) <= 45


class PickyServos(RecordingServos):
    """Servos that fail on pin 4 (as machine.Pin may on a board) and count live instances."""

    live = 0

    def __init__(self, cfg):
        if cfg["left"]["pin"] == 4:
            raise ValueError("invalid pin")
        super().__init__(cfg)
        PickyServos.live += 1

    def deinit(self):
        PickyServos.live -= 1


def test_config_that_fails_is_rolled_back_and_not_saved():
    path = "/tmp/locust_fw_rollback.json"
    config.save(config.default(), path)
    PickyServos.live = 0
    port = ScriptedPort()
    ctl = robot.Controller(port, PickyServos, config.default(), (), path, "esp32")
    ctl.handle_line(_req(1, "config", key="left.pin", value=4, write=1)[:-1])   # rules allow, board refuses
    ctl.handle_line(_req(2, "config", key="left.pin", value=34, write=1)[:-1])  # the chip's rules refuse
    ctl.handle_line(_req(3, "pose", left_deg=10, right_deg=10)[:-1])
    m1, m2, m3 = port.messages()
    assert m1["error"] == P.E_RANGE and "invalid pin" in m1["detail"]
    assert m2["error"] == P.E_RANGE and "GPIO34" in m2["detail"]
    assert m3["ok"] and ctl.servos.log[-1][1:] == (10, 10)  # the old servos drive the legs again
    assert ctl.cfg["left"]["pin"] == 18 and PickyServos.live == 1
    assert config.load(path) == (config.default(), [])  # nothing saved


def test_boot_falls_back_without_raising():
    bad = config.with_value(config.default(), "left.pin", 4)
    cfg, problems, servos = robot.boot_servos(bad, [], "esp32", PickyServos)
    assert cfg == config.default("esp32") and len(problems) == 2 and isinstance(servos, PickyServos)
    cfg, problems, servos = robot.boot_servos(bad, [], "esp32", lambda c: PickyServos(bad))
    assert isinstance(servos, robot.NoServos) and len(problems) == 2


class FailingRest(RecordingServos):
    def rest(self):
        raise OSError("PWM failed")


def test_hop_ends_idle_even_if_rest_fails():
    port = ScriptedPort()
    ctl = robot.Controller(port, FailingRest, config.default(), (), "/tmp/locust_fw_ctl.json")
    ctl.handle_line(_req(1, "hop", cycles=1, push_ms=20, wait_ms=20, heartbeat_ms=5000)[:-1])
    try:
        ctl.step(0)
    except OSError:
        pass
    assert ctl.hop is None  # not left "busy": the next command is served
    ctl.handle_line(_req(2, "ping")[:-1])
    assert port.messages()[-1]["ok"]


def test_elapsed_sums_across_ticks_wraps():
    """ticks_us wraps at 2**30 on a board and ticks_diff is valid to 2**29: the hop clock sums
    the steps between readings, so 8 steps of 2**28 us (2**31 us, 36 min) read exactly."""
    real = robot.ticks_us
    seq = [(1 << 30) - 10 + k * (1 << 28) & ((1 << 30) - 1) for k in range(9)]
    robot.ticks_us = lambda: seq.pop(0)
    try:
        clock = robot.Elapsed()
        clock.start()
        totals = [clock.now() for _ in range(8)]
    finally:
        robot.ticks_us = real
    assert totals == [k * (1 << 28) for k in range(1, 9)]


def test_report_rebuilds_each_phase_from_the_schedule():
    ctl, port = _controller()
    ctl.handle_line(_req(7, "hop", cycles=5, push_deg=-20, push_ms=20, wait_ms=30, heartbeat_ms=5000)[:-1])
    ctl.step(0)
    events = [[m["cycle"], m["phase"], m["commanded_us"], m["measured_us"]] for m in port.messages()
              if m.get("ev") == P.EV_PHASE]
    pages = []
    for start in (0, 8):
        ctl.handle_line(_req(8 + start, "report", start=start)[:-1])
        last = bytes(port.out).split(b"\n")[-2]
        reply = json.loads(last[1:-9])  # a report page is longer than a request may be
        assert reply["total"] == 10 and reply["status"] == P.HOP_COMPLETE
        pages += reply["phases"]
    assert pages == events and len(events) == 10
