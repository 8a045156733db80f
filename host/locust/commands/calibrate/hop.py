"""``locust calibrate hop``: the model fitted to filmed hops of one or more leg sets."""

from __future__ import annotations

import functools
from pathlib import Path

import click

from ...calibrate import jobs
from ...calibrate.hop import DEFAULT_KEYS, check_fittable
from ...calibrate.outputs import save_hops
from ...progress import progress
from .options import out_folder, out_option, write_option, write_target
from .output import interruptible, print_value, show, written


@click.command()
@click.argument("runs", nargs=-1, required=True)
@click.option("--fit", "fit_keys", default=",".join(DEFAULT_KEYS), show_default=True, metavar="KEY[,KEY...]",
              help="Robot parameters to fit, shared by every run (any real-valued key of `locust params`).")
@click.option("--config", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Robot to start from, the values every run shares [default: the --write file if it exists, "
                   "else the robot the runs' run.json record; runs on different robots are refused].")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help="Override a starting value (repeatable).")
@click.option("--max-iter", type=click.IntRange(1, 200), default=30, show_default=True, help="Solver iterations.")
@click.option("--json", "as_json", is_flag=True, help="Print the results as JSON.")
@click.option("--no-plot", is_flag=True, help="Do not draw the fit plots.")
@functools.partial(out_option, what="<run>-hops-fit.png")
@functools.partial(write_option, help_text="Update this robot.toml with the identifiable fitted values only, "
                                           "source fit:hops.")
def hop(runs, fit_keys, config, sets, max_iter, as_json, no_plot, out_dir, write_path):
    """Fit the model to filmed hops: friction, hinge stiffness, servo speed on the robot.

    Each RUN is a `locust hop --out` folder holding its run.json and the track of its video
    (`locust track`), as NAME=FOLDER or a folder named after its leg set (small-1/, large/).
    Runs of different leg sets are fitted together: their geometry differs, the fitted
    physics is shared. The firmware's measured phase times drive each simulation; the
    tracked nose and foot are compared with the simulated markers, both aligned on the first
    push. Prints each value with its 95% interval and the RMS residual per run, and draws
    <run>-hops-fit.png in --out (tracked against the fitted simulation).

    \b
    Example:
      locust calibrate hop small=runs/s1 large=runs/l1 --write calibration/robot.toml
    """
    keys = [k.strip() for k in fit_keys.split(",") if k.strip()]
    check_fittable(keys)
    write_path = write_target(write_path)
    base, said = jobs.hop_start(list(runs), config, sets, write_path)
    click.echo(said, err=True)
    folder = out_folder(out_dir, None, no_plot, as_json)
    with progress(label="fitting hops: simulations") as bar, interruptible("the hop fit"):
        def done(n: int, planned: int) -> None:
            bar.length = planned
            bar.update(n - bar.pos)

        fit = jobs.hops(base, list(runs), keys, max_iter=max_iter, progress=done)
    out = save_hops(fit, plot_folder=folder, write_path=write_path, robot=base)
    if as_json:
        show(out, as_json)
    else:
        _print_hops(fit.result, out)


def _print_hops(fit, out: dict) -> None:
    """The hop fit as a person reads it: each value a row, each run's residual, notes, plots."""
    click.echo(f"# hops: {len(fit.runs)} runs, {fit.simulations} simulations, {fit.wall_s:.1f} s")
    click.echo(f"# 95% intervals: {fit.interval}")
    for key, val in out["parameters"].items():
        print_value(key, val)
    for run in fit.runs:
        click.echo(f"{run.config:8s} {run.source}: RMS residual {1000 * run.rms_m:.3f} mm")
    for note in fit.notes:
        click.echo(f"note: {note}")
    for plot in out.get("plots", []):
        click.echo(f"plot: {plot}")
    written(out)
