"""``locust virtual``: a virtual robot on a pseudo-terminal."""

from __future__ import annotations

import signal
import sys
from pathlib import Path

import click

from ..errors import DeviceError
from ..tables import hop_table, plant_lines
from ._device import CHIPS, info, plant_options
from .options import DEFAULTED, robot_options


@click.command()
@click.option("--flash-dir", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="The virtual robot's flash folder. "
                   "Default: $LOCUST_VIRTUAL_DIR/flash or ~/.cache/locust/virtual/flash.")
@click.option("--pwm-log", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write every PWM change (and the horn angle it means) to this CSV file (must not exist).")
@click.option("--chip", type=click.Choice(CHIPS), default="esp32", show_default=True,
              help="The chip whose limits the virtual robot has: its pins (os.uname().machine names it).")
@plant_options
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
    from ..device.hop_job import hopped_robot
    from ..device.interrupts import interrupt
    from ..device.plant import make_plant
    from ..device.virtual import VirtualRobot

    if pwm_log is not None and pwm_log.exists():
        raise DeviceError(f"{pwm_log} exists; a log is never overwritten", "choose another --pwm-log path")
    from ..device.announce import announce, withdraw

    robot, source = hopped_robot(preset, config, sets, None,
                                 defaulted=bool(click.get_current_context().meta.get(DEFAULTED)))
    shown = []

    def show_hop(hop: dict) -> None:       # each hop as it is done, the rows `locust sim` prints
        header, row = hop_table([{**hop, "cycle": len(shown) + 1}])
        info(row if shown else f"{header}\n{row}")
        shown.append(hop)

    vr = VirtualRobot(flash_dir, make_plant(plant, robot, video, video_fps, on_hop=show_hop), log_path=pwm_log,
                      chip=chip).start()
    announce(vr.device_path, source)      # a hop on its pty records this robot
    click.echo(vr.device_path)
    sys.stdout.flush()
    info(f"virtual robot ({vr.chip}): flash {vr.flash_dir}, {vr.scheduling} scheduling, "
          f"plant {type(vr.plant).__name__}; Ctrl-C to stop")
    signal.signal(signal.SIGTERM, interrupt)
    try:
        while True:
            signal.pause()
    except KeyboardInterrupt:
        pass
    finally:
        withdraw(vr.device_path)
        summary = vr.stop()
        info(f"virtual robot stopped after {vr.boots} boot(s)")
        for line in plant_lines(summary):
            info(line)
