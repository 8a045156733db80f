"""``locust measure supply``: the servos' supply from a multimeter at the servo plug
(docs/hardware.md, "The supply with a multimeter")."""

from __future__ import annotations

from pathlib import Path

import click

from ...errors import MeasureError
from ...fileio import json_text
from ...io import robot_toml
from ..options import FINITE, robot_options, say_written_from

TERMS_SHOWN = 3
UNITS = {"power.source_resistance_ohm": "Ω", "power.current_limit_a": "A"}
WORDS = {"resistance": "source resistance", "limit": "current limit"}


@click.command("supply", context_settings={"ignore_unknown_options": True})   # a reading of -4.9 V is an argument
@click.argument("rest_v", metavar="REST_V", type=FINITE)
@click.argument("stall_v", metavar="STALL_V", type=FINITE)
@robot_options
@click.option("--amps", "stall_a", type=FINITE, default=None,
              help="Both servos' current, stalled, read by a meter in series with their shared + lead, in A.")
@click.option("--source", "solve", type=click.Choice(["resistance", "limit"]), default="resistance",
              show_default=True,
              help="Read the sag as the source's resistance, or as its current limit (a polyfuse, a port's switch).")
@click.option("--volts-accuracy", default="0.5%+2", show_default=True, metavar="P%+N",
              help="The meter's accuracy on its volts range, as its manual gives it.")
@click.option("--volts-digit", type=FINITE, default=0.01, show_default=True,
              help="The volts range's last digit, in V (0.01 on a 20 V range).")
@click.option("--amps-accuracy", default="1.2%+3", show_default=True, metavar="P%+N",
              help="The meter's accuracy on its current range.")
@click.option("--amps-digit", type=FINITE, default=0.01, show_default=True,
              help="The current range's last digit, in A (0.01 on a 10 A range).")
@click.option("--write", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the whole robot with the measured values in place (refuses to overwrite).")
@click.option("--force", is_flag=True, help="With --write: overwrite an existing file.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
def supply(rest_v, stall_v, preset, config, sets, stall_a, solve, volts_accuracy, volts_digit, amps_accuracy,
           amps_digit, write, force, as_json):
    """The supply's voltage and its resistance or current limit, from a multimeter.

    Read the servo plug's volts (DC) with both servos at rest (REST_V), then with both horns
    held still by hand while they push (STALL_V: `locust pose -30 -30`, a second or two). The
    sag is the source's resistance, or with --source limit its current limit; the intervals
    count the meter's accuracy, the servos' winding resistance and the board's own draw from
    the robot file (docs/hardware.md).

    \b
    Examples:
      locust measure supply 4.97 4.52 --preset small
      locust measure supply 4.97 4.52 --amps 0.91 --write robot.toml
      locust measure supply 4.98 3.80 --source limit --config robot.toml --write robot.toml --force
    """
    from ...measure.meter import MeterSpec
    from ...measure.supply import SupplyReadings, measure_supply

    robot = robot_toml.resolve_robot(preset, config, sets)
    say_written_from(preset, config, write)
    if write is not None and write.exists() and not force:
        raise MeasureError(f"{write} exists", "choose another path, or add --force to overwrite it")
    volts = MeterSpec.parse(volts_accuracy, volts_digit, "--volts-accuracy")
    amps = None if stall_a is None else MeterSpec.parse(amps_accuracy, amps_digit, "--amps-accuracy")
    res = measure_supply(robot, SupplyReadings(rest_v, stall_v, stall_a), volts, amps, solve)
    if write is not None:
        robot_toml.save_robot(res.robot, write)
    if as_json:
        out = res.to_json()
        out["written"] = str(write) if write is not None else None
        click.echo(json_text(out), nl=False)
        return
    for line in _lines(robot.name, res):
        click.echo(line)
    if write is not None:
        click.echo(f"wrote {write}")


def _value(e, unit: str, key: str, digits: int = 3) -> str:
    lo, hi = e.ci95
    return (f"{e.value:.{digits}f} ± {e.sd:.{digits}f} {unit} (95 %: {lo:.{digits}f} to {hi:.{digits}f}; "
            f"the robot's {key})")


def _lines(name: str, res) -> list[str]:
    r, unit = res.readings, UNITS[res.key]
    amps = "" if r.stall_a is None else f", drawing {r.stall_a:g} A"
    lines = [f"{name}: the servo plug {r.rest_v:g} V at rest, {r.stall_v:g} V with both horns stalled{amps} "
             f"(a meter of {res.volts.describe()} V)",
             f"  at rest: {_value(res.rest, 'V', 'power.supply_voltage_v')}",
             f"  {WORDS[res.solve]}: {_value(res.value, unit, res.key)}"]
    terms = sorted(res.sd_terms.items(), key=lambda kv: -kv[1])[:TERMS_SHOWN]
    lines.append("    its largest sd terms: " + ", ".join(f"{k} {v:.3f} {unit}" for k, v in terms))
    if res.solve == "resistance":
        lines.append(f"  read so, the current limit is at least {res.bound:.3f} A "
                     "(--source limit reads the sag as it)")
    else:
        lines.append(f"  read so, the resistance is at most {res.bound:.3f} Ω "
                     "(--source resistance reads the sag as it)")
    if res.winding_ohm is not None:
        lines.append(f"  the stalled servos' winding: {res.winding_ohm:.2f} Ω each "
                     f"(2 x {r.stall_v:g} V / {r.stall_a:g} A)")
    lines.append(f"  the robot written reads {res.predicted.stall_v:.3f} V stalled, the servos drawing "
                 f"{res.predicted.stall_a:.3f} A")
    lines += [f"  note: {n}" for n in res.notes]
    return lines
