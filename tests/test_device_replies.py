"""A board that answers out of shape: a hello with a version that is no version, a config
reply without its config, hop events missing keys or holding strings, infinities and 2^70.
Each command that talks to it (``hop``, ``config``, ``pose``) stops with one clear
``error:``/``hint:`` quoting the line, exit 2, no traceback (tests/probing.py).

The board is a SYNTHETIC double on a pseudo-terminal: it speaks the real wire format
(``locust.firmware.protocol``: ``$json*crc``), answers as the firmware does, and replaces
one field of one reply or event by a value a seeded generator draws.
"""

from __future__ import annotations

import os
import pty
import random
import threading
import time
import tty

import pytest

from locust.firmware import config as fw_config
from locust.firmware import protocol
from probing import assert_clear_error, invoke, tree

MISSING = object()


class FakeBoard:
    """The firmware's answers, on a pty; ``spoil(cmd_or_event, msg)`` may change any message
    before it is sent."""

    def __init__(self, spoil=lambda what, msg: msg):
        self.master, self.slave = pty.openpty()
        tty.setraw(self.slave)
        self.port = os.ttyname(self.slave)
        self.spoil = spoil
        self.stopped = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _send(self, what: str, msg: dict) -> None:
        msg = self.spoil(what, msg)
        os.write(self.master, protocol.encode(msg))   # json.dumps writes inf as Infinity, as a board's JSON may

    def _answer(self, req: dict) -> None:
        cmd, rid = req.get("cmd"), req.get("id")
        if cmd == "hello":
            self._send("hello", protocol.reply(rid, name=protocol.NAME, version=protocol.VERSION,
                                               protocol=protocol.PROTOCOL, platform="esp32", micropython=[1, 26, 0],
                                               machine="ESP32 module", chip="esp32", reset="power_on",
                                               config_problems=[], hopping=False))
        elif cmd == "config":
            self._send("config", protocol.reply(rid, config=fw_config.default("esp32")))
        elif cmd == "hop":
            self._send("hop", protocol.reply(rid))
            push, wait = req["push_ms"] * 1000, req["wait_ms"] * 1000
            for i in range(2 * req["cycles"]):
                c, start = i // 2 + 1, (i // 2) * (push + wait) + (push if i % 2 else 0)
                self._send("phase", protocol.event(protocol.EV_PHASE, hop=rid, i=i, cycle=c,
                                                   phase="wait" if i % 2 else "push", commanded_us=start,
                                                   measured_us=start + 150))
            self._send("done", protocol.event(protocol.EV_DONE, hop=rid, status=protocol.HOP_COMPLETE,
                                              phases=2 * req["cycles"], total=2 * req["cycles"], max_err_us=150,
                                              rest_us=0, ticks_us=[100, 900]))
        elif cmd in ("pose", "rest"):
            self._send(cmd, protocol.reply(rid, left_deg=req.get("left_deg", 0.0), right_deg=req.get("right_deg", 0.0)))
        elif cmd == "report":
            self._send("report", protocol.reply(rid, status=protocol.HOP_COMPLETE, total=0, start=0, phases=[]))
        else:   # ping, stop
            self._send(cmd, protocol.reply(rid))

    def _serve(self) -> None:
        lines = protocol.LineReader()
        while not self.stopped.is_set():
            try:
                data = os.read(self.master, 4096)
            except OSError:
                return
            for line in lines.feed(data):
                try:
                    self._answer(protocol.decode(line))
                except (protocol.ProtocolError, TypeError):
                    continue

    def close(self) -> None:
        self.stopped.set()
        os.close(self.slave)
        os.close(self.master)
        self.thread.join(timeout=2)


def _with(field: str, value):
    """A spoil that sets (or with MISSING, removes) ``field`` of every message it is given."""
    def spoil(msg):
        msg = dict(msg)
        if value is MISSING:
            msg.pop(field, None)
        else:
            msg[field] = value
        return msg
    return spoil


