"""``locust ports``: the serial ports, the likely ESP32 marked."""

from __future__ import annotations

import click

from ..fileio import json_text


@click.command()
@click.option("--json", "as_json", is_flag=True, help="Print the ports as JSON.")
def ports(as_json):
    """List serial ports with VID:PID and serial number; mark the likely ESP32 (*)."""
    from ..device.ports import list_serial_ports

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
