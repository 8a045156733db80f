"""``locust sweep`` and ``locust optimize``: design search on the audited simulation."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..errors import SweepError
from ..fileio import json_text
from ..params import resolve_robot
from ..params_cli import robot_options
from ..progress import progress
from ..tables import mm


def _describe(row: dict, names: list[str]) -> str:
    where = ", ".join(f"{n}={row[n]:.6g}" for n in names)
    return (f"design {row['design']} ({where}, {row['outcome']}): {mm(row['distance_m'])} mm, "
            f"highest nose {mm(row['max_nose_height_m'])} mm, {row['hops']} airborne hops")


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
                   "distance_m and max_nose_height_m are those means.")
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
    from ..api.sweeps import sweep as run_sweep
    from ..api.sweeps import sweep_axes
    from .execute import check_scheduler
    from .run import grid_size

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
        click.echo("best valid " + _describe(summary.best, names))
    click.echo(f"results: {summary.folder / 'results.csv'}")
    for p in summary.plots:
        click.echo(f"plot: {p}")


def _steps(items: tuple[str, ...]) -> dict[str, float]:
    out = {}
    for item in items:
        name, sep, text = item.partition("=")
        try:
            out[name.strip()] = float(text)
        except ValueError:
            raise SweepError(f"--step {item!r} is not NAME=STEP", "e.g. --step geometry.crank_start_deg=18") from None
        if not sep:
            raise SweepError(f"--step {item!r} is not NAME=STEP", "e.g. --step geometry.crank_start_deg=18")
    return out


@click.command()
@robot_options
@click.option("--vary", "varies", multiple=True, required=True, metavar="NAME=LOW:HIGH|NAME=A,B,C",
              help="A parameter (dotted name or `scale`) and its range, or its values A,B,C (a categorical). "
                   "Repeat for several.")
@click.option("--step", "steps", multiple=True, metavar="NAME=STEP",
              help="Take a --vary range in steps (a horn's spline step: geometry.crank_start_deg=18).")
@click.option("--objective", "objective_names", multiple=True, metavar="distance|nose_rise|flight",
              help="What to maximise, per hop over the run (repeat for a Pareto front; default distance).")
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
              help="Folder for pareto.csv, pareto.png, trials.csv, optimize.json, best-*.toml "
                   "(and the journal by default).")
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
      locust optimize --preset medium --objective distance --objective nose_rise \\
          --vary scale=0:0.02 --vary schedule.push_deg=-40:-15 --robust 8 --max-flip 0.05 \\
          --trials 24 --out o
      locust optimize --vary geometry.crank_start_deg=-126:-54 --step geometry.crank_start_deg=18 \\
          --objective nose_rise --trials 20 --out horn
    """
    from .design import parse_bound
    from .objectives import objectives_named
    from .optimize import run_optimize

    base = resolve_robot(preset, config, sets)
    step_of = _steps(steps)
    bounds = [parse_bound(v, base, step_of.get(v.partition("=")[0].strip())) for v in varies]
    if len({b.name for b in bounds}) != len(bounds):
        raise SweepError("--vary names a parameter twice", "give each parameter one --vary")
    unknown = sorted(set(step_of) - {b.name for b in bounds})
    if unknown:
        raise SweepError(f"--step {unknown[0]}: no --vary range of that name", "give --vary NAME=LOW:HIGH with it")
    objectives = objectives_named(list(objective_names))
    if repair:
        _repair(storage, out)
    with progress(length=trials, label="optimize", show_pos=True, show_eta=True) as bar:
        summary = run_optimize(base, bounds, trials, cycles, out, storage=storage, study_name=study_name,
                               seed=seed, jobs=jobs, progress=bar.update, objectives=objectives, draws=draws or 0,
                               quantile=quantile, max_flip=max_flip, sampler=sampler, scheduler=scheduler)
    _report(summary, bounds, objectives, out)


def _report(summary, bounds, objectives, out: Path) -> None:
    from .pareto import describe

    click.echo(f"study {summary.study_name!r}: {summary.trials} trials ({summary.computed} computed now), "
               f"{summary.complete} valid, {summary.pruned} pruned as invalid; {len(summary.front)} on the front")
    if not summary.picks:
        click.echo("no valid design within the flip limit yet")
    names = [b.name for b in bounds]
    for pick, row in summary.picks.items():
        click.echo(f"{pick}: " + describe(row, names, objectives))
        click.echo(f"  as a robot file: {summary.robots[pick]}")
    click.echo(f"results: {out / 'pareto.csv'}, {out / 'pareto.png'}, {out / 'trials.csv'}, {out / 'optimize.json'}")
    if summary.interrupted:
        kept = summary.complete + summary.pruned
        click.echo(f"interrupted: {kept} finished trial{'s' * (kept != 1)} kept in the study and the files above "
                   "(a trial under way is not); rerun the same command to continue", err=True)
        sys.exit(130)


def _repair(storage: str | None, out: Path) -> None:
    """--repair: cut the torn last line of the study's journal file (saved beside it first)."""
    from .journal import repair
    from .storage import RDB_PREFIXES

    if storage is not None and storage.startswith(RDB_PREFIXES):
        raise SweepError(f"--repair mends a journal file; --storage {storage} is a database",
                         "leave --repair off (a database is not torn by a full disk)")
    journal = Path(storage.removeprefix("journal:")) if storage else out / "study.journal"
    if not journal.is_file():
        raise SweepError(f"--repair: there is no journal {journal}", "give the --out (or --storage) of the study")
    click.echo(repair(journal).line(), err=True)
