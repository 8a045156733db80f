"""``locust hop``: the bang-bang schedule on the robot, into a run record."""

from __future__ import annotations

import math
import os
import signal
from pathlib import Path

import click

from ..errors import DeviceError, LocustError
from ..fileio import json_text
from ..io import run_record as R
from ..progress import progress
from ._device import MAX_VIDEO_FRAMES, PORT_HELP, ROBOT_SCHEDULE, hopped_robot, info, interrupt, plant_options
from .options import DEFAULTED, FiniteFloat, robot_options


@click.command()
@click.option("--port", default=None, help=PORT_HELP)
@click.option("--cycles", type=click.IntRange(*R.hop_range("cycles")), default=None,
              help=f"Hop cycles [robot schedule: {ROBOT_SCHEDULE.cycles}].")
@click.option("--push-deg", type=FiniteFloat(low=R.hop_range("push_deg")[0], high=R.hop_range("push_deg")[1]),
              default=None,
              help=f"Horn angle of the push, deg [robot schedule: {ROBOT_SCHEDULE.push_deg:g}].")
@click.option("--push-ms", type=click.IntRange(*R.hop_range("push_ms")), default=None,
              help=f"Push time, ms [robot schedule: {ROBOT_SCHEDULE.push_s * 1000:g}].")
@click.option("--wait-ms", type=click.IntRange(*R.hop_range("wait_ms")), default=None,
              help=f"Wait (rest) time, ms [robot schedule: {ROBOT_SCHEDULE.wait_s * 1000:g}].")
@click.option("--heartbeat-ms", type=click.IntRange(*R.hop_range("heartbeat_ms")),
              default=R.hop_default("heartbeat_ms"), show_default=True,
              help="The robot returns to rest if the host is silent this long.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Directory for run.json (must not hold one), named on the first line. Default: "
                   "data/runs/<timestamp>/. A hop the board never answered leaves no folder.")
@click.option("--json", "as_json", is_flag=True, help="Print the run record as JSON.")
@click.option("--leg-set", "leg_set_name", default=None, metavar="NAME",
              help="The legs on the robot (small, medium, large, or a name of your own), recorded in "
                   "run.json for `locust report`. Default: the --preset when it is a leg set. "
                   "A known leg set is built on the --config robot for the virtual robot.")
