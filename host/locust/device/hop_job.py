"""The hop as a job, from options to the run record: ``locust hop`` and
:func:`locust.api.hopping.hop` both call :func:`run_hop_job`.

It builds the robot that hops (``--preset``/``--config``, ``--leg-set``, ``--set``; on a
running ``locust virtual``, the robot that one simulates), the schedule (each value the
option's, else the robot's), the run folder, and then runs :func:`locust.device.hop.run_hop`
on the port, a ``--port sim`` virtual robot filming it when asked. A hop that never began
(nothing flashed, the wrong port, Ctrl-C at the handshake) leaves no folder behind; a
failure after the phases (the video onto a full disk, a signal while it was finished) is
written into the record, which keeps every phase.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import DeviceError, LocustError
from ..io import run_record as R
from ..io.robot_toml import default_robot, resolve_robot
from ..progress import progress
from .interrupts import signals_interrupt
from .plant import FPS_RANGE, PLANTS, VIDEO_FPS
from .ports import SIM

MAX_VIDEO_FRAMES = 10_000    # the frames a virtual robot's video may hold (100 cycles at 60 frames/s: 7830)


@dataclass(frozen=True)
class HopOptions:
    """What a hop is asked, one field for each option of ``locust hop`` (``--json`` aside: the
    record returned is what it prints).

    Attributes
    ----------
    port : str or None
        A serial port, ``sim`` for a virtual robot, or None for the one likely ESP32.
    cycles : int or None
        Hop cycles; None: the robot's ``schedule.cycles``.
    push_deg : float or None
        Horn angle of the push [deg]; None: the robot's ``schedule.push_deg``.
    push_ms : int or None
        Push time [ms]; None: the robot's ``schedule.push_s``.
    wait_ms : int or None
        Wait (rest) time [ms]; None: the robot's ``schedule.wait_s``.
    heartbeat_ms : int
        The robot returns to rest if the host is silent this long [ms].
    out : Path or None
        The folder for ``run.json`` (must not hold one); None: ``data/runs/<timestamp>/``.
    leg_set : str or None
        The legs on the robot, recorded in ``run.json``; None: the preset's when it is a leg set.
    plant : str
        With the virtual robot: what the servos drive (``auto``, ``mujoco`` or ``record``).
    video : Path or None
        With the virtual robot: the video it renders of the simulated robot.
    video_fps : int
        Frames per second of ``video`` [frames/s].
    preset : str or None
        A built-in parameter set.
    config : Path or None
        A robot.toml; overrides ``preset``.
    sets : tuple of str
        ``KEY=VALUE`` overrides of the robot's parameters.
    robot_line : str or None
        The line that says which robot a hop given neither ``preset`` nor ``config`` runs on
        (the command line's robot options resolve it); None with either given.
    """

    port: str | None = None
    cycles: int | None = None
    push_deg: float | None = None
    push_ms: int | None = None
    wait_ms: int | None = None
    heartbeat_ms: int = R.hop_default("heartbeat_ms")
    out: Path | None = None
    leg_set: str | None = None
    plant: str = "auto"
    video: Path | None = None
    video_fps: int = VIDEO_FPS
    preset: str | None = None
    config: Path | None = None
    sets: tuple[str, ...] = ()
    robot_line: str | None = None


@dataclass(frozen=True)
class HopJobResult:
    """What a hop left behind.

    Attributes
    ----------
    record : locust.io.run_record.RunRecord
        The record as written in ``run.json``: its ``status`` is ``complete`` only when every
        phase was reported and the firmware finished the schedule (``default_config`` when the
        board ran on its defaults, ``incomplete`` when the firmware ended it early).
    folder : Path
        The folder ``run.json`` is in.
    simulated : dict
        A ``--port sim`` virtual robot's plant summary (``plant``; with the live model its
        simulated hops, SI units); empty for a board.
    """

    record: R.RunRecord
    folder: Path
    simulated: dict


def run_hop_job(options: HopOptions, say: Callable[[str], None] | None = None) -> HopJobResult:
    """Run the hop ``options`` ask for and keep its run record.

    Parameters
    ----------
    options : HopOptions
        The hop's options.
    say : callable, optional
        ``say(line)`` with each line ``locust hop`` prints on stderr before its summary (the
        output folder first, the robot, the virtual robot); None: nothing is said. A progress
        bar shows on stderr.

    Returns
    -------
    HopJobResult
        The record, its folder and the virtual robot's summary.

    Raises
    ------
    locust.errors.DeviceError
        An option out of its limits, no board, a board that refused the hop, stopped reporting,
        rebooted or was lost, or an interruption: the message says what was recorded, and a hop
        that never began leaves no folder.
    locust.errors.ParamsError
        A robot that cannot be read or built.
    """
    say = say or (lambda line: None)
    _check(options)
    options = _robot_named(options)
    robot, source = hopped_robot(options.preset, options.config, options.sets, options.leg_set,
                                 defaulted=options.robot_line is not None)
    made = _first_missing(Path(options.out) if options.out is not None else R.RUNS_ROOT)
    directory = R.run_dir(options.out)
    # what a hop that never started made goes again: the folders it created, none that was there
    made = made if made is not None else (directory if options.out is None else None)
    say(f"output folder: {directory}")
    source = _virtual_robot_source(options.port, source, options.robot_line, say)
    schedule = hop_schedule(robot.schedule, options)
    # the virtual robot's fixed video camera is framed on this schedule's planned run
    # (the options are in the firmware's limits; the robot itself judges its servo travel)
    robot = robot.with_values({"schedule.cycles": schedule.cycles, "schedule.push_deg": schedule.push_deg,
                               "schedule.push_s": schedule.push_ms / 1000, "schedule.wait_s": schedule.wait_ms / 1000},
                              "locust hop options")
    if options.video is not None and options.port == SIM:
        try:
            _video_frames(schedule, options.video, options.video_fps, say)
        except LocustError as exc:
            _remove_empty(directory, made)
            raise _unrecorded(exc, directory) from None
    held = R.claim(directory)   # a second hop into the same --out is refused (the folder is the other's)
    simulated: dict = {}      # the virtual robot's simulated hops (--port sim)
    try:
        # a kill (SIGTERM) or a closed terminal (SIGHUP) ends the hop as Ctrl-C does: the robot to
        # rest, the record says so, a --port sim virtual robot stops
        with signals_interrupt():
            rec = _hop_on_port(options, robot, source, schedule, directory, made, say, simulated.update)
    finally:
        os.close(held)
    return HopJobResult(rec, directory, simulated)


def _hop_on_port(options: HopOptions, robot, source: R.RobotSource, schedule: R.HopSchedule, directory: Path,
                 made: Path | None, say: Callable[[str], None],
                 on_simulated: Callable[[dict], None]) -> R.RunRecord:
    """The hop on the port (a virtual robot started for it on ``sim``); what a failure
    around it cost is said, and a hop that never began removes the folders it made."""
    from .hop import run_hop
    from .link import Link
    from .session import open_port

    rec = None
    virtual: list = []       # the virtual robot (--port sim): its host's stalls go in the record
    try:
        with open_port(options.port, plant=options.plant, video=options.video, robot=robot, info=say,
                       video_fps=options.video_fps, on_close=on_simulated, on_open=virtual.append) as device:
            with Link(device) as link:
                with progress(length=schedule.phases, label="hop") as bar:
                    rec = run_hop(link, schedule, directory,
                                  on_phase=lambda p: (bar.update(1),
                                                      setattr(bar, "label", f"cycle {p.cycle} {p.phase}")),
                                  robot=source, stalls=virtual[0].stalls if virtual else None)
    except BaseException as exc:
        reported = _reported(exc, rec, directory, made)
        if reported is not exc:
            raise reported from None
        raise
    return rec


def _reported(exc: BaseException, rec: R.RunRecord | None, directory: Path, made: Path | None) -> BaseException:
    """What to report of ``exc``, which ended the hop: said in the record when it came after
    the phases; a hop that never began leaves no folder, and its error says so."""
    reported = _note_after_hop(rec, directory, exc) if isinstance(exc, LocustError) else exc
    never_began = not (directory / R.RECORD_NAME).exists()
    if isinstance(exc, KeyboardInterrupt) and never_began:
        reported = DeviceError("interrupted before the hop began", "run the hop again when ready")
    _remove_empty(directory, made)   # a hop that never started leaves no folder
    if never_began and isinstance(reported, LocustError):
        reported = _unrecorded(reported, directory)   # (the first line named the folder)
    return reported


def _check(options: HopOptions) -> None:
    """The options within the limits the command line's own types keep them in (the
    firmware's for the schedule), checked before anything is made."""
    for name in ("cycles", "push_deg", "push_ms", "wait_ms", "heartbeat_ms"):
        value = getattr(options, name)
        low, high = R.hop_range(name)
        whole = name != "push_deg"
        if value is not None and not _within(value, low, high, whole):
            raise DeviceError(f"{name} {value!r} is not {'a whole number' if whole else 'a number'} "
                              f"within {low:g}..{high:g}", "see `locust hop --help` for each option's limits")
    if not _within(options.video_fps, *FPS_RANGE, whole=True):
        raise DeviceError(f"video_fps {options.video_fps!r} is not a whole number within "
                          f"{FPS_RANGE[0]}..{FPS_RANGE[1]}", "60 is a real camera's rate")
    if options.plant not in PLANTS:
        raise DeviceError(f"unknown plant {options.plant!r}", f"choose one of {', '.join(PLANTS)}")


