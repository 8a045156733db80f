"""``locust ports``, ``flash``, ``hop``, ``pose``, ``repl``, ``virtual``: thin wrappers."""

from __future__ import annotations

import math
import os
import signal
import sys
from pathlib import Path

import click

from ..errors import DeviceError, LocustError
from ..fileio import json_text
from ..firmware import config as fw_config
from ..io import run_record as R
from ..options import FiniteFloat
from ..params import Schedule, resolve_robot
from ..params_cli import DEFAULTED, robot_options
from ..progress import progress
from ..tables import hop_table, plant_lines
from .plant import PLANTS

CHIPS = tuple(fw_config.CHIPS)  # the chips whose pin rules the firmware knows, and the virtual robot models
MAX_VIDEO_FRAMES = 10_000    # the frames a virtual robot's video may hold (100 cycles at 60 frames/s: 7830)
VIDEO_FPS = 60                # the virtual robot's camera, as docs/hardware.md asks of a real one
PORT_HELP = "Serial port (e.g. /dev/ttyUSB0), or 'sim' for the virtual robot. Default: the one likely ESP32."
ROBOT_SCHEDULE = Schedule()   # the robot parameters' default schedule, named in the hop options' help


def _info(msg: str) -> None:
    click.echo(msg, err=True)


def _plant_options(func):
    func = click.option("--video", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help="With the virtual robot: render the simulated robot to this video "
                             "(fixed camera framed on the planned hops, "
                             "with .truth.csv and .camera.json beside it for `locust track`).")(func)
    func = click.option("--fps", "video_fps", type=click.IntRange(1, 1000), default=VIDEO_FPS, show_default=True,
                        help="With --video: frames per second of the rendered video (docs/hardware.md asks "
                             "60 or more of a real camera: a hop's flight lasts a few frames at 30).")(func)
    func = click.option("--plant", type=click.Choice(PLANTS), default="auto", show_default=True,
                        help="With the virtual robot: what the servos drive (mujoco: the live model; "
                             "record: only record the commands; auto: mujoco when installed).")(func)
    return func


@click.command()
@click.option("--json", "as_json", is_flag=True, help="Print the ports as JSON.")
def ports(as_json):
    """List serial ports with VID:PID and serial number; mark the likely ESP32 (*)."""
    from .ports import list_serial_ports

    found = list_serial_ports()
    if as_json:
        click.echo(json_text([{**vars(p), "vid_pid": p.vid_pid} for p in found]), nl=False)
        return
    if not found:
        click.echo("no serial ports found (use --port sim for the virtual robot)")
        return
    for p in found:
        mark = "*" if p.esp32_hint else " "
        click.echo(f"{mark} {p.device:20s} {p.vid_pid:10s} {p.serial_number or '-':20s} "
                   f"{p.esp32_hint or p.description}")


@click.command()
@click.option("--port", default=None, help=PORT_HELP)
@click.option("--compile", "compile_mpy", is_flag=True,
              help="Compile the modules with mpy-cross (.mpy: faster import, less RAM).")
@click.option("--reset-config", is_flag=True,
              help="Write config.json from the robot parameters (pulse range, travel) even if the board has one.")
@click.option("--servo", "servo_sets", multiple=True, metavar="KEY=VALUE",
              help="Then set one servo config value on the board, e.g. --servo right.trim_deg=2.5. Repeatable.")