@plant_options
@robot_options(say=False)   # the robot line comes once a virtual robot on --port is known
def hop(port, cycles, push_deg, push_ms, wait_ms, heartbeat_ms, out, as_json, leg_set_name, plant, video, video_fps,
        preset, config, sets):
    """Run the bang-bang hop schedule (push, wait; N cycles) and save the run record.

    Phases are timed on the robot (ticks_us); run.json gets the commanded and measured start
    of every phase and the jitter, which robot and leg set were hopped (--preset/--config,
    --leg-set), and the board's config (chip, pins, trims) read back before the hop. Ctrl-C or
    a lost cable: the robot goes to rest, the record keeps what arrived (status incomplete)
    and the command exits non-zero; so does a hop the board ran on its default config because
    its config.json was unreadable (status default_config).
    """
    from ..device.hop import run_hop
    from ..device.link import Link
    from ..device.session import open_port

    robot, source = hopped_robot(preset, config, sets, leg_set_name)
    made = _first_missing(Path(out) if out is not None else R.RUNS_ROOT)
    directory = R.run_dir(out)
    # what a hop that never started made goes again: the folders it created, none that was there
    made = made if made is not None else (directory if out is None else None)
    info(f"output folder: {directory}")
    source = _virtual_robot_source(port, source)
    s = robot.schedule
    schedule = R.HopSchedule(cycles=cycles or s.cycles, push_deg=s.push_deg if push_deg is None else push_deg,
                             push_ms=push_ms or round(s.push_s * 1000), wait_ms=wait_ms or round(s.wait_s * 1000),
                             heartbeat_ms=heartbeat_ms)
    # the virtual robot's fixed video camera is framed on this schedule's planned run
    # (the options are in the firmware's limits; the robot itself judges its servo travel)
    robot = robot.with_values({"schedule.cycles": schedule.cycles, "schedule.push_deg": schedule.push_deg,
                               "schedule.push_s": schedule.push_ms / 1000, "schedule.wait_s": schedule.wait_ms / 1000},
                              "locust hop options")
    if video is not None and port == "sim":
        try:
            _video_frames(schedule, video, video_fps)
        except LocustError as exc:
            _remove_empty(directory, made)
            raise _unrecorded(exc, directory) from None
    held = R.claim(directory)   # a second hop into the same --out is refused (the folder is the other's)
    # a kill (SIGTERM) or a closed terminal (SIGHUP) ends the hop as Ctrl-C does: the robot to
    # rest, the record says so, a --port sim virtual robot stops
    previous = {sig: signal.signal(sig, interrupt) for sig in (signal.SIGTERM, signal.SIGHUP)}
    rec = None
    simulated: dict = {}     # the virtual robot's simulated hops (--port sim)
    virtual: list = []       # the virtual robot (--port sim): its host's stalls go in the record
    try:
        with open_port(port, plant=plant, video=video, robot=robot, info=info, video_fps=video_fps,
                       on_close=simulated.update, on_open=virtual.append) as device:
            with Link(device) as link:
                with progress(length=schedule.phases, label="hop") as bar:
                    rec = run_hop(link, schedule, directory,
                                  on_phase=lambda p: (bar.update(1),
                                                      setattr(bar, "label", f"cycle {p.cycle} {p.phase}")),
                                  robot=source, stalls=virtual[0].stalls if virtual else None)
    except BaseException as exc:
        reported = _note_after_hop(rec, directory, exc) if isinstance(exc, LocustError) else exc
        never_began = not (directory / R.RECORD_NAME).exists()
        if isinstance(exc, KeyboardInterrupt) and never_began:
            reported = DeviceError("interrupted before the hop began", "run the hop again when ready")
        _remove_empty(directory, made)   # a hop that never started leaves no folder
        if never_began and isinstance(reported, LocustError):
            reported = _unrecorded(reported, directory)   # (the first line named the folder)
        if reported is not exc:
            raise reported from None
        raise
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        os.close(held)
    path = directory / R.RECORD_NAME
    if as_json:
        doc = rec.to_dict()
        if simulated.get("plant") == "mujoco":
            doc["simulated"] = simulated      # what the virtual robot's simulation did, SI units
        click.echo(json_text(doc), nl=False)
    j, stall_s = R.jitter(rec.phases), R.host_stall_max_s(rec.phases)
    info(f"{rec.status}: {len(rec.phases)}/{schedule.phases} phases"
          + (f", start error max {j.max_abs_ms:.3f} ms (mean {j.mean_ms:.3f}, sd {j.std_ms:.3f})" if j else "")
          + (f", host stall max {stall_s * 1000:.2f} ms" if stall_s is not None else "")
          + f"; record {path}")
    note = R.timing_note(rec.phases)
    if note:
        info(f"{note}; that lateness is the host's, not the firmware's: hop again with less running beside it")
    if rec.status == R.DEFAULT_CONFIG:
        raise DeviceError(f"every phase ran, but {rec.message}",
                          f"{R.CONFIG_FIX_HINT}; then hop again (this record, {path}, says {R.DEFAULT_CONFIG})")
    if rec.status != R.COMPLETE:
        raise DeviceError(f"the hop did not complete: {rec.message}", f"the partial record is in {path}")


def _virtual_robot_source(port, source):
    """The robot a ``locust virtual`` on ``port`` simulates, when it is one: that is what hops."""
    from ..device.announce import announced
    from ..device.ports import SIM

    said = click.get_current_context().meta.get(DEFAULTED)
    theirs = announced(port) if port not in (None, SIM) else None
    if theirs is None:
        if said:
            info(said)
        return source
    if theirs.leg_set is None and source.leg_set is not None:
        theirs = R.RobotSource(theirs.preset, theirs.robot_file, source.leg_set)    # --leg-set names the legs
    mine = click.get_current_context().meta.get(DEFAULTED, False)
    if not mine and (theirs.preset, theirs.robot_file) != (source.preset, source.robot_file):
        info(f"warning: the virtual robot on {port} simulates {theirs.robot_file or theirs.preset}, "
              f"not {source.robot_file or source.preset}: run.json records its robot")
    info(f"robot: {theirs.robot_file or theirs.preset}, the one the virtual robot on {port} simulates")
    return theirs


def _video_frames(schedule: R.HopSchedule, video: Path, fps: int) -> None:
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
    info(f"video: about {frames} frames for the hop ({run_s:.1f} s at {fps} frames/s), and more for the "
         "seconds the virtual robot stands before and after it (its clock runs from its boot to the "
         "command's end); the command ends when the last is written")


def _note_after_hop(rec, directory: Path, exc: LocustError) -> LocustError:
    """The run record says what a failure after the phases cost (the virtual robot's video onto
    a full disk, or interrupted while it was finished), and every phase is kept. Returns the
    error to report: both failures, when the hop had failed first. A signal that came once the
    video was finished all the same (``VIDEO_KEPT``) cost nothing the record describes: it
    stays as the hop left it, beside its video."""
    from ..device.virtual import VIDEO_KEPT, VIDEO_NOT_KEPT

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
