"""``locust params``: show the parameters a command would run on, or write a robot.toml."""

from __future__ import annotations

import os
from pathlib import Path

import click

from .. import params as robot_params
from ..errors import ParamsError
from ..fileio import json_text, locked
from ..io import robot_toml
from .options import robot_options, say_written_from


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
    robot = robot_toml.resolve_robot(preset, config, sets)
    say_written_from(preset, config, write)
    if write:
        _write(robot, write, force, config, sets)
        click.echo(f"wrote {write}")
        return
    load, why = _standing(robot)
    if as_json:
        out = {k: {"value": v, **_source(robot, k)} for k, v in robot.flat().items()}
        click.echo(json_text({"name": robot.name, "leg_set": robot.leg_set,
                              "leg_set_added_m": robot_params.leg_set_spec(robot.leg_set).added_m, "values": out,
                              "nose_load_kg": load.nose_load_kg if load else None,
                              "total_mass_kg": load.total_mass_kg if load else None}), nl=False)
        return
    click.echo(f"# {robot.name}")
    added_mm = robot_params.leg_set_spec(robot.leg_set).added_m * 1000
    click.echo(f"# leg set: {robot.leg_set} ({added_mm:+g} mm on every link of "
               "the cut file's strip)")
    for key, value in robot.flat().items():
        prov, parent = robot.source_of(key), robot.inherits(key)
        unc = f" ± {prov.uncertainty:.3g}" if prov.uncertainty is not None else ""
        shown = f"{value:.6g}" if isinstance(value, float) else str(value)
        click.echo(f"{key:42s} {shown:>12}{unc:12s}  [{prov.source if parent is None else '= ' + parent}]")
    click.echo(f"# standing at rest: {load.nose_load_kg * 1000:.1f} g of its {load.total_mass_kg * 1000:.1f} g on the "
               "nose (a kitchen scale under it, feet level with the pan)" if load else
               f"# standing at rest: no nose load ({why})")


def _source(robot: robot_params.Robot, key: str) -> dict:
    """A value's provenance for --json; an inherited one names the key it takes its value from."""
    parent = robot.inherits(key)
    if parent is not None:
        return {"inherits": parent}
    return {a: b for a, b in vars(robot.source_of(key)).items() if b is not None}


def _standing(robot: robot_params.Robot):
    """The model's standing load (:func:`locust.sim.statics.standing_load`), or None and why not."""
    from ..errors import LocustError
    from ..sim.statics import standing_load

    try:
        return standing_load(robot), ""
    except LocustError as exc:
        return None, exc.message


def _write(robot: robot_params.Robot, write: Path, force: bool, config: Path | None, sets) -> None:
    """--write: a new file is created exclusively (a file another command made a moment ago is
    not replaced); --force replaces one under its lock; ``--config F --set ... --write F
    --force`` updates F as it is now (another process's update kept), its comments kept.
    A file written from a --config keeps that file's comments and layout."""
    if not force:
        if write.exists():
            raise ParamsError(f"{write} exists", "choose another path, or add --force to overwrite it")
        robot_toml.save_robot(robot, write, template=robot_toml.file_text(config) if config else None, exclusive=True)
        return
    if config is not None and os.path.realpath(config) == os.path.realpath(write):
        overrides = robot_params.parse_set_options(sets)
        robot_toml.update_robot(
            write, lambda now: robot_params.check_robot(now.with_values(overrides, "override") if overrides else now))
        return
    with locked(write):   # replaced by this robot: the layout of its --config, if any
        robot_toml.save_robot(robot, write, template=robot_toml.file_text(config) if config else None)
