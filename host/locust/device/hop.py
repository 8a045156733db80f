"""Run the hop schedule on the robot and keep the run record up to date as phases arrive.

The firmware times the phases itself (``ticks_us``) and reports each one live; the host
sends a heartbeat all along, so that a host that dies or a cable that is pulled leaves the
robot at rest within the heartbeat timeout. Whatever happens, ``run.json`` holds what
arrived, with status ``complete`` only when every phase was reported and the firmware
finished the schedule. On a virtual robot each phase also gets its host stall (the time the
host held the interpreter off while it was due, :mod:`locust.device.stalls`), so the record
can say when the timing is the host's rather than the firmware's.
"""

from __future__ import annotations

import queue
import time
from collections.abc import Callable
from pathlib import Path

from ..errors import DeviceError
from ..firmware import protocol as P
from ..io import run_record as R
from .board import read_board
from .link import CLOSED, Link
from .replies import check_scheduled, done_event, phase_event, report_page
from .stalls import StallWatch

RECORD_EVERY_S = 0.25  # run.json is rewritten at most this often during a hop
LATE_END_S = 3.0       # past the schedule's end, a hop whose board has not said it ended is given up


def _fetch_report(link: Link, rec: R.RunRecord) -> None:
    """Ask for the firmware's own list of phases: fills any event lost on the line."""
    start = 0
    while True:
        page = link.call("report", start=start)
        phases, total = report_page(page, link.port)
        for phase in phases:
            rec.add_phase(check_scheduled(phase, rec.schedule, link.port, page))
        start += len(phases)
        if not phases or start >= total:
            return


def run_hop(link: Link, schedule: R.HopSchedule, directory: Path,
            on_phase: Callable[[R.Phase], None] = lambda p: None,
            robot: R.RobotSource | None = None, stalls: StallWatch | None = None) -> R.RunRecord:
    """Run ``schedule`` on the robot, writing ``run.json`` in ``directory`` as phases arrive.

    No record is written until the board answers the handshake. Whatever ends the hop
    (Ctrl-C, a lost cable, a reboot, silence) the robot is sent to rest and the record keeps
    what arrived, marked ``incomplete``.

    Parameters
    ----------
    link : Link
        An open link to the board.
    schedule : HopSchedule
        Cycles, push angle [deg], push and wait times [ms] and heartbeat timeout [ms].
    directory : Path
        The run folder ``run.json`` is written in.
    on_phase : callable, optional
        ``on_phase(phase)`` for each phase as it arrives.
    robot : RobotSource, optional
        The robot recorded in ``run.json`` (a virtual robot's preset or robot file).
    stalls : StallWatch, optional
        A virtual robot's watch on its interpreter (:attr:`VirtualRobot.stalls`): each phase
        gets its host stall, and the record says when the timing is the host's. None for a
        real board (not applicable).

    Returns
    -------
    RunRecord
        The record as written: ``complete`` only when every phase was reported and the
        firmware finished the schedule (``default_config`` when it ran on its defaults).

    Raises
    ------
    DeviceError
        The robot refused the hop, stopped reporting, rebooted, the port was lost, or the hop
        was interrupted; the message gives the phases recorded and the record's path.
    """
    rec = R.RunRecord(schedule=schedule, port=link.port, message="running", robot=robot or R.RobotSource())
    # no record until the board has answered: a hop that never started (nothing flashed, the
    # wrong port, Ctrl-C at the handshake) leaves no run folder behind
    try:
        hello = link.hello(soft_reset=True)    # mpremote leaves a board at the REPL
    except KeyboardInterrupt:
        raise DeviceError("interrupted before the board answered: no hop ran",
                          "run the hop again when ready") from None
    rec.firmware_version = hello.get("version")
    R.write(rec, directory)
    try:
        _hop(link, rec, directory, hello, on_phase, stalls)
    except KeyboardInterrupt:
        raise _interrupted(link, rec, directory) from None
    except DeviceError as exc:
        raise _failed(link, rec, directory, exc) from None
    finally:
        link.stop_heartbeat()
        if stalls is not None:
            stalls.stop()
    _judge(rec)
    R.write(rec, directory)
    return rec


def _hop(link: Link, rec: R.RunRecord, directory: Path, hello: dict, on_phase: Callable[[R.Phase], None],
         stalls: StallWatch | None) -> None:
    """The hop itself, once the board has answered: its config read, the schedule sent, the
    phases followed to the board's end, any phase lost on the line asked for again."""
    schedule = rec.schedule
    if hello.get("hopping"):
        link.call("stop")
    rec.board = read_board(link, hello)
    R.write(rec, directory)
    while not link.events.empty():  # a boot event from before we connected is old news
        link.events.get_nowait()
    link.start_heartbeat(schedule.heartbeat_ms / 8000.0)  # 8 beats in each timeout
    if stalls is not None:
        stalls.start()
    end_us = _follow(link, rec, directory, _start(link, rec, directory), on_phase)
    link.stop_heartbeat()
    if len(rec.phases) < schedule.phases:
        _fetch_report(link, rec)
    if stalls is not None:
        stalls.stop()
        if rec.firmware_ticks_us and end_us is not None:
            rec.set_host_stalls(stalls.phase_stalls_us(rec.firmware_ticks_us[1], end_us, rec.phases))


