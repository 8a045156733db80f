"""``locust flash``: the MicroPython firmware onto the board (mpremote)."""

from __future__ import annotations

import click

from ..io import run_record as R
from ..io.robot_toml import resolve_robot
from ._device import PORT_HELP, info, parse_servo_set
from .options import robot_options


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
    from ..device.board import write_values
    from ..device.flash import flash as do_flash
    from ..device.link import Link
    from ..device.session import open_port

    edits = [parse_servo_set(s) for s in servo_sets]
    servo = resolve_robot(preset, config, sets).servo if reset_config else None
    with open_port(port, plant="record", info=info, firmware=False) as device:
        # the edits are checked against the board's chip before any file is written
        result = do_flash(device, compile_mpy=compile_mpy, servo=servo, edits=edits,
                          progress=lambda s: info(f"  {s}"))
        if edits:
            with Link(device) as link:
                link.hello()
                write_values(link, edits, info)
    names = ", ".join(f.name for f in result.files)
    click.echo(f"flashed locust firmware {result.firmware_version} to {port or device} ({result.board}): "
               f"{len(result.files)} files verified by SHA-256 ({names})"
               f"{'; wrote config.json' if result.config_written else ''} in {result.elapsed_s:.1f} s")
    if result.config_problems and not edits:   # a --servo edit saved a whole valid config
        info("warning: the board runs on its default config: " + "; ".join(result.config_problems))
        info(f"  fix: {R.CONFIG_FIX_HINT}")