@robot_options
def flash(port, compile_mpy, reset_config, servo_sets, preset, config, sets):
    """Copy the firmware to the board (mpremote), verify each file by SHA-256, reset, handshake.

    The board needs MicroPython first; a board without it gets the command that installs it.
    With --port sim the files go to the virtual robot's flash folder
    ($LOCUST_VIRTUAL_DIR/flash, default ~/.cache/locust/virtual/flash).
    """
    from .board import write_values
    from .flash import flash as do_flash
    from .link import Link
    from .session import open_port

    edits = [_parse_servo_set(s) for s in servo_sets]
    servo = resolve_robot(preset, config, sets).servo if reset_config else None
    with open_port(port, plant="record", info=_info, firmware=False) as device:
        # the edits are checked against the board's chip before any file is written
        result = do_flash(device, compile_mpy=compile_mpy, servo=servo, edits=edits,
                          progress=lambda s: _info(f"  {s}"))
        if edits:
            with Link(device) as link:
                link.hello()
                write_values(link, edits, _info)
    names = ", ".join(f.name for f in result.files)
    click.echo(f"flashed locust firmware {result.firmware_version} to {port or device} ({result.board}): "
               f"{len(result.files)} files verified by SHA-256 ({names})"
               f"{'; wrote config.json' if result.config_written else ''} in {result.elapsed_s:.1f} s")
    if result.config_problems and not edits:   # a --servo edit saved a whole valid config
        _info("warning: the board runs on its default config: " + "; ".join(result.config_problems))
        _info(f"  fix: {R.CONFIG_FIX_HINT}")


def _parse_servo_set(item: str, option: str = "--servo") -> tuple[str, float]:
    key, sep, value = item.partition("=")
    try:
        number = float(value)
    except ValueError:
        raise DeviceError(f"{option} {item!r} is not KEY=NUMBER", f"e.g. {option} left.trim_deg=-1.5") from None
    if not math.isfinite(number):
        raise DeviceError(f"{option} {item!r}: {value.strip()} is not a finite number; nothing was sent",
                          f"e.g. {option} left.trim_deg=-1.5")
    return key.strip(), number


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
@_plant_options
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
    from .hop import run_hop
    from .link import Link
    from .session import open_port

    robot, source = _hopped_robot(preset, config, sets, leg_set_name)
    made = _first_missing(Path(out) if out is not None else R.RUNS_ROOT)
    directory = R.run_dir(out)
    # what a hop that never started made goes again: the folders it created, none that was there
    made = made if made is not None else (directory if out is None else None)
    _info(f"output folder: {directory}")
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
        except LocustError:
            _remove_empty(directory, made)
            raise
    held = R.claim(directory)   # a second hop into the same --out is refused (the folder is the other's)
    # a kill (SIGTERM) or a closed terminal (SIGHUP) ends the hop as Ctrl-C does: the robot to
    # rest, the record says so, a --port sim virtual robot stops
    previous = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGTERM, signal.SIGHUP)}
    rec = None
    simulated: dict = {}     # the virtual robot's simulated hops (--port sim)
    try:
        with open_port(port, plant=plant, video=video, robot=robot, info=_info, video_fps=video_fps,
                       on_close=simulated.update) as device:
            with Link(device) as link:
                with progress(length=schedule.phases, label="hop") as bar:
                    rec = run_hop(link, schedule, directory,
                                  on_phase=lambda p: (bar.update(1),
                                                      setattr(bar, "label", f"cycle {p.cycle} {p.phase}")),
                                  robot=source)
    except BaseException as exc:
        reported = _note_after_hop(rec, directory, exc) if isinstance(exc, LocustError) else exc
        if isinstance(exc, KeyboardInterrupt) and not (directory / R.RECORD_NAME).exists():
            reported = DeviceError("interrupted before the hop began: no run record was written",
                                   "run the hop again when ready")
        _remove_empty(directory, made)   # a hop that never started leaves no folder
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
    j = R.jitter(rec.phases)
    _info(f"{rec.status}: {len(rec.phases)}/{schedule.phases} phases"
          + (f", start error max {j.max_abs_ms:.3f} ms (mean {j.mean_ms:.3f}, sd {j.std_ms:.3f})" if j else "")
          + f"; record {path}")
    if rec.status == R.DEFAULT_CONFIG:
        raise DeviceError(f"every phase ran, but {rec.message}",
                          f"{R.CONFIG_FIX_HINT}; then hop again (this record, {path}, says {R.DEFAULT_CONFIG})")
    if rec.status != R.COMPLETE:
        raise DeviceError(f"the hop did not complete: {rec.message}", f"the partial record is in {path}")