def _within(value, low: float, high: float, whole: bool) -> bool:
    """Whether ``value`` is a number (a whole one, with ``whole``), finite and in ``low..high``."""
    kind = numbers.Integral if whole else numbers.Real
    return isinstance(value, kind) and not isinstance(value, bool) and math.isfinite(value) and low <= value <= high


def _robot_named(options: HopOptions) -> HopOptions:
    """``options`` with the robot a hop runs on named: neither ``preset`` nor ``config`` is the
    default robot (:func:`locust.io.robot_toml.default_robot`), as on the command line."""
    if options.preset is not None or options.config is not None:
        return options
    choice = default_robot()
    return dataclasses.replace(options, preset=choice.preset, config=choice.robot_file, robot_line=choice.line)


def hopped_robot(preset: str | None, config: Path | None, sets, leg_set_name: str | None,
                 defaulted: bool = False):
    """The robot that hops and what ``run.json`` records of it.

    Parameters
    ----------
    preset : str or None
        A built-in parameter set.
    config : Path or None
        A robot.toml; overrides ``preset``.
    sets : sequence of str
        ``KEY=VALUE`` overrides.
    leg_set_name : str or None
        The legs on the robot (``--leg-set``), in place of the leg set it carries; a known
        leg set is built on the robot.
    defaulted : bool, default False
        Neither ``preset`` nor ``config`` was named (the default robot's).

    Returns
    -------
    tuple of (Robot, RobotSource)
        The robot, and the record's note of it: the leg set named, else the robot's.

    Raises
    ------
    locust.errors.DeviceError
        A leg set's name that cannot be one, or one that contradicts a leg-set preset.
    locust.errors.ParamsError
        A robot that cannot be read or built.
    """
    from ..params import LEG_SETS, check_robot, leg_set, parse_set_options

    # a leg-set preset named on the command line is the legs hopped; --leg-set may not contradict it
    preset_set = preset if config is None and preset in LEG_SETS and not defaulted else None
    if leg_set_name is not None:
        leg_set_name = R.check_leg_set(leg_set_name)
        if preset_set and leg_set_name != preset_set:
            raise DeviceError(f"--leg-set {leg_set_name} contradicts --preset {preset}, which is the {preset} leg set",
                              f"give --preset {leg_set_name}, or --leg-set with --config robot.toml")
    robot = resolve_robot(preset, config, ())
    if leg_set_name in LEG_SETS:
        robot = leg_set(robot, leg_set_name, source=f"leg-set:{leg_set_name}")
    overrides = parse_set_options(sets)
    robot = check_robot(robot.with_values(overrides, "override") if overrides else robot)
    source = R.RobotSource(preset=None if config else preset, robot_file=str(config) if config else None,
                         leg_set=leg_set_name or robot.leg_set)
    return robot, source


