"""``locust sweep``: a grid of designs on the audited simulation."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..fileio import json_text
from ..io.robot_toml import resolve_robot
from ..progress import progress
from ..tables import mm, outcome_words
from .options import robot_options


def _describe(row: dict, names: list[str], cycles: int) -> str:
    """A design's values and figures as a person reads them (lengths in mm, each with its unit)."""
    from ..sweep.design import design_text

    where = ", ".join(design_text(n, row[n]) for n in names)
    return (f"design {row['design']} ({where}; {outcome_words(row['outcome'])}): distance {mm(row['distance_m'])} mm "
            f"over the run ({mm(row['distance_m'] / cycles)} mm per hop), highest nose {mm(row['max_nose_height_m'])} "
            f"mm above the floor, {row['hops']} airborne hops")


@click.command()
@robot_options
@click.option("--vary", "varies", multiple=True, required=True, metavar="NAME=START:STOP:N",
              help="A parameter by dotted name, or `scale` (metres added to all four links), "
                   "with N values from START to STOP. Repeat for a grid.")
@click.option("--cycles", type=click.IntRange(1, 100), default=3, show_default=True, help="Hop cycles per design.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Folder for results.csv, sweep.json and plots. Rerun with the same folder to resume.")
@click.option("--jobs", type=click.IntRange(1, 1024), default=None,
              help="Parallel workers (default: every local core).")
@click.option("--scheduler", default="local", show_default=True, metavar="local|dask-local|tcp://HOST:PORT",
              help="local: a process per core; dask-local: a Dask LocalCluster; tcp://...: a Dask cluster.")
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON.")
@click.option("--samples", type=click.IntRange(2, 256), default=None, metavar="N",
              help="Rank designs by their mean over N draws of the robot file's uncertain values: "
                   "distance_m (over the run) and max_nose_height_m are those means.")
def sweep(preset, config, sets, varies, cycles, out, jobs, scheduler, as_json, samples):
    """Simulate a grid of designs and report the best valid one.

    Each design is checked before simulation (the four-bar assembles and stays closed over the
    commanded crank range) and audited after; a design that fails is kept in results.csv with
    `valid` False and the reason, and is never chosen as best. Rows are written as designs
    finish, so an interrupted sweep resumes where it stopped.

    \b
    Examples:
      locust sweep --preset seed --vary scale=0:0.05:30 --cycles 3 --out sweep-scale
      locust sweep --vary geometry.leg_m=0.04:0.1:7 --vary geometry.crank_m=0.03:0.06:4 --out grid
      locust sweep --vary scale=0:0.05:30 --scheduler tcp://10.0.0.5:8786 --out cluster-run
    """
    from ..api.sweeps import sweep_axes
    from ..api.sweeps import sweep_designs as run_sweep
    from ..sweep.execute import check_scheduler
    from ..sweep.run import grid_size

    base = resolve_robot(preset, config, sets)
    axes = sweep_axes(base, list(varies))
    names = [a.name for a in axes]
    check_scheduler(scheduler)
    total = grid_size(axes)
    with progress(length=total, label=f"sweep ({scheduler})", show_pos=True, show_eta=True) as bar:
        try:
            summary = run_sweep(base, axes, cycles, out=out, scheduler=scheduler, jobs=jobs, progress=bar.update,
                                samples=samples or 0, say=lambda line: click.echo(line, err=True))
        except KeyboardInterrupt:
            click.echo(f"\ninterrupted: finished designs are in {out}/results.csv; "
                       "rerun the same command to resume", err=True)
            sys.exit(130)
    rows = summary.rows
    valid = [r for r in rows if r["valid"]]
    if as_json:
        click.echo(json_text({"folder": str(summary.folder), "designs": len(rows), "valid": len(valid),
                              "computed": summary.computed, "resumed": summary.resumed,
                              "wall_s": summary.wall_s, "best": summary.best,
                              "plots": [str(p) for p in summary.plots]}), nl=False)
        return
    over = sum(1 for r in valid if r["outcome"] == "goes_over")
    click.echo(f"{len(rows)} designs ({summary.resumed} from an earlier run, {summary.computed} computed in "
               f"{summary.wall_s:.1f} s), {len(valid)} valid, {over} of them going over onto their backs")
    reasons: dict[str, int] = {}
    for r in rows:
        if not r["valid"]:
            key = r["reason"].split(":")[0]
            reasons[key] = reasons.get(key, 0) + 1
    for reason, n in sorted(reasons.items(), key=lambda kv: -kv[1]):
        click.echo(f"  invalid x{n}: {reason}")
    if summary.best is None:
        click.echo("no valid design that stays on its feet: nothing to recommend")
    else:
        click.echo("best valid " + _describe(summary.best, names, cycles))
    click.echo(f"results: {summary.folder / 'results.csv'}")
    for p in summary.plots:
        click.echo(f"plot: {p}")