def _virtual_robot_source(port, source):
    """The robot a ``locust virtual`` on ``port`` simulates, when it is one: that is what hops."""
    from .announce import announced
    from .ports import SIM

    said = click.get_current_context().meta.get(DEFAULTED)
    theirs = announced(port) if port not in (None, SIM) else None
    if theirs is None:
        if said:
            _info(said)
        return source
    if theirs.leg_set is None and source.leg_set is not None:
        theirs = R.RobotSource(theirs.preset, theirs.robot_file, source.leg_set)    # --leg-set names the legs
    mine = click.get_current_context().meta.get(DEFAULTED, False)
    if not mine and (theirs.preset, theirs.robot_file) != (source.preset, source.robot_file):
        _info(f"warning: the virtual robot on {port} simulates {theirs.robot_file or theirs.preset}, "
              f"not {source.robot_file or source.preset}: run.json records its robot")
    _info(f"robot: {theirs.robot_file or theirs.preset}, the one the virtual robot on {port} simulates")
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
    _info(f"video: about {frames} frames to render ({run_s:.1f} s at {fps} frames/s); the command ends when "
          "the last is written")


def _note_after_hop(rec, directory: Path, exc: LocustError) -> LocustError:
    """The run record says what a failure after the phases cost (the virtual robot's video onto
    a full disk, or interrupted while it was finished), and every phase is kept. Returns the
    error to report: both failures, when the hop had failed first."""
    from .virtual import VIDEO_NOT_KEPT

    path = directory / R.RECORD_NAME
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
    first = exc.__context__   # (the signal, raised while the hop's own error unwound)
    while first is not None and not isinstance(first, LocustError):
        first = first.__context__
    return DeviceError(f"{first.message}; {exc.message}", first.hint) if first is not None else exc


def _hopped_robot(preset, config, sets, leg_set_name):
    """(robot, what run.json records of it): --config or --preset, the leg set on it, --set."""
    from ..params import LEG_SETS, check_robot, leg_set, parse_set_options

    defaulted = click.get_current_context().meta.get(DEFAULTED, False)
    # a leg-set preset names the legs hopped when given; the default one (the robot as built) does not
    preset_set = preset if config is None and preset in LEG_SETS and not defaulted else None
    if leg_set_name is not None:
        leg_set_name = R.check_leg_set(leg_set_name)
        if preset_set and leg_set_name != preset_set:
            raise DeviceError(f"--leg-set {leg_set_name} contradicts --preset {preset}, which is the {preset} leg set",
                              f"give --preset {leg_set_name}, or --leg-set with --config robot.toml")
    robot = resolve_robot(preset, config, ())
    if leg_set_name in LEG_SETS and not preset_set:
        robot = leg_set(robot, leg_set_name, source=f"leg-set:{leg_set_name}")
    overrides = parse_set_options(sets)
    robot = check_robot(robot.with_values(overrides, "override") if overrides else robot)
    source = R.RobotSource(preset=None if config else preset, robot_file=str(config) if config else None,
                           leg_set=leg_set_name or preset_set)
    return robot, source


@click.command("config")
@click.option("--port", default=None, help=PORT_HELP)
@click.option("--set", "servo_sets", multiple=True, metavar="KEY=VALUE",
              help="Set one servo config value on the board and save its config.json, e.g. "
                   "--set right.trim_deg=2.5 (keys: left./right. pin, trim_deg, direction, pulse_min_us, "
                   "pulse_max_us, range_deg, travel_deg). Repeatable. Nothing is flashed.")