def hop_schedule(schedule, options: HopOptions) -> R.HopSchedule:
    """The schedule commanded: each value the option's, else the robot's ``schedule``.

    Parameters
    ----------
    schedule : locust.params.Schedule
        The robot's schedule.
    options : HopOptions
        The hop's options.

    Returns
    -------
    locust.io.run_record.HopSchedule
    """
    return R.HopSchedule(cycles=options.cycles or schedule.cycles,
                       push_deg=schedule.push_deg if options.push_deg is None else options.push_deg,
                       push_ms=options.push_ms or round(schedule.push_s * 1000),
                       wait_ms=options.wait_ms or round(schedule.wait_s * 1000), heartbeat_ms=options.heartbeat_ms)


def _virtual_robot_source(port: str | None, source: R.RobotSource, robot_line: str | None,
                          say: Callable[[str], None]) -> R.RobotSource:
    """The robot a ``locust virtual`` on ``port`` simulates, when it is one: that is what hops."""
    from .announce import announced

    theirs = announced(port) if port not in (None, SIM) else None
    if theirs is None:
        if robot_line:
            say(robot_line)
        return source
    if theirs.leg_set is None and source.leg_set is not None:
        theirs = R.RobotSource(theirs.preset, theirs.robot_file, source.leg_set)    # --leg-set names the legs
    if not robot_line and (theirs.preset, theirs.robot_file) != (source.preset, source.robot_file):
        say(f"warning: the virtual robot on {port} simulates {theirs.robot_file or theirs.preset}, "
            f"not {source.robot_file or source.preset}: run.json records its robot")
    say(f"robot: {theirs.robot_file or theirs.preset}, the one the virtual robot on {port} simulates")
    return theirs