def _start(link: Link, rec: R.RunRecord, directory: Path) -> int:
    """Send the schedule; the id the board's events of this hop carry (a refusal is recorded)."""
    s = rec.schedule
    reply = link.request("hop", cycles=s.cycles, push_deg=s.push_deg, push_ms=s.push_ms, wait_ms=s.wait_ms,
                         heartbeat_ms=s.heartbeat_ms)
    if not reply.get("ok"):
        rec.status, rec.message = R.ERROR, f"{reply.get('error')}: {reply.get('detail')}"
        R.write(rec, directory)
        raise DeviceError(f"the robot refused the hop: {rec.message}",
                          "see `locust hop --help` and docs/protocol.md for the limits")
    return reply["id"]   # the id of our request: the reply was matched by it


def _follow(link: Link, rec: R.RunRecord, directory: Path, hop_id: int,
            on_phase: Callable[[R.Phase], None]) -> int | None:
    """Record each phase of hop ``hop_id`` as the board reports it, until its ``done`` event;
    the board's ticks at the end [us] (None if it gave none)."""
    schedule = rec.schedule
    last_write = 0.0
    last: R.Phase | None = None
    deadline = time.monotonic() + schedule.duration_s + LATE_END_S
    while True:
        ev = _next_event(link, schedule, deadline)
        if ev.get("hop") != hop_id:
            continue
        if ev.get("ev") == P.EV_PHASE:
            phase = last = check_scheduled(phase_event(ev, link.port), schedule, link.port, ev, last)
            rec.add_phase(phase)
            # rewriting the whole record at each of 2000 phases costs more than the phases
            # last: a host that falls behind stops reading, the board's output blocks and its
            # phases start late. So at most every RECORD_EVERY_S while phases stream in.
            if time.monotonic() - last_write >= RECORD_EVERY_S:
                R.write(rec, directory)
                last_write = time.monotonic()
            on_phase(phase)
        elif ev.get("ev") == P.EV_DONE:
            rec.firmware_status, rec.firmware_ticks_us, end_us = done_event(ev, link.port)
            return end_us


def _next_event(link: Link, schedule: R.HopSchedule, deadline: float) -> dict:
    """The board's next event during the hop; silence, a lost port, a reboot or a hop that
    goes on past ``deadline`` (``time.monotonic()``) are errors."""
    if time.monotonic() > deadline:   # (a board that reports on and on never ends the hop)
        raise DeviceError(f"the robot had not ended the hop {LATE_END_S:g} s after its "
                          f"{schedule.duration_s:g} s schedule",
                          "the board's firmware is not this toolkit's, or it is damaged: flash it again "
                          "with `locust flash`")
    try:
        ev = link.events.get(timeout=max(0.1, deadline - time.monotonic()))
    except queue.Empty:
        raise DeviceError("the robot stopped reporting mid-hop",
                          "check the cable and the power; the record keeps what arrived") from None
    if ev is CLOSED:
        raise link.lost_error()
    if ev.get("ev") == P.EV_BOOT:
        cause = ev.get("reset", "unknown")
        what = ("a brown-out (MicroPython reports it as a power-on reset)" if cause == "power_on"
                else f"a {cause} reset")
        raise DeviceError(f"the robot rebooted mid-hop: {what}",
                          "check the servo power supply: two servos pushing can sag the ESP32's supply")
    return ev


def _interrupted(link: Link, rec: R.RunRecord, directory: Path) -> DeviceError:
    """Ctrl-C or a kill mid-hop: the robot to rest, the record kept as ``incomplete``."""
    _stop_quietly(link)
    rec.status, rec.message = R.INCOMPLETE, "interrupted (Ctrl-C or a kill); the robot was sent to rest"
    R.write(rec, directory)
    return DeviceError(f"hop interrupted after {len(rec.phases)} of {rec.schedule.phases} phases; "
                       f"partial record in {directory / R.RECORD_NAME}",
                       "the robot is at rest; run the hop again when ready")


def _failed(link: Link, rec: R.RunRecord, directory: Path, exc: DeviceError) -> DeviceError:
    """A hop that failed mid-way: the robot to rest, the record kept (``incomplete``, or the
    board's refusal as ``error``), the error saying how far it got."""
    _stop_quietly(link)
    if rec.status != R.ERROR:
        rec.status, rec.message = R.INCOMPLETE, exc.message
    R.write(rec, directory)
    return DeviceError(f"{exc.message} (after {len(rec.phases)} of {rec.schedule.phases} phases; "
                       f"partial record in {directory / R.RECORD_NAME})", exc.hint)


def _judge(rec: R.RunRecord) -> None:
    """The verdict of a hop the board ended: ``complete`` only with every phase reported and
    the firmware's own ``complete`` (``default_config`` when it ran on its defaults)."""
    complete = rec.firmware_status == P.HOP_COMPLETE and len(rec.phases) == rec.schedule.phases
    rec.status = R.COMPLETE if complete else R.INCOMPLETE
    rec.message = None if complete else f"firmware ended the hop: {rec.firmware_status}"
    if complete and rec.board is not None and rec.board.on_defaults:
        rec.status = R.DEFAULT_CONFIG
        rec.message = "the board ran on its default config, not its config.json: " + "; ".join(rec.board.problems)


def _stop_quietly(link: Link) -> None:
    try:
        link.request("stop", timeout_s=0.5)
    except (DeviceError, KeyboardInterrupt):
        pass
