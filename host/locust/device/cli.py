"""``locust ports``, ``locust flash``, ``locust hop``, ``locust virtual``: thin wrappers."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import click

from ..errors import DeviceError
from ..fileio import json_text
from ..params import Schedule, resolve_robot
from ..params_cli import robot_options
from ..progress import progress
from . import record as R
from .plant import PLANTS

PORT_HELP = "Serial port (e.g. /dev/ttyUSB0), or 'sim' for the virtual robot. Default: the one likely ESP32."
ROBOT_SCHEDULE = Schedule()   # the robot parameters' default schedule, named in the hop options' help


def _info(msg: str) -> None:
    click.echo(msg, err=True)


def _plant_options(func):
    func = click.option("--video", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help="With the virtual robot: render the simulated robot to this video "
                             "(fixed camera framed on the planned hops, "
                             "with .truth.csv and .camera.json beside it for `locust track`).")(func)
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
    from .flash import flash as do_flash
    from .flash import servo_config
    from .link import Link
    from .session import open_port

    edits = [_parse_servo_set(s) for s in servo_sets]
    servo_cfg = servo_config(resolve_robot(preset, config, sets).servo) if reset_config else None
    with open_port(port, plant="record", info=_info) as device:
        result = do_flash(device, compile_mpy=compile_mpy, config=servo_cfg, progress=lambda s: _info(f"  {s}"))
        if edits:
            with Link(device) as link:
                link.hello()
                for key, value in edits:
                    link.call("config", key=key, value=value, write=1)
                    _info(f"  set {key} = {value:g}")
    names = ", ".join(f.name for f in result.files)
    click.echo(f"flashed locust firmware {result.firmware_version} to {port or device} ({result.board}): "
               f"{len(result.files)} files verified by SHA-256 ({names})"
               f"{'; wrote config.json' if result.config_written else ''} in {result.elapsed_s:.1f} s")


def _parse_servo_set(item: str) -> tuple[str, float]:
    key, sep, value = item.partition("=")
    try:
        return key.strip(), float(value)
    except ValueError:
        raise DeviceError(f"--servo {item!r} is not KEY=NUMBER", "e.g. --servo left.trim_deg=-1.5") from None


@click.command()
@click.option("--port", default=None, help=PORT_HELP)
@click.option("--cycles", type=click.IntRange(*R.hop_range("cycles")), default=None,
              help=f"Hop cycles [robot schedule: {ROBOT_SCHEDULE.cycles}].")
@click.option("--push-deg", type=float, default=None,
              help=f"Horn angle of the push, deg [robot schedule: {ROBOT_SCHEDULE.push_deg:g}].")
@click.option("--push-ms", type=click.IntRange(*R.hop_range("push_ms")), default=None,
              help=f"Push time, ms [robot schedule: {ROBOT_SCHEDULE.push_s * 1000:g}].")
@click.option("--wait-ms", type=click.IntRange(*R.hop_range("wait_ms")), default=None,
              help=f"Wait (rest) time, ms [robot schedule: {ROBOT_SCHEDULE.wait_s * 1000:g}].")
@click.option("--heartbeat-ms", type=click.IntRange(*R.hop_range("heartbeat_ms")),
              default=R.hop_default("heartbeat_ms"), show_default=True,
              help="The robot returns to rest if the host is silent this long.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Directory for run.json (must not hold one). Default: data/runs/<timestamp>/.")
@click.option("--json", "as_json", is_flag=True, help="Print the run record as JSON.")
@_plant_options
@robot_options
def hop(port, cycles, push_deg, push_ms, wait_ms, heartbeat_ms, out, as_json, plant, video, preset, config, sets):
    """Run the bang-bang hop schedule (push, wait; N cycles) and save the run record.

    Phases are timed on the robot (ticks_us); run.json gets the commanded and measured start
    of every phase and the jitter. Ctrl-C or a lost cable: the robot goes to rest, the
    record keeps what arrived (status incomplete) and the command exits non-zero.
    """
    from .hop import run_hop
    from .link import Link
    from .session import open_port

    robot = resolve_robot(preset, config, sets)
    s = robot.schedule
    schedule = R.HopSchedule(cycles=cycles or s.cycles, push_deg=s.push_deg if push_deg is None else push_deg,
                             push_ms=push_ms or round(s.push_s * 1000), wait_ms=wait_ms or round(s.wait_s * 1000),
                             heartbeat_ms=heartbeat_ms)
    directory = R.run_dir(out)
    # the virtual robot's fixed video camera is framed on this schedule's planned run
    robot = robot.with_values({"schedule.cycles": schedule.cycles, "schedule.push_deg": schedule.push_deg,
                               "schedule.push_s": schedule.push_ms / 1000, "schedule.wait_s": schedule.wait_ms / 1000},
                              "locust hop options")
    with open_port(port, plant=plant, video=video, robot=robot, info=_info) as device:
        with Link(device) as link:
            with progress(length=schedule.phases, label="hop") as bar:
                rec = run_hop(link, schedule, directory,
                              on_phase=lambda p: (bar.update(1), setattr(bar, "label", f"cycle {p.cycle} {p.phase}")))
    path = directory / R.RECORD_NAME
    if as_json:
        click.echo(json_text(rec.to_dict()), nl=False)
    j = R.jitter(rec.phases)
    _info(f"{rec.status}: {len(rec.phases)}/{schedule.phases} phases"
          + (f", start error max {j.max_abs_ms:.3f} ms (mean {j.mean_ms:.3f}, sd {j.std_ms:.3f})" if j else "")
          + f"; record {path}")
    if rec.status != R.COMPLETE:
        raise DeviceError(f"the hop did not complete: {rec.message}", f"the partial record is in {path}")


def _interrupt(signum, frame):
    raise KeyboardInterrupt


@click.command()
@click.option("--flash-dir", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="The virtual robot's flash folder. "
                   "Default: $LOCUST_VIRTUAL_DIR/flash or ~/.cache/locust/virtual/flash.")
@click.option("--pwm-log", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write every PWM change (and the horn angle it means) to this CSV file (must not exist).")
@_plant_options
@robot_options
def virtual(flash_dir, pwm_log, plant, video, preset, config, sets):
    """Start a virtual robot in the foreground; print its device path (/dev/pts/N) first.

    The firmware in the flash folder runs on the real MicroPython interpreter (unix port)
    behind that pseudo-terminal; any serial tool, mpremote or `locust hop --port /dev/pts/N`
    can talk to it. Fill the flash with `locust flash --port /dev/pts/N`. Ctrl-C stops it.
    """
    from .plant import make_plant
    from .virtual import VirtualRobot

    if pwm_log is not None and pwm_log.exists():
        raise DeviceError(f"{pwm_log} exists; a log is never overwritten", "choose another --pwm-log path")
    robot = resolve_robot(preset, config, sets)
    vr = VirtualRobot(flash_dir, make_plant(plant, robot, video), log_path=pwm_log).start()
    click.echo(vr.device_path)
    sys.stdout.flush()
    _info(f"virtual robot: flash {vr.flash_dir}, {vr.scheduling} scheduling, "
          f"plant {type(vr.plant).__name__}; Ctrl-C to stop")
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        while True:
            signal.pause()
    except KeyboardInterrupt:
        pass
    finally:
        summary = vr.stop()
        _info(f"virtual robot stopped after {vr.boots} boot(s); " + ", ".join(f"{k}={v}" for k, v in summary.items()))