INF, NAN, HUGE = float("inf"), float("nan"), 2**70
WRONG_TYPES = [MISSING, "x", [], {}, True, None, INF]
# (message, {field: values no board of this toolkit sends there}, commands that read it)
TARGETS = [
    ("hello", {"micropython": ["micropython", "1..26", 5, HUGE, INF, [], {}, [1], True, 1.5, [1, "26"], [HUGE, 0]],
               "version": ["x", "1..26", "micropython", 5, HUGE, INF, [], {}, True, 1.5, "1." * 200 + "0"],
               "protocol": [MISSING, "x", "1..26", HUGE, INF, NAN, [], {}, True, 1.5, None],
               "chip": [5, HUGE, INF, [], {}, True, 1.5, "x" * 500],
               "config_problems": ["x", 5, INF, {}, [1, 2], True, [["nested"]]],
               "hopping": ["x", 5, INF, [], {}, 1.5, "micropython"]}, ["hop", "config", "pose"]),
    ("config", {"config": [MISSING, "x", 5, INF, [], [1], True, None, 1.5]}, ["hop", "config"]),
    ("phase", {"cycle": WRONG_TYPES + [HUGE, -HUGE, NAN, 1.5, -1, 5000],
               "phase": WRONG_TYPES + [5, "micropython", "PUSH"],
               "commanded_us": WRONG_TYPES + [HUGE, -HUGE, -INF, NAN, 1.5, -1],
               "measured_us": WRONG_TYPES + [HUGE, -HUGE, -INF, NAN, 1.5, -1]}, ["hop"]),
    ("done", {"status": [MISSING, 5, HUGE, INF, [], {}, True, None, 1.5, "x" * 500],
              "ticks_us": ["x", 5, HUGE, INF, [], {}, [1], True, 1.5, [HUGE, 0], [1, INF]],
              "rest_us": ["x", HUGE, -HUGE, INF, NAN, [], {}, True, 1.5, -1]}, ["hop"]),
    ("hop", {"id": ["x", HUGE, INF, [], {}, [1], None, 1.5, True]}, ["hop"]),   # then no reply to this request
    ("pose", {"left_deg": WRONG_TYPES + [HUGE, -INF, NAN, "micropython", 1e6],
              "right_deg": WRONG_TYPES + [HUGE, -INF, NAN, "micropython", 1e6]}, ["pose"]),
]


PAIRS = [(what, field, values, commands) for what, fields, commands in TARGETS for field, values in fields.items()]


def _draw(seed: int):
    """(message, field, value, command): one field of one message replaced by a bad value;
    every field in turn, the value and the command drawn."""
    rng = random.Random(seed)
    what, field, values, commands = PAIRS[seed % len(PAIRS)]
    return what, field, rng.choice(values), rng.choice(commands)


def _args(command: str, port: str, out) -> list:
    if command == "hop":
        return ["hop", "--port", port, "--cycles", "1", "--push-ms", "50", "--wait-ms", "50", "--out", out / "run"]
    if command == "config":
        return ["config", "--port", port]
    return ["pose", "10", "-10", "--port", port]


@pytest.mark.timeout(60)
@pytest.mark.parametrize("seed", range(3 * len(PAIRS)))
def test_a_malformed_reply_is_a_clear_error_quoting_the_line(tmp_path, monkeypatch, seed):
    what, field, value, command = _draw(seed)
    board = FakeBoard(lambda w, msg: _with(field, value)(msg) if w == what else msg)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine.txt").write_text("mine\n")
    before = tree(tmp_path)
    try:
        t0 = time.monotonic()
        res = invoke(_args(command, board.port, tmp_path))
        seconds = time.monotonic() - t0
    finally:
        board.close()
    assert_clear_error(res, *(["no reply to 'hop'"] if (what, field) == ("hop", "id") else
                              ["the board's", "in the line {"]))
    assert seconds < 10
    after = {k: v for k, v in tree(tmp_path).items() if not k.startswith("run")}
    assert after == before   # only the hop's own record, kept with what arrived


@pytest.mark.timeout(60)
@pytest.mark.parametrize("command", ["hop", "config", "pose"])
def test_the_double_answers_as_the_firmware_does(tmp_path, command):
    board = FakeBoard()
    try:
        res = invoke(_args(command, board.port, tmp_path))
    finally:
        board.close()
    assert res.exit_code == 0, res.output
    if command == "hop":
        saved = (tmp_path / "run" / "run.json").read_text()
        assert '"status": "complete"' in saved
        # a board's own clock times its phases: no host to stall it (not applicable)
        assert '"host_stall_max_s": null' in saved and "host stall" not in res.stderr


# -- phases that are not the schedule's, a hop that never ends, a config out of the firmware's limits --