@click.option("--json", "as_json", is_flag=True, help="Print the board's config as JSON.")
def board_config(port, servo_sets, as_json):
    """Read the board's servo config back (chip, pins, trims, pulse ranges), or change it.

    
      locust config --port /dev/ttyUSB0                           what the firmware runs on
      locust config --port /dev/ttyUSB0 --set left.trim_deg=2.5   trim without reflashing

    The board checks each value against its limits and its chip's pins and saves the whole
    config.json; a config.json it could not read (it then runs on its defaults, and says so
    here) is replaced by a valid one. `locust hop` records the same config in run.json.
    """
    from .board import read_board, table, write_values
    from .link import Link
    from .session import open_port

    edits = [_parse_servo_set(s, "--set") for s in servo_sets]
    with open_port(port, plant="record", info=_info) as device:
        with Link(device) as link:
            hello = link.hello()
            write_values(link, edits, _info)
            board = read_board(link, None if edits else hello)
    if as_json:
        click.echo(json_text(board.to_dict()), nl=False)
    else:
        click.echo(f"board on {port or device}: {fw_config.chip_name(board.chip) if board.chip else 'unknown chip'} "
                   f"({board.machine}), firmware {hello.get('version')}")
        click.echo(table(board))
        click.echo("config.json: " + ("NOT in use, the firmware runs on its defaults" if board.on_defaults
                                      else "in use"))
    if board.on_defaults:
        _info("warning: the board runs on its default config: " + "; ".join(board.problems))
        _info(f"  fix: {R.CONFIG_FIX_HINT}")


@click.command(context_settings={"ignore_unknown_options": True})  # `pose -20 10`: -20 is an angle
@click.argument("left_deg", type=float, required=False)
@click.argument("right_deg", type=float, required=False)
@click.option("--rest", is_flag=True, help="Both horns to rest (0 deg, the servos' centre).")
@click.option("--port", default=None, help=PORT_HELP)
def pose(left_deg, right_deg, rest, port):
    """Move both servo horns to LEFT_DEG RIGHT_DEG and hold them there: for assembly and trim.

    \b
    Centring, before the horns go on:
      locust pose --rest            both servos to their centre (horn 0 deg) and hold
    then push each horn onto its spline as close to its rest position as the splines allow.
    Trimming the rest of the error:
      locust pose 0 0               look at the legs at rest
      locust config --set left.trim_deg=2.5   (shaft deg; reversed on the mirrored right leg)
    Checking the travel and the direction of each leg:
      locust pose -20 10            left horn -20 deg, right horn +10 deg

    Angles are horn degrees from rest in the firmware's units: push is negative and both legs
    use the same sign (the right servo is mirrored by its config's direction). The protocol
    allows -90..90; the robot refuses anything beyond its servo travel (travel_deg, +-45 deg
    by default). Negative angles can be typed directly or after `--` (`locust pose -- -20 -20`).

    The pose holds after the command ends, until the robot is told otherwise: another pose, or
    a hop, a servo config change or Ctrl-C into the REPL, which leave it at rest, or a reset,
    which stops the pulses (the servos go limp) until the firmware starts and sets them to rest.
    With --port sim the virtual robot lives only as long as the command: use `locust virtual`
    and its /dev/pts/N to watch a pose there.
    """
    from .link import Link
    from .pose import check_angles
    from .pose import pose as do_pose
    from .session import open_port

    given = [a for a in (left_deg, right_deg) if a is not None]
    if rest and given:
        raise DeviceError("give either LEFT_DEG RIGHT_DEG or --rest, not both", "e.g. `locust pose -20 10`")
    if not rest and len(given) != 2:
        raise DeviceError("a pose needs both angles, LEFT_DEG and RIGHT_DEG (or --rest)",
                          "e.g. `locust pose -20 10`, `locust pose --rest`; see `locust pose --help`")
    if not rest:
        left_deg, right_deg = check_angles(left_deg, right_deg)  # before any port is opened
    with open_port(port, plant="record", info=_info) as device:
        with Link(device) as link:
            left, right = do_pose(link, None if rest else left_deg, None if rest else right_deg)
    click.echo(f"{'rest' if rest else 'pose'}: left {left:g} deg, right {right:g} deg (horn, from rest) "
               f"on {port or device}; held until another command moves the servos or a reset")


