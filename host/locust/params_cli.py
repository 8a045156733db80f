"""``locust params``: show the parameters a command would run on, or write a robot.toml."""

from __future__ import annotations

import functools
import os
from pathlib import Path

import click

from . import params as P
from .errors import ParamsError
from .fileio import json_text, locked

ROBOT_FILE = Path("calibration") / "robot.toml"   # what `locust calibrate --write` makes: the robot as calibrated
DEFAULT_PRESET = "small"                          # the robot as built, no legs added (README, "What the presets are")
DEFAULTED = "locust.robot_defaulted"              # click context meta: no --preset or --config was given


def default_robot() -> tuple[str | None, Path | None, str]:
    """(preset, robot file, the line saying which) when a command is given neither: the
    calibrated robot in the current folder, else the robot as built."""
    if ROBOT_FILE.is_file():
        return None, ROBOT_FILE, f"robot: {ROBOT_FILE} (found here; --preset or --config to choose another)"
    return DEFAULT_PRESET, None, (f"robot: {DEFAULT_PRESET}, the robot as built (no {ROBOT_FILE} here; "
                                  "--preset or --config to choose another)")


def robot_options(func=None, *, say: bool = True):
    """The shared --preset / --config / --set options of every command that needs a robot.

    With neither --preset nor --config the command runs on :func:`default_robot`, and its
    first line of output (on stderr) says which; ``say=False``: the command prints that line
    itself (the click context's meta ``DEFAULTED`` holds it), once it knows better."""
    if func is None:
        return functools.partial(robot_options, say=say)
    command = func

    @functools.wraps(command)
    def wrapper(*args, preset, config, **kwargs):
        if preset is None and config is None:
            preset, config, said = default_robot()
            if say:
                click.echo(said, err=True)
            click.get_current_context().meta[DEFAULTED] = said
        return command(*args, preset=preset, config=config, **kwargs)

    func = click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
                        help="Override any parameter by its dotted name, "
                             "e.g. --set servo.kp_nm_per_rad=0.4. Repeatable.")(wrapper)
    func = click.option("--config", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help=f"A robot.toml (e.g. {ROBOT_FILE}); overrides --preset.")(func)
    func = click.option("--preset", type=click.Choice(list(P.PRESETS)), default=None,
                        help=f"Built-in parameter set [default: {ROBOT_FILE} when the current folder has one, "
                             f"else {DEFAULT_PRESET}, the robot as built].")(func)
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
        _write(robot, write, force, config, sets)
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


def _write(robot: P.Robot, write: Path, force: bool, config: Path | None, sets) -> None:
    """--write: a new file is created exclusively (a file another command made a moment ago is
    not replaced); --force replaces one under its lock; ``--config F --set ... --write F
    --force`` updates F as it is now (another process's update kept), its comments kept.
    A file written from a --config keeps that file's comments and layout."""
    if not force:
        if write.exists():
            raise ParamsError(f"{write} exists", "choose another path, or add --force to overwrite it")
        P.save_robot(robot, write, template=P.file_text(config) if config else None, exclusive=True)
        return
    if config is not None and os.path.realpath(config) == os.path.realpath(write):
        overrides = P.parse_set_options(sets)
        P.update_robot(write, lambda now: P.check_robot(now.with_values(overrides, "override") if overrides else now))
        return
    with locked(write):   # replaced by this robot: the layout of its --config, if any
        P.save_robot(robot, write, template=P.file_text(config) if config else None)