def _phases(change):
    """A spoil that passes each phase event (by its index ``i``) through ``change(i, event)``."""
    return lambda what, msg: change(msg["i"], dict(msg)) if what == "phase" else msg


def _set(**by_index):
    """``change`` setting, for phase ``i``, each field to ``by_index[field][i]``."""
    def change(i, msg):
        for key, values in by_index.items():
            msg[key] = values[i]
        return msg
    return change


# the hop of _args: 1 cycle, push 50 ms then wait 50 ms: commanded at 0 and 50,000 us
NOT_THE_SCHEDULES = {
    "a clock that runs backwards": (_set(measured_us=[60_000, 50_100]), "its clock ran backwards"),
    "cycle 0": (_set(cycle=[0, 0]), "not a phase of the 1 cycles sent"),
    "cycles 998 and 997": (_set(cycle=[998, 997]), "not a phase of the 1 cycles sent"),
    "every commanded start 0": (_set(commanded_us=[0, 0]), "not at the schedule's 50,000 us"),
    "a phase started early": (_set(measured_us=[150, 49_000]), "before it was due"),
    "a wait reported before its push": (_set(phase=["wait", "push"], commanded_us=[50_000, 0],
                                             measured_us=[50_150, 50_300]), "came after cycle 1's wait"),
}


@pytest.mark.timeout(60)
@pytest.mark.parametrize("case", list(NOT_THE_SCHEDULES))
def test_a_phase_that_is_not_the_schedules_is_a_clear_error(tmp_path, monkeypatch, case):
    change, words = NOT_THE_SCHEDULES[case]
    board = FakeBoard(_phases(change))
    monkeypatch.chdir(tmp_path)
    try:
        res = invoke(_args("hop", board.port, tmp_path))
    finally:
        board.close()
    assert_clear_error(res, "the board's", "in the line {", words)
    assert '"status": "incomplete"' in (tmp_path / "run" / "run.json").read_text()


class RepeatingBoard(FakeBoard):
    """Answers the hop, then sends one event every millisecond and never ends the hop: the
    hop's first phase again and again, or (``other_hop``) a phase of another hop."""

    def __init__(self, other_hop: bool):
        self.other_hop = other_hop
        super().__init__()

    def _answer(self, req):
        if req.get("cmd") != "hop":
            return super()._answer(req)
        self._send("hop", protocol.reply(req["id"]))
        ev = protocol.event(protocol.EV_PHASE, hop=req["id"] + 1000 * self.other_hop, i=0, cycle=1, phase="push",
                            commanded_us=0, measured_us=150)

        def repeat():
            while not self.stopped.is_set():
                try:
                    os.write(self.master, protocol.encode(ev))
                except OSError:
                    return
                time.sleep(0.001)
        threading.Thread(target=repeat, daemon=True).start()


@pytest.mark.timeout(60)
@pytest.mark.parametrize("other_hop, words", [(False, ["came after cycle 1's push", "the board's"]),
                                              (True, ["had not ended the hop 3 s after its 0.1 s schedule"])])
def test_a_board_that_reports_on_and_on_is_given_up_by_the_schedules_end(tmp_path, monkeypatch, other_hop, words):
    board = RepeatingBoard(other_hop)
    monkeypatch.chdir(tmp_path)
    try:
        t0 = time.monotonic()
        res = invoke(_args("hop", board.port, tmp_path))
        seconds = time.monotonic() - t0
    finally:
        board.close()
    assert_clear_error(res, *words)
    assert seconds < 0.1 + 3.0 + 5.0    # the schedule, the 3 s of grace, the handshake on a loaded host


@pytest.mark.timeout(60)
@pytest.mark.parametrize("field, value", [("pin", 99999), ("trim_deg", 1e308), ("travel_deg", -5)])
@pytest.mark.parametrize("command", ["config", "hop"])
def test_a_config_outside_the_firmwares_own_limits_is_not_in_use(tmp_path, monkeypatch, field, value, command):
    def spoil(what, msg):
        if what == "config":
            msg = dict(msg, config=fw_config.default("esp32"))
            msg["config"]["left"] = dict(msg["config"]["left"], **{field: value})
        return msg

    board = FakeBoard(spoil)
    monkeypatch.chdir(tmp_path)
    try:
        res = invoke(_args(command, board.port, tmp_path))
    finally:
        board.close()
    assert_clear_error(res, "the board's config reply holds a config the firmware refuses", f"left.{field}=")
    assert "in use" not in res.output