@click.command()
@click.option("--port", default=None, help=PORT_HELP)
def repl(port):
    """Open MicroPython's REPL on the robot (mpremote connect PORT repl); leave with Ctrl-] or Ctrl-X.

    \b
    In the REPL session:
      Ctrl-C      stops the locust command loop (servos to rest) and gives the >>> prompt;
                  ignored while a hop runs
      Ctrl-D      at the >>> prompt: soft reset, main.py starts the command loop again
      Ctrl-] or Ctrl-X   leave mpremote (the board stays as it is)

    Until Ctrl-C the command loop owns the console: nothing is echoed, and a line you type is
    answered with a bad_frame reply. For scripts, `mpremote connect PORT exec "..."` gets in
    the same way (its own Ctrl-C); `locust hop`/`pose` need the command loop again (Ctrl-D
    here, `locust flash`, or a reset).

    With --port sim a virtual robot runs (its /dev/pts/N is printed) for as long as the REPL
    session; to use the same virtual robot with other commands too, start `locust virtual`
    and pass its /dev/pts/N as --port.
    """
    from .repl import require_terminal, run_repl
    from .session import open_port

    require_terminal()  # before a virtual robot is started for nothing
    # a closed terminal (SIGHUP) or a kill (SIGTERM) must still stop a --port sim virtual robot
    previous = {sig: signal.signal(sig, _interrupt) for sig in (signal.SIGTERM, signal.SIGHUP)}
    try:
        with open_port(port, plant="record", info=_info, firmware=False) as device:
            _info(f"mpremote REPL on {device}: Ctrl-C for the >>> prompt, Ctrl-D there restarts the firmware, "
                  "Ctrl-] or Ctrl-X leaves")
            run_repl(device)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _interrupt(signum, frame):
    raise KeyboardInterrupt


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


@click.command()
@click.option("--flash-dir", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="The virtual robot's flash folder. "
                   "Default: $LOCUST_VIRTUAL_DIR/flash or ~/.cache/locust/virtual/flash.")
@click.option("--pwm-log", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write every PWM change (and the horn angle it means) to this CSV file (must not exist).")
@click.option("--chip", type=click.Choice(CHIPS), default="esp32", show_default=True,
              help="The chip whose limits the virtual robot has: its pins (os.uname().machine names it).")
@_plant_options
@robot_options
def virtual(flash_dir, pwm_log, chip, plant, video, video_fps, preset, config, sets):
    """Start a virtual robot in the foreground; print its device path (/dev/pts/N) first.

    The firmware in the flash folder runs on the real MicroPython interpreter (unix port)
    behind that pseudo-terminal; any serial tool, mpremote or `locust hop --port /dev/pts/N`
    can talk to it. Fill the flash with `locust flash --port /dev/pts/N`. Ctrl-C stops it.

    It has a board's limits (docs/device.md): 30-bit ticks that wrap a few seconds after each
    boot, poll timeouts on a 10 ms tick, the chip's pin rules, a heap like a board without
    PSRAM, servos limp after a soft reset, Ctrl-C that interrupts anywhere while idle.
    """
    from .plant import make_plant
    from .virtual import VirtualRobot

    if pwm_log is not None and pwm_log.exists():
        raise DeviceError(f"{pwm_log} exists; a log is never overwritten", "choose another --pwm-log path")
    from .announce import announce, withdraw

    robot, source = _hopped_robot(preset, config, sets, None)
    shown = []

    def show_hop(hop: dict) -> None:       # each hop as it is done, the rows `locust sim` prints
        header, row = hop_table([{**hop, "cycle": len(shown) + 1}])
        _info(row if shown else f"{header}\n{row}")
        shown.append(hop)

    vr = VirtualRobot(flash_dir, make_plant(plant, robot, video, video_fps, on_hop=show_hop), log_path=pwm_log,
                      chip=chip).start()
    announce(vr.device_path, source)      # a hop on its pty records this robot
    click.echo(vr.device_path)
    sys.stdout.flush()
    _info(f"virtual robot ({vr.chip}): flash {vr.flash_dir}, {vr.scheduling} scheduling, "
          f"plant {type(vr.plant).__name__}; Ctrl-C to stop")
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        while True:
            signal.pause()
    except KeyboardInterrupt:
        pass
    finally:
        withdraw(vr.device_path)
        summary = vr.stop()
        _info(f"virtual robot stopped after {vr.boots} boot(s)")
        for line in plant_lines(summary):
            _info(line)
