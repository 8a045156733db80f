"""A board's replies and events checked like any input file: every field the host uses has
its type and range, or the command stops with a :class:`DeviceError` quoting the line.

The firmware of this toolkit always answers in shape; a reply out of shape comes from other
firmware on the port, a damaged board or a line mangled past its CRC check. None of it may
end the host in a traceback or reach the run record.
"""

from __future__ import annotations

import json
import math
import re

from ..errors import DeviceError
from ..firmware import config as fw_config
from ..firmware import protocol as P
from ..firmware import schedule as fw_schedule
from ..io import run_record as R

_HOP = P.COMMANDS["hop"]
# The latest a phase can start, from the start of the hop: the longest schedule the firmware
# takes (cycles x (push + wait) at their limits), twice over for a late measurement.
MAX_PHASE_US = 2 * _HOP["cycles"][2] * (_HOP["push_ms"][2] + _HOP["wait_ms"][2]) * 1000
MAX_CYCLE = _HOP["cycles"][2]
PHASE_NAMES = ("push", "wait")
TICKS_US_MAX = 2**30          # the board's ticks_us wrap at 2^30
VERSION = re.compile(r"\d+(\.\d+)+([-+][0-9A-Za-z.]+)?")   # the firmware's release: 0.1.0
MAX_TEXT = 200                # a version, chip or status name: a few words
HINT = ("the port answers with something other than this toolkit's firmware, or the board is damaged: "
        "flash it again with `locust flash --port PORT`")


def malformed(port: str, what: str, msg) -> DeviceError:
    """The error for a reply or event whose ``what`` is out of shape, quoting the line.

    Parameters
    ----------
    port : str
        The serial port the line came from.
    what : str
        What is wrong with it, e.g. ``"protocol is not a whole number"``.
    msg : dict
        The decoded reply or event (quoted, cut to 300 characters).

    Returns
    -------
    DeviceError
        The error to raise, with a hint to flash the board again.
    """
    line = json.dumps(msg, separators=(",", ":"), default=repr)
    shown = line if len(line) <= 300 else line[:297] + "..."
    return DeviceError(f"{port}: the board's {what}, in the line {shown}",
                       HINT.replace("PORT", port))


