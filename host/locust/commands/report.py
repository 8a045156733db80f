"""``locust report``: simulation against measurement, as one HTML page and a PNG dashboard."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..io.robot_toml import load_robot, resolve_robot
from .options import import_options, robot_options


def _stage(msg: str) -> None:
    click.echo(f"report: {msg}", err=True)


def headline(c) -> list[str]:
    """A configuration's result in words and mm: how the simulated and the filmed runs ended,
    the simulation's distance (``locust sim``'s), the marker's travel on both sides and the jump.

    Parameters
    ----------
    c : locust.report.compare.Comparison

    Returns
    -------
    list of str
        The predicted line, then the measured one when a trial has a track.
    """
    from ..report.compare import ending_of
    from ..report.ending import trials_words, words

    def mm(value_m: float) -> str:
        return f"{value_m * 1000:.1f} mm"

    end = c.predicted_ending
    if end is None:
        lines = ["predicted: simulation INVALID"]
    else:
        jump = "" if end.over_hop == 1 else f", jump {mm(c.predicted_jump_m)}"
        lines = [f"predicted: {words(end)}; distance {mm(c.predicted_distance_m)} (locust sim's), marker travel "
                 f"{mm(c.predicted_marker_travel_m)}{jump}"]
    if c.marker_travel.n:
        n = c.marker_travel.n
        jump = f", jump {mm(c.jump.mean)}" if c.jump.n else ""
        lines.append(f"measured ({n} trial{'s' * (n != 1)}): {trials_words([ending_of(m) for m in c.trials])}; "
                     f"marker travel {mm(c.marker_travel.mean)}{jump}")
    else:
        lines.append("measured: no track")
    return lines


@click.command()
@click.option("--measured", "measured", multiple=True, required=True, metavar="[NAME=]PATH[,PATH...]",
              help="Trials: a folder (track *.tracks.csv and/or run.json), a track file or a run.json. "
                   "NAME= gives the configuration (small/medium/large or any name); without it the "
                   "folder's name does (hops/medium-2/ -> medium). Repeatable; several paths = repeated trials.")
@robot_options
@click.option("--added", "added", multiple=True, metavar="NAME=METRES",
              help="Length added to every link for configuration NAME (small/medium/large default to 0/0.01/0.02).")
@click.option("--sweep", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="A `locust sweep --out` folder: its landscape is drawn with the physical designs marked.")
@click.option("--optimize", "study", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="A `locust optimize --out` folder: its Pareto front and the designs it picks.")
@click.option("--cycles", type=click.IntRange(1, 100), default=None,
              help="Hop cycles to simulate and measure [the run records' cycles, else the robot's schedule].")
@click.option("--marker", default="nose", show_default=True,
              help="Marker compared: its track (x forward, y up, metres) against the model's marker of that name.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=Path("reports"), show_default=True,
              help="Parent folder; the report goes into a new report/ (report-2/, ...) inside, never over another.")
@click.option("--side-by-side", "side_by_side", is_flag=True,
              help="Also write <trial>.side_by_side.webm for each trial with a video: the filmed hop beside the "
                   "simulation from the same camera (its camera.json), on the schedule's clock; the page plays it.")
@click.option("--samples", type=click.IntRange(2, 256), default=None, metavar="N",
              help="Draw the robot file's uncertain values N times per configuration: bands on the predicted "
                   "curves, error bars on the predicted hops.")
@click.option("--before", "before_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="The robot.toml before a fit (e.g. `locust calibrate hop`): its predictions are drawn too.")
@click.option("--explain", is_flag=True,
              help="Explain each configuration as `locust sim --explain` does: a tornado figure of each uncertain "
                   "value's -/+2 sd effect on nose rise and distance, and why it goes over, in words (some 300 "
                   "runs a configuration).")
@import_options
def report(measured, config, preset, sets, added, sweep, study, cycles, marker, out, side_by_side, samples, before_path,
           explain, imports):
    """Compare simulation and measurement for each configuration in one self-contained HTML page.

    Each configuration (Small/Medium/Large: the --config/--preset robot with +0/+10/+20 mm on
    all four links) is simulated with those parameters, audited, and compared with its tracks:
    displacement and height against time, jump height (± 1 sd over repeated trials), per-hop
    errors, the parameters with their source and uncertainty, the sweep landscape with the
    designs marked (--sweep), and the firmware timing of the runs. Writes report.html (figures
    embedded), dashboard.png and report.json.

    \b
    Examples:
      locust report --measured runs/small-1 --measured runs/small-2 --measured runs/large-1 \\
                    --config calibration/robot.toml
      locust report --measured medium=a.tracks.csv,b.tracks.csv --preset seed --sweep sweep/ --cycles 6
    """
    from ..api.reports import make_report as build_report
    from ..report.checks import collapsed
    from ..trials.configs import parse_added

    robot = resolve_robot(preset, config, sets)
    source = str(config) if config else f"preset {preset}"
    if sets:
        source += " with " + ", ".join(sets)
    result = build_report(robot, list(measured), out=out, robot_source=source, cycles=cycles, sweep=sweep,
                          added=parse_added(added), marker=marker, progress=_stage, side_by_side=side_by_side,
                          samples=samples or 0, before=load_robot(before_path) if before_path else None,
                          imports=imports, study=study, explain=explain)
    for c in result.comparisons:
        for line in headline(c):
            click.echo(f"{c.config:8s} {line}", err=True)
    for warning in collapsed(result.warnings):     # one line for what several trials share
        click.echo(f"warning: {warning.message}", err=True)
    click.echo(f"dashboard: {result.dashboard_path}", err=True)
    for v in result.side_by_side:
        if v.path is not None:
            click.echo(f"side by side: {v.path}", err=True)
    click.echo(str(result.html_path))
    sys.stdout.flush()
