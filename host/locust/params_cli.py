"""``locust params``: show the parameters a command would run on, or write a robot.toml."""

from __future__ import annotations

from pathlib import Path

import click

from . import params as P
from .errors import ParamsError
from .fileio import json_text


def robot_options(func):
    """The shared --preset / --config / --set options of every command that needs a robot."""
    func = click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
                        help="Override any parameter by its dotted name, "
                             "e.g. --set servo.kp_nm_per_rad=0.4. Repeatable.")(func)
    func = click.option("--config", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help="A robot.toml (e.g. calibration/robot.toml); overrides --preset.")(func)
    func = click.option("--preset", type=click.Choice(list(P.PRESETS)), default="seed", show_default=True,
                        help="Built-in parameter set.")(func)
    return func


@click.command()
@robot_options
@click.option("--json", "as_json", is_flag=True, help="Print values as JSON.")
@click.option("--write", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the resulting parameter set to this robot.toml (refuses to overwrite).")
@click.option("--force", is_flag=True, help="With --write: overwrite an existing file.")
def params(preset, config, sets, as_json, write, force):
    """Show the robot parameters, with their source and uncertainty.

    Every key can be overridden on any command with --set KEY=VALUE. Below them, the
    model's load under the nose standing at rest, as a kitchen scale reads it (--json:
    nose_load_kg; `locust measure nose-load` takes the scale's reading back).
    """
    robot = P.resolve_robot(preset, config, sets)
    if write:
        if write.exists() and not force:
            raise ParamsError(f"{write} exists", "choose another path, or add --force to overwrite it")
        P.save_robot(robot, write)
        click.echo(f"wrote {write}")
        return
    load, why = _standing(robot)
    if as_json:
        out = {k: {"value": v, **{a: b for a, b in vars(robot.source_of(k)).items() if b is not None}}
               for k, v in robot.flat().items()}
        click.echo(json_text({"name": robot.name, "values": out,
                              "nose_load_kg": load.nose_load_kg if load else None,
                              "total_mass_kg": load.total_mass_kg if load else None}), nl=False)
        return
    click.echo(f"# {robot.name}")
    for key, value in robot.flat().items():
        prov = robot.source_of(key)
        unc = f" ± {prov.uncertainty:g}" if prov.uncertainty is not None else ""
        click.echo(f"{key:42s} {value!s:>12}{unc:12s}  [{prov.source}]")
    click.echo(f"# standing at rest: {load.nose_load_kg * 1000:.1f} g of its {load.total_mass_kg * 1000:.1f} g on the "
               "nose (a kitchen scale under it, feet level with the pan)" if load else
               f"# standing at rest: no nose load ({why})")


def _standing(robot: P.Robot):
    """The model's standing load (:func:`locust.sim.statics.standing_load`), or None and why not."""
    from .errors import LocustError
    from .sim.statics import standing_load

    try:
        return standing_load(robot), ""
    except LocustError as exc:
        return None, exc.message