def _is_int(value, low: int, high: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and low <= value <= high


def _is_text(value) -> bool:
    return isinstance(value, str) and len(value) <= MAX_TEXT


def check_hello(msg: dict, port: str) -> dict:
    """``msg`` if its version, protocol, chip, config problems and state have their types.

    Parameters
    ----------
    msg : dict
        The board's ``hello`` reply.
    port : str
        The serial port, for the message.

    Returns
    -------
    dict
        ``msg`` itself.

    Raises
    ------
    DeviceError
        A field is out of shape.
    """
    version = msg.get("micropython")
    if version is not None and not (isinstance(version, list) and 2 <= len(version) <= 4
                                    and all(_is_int(v, 0, 10_000) for v in version)):
        raise malformed(port, "MicroPython version is not a list of whole numbers like [1, 26, 0]", msg)
    if msg.get("version") is not None and not (_is_text(msg["version"]) and VERSION.fullmatch(msg["version"])):
        raise malformed(port, "firmware version is not a release number like 0.1.0", msg)
    for key in ("chip", "machine", "platform"):
        if msg.get(key) is not None and not _is_text(msg[key]):
            raise malformed(port, f"{key} is not a short text", msg)
    if not _is_int(msg.get("protocol"), 0, 10_000):
        raise malformed(port, "protocol is not a whole number", msg)
    problems = msg.get("config_problems")
    if problems is not None and not (isinstance(problems, list) and all(_is_text(p) for p in problems)):
        raise malformed(port, "config_problems is not a list of texts", msg)
    if msg.get("hopping") is not None and not isinstance(msg["hopping"], bool):
        raise malformed(port, "hopping is not true or false", msg)
    return msg


def check_config(msg: dict, port: str, chip: str | None = None) -> dict:
    """The ``config`` object of a ``config`` reply, within the firmware's own limits.

    The firmware runs only on a config that passes its own checks (``config.problems``: each
    value's limits, and ``chip``'s pin rules), its saved config.json or else its default: a
    reply outside them is not what it runs on.

    Parameters
    ----------
    msg : dict
        The board's ``config`` reply.
    port : str
        The serial port, for the message.
    chip : str, optional
        The chip the board says it is (its ``hello``), whose pins are checked too.

    Returns
    -------
    dict
        The board's config.

    Raises
    ------
    DeviceError
        The reply holds no config object, or one the firmware would refuse.
    """
    cfg = msg.get("config")
    if not isinstance(cfg, dict):
        raise malformed(port, "config reply holds no config object", msg)
    problems = fw_config.problems(cfg, chip if chip in fw_config.CHIPS else None)
    if problems:
        raise malformed(port, f"config reply holds a config the firmware refuses to run on ({problems[0]})", msg)
    return cfg


def _phase_fields(port: str, what: str, msg, cycle, name, commanded_us, measured_us) -> R.Phase:
    if not (_is_int(cycle, 0, MAX_CYCLE) and name in PHASE_NAMES and _is_int(commanded_us, 0, MAX_PHASE_US)
            and _is_int(measured_us, 0, MAX_PHASE_US)):
        raise malformed(port, f"{what} is not a cycle 0 to {MAX_CYCLE}, a phase ({' or '.join(PHASE_NAMES)}) and "
                              f"two times 0 to {MAX_PHASE_US:,} us", msg)
    return R.Phase(cycle, name, commanded_us, measured_us)


def phase_event(ev: dict, port: str) -> R.Phase:
    """The phase a ``phase`` event reports.

    Parameters
    ----------
    ev : dict
        The event.
    port : str
        The serial port, for the message.

    Returns
    -------
    Phase
        Cycle, phase name and the commanded and measured durations [us].

    Raises
    ------
    DeviceError
        A field is out of shape or out of range.
    """
    return _phase_fields(port, "phase event", ev, ev.get("cycle"), ev.get("phase"), ev.get("commanded_us"),
                         ev.get("measured_us"))


def check_scheduled(phase: R.Phase, schedule: R.HopSchedule, port: str, msg, after: R.Phase | None = None) -> R.Phase:
    """``phase`` if it is one the hop's schedule commands, and may follow ``after``.

    The firmware reports the phases of the schedule it was sent, in order, each started when
    it was due or later (it spins until then), on a clock that never runs backwards.

    Parameters
    ----------
    phase : Phase
        A phase the board reported.
    schedule : HopSchedule
        The schedule sent.
    port : str
        The serial port, for the message.
    msg : dict
        The event or reply it came in (quoted).
    after : Phase, optional
        The phase the board reported before it, in the same stream of events.

    Returns
    -------
    Phase
        ``phase`` itself.

    Raises
    ------
    DeviceError
        Not a phase of the schedule, not its commanded start, started early, out of order, or
        measured before the phase before it.
    """
    i = 2 * (phase.cycle - 1) + (phase.phase == "wait")
    if not 0 <= i < schedule.phases:
        raise malformed(port, f"phase is cycle {phase.cycle}'s {phase.phase}, not a phase of the {schedule.cycles} "
                              "cycles sent", msg)
    start_us = fw_schedule.phase(i, schedule.push_deg, schedule.push_ms, schedule.wait_ms)[2]
    if phase.commanded_us != start_us:
        raise malformed(port, f"phase says cycle {phase.cycle}'s {phase.phase} was commanded at "
                              f"{phase.commanded_us:,} us, not at the schedule's {start_us:,} us", msg)
    if phase.measured_us < phase.commanded_us:
        raise malformed(port, f"phase started {phase.commanded_us - phase.measured_us:,} us before it was due "
                              "(the firmware waits for each phase's start)", msg)
    if after is not None:
        before = 2 * (after.cycle - 1) + (after.phase == "wait")
        if i <= before:
            raise malformed(port, f"phase cycle {phase.cycle}'s {phase.phase} came after cycle {after.cycle}'s "
                                  f"{after.phase} (the firmware reports them in order, once each)", msg)
        if phase.measured_us < after.measured_us:
            raise malformed(port, f"phase was measured {after.measured_us - phase.measured_us:,} us before the one "
                                  "before it: its clock ran backwards", msg)
    return phase


def done_event(ev: dict, port: str) -> tuple[str, list[int] | None, int | None]:
    """The status, tick counts and length of a ``done`` event.

    Parameters
    ----------
    ev : dict
        The event.
    port : str
        The serial port, for the message.

    Returns
    -------
    tuple
        (status, ticks_us, rest_us): the firmware's status text, its ``ticks_us`` at the start
        and end of the hop [us] (None when it sent none), and the hop's length on its clock at
        that end [us] (None when it sent none).

    Raises
    ------
    DeviceError
        A field is out of shape or out of range.
    """
    status, ticks, rest = ev.get("status"), ev.get("ticks_us"), ev.get("rest_us")
    if not _is_text(status):
        raise malformed(port, "done event has no status text", ev)
    if ticks is not None and not (isinstance(ticks, list) and len(ticks) == 2
                                  and all(_is_int(t, 0, TICKS_US_MAX) for t in ticks)):
        raise malformed(port, "done event's ticks_us is not two whole numbers 0 to 2^30", ev)
    if rest is not None and not _is_int(rest, 0, MAX_PHASE_US):
        raise malformed(port, f"done event's rest_us is not a whole number 0 to {MAX_PHASE_US:,} us", ev)
    return status, ticks, rest


def report_page(msg: dict, port: str) -> tuple[list[R.Phase], int]:
    """The phases and total of a ``report`` reply (one page of the firmware's own list).

    Parameters
    ----------
    msg : dict
        The reply.
    port : str
        The serial port, for the message.

    Returns
    -------
    tuple
        (phases, total): this page's phases and the number the firmware holds in all.

    Raises
    ------
    DeviceError
        A field or row is out of shape or out of range.
    """
    rows, total = msg.get("phases"), msg.get("total")
    if not (isinstance(rows, list) and _is_int(total, 0, 2 * MAX_CYCLE)):
        raise malformed(port, "report reply has no list of phases and total", msg)
    phases = []
    for row in rows:
        if not (isinstance(row, list) and len(row) == 4):
            raise malformed(port, "report row is not [cycle, phase, commanded_us, measured_us]", msg)
        phases.append(_phase_fields(port, "report row", msg, *row))
    return phases, total


def pose_angles(reply: dict, port: str) -> tuple[float, float]:
    """The angles a ``pose`` or ``rest`` reply says the servos were set to.

    Parameters
    ----------
    reply : dict
        The reply.
    port : str
        The serial port, for the message.

    Returns
    -------
    tuple of float
        (left_deg, right_deg) [deg].

    Raises
    ------
    DeviceError
        Either angle is missing, not finite, or beyond +-180 deg.
    """
    angles = reply.get("left_deg"), reply.get("right_deg")
    if not all(isinstance(a, (int, float)) and not isinstance(a, bool) and math.isfinite(a) and abs(a) <= 180
               for a in angles):
        raise malformed(port, "pose reply has no left_deg and right_deg within +-180 deg", reply)
    return float(angles[0]), float(angles[1])