def _video_frames(schedule: R.HopSchedule, video: Path, fps: int, say: Callable[[str], None]) -> None:
    """Say how many frames the virtual robot's video will hold before the hop starts (each is
    rendered on the CPU: a second of run at --fps 1000 is minutes of rendering); refuse more
    than MAX_VIDEO_FRAMES (every schedule at the default 60 frames/s fits)."""
    from ..sim.live import PREROLL_S

    run_s = PREROLL_S + schedule.duration_s
    frames = math.ceil(run_s * fps)
    if frames > MAX_VIDEO_FRAMES:
        raise DeviceError(f"--video {video}: {run_s:.1f} s of run at --fps {fps} is {frames} frames, over the "
                          f"{MAX_VIDEO_FRAMES} a video of the virtual robot may hold (each is rendered on the CPU)",
                          f"lower --fps (60 is a real camera's rate) or --cycles, to at most "
                          f"{MAX_VIDEO_FRAMES // math.ceil(run_s)} frames/s for this schedule")
    say(f"video: about {frames} frames for the hop ({run_s:.1f} s at {fps} frames/s), and more for the "
        "seconds the virtual robot stands before and after it (its clock runs from its boot to the "
        "command's end); the command ends when the last is written")


def _note_after_hop(rec: R.RunRecord | None, directory: Path, exc: LocustError) -> LocustError:
    """The run record says what a failure after the phases cost (the virtual robot's video onto
    a full disk, or interrupted while it was finished), and every phase is kept. Returns the
    error to report: both failures, when the hop had failed first. A signal that came once the
    video was finished all the same (``VIDEO_KEPT``) cost nothing the record describes: it
    stays as the hop left it, beside its video."""
    from .virtual import VIDEO_KEPT, VIDEO_NOT_KEPT

    path = directory / R.RECORD_NAME
    if exc.message == VIDEO_KEPT:
        return _after_first(exc)
    if rec is None and exc.message == VIDEO_NOT_KEPT and path.is_file():
        rec = R.read_run_record(path)   # (the hop's own failure wrote it, or a signal came as it returned)
    if rec is None:
        return exc
    if rec.status == R.COMPLETE:
        rec.status, rec.message = R.INCOMPLETE, f"after the hop: {exc.message}"
    elif exc.message == VIDEO_NOT_KEPT:
        rec.message = f"{rec.message}; {VIDEO_NOT_KEPT}" if rec.message else VIDEO_NOT_KEPT
    else:
        return exc
    R.write(rec, directory)
    return _after_first(exc)


def _after_first(exc: LocustError) -> LocustError:
    """``exc`` after the hop's own error it was raised during, when there was one (both said)."""
    first = exc.__context__   # (the signal, raised while the hop's own error unwound)
    while first is not None and not isinstance(first, LocustError):
        first = first.__context__
    return DeviceError(f"{first.message}; {exc.message}", first.hint) if first is not None else exc


def _unrecorded(exc: LocustError, directory: Path) -> DeviceError:
    """``exc`` saying that no record was written and what became of the output folder the
    command's first line named (a hop that never began removes the folder it made)."""
    note = (f"no run record was written, so {directory} was not kept" if not directory.exists()
            else f"no run record was written in {directory}")
    return DeviceError(f"{exc.message}; {note}", exc.hint)


def _first_missing(path: Path) -> Path | None:
    """The outermost folder of ``path`` that does not exist yet (what making it would create)."""
    missing = None
    for p in (path, *path.parents):
        if p.exists():
            break
        missing = p
    return missing


def _remove_empty(directory: Path, top: Path | None) -> None:
    """Remove ``directory`` and its parents up to ``top`` while they are empty (none if ``top``
    is None: the folder was there before)."""
    if top is None:
        return
    for p in (directory, *directory.parents):
        try:
            p.rmdir()   # only an empty folder goes
        except OSError:
            return
        if p == top:
            return
