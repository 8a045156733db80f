"""``locust config``: the board's servo config read back, or a trim set."""

from __future__ import annotations

import click

from ..fileio import json_text
from ..firmware import config as fw_config
from ..io import run_record as R
from ._device import PORT_HELP, info, parse_servo_set


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
    from ..device.board import read_board, table, write_values
    from ..device.link import Link
    from ..device.session import open_port

    edits = [parse_servo_set(s, "--set") for s in servo_sets]
    with open_port(port, plant="record", info=info) as device:
        with Link(device) as link:
            hello = link.hello()
            write_values(link, edits, info)
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
        info("warning: the board runs on its default config: " + "; ".join(board.problems))
        info(f"  fix: {R.CONFIG_FIX_HINT}")
