"""What the board's commands share: the port option's help, the virtual robot's plant and video
options, the robot a hop runs on."""

from __future__ import annotations

import math
from pathlib import Path

import click

from ..device.plant import PLANTS
from ..errors import DeviceError
from ..firmware import config as fw_config
from ..io import run_record as R
from ..io.robot_toml import resolve_robot
from ..params import Schedule
from .options import DEFAULTED

CHIPS = tuple(fw_config.CHIPS)  # the chips whose pin rules the firmware knows, and the virtual robot models


MAX_VIDEO_FRAMES = 10_000    # the frames a virtual robot's video may hold (100 cycles at 60 frames/s: 7830)


VIDEO_FPS = 60                # the virtual robot's camera, as docs/hardware.md asks of a real one


PORT_HELP = "Serial port (e.g. /dev/ttyUSB0), or 'sim' for the virtual robot. Default: the one likely ESP32."


ROBOT_SCHEDULE = Schedule()   # the robot parameters' default schedule, named in the hop options' help


def info(msg: str) -> None:
    click.echo(msg, err=True)


def plant_options(func):
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


def parse_servo_set(item: str, option: str = "--servo") -> tuple[str, float]:
    key, sep, value = item.partition("=")
    try:
        number = float(value)
    except ValueError:
        raise DeviceError(f"{option} {item!r} is not KEY=NUMBER", f"e.g. {option} left.trim_deg=-1.5") from None
    if not math.isfinite(number):
        raise DeviceError(f"{option} {item!r}: {value.strip()} is not a finite number; nothing was sent",
                          f"e.g. {option} left.trim_deg=-1.5")
    return key.strip(), number


def hopped_robot(preset, config, sets, leg_set_name):
    """(robot, what run.json records of it): --config or --preset, --leg-set in place of the
    leg set it carries, --set. The record names the leg set hopped: --leg-set's, else the robot's."""
    from ..params import LEG_SETS, check_robot, leg_set, parse_set_options

    defaulted = click.get_current_context().meta.get(DEFAULTED, False)
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


def interrupt(signum, frame):
    raise KeyboardInterrupt
