"""``locust optimize``: designs that hop far and high without going over (Optuna)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..io.robot_toml import resolve_robot
from .options import JobBar, robot_options


@click.command()
@robot_options
@click.option("--vary", "varies", multiple=True, required=True, metavar="NAME=LOW:HIGH|NAME=A,B,C",
              help="A parameter (dotted name or `scale`) and its range, or its values A,B,C (a categorical). "
                   "Repeat for several.")
@click.option("--step", "steps", multiple=True, metavar="NAME=STEP",
              help="Take a --vary range in steps (a horn's spline step: geometry.crank_start_deg=18).")
@click.option("--objective", "objective_names", multiple=True,
              metavar="distance_per_hop|nose_rise_per_hop|flight_per_hop",
              help="What to maximise, each a figure per hop of the run (repeat for a Pareto front; "
                   "default distance_per_hop).")
@click.option("--robust", "draws", type=click.IntRange(2, 256), default=None, metavar="N",
              help="Judge each design over N draws of the robot file's uncertain values (the same draws for "
                   "every design); each objective is their --quantile.")
@click.option("--quantile", type=click.FloatRange(0, 1), default=0.1, show_default=True,
              help="With --robust: the quantile of the draws taken as the figure (0.1: what 9 draws in 10 beat).")
@click.option("--max-flip", type=click.FloatRange(0, 1), default=None, metavar="P",
              help="The largest share of draws (or the nominal run) that may go over onto its back.")
@click.option("--trials", type=click.IntRange(1, 100000), default=50, show_default=True,
              help="Finished trials the study should hold; a rerun computes only those missing.")
@click.option("--cycles", type=click.IntRange(1, 100), default=3, show_default=True)
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Folder for pareto.csv, pareto.png, study.html (Optuna's history, importances and "
                   "interactive front), trials.csv, optimize.json, best-*.toml (and the journal by default).")
@click.option("--storage", default=None, metavar="URL",
              help="Optuna storage: a journal file path (default OUT/study.journal) or an RDB URL "
                   "such as sqlite:///study.db to share a study between machines.")
@click.option("--study", "study_name", default="locust", show_default=True, help="Study name in the storage.")
@click.option("--sampler", type=click.Choice(["tpe", "nsga2"]), default="tpe", show_default=True,
              help="Optuna's multi-objective TPE or NSGA-II.")
@click.option("--seed", type=int, default=0, show_default=True, help="Sampler seed.")
@click.option("--jobs", type=click.IntRange(1, 1024), default=1, show_default=True,
              help="Trials run at once, each in its own process (or Dask worker).")
@click.option("--scheduler", default="local", show_default=True, metavar="local|dask-local|tcp://HOST:PORT",
              help="local: --jobs processes; dask-local or tcp://...: a Dask cluster (its workers must reach "
                   "--storage).")
@click.option("--repair", is_flag=True,
              help="First mend a journal whose last line a full disk left torn: the file is saved as "
                   "study.journal.torn-N beside it, then the torn line is cut (every whole trial kept).")
def optimize(preset, config, sets, varies, steps, objective_names, draws, quantile, max_flip, trials, cycles, out,
             storage, study_name, sampler, seed, jobs, scheduler, repair):
    """Search design ranges for the hops that go farthest and highest without going over (Optuna).

    Each design is checked, simulated, audited and classified (goes_over, rears_and_returns,
    stays_low); a design that goes over scores 0 (a robot on its back does not hop again).
    Invalid designs are pruned with their reason. Rerunning with the same --out (or --storage)
    resumes the study; other settings are refused.

    \b
    Examples:
      locust optimize --preset medium --objective distance_per_hop --objective nose_rise_per_hop \\
          --vary scale=0:0.02 --vary schedule.push_deg=-40:-15 --robust 8 --max-flip 0.05 \\
          --trials 24 --out o
      locust optimize --vary geometry.crank_start_deg=-126:-54 --step geometry.crank_start_deg=18 \\
          --objective nose_rise_per_hop --trials 20 --out horn
    """
    from ..sweep.study import OptimizeOptions, optimize_study, parse_steps

    robot = resolve_robot(preset, config, sets)
    options = OptimizeOptions(out=out, vary=varies, steps=parse_steps(steps), objectives=objective_names,
                              robust=draws or 0, quantile=quantile, max_flip=max_flip, trials=trials, cycles=cycles,
                              storage=storage, study_name=study_name, sampler=sampler, seed=seed, jobs=jobs,
                              scheduler=scheduler, repair=repair)
    with JobBar(trials, "optimize", show_pos=True, show_eta=True) as bar:
        summary = optimize_study(robot, options, progress=bar.update, say=bar.say)
    _report(summary, out)


def _report(summary, out: Path) -> None:
    from ..sweep.pareto import describe

    click.echo(f"study {summary.study_name!r}: {summary.trials} trials ({summary.computed} computed now), "
               f"{summary.complete} valid, {summary.pruned} pruned as invalid; {len(summary.front)} on the front")
    if not summary.picks:
        click.echo("no valid design within the flip limit yet")
    for pick, row in summary.picks.items():
        click.echo(f"{pick}: " + describe(row, list(summary.names), list(summary.objectives)))
        click.echo(f"  as a robot file: {summary.robots[pick]}")
    click.echo(f"results: {out / 'pareto.csv'}, {out / 'pareto.png'}, {out / 'trials.csv'}, {out / 'optimize.json'}")
    if summary.complete:
        click.echo(f"Optuna's views (history, importances, interactive front): {out / 'study.html'}")
    if summary.interrupted:
        kept = summary.complete + summary.pruned
        click.echo(f"interrupted: {kept} finished trial{'s' * (kept != 1)} kept in the study and the files above "
                   "(a trial under way is not); rerun the same command to continue", err=True)
        sys.exit(130)
