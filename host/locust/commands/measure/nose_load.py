"""``locust measure nose-load``: the servo axis from the nose's weight on a kitchen scale
(docs/hardware.md)."""

from __future__ import annotations

from pathlib import Path

import click

from ...errors import MeasureError
from ...fileio import json_text
from ...io import robot_toml
from ..options import POSITIVE, robot_options, say_written_from

TERMS_SHOWN = 3


def _mm(e) -> str:
    lo, hi = e.ci95
    return f"{e.value * 1000:.1f} ± {e.sd * 1000:.1f} mm (95 %: {lo * 1000:.1f} to {hi * 1000:.1f})"


@click.command("nose-load")
@click.argument("grams", type=POSITIVE)
@robot_options
@click.option("--resolution-g", type=POSITIVE, default=1.0, show_default=True,
              help="The scale's resolution (its last digit), in grams.")
@click.option("--total-g", type=POSITIVE, default=None,
              help="The whole robot weighed on the same scale, in grams: sets the plate's mass first.")
@click.option("--write", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the whole robot with the measured values in place (refuses to overwrite).")
@click.option("--force", is_flag=True, help="With --write: overwrite an existing file.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def nose_load(grams, preset, config, sets, resolution_g, total_g, write, force, as_json):
    """Place the servo axis along the plate from the nose's weight on a kitchen scale.

    Stand the robot with its nose on the scale's pan and its feet level with the pan (on a
    book as thick as the scale), servos at rest (0 deg), and read GRAMS. The model's robot
    is moved along geometry.servo_axis_x_m until it reads the same (docs/hardware.md says why
    that value); the interval counts the scale's resolution and every other uncertain value
    of the robot file, and is combined with the file's own interval for the axis.

    \b
    Examples:
      locust measure nose-load 4 --preset medium
      locust measure nose-load 4.2 --resolution-g 0.1 --total-g 31.3 --config measured.toml --write robot.toml
    """
    from ...measure.nose_load import AXIS_KEY, PLATE_KEY, measure_nose_load

    robot = robot_toml.resolve_robot(preset, config, sets)
    say_written_from(preset, config, write)
    if write is not None and write.exists() and not force:
        raise MeasureError(f"{write} exists", "choose another path, or add --force to overwrite it")
    res = measure_nose_load(robot, grams / 1000, resolution_g / 1000, None if total_g is None else total_g / 1000)
    if write is not None:
        robot_toml.save_robot(res.robot, write)
    if as_json:
        out = res.to_json()
        out["written"] = str(write) if write is not None else None
        click.echo(json_text(out), nl=False)
        return
    click.echo(f"{robot.name}: nose {grams:g} g on a {resolution_g:g} g scale"
               + (f", the whole robot {total_g:g} g" if total_g is not None else ""))
    if res.plate_mass is not None:
        lo, hi = res.plate_mass.ci95
        click.echo(f"  plate mass: {res.plate_mass.value * 1000:.2f} ± {res.plate_mass.sd * 1000:.2f} g "
                   f"(95 %: {lo * 1000:.2f} to {hi * 1000:.2f}; the robot's {PLATE_KEY})")
    click.echo(f"  servo axis from the plate's middle, from the scale alone: {_mm(res.axis_from_scale)} "
               f"(the robot's {AXIS_KEY})")
    terms = sorted(res.axis_sd_terms_m.items(), key=lambda kv: -kv[1])[:TERMS_SHOWN]
    click.echo("    its largest sd terms: " + ", ".join(f"{k} {v * 1000:.1f} mm" for k, v in terms))
    if res.axis_before is not None:
        click.echo(f"  the robot file's: {_mm(res.axis_before)}")
        click.echo(f"  combined: {_mm(res.axis)}")
    click.echo(f"  the model then reads {res.predicted_nose_load_kg * 1000:.2f} g; centre of mass "
               f"{res.com_from_nose_m * 1000:.1f} mm from the nose along the plate")
    if write is not None:
        click.echo(f"wrote {write}")
