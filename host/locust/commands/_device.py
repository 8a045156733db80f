"""What the board's commands share: the port option's help, the virtual robot's plant and video
options, the servo config's KEY=VALUE."""

from __future__ import annotations

import math
from pathlib import Path

import click

from ..device.plant import FPS_RANGE, PLANTS, VIDEO_FPS
from ..errors import DeviceError
from ..firmware import config as fw_config
from ..params import Schedule

CHIPS = tuple(fw_config.CHIPS)  # the chips whose pin rules the firmware knows, and the virtual robot models


PORT_HELP = "Serial port (e.g. /dev/ttyUSB0), or 'sim' for the virtual robot. Default: the one likely ESP32."


ROBOT_SCHEDULE = Schedule()   # the robot parameters' default schedule, named in the hop options' help


def info(msg: str) -> None:
    click.echo(msg, err=True)


def plant_options(func):
    func = click.option("--video", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help="With the virtual robot: render the simulated robot to this video "
                             "(fixed camera framed on the planned hops, "
                             "with .truth.csv and .camera.json beside it for `locust track`).")(func)
    func = click.option("--fps", "video_fps", type=click.IntRange(*FPS_RANGE), default=VIDEO_FPS, show_default=True,
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
