"""``run_optimize``: the designs that hop farthest and highest without going over, with Optuna.

Each trial is a design judged by a judge (:class:`locust.sweep.robust.DesignJudge`: checked,
simulated, audited, classified, on its nominal run or over draws of its uncertain values) on
one or more objectives (:mod:`locust.sweep.objectives`), all maximised. With several
objectives the study is multi-objective (Optuna's TPE or NSGA-II) and its result is the Pareto
front. ``max_flip`` is an Optuna constraint (``trial.set_constraint``): a design whose share of
draws that go over exceeds it is infeasible, never on the front. A design that fails is pruned
with its reason (``user_attrs["reason"]``).

The study lives in a journal file by default (``study.journal`` in the output folder; several
processes may share it), or in any database Optuna's RDB storage takes (``sqlite:///study.db``,
``postgresql://...``). It records what it searches (base robot, ranges, cycles, objectives,
draws, quantile, flip limit) as its user attribute ``locust``: a rerun with other settings is
refused. ``trials`` is the number of finished trials the study should hold: a rerun computes
only those missing, so a study killed part way resumes where it stopped.

:func:`run_optimize` checks the request, opens the study, maps its trials (:mod:`.trial`, one
a task) over local processes or a Dask cluster and writes what the study holds
(:func:`summarise`).
"""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import SweepError
from ..fileio import atomic_write_json, make_folder
from ..io.robot_toml import save_robot
from ..io.study_store import write_tables
from ..params import Robot
from .design import Bound, design_robot, is_integer
from .journal import full_disk
from .objectives import DEFAULT, OBJECTIVES, OUTCOMES, Judgement, Objective
from .pareto import picks, plot_front
from .storage import SETTINGS_ATTR, check_folder, check_journal_file, check_storage, open_storage
from .trial import StudySpec, TrialOf, finished_trials
from .views import STUDY_PAGE, write_study_page

SAMPLERS = ("tpe", "nsga2")


def settings(robot: Robot, bounds: list[Bound], cycles: int, objectives: list[Objective] | None = None,
             draws: int = 0, quantile: float | None = None, max_flip: float | None = None,
             sampler: str = "tpe") -> dict[str, Any]:
    """What a study searches, as JSON holds it: a rerun must ask for exactly this.

    Parameters
    ----------
    robot : Robot
        The robot every design starts from.
    bounds : list of Bound
        The design variables and their ranges.
    cycles : int
        Hop cycles each design runs.
    objectives : list of Objective, optional
        What is maximised.
    draws : int, default 0
        Draws of the uncertain values per design.
    quantile : float, optional
        The quantile of the draws optimised (kept only with ``draws``).
    max_flip : float, optional
        The largest share of draws that may go over.
    sampler : str, default "tpe"
        ``tpe`` or ``nsga2``.

    Returns
    -------
    dict
        ``robot``, ``parameters``, ``vary``, ``cycles``, ``objectives``, ``robust``,
        ``quantile``, ``max_flip`` and ``sampler``, as a JSON round trip gives them back.
    """
    return json.loads(json.dumps({
        "base": robot.name, "parameters": robot.flat(), "vary": [b.to_dict() for b in bounds], "cycles": cycles,
        "objectives": [o.name for o in objectives or []], "robust": draws,
        "quantile": quantile if draws else None, "max_flip": max_flip, "sampler": sampler}))


SETTING_NAMES = ("base", "vary", "cycles", "objectives", "robust", "quantile", "max_flip", "sampler")


def check_settings(study, wanted: dict[str, Any], where: str) -> None:
    """Refuse to continue a study that searches something else (or that this tool did not make).

    Parameters
    ----------
    study : optuna.Study
        The study found in the storage.
    wanted : dict
        :func:`settings` of this run.
    where : str
        The storage, for the message.

    Raises
    ------
    SweepError
        The study holds no settings of ours, or other ones (naming those that differ).
    """
    held = study.user_attrs.get(SETTINGS_ATTR)
    hint = "give a new --out folder (or --storage / --study), or rerun the exact command that made it"
    if held is None:
        raise SweepError(f"{where}: study {study.study_name!r} was not made by `locust optimize`", hint)
    if held != wanted:
        diff = [k for k in SETTING_NAMES if held.get(k) != wanted.get(k)]
        params = held.get("parameters") or {}
        diff += [k for k, v in wanted["parameters"].items() if params.get(k) != v][:3]
        raise SweepError(f"{where}: study {study.study_name!r} searches other settings ({', '.join(diff) or 'ranges'} "
                         "differ); its trials cannot be ranked against these", hint)


@dataclass
class OptimizeSummary:
    """What :func:`run_optimize` left in its folder.

    Attributes
    ----------
    study_name : str
        The study's name.
    trials : int
        Trials the study holds (any state).
    complete, pruned : int
        Those complete, and those pruned with a reason.
    front : list of dict
        The Pareto front's rows (feasible trials only), by trial number.
    picks : dict of str to dict
        ``best-<objective>`` and ``knee`` to their rows.
    folder : Path
        The output folder.
    computed : int
        Trials this call ran.
    interrupted : bool
        The run was stopped by Ctrl-C (finished trials kept).
    robots : dict of str to Path or None
        The robot file written for each pick.
    names : tuple of str
        The design variables, by dotted name, in the order searched (the rows' columns).
    objectives : tuple of Objective
        What is maximised, in order.
    """

    study_name: str
    trials: int
    complete: int
    pruned: int
    front: list[dict[str, Any]]
    picks: dict[str, dict[str, Any]]
    folder: Path
    computed: int = 0
    interrupted: bool = False
    robots: dict[str, Path] | None = None     # best-<objective>.toml, knee.toml
    names: tuple[str, ...] = ()
    objectives: tuple[Objective, ...] = ()

    @property
    def best(self) -> dict[str, Any] | None:
        """The first objective's best design on the front."""
        return next(iter(self.picks.values()), None)


def run_optimize(robot: Robot, bounds: list[Bound], trials: int, cycles: int, folder: Path,
                 storage: str | None = None, study_name: str = "locust", seed: int = 0, jobs: int = 1,
                 progress: Callable[[int], None] | None = None, objectives: list[Objective] | None = None,
                 judge: Callable[[dict[str, Any]], Judgement] | None = None, draws: int = 0,
                 quantile: float = 0.1, max_flip: float | None = None, sampler: str = "tpe",
                 scheduler: str = "local") -> OptimizeSummary:
    """Run (or resume) the study into ``folder`` until it holds ``trials`` finished trials.

    Parameters
    ----------
    robot : Robot
        The robot every design starts from.
    bounds : list of Bound
        The design variables and their ranges.
    trials : int
        Finished trials (complete or pruned) the study should hold; a rerun computes the rest.
    cycles : int
        Hop cycles each design runs.
    folder : Path
        Output folder (and the journal, unless ``storage``).
    storage : str, optional
        A journal file path or a database URL Optuna's RDB storage takes.
    study_name : str, default "locust"
        The study's name in the storage.
    seed : int, default 0
        The samplers' base seed.
    jobs, scheduler : int, str
        Trials run at once: ``jobs`` local processes, or a Dask cluster (``dask-local``,
        ``tcp://HOST:PORT``; its workers must reach the storage).
    progress : callable, optional
        ``progress(n)`` as trials finish: first, as they begin, with those finished before this
        run (0 for a new study), then 1 a trial.
    objectives : list of Objective
        What is maximised (default: distance_per_hop).
    judge : callable, optional
        ``judge(values) -> Judgement``; default :class:`~locust.sweep.robust.DesignJudge` of
        ``robot`` with ``draws`` and ``quantile``.
    draws : int
        0: each design's nominal run; N: N draws of its uncertain values, the figure optimised
        being the ``quantile`` over them.
    quantile : float, default 0.1
        The quantile of the draws optimised.
    max_flip : float, optional
        The largest share of draws that may go over (an Optuna constraint).
    sampler : str, default "tpe"
        ``tpe`` or ``nsga2``.

    Returns
    -------
    OptimizeSummary
        The front, the picks and the robot files written; after Ctrl-C, what was finished.

    Raises
    ------
    SweepError
        An unknown sampler or scheduler, an unreachable Dask scheduler, a folder or storage
        holding something else, a study with other settings, an integer range holding no whole
        number, or a full disk.
    """
    import optuna

    from .robust import DesignJudge

    optuna.logging.set_verbosity(optuna.logging.ERROR)
    objectives = objectives or [OBJECTIVES[DEFAULT]]
    integers = check_request(robot, bounds, folder, storage, sampler, scheduler)
    make_folder(folder)
    storage_obj = open_storage(storage, folder)
    where = storage or str(folder / "study.journal")
    study = open_study(storage_obj, study_name, settings(robot, bounds, cycles, objectives, draws, quantile, max_flip,
                                                         sampler), where, objectives)
    before = len(study.trials)
    left = max(0, trials - len(finished_trials(study)))
    judge = judge or DesignJudge(robot, cycles, tuple(objectives), draws, quantile)
    spec = StudySpec(storage, folder, study_name, tuple(bounds), integers, tuple(objectives), judge, max_flip,
                     sampler, seed, trials)
    if progress:
        progress(trials - left)   # finished before this run: the trials begin
    # a resumed study must not draw its first samples again: each trial's sampler seed moves on
    # with the trials the study held before it
    computed, interrupted = run_trials(spec, [before + k for k in range(left)], scheduler, jobs, progress, where)
    return summarise(optuna.load_study(study_name=study_name, storage=storage_obj), folder, robot, objectives,
                     max_flip, computed, interrupted=interrupted)


def check_request(robot: Robot, bounds: list[Bound], folder: Path, storage: str | None, sampler: str,
                  scheduler: str) -> frozenset[str]:
    """Refuse, before anything is written, a study that cannot run: an unknown sampler or
    scheduler, an unreachable Dask scheduler, a folder or storage holding something else, an
    integer range holding no whole number.

    Parameters
    ----------
    robot : Robot
        The robot every design starts from.
    bounds : list of Bound
        The design variables and their ranges.
    folder : Path
        Output folder (and the journal, unless ``storage``).
    storage : str or None
        A journal file path or a database URL.
    sampler, scheduler : str
        As :func:`run_optimize` takes them.

    Returns
    -------
    frozenset of str
        The design variables that are whole numbers.

    Raises
    ------
    SweepError
        Any of the above.
    """
    from .execute import check_scheduler, probe_dask_scheduler

    if sampler not in SAMPLERS:
        raise SweepError(f"--sampler {sampler!r}: not one of {', '.join(SAMPLERS)}", "use tpe or nsga2")
    check_scheduler(scheduler)
    if scheduler.startswith("tcp://"):
        probe_dask_scheduler(scheduler)
    check_folder(folder)
    if storage is None:
        check_journal_file(folder / "study.journal")
    check_storage(storage)
    integers = frozenset(b.name for b in bounds if is_integer(robot, b.name))
    for b in bounds:
        if b.name in integers and math.floor(b.high) < math.ceil(b.low):
            raise SweepError(f"--vary {b.name}={b.low:g}:{b.high:g} holds no whole number, and {b.name} is one",
                             f"give a range with at least one integer, e.g. {b.name}={math.floor(b.low)}:"
                             f"{math.floor(b.low) + 2}")
    return integers


def open_study(storage, study_name: str, wanted: dict[str, Any], where: str, objectives: list[Objective]):
    """The study in ``storage``, checked to search ``wanted``; a new one, recording ``wanted``
    and its objectives' column names, when there is none.

    Parameters
    ----------
    storage : optuna.storages.BaseStorage
        The opened storage.
    study_name : str
        The study's name in it.
    wanted : dict
        :func:`settings` of this run.
    where : str
        The storage, for messages.
    objectives : list of Objective
        What is maximised.

    Returns
    -------
    optuna.Study
        The study, every objective maximised.

    Raises
    ------
    SweepError
        A study of that name searching other settings (:func:`check_settings`).
    """
    import optuna

    try:
        held = optuna.load_study(study_name=study_name, storage=storage)
    except KeyError:
        held = None
    if held is not None:
        check_settings(held, wanted, where)
    study = optuna.create_study(study_name=study_name, storage=storage, load_if_exists=True,
                                directions=["maximize"] * len(objectives))
    if held is None:
        study.set_user_attr(SETTINGS_ATTR, wanted)
        # the columns' names, units included: what Optuna's views and optuna-dashboard label
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)   # stable since Optuna 3.2
            study.set_metric_names([o.column for o in objectives])
    return study


def run_trials(spec: StudySpec, items: list[int], scheduler: str, jobs: int,
               progress: Callable[[int], None] | None, where: str) -> tuple[int, bool]:
    """Run the trials ``items`` on the scheduler's workers.

    Parameters
    ----------
    spec : StudySpec
        The study.
    items : list of int
        The trials' indices (each seeds its sampler).
    scheduler : str
        ``local`` (``jobs`` processes, no more than the trials), ``dask-local`` or ``tcp://HOST:PORT``.
    jobs : int
        Trials run at once.
    progress : callable, optional
        ``progress(1)`` as each trial finishes.
    where : str
        The storage, for messages.

    Returns
    -------
    computed : int
        Trials this call ran.
    interrupted : bool
        Ctrl-C stopped the run (the trial under way is dropped; every finished one is kept).

    Raises
    ------
    SweepError
        The disk filled up while the study was written.
    """
    from .execute import mapper, plan_jobs

    if not scheduler.startswith("tcp://"):
        jobs, _ = plan_jobs(jobs, len(items))
    computed = 0
    try:
        with mapper(scheduler, jobs) as run_map:
            for number in run_map(TrialOf(spec), items):
                computed += number >= 0
                if progress:
                    progress(1)
    except (OSError, AssertionError) as exc:   # Optuna's own assertion fails after its write did
        full = full_disk(exc)
        if full is None:
            raise
        raise SweepError(f"{where}: the disk is full ({full.strerror}) while the study was written: the trial "
                         "under way is lost, every finished one is kept in it",
                         "free some space on that disk, then rerun the same command with --repair (it saves the "
                         "study as it is and cuts a line the full disk left torn)") from None
    except KeyboardInterrupt:   # the trial under way is dropped (FAIL); every finished one is kept
        return computed, True
    return computed, False


def trial_rows(study, names: list[str], objectives: list[Objective], max_flip: float | None) -> list[dict[str, Any]]:
    """One tidy row per trial: its state, design values by dotted name, each objective's figure
    optimised and its mean, the flip share and every outcome's share, the draws, the reason.

    Parameters
    ----------
    study : optuna.Study
        The study.
    names : list of str
        The design variables.
    objectives : list of Objective
        What is maximised.
    max_flip : float or None
        The largest share of draws that may go over.

    Returns
    -------
    list of dict
        The rows of trials.csv.
    """
    rows = []
    for t in study.get_trials(deepcopy=False):
        state = t.state.name.lower()
        means = t.user_attrs.get("means", {})
        shares = t.user_attrs.get("outcome_shares", {})
        row: dict[str, Any] = {"trial": t.number, "state": state}
        row.update({n: t.params.get(n, math.nan) for n in names})
        for k, o in enumerate(objectives):
            row[o.column] = t.values[k] if state == "complete" else math.nan
            row[f"{o.column}_mean"] = means.get(o.column, math.nan)
        flip = t.user_attrs.get("flip_share", math.nan)
        row["flip_share"] = flip
        row.update({f"share_{name}": shares.get(name, math.nan) for name in OUTCOMES})
        row["feasible"] = state == "complete" and (max_flip is None or flip <= max_flip)
        row["draws"] = t.user_attrs.get("draws", 0)
        row["draws_valid"] = t.user_attrs.get("draws_valid", 0)
        row["reason"] = t.user_attrs.get("reason", "")
        rows.append(row)
    return rows


def summarise(study, folder: Path, robot: Robot, objectives: list[Objective], max_flip: float | None,
              computed: int = 0, interrupted: bool = False) -> OptimizeSummary:
    """Write trials.csv, pareto.csv, pareto.png, study.html (Optuna's own views of the study),
    optimize.json and a robot file for each pick.

    Parameters
    ----------
    study : optuna.Study
        The study, loaded after the run.
    folder : Path
        The output folder.
    robot : Robot
        The robot every design starts from.
    objectives : list of Objective
        What is maximised.
    max_flip : float or None
        The largest share of draws that may go over.
    computed : int, default 0
        Trials this run computed.
    interrupted : bool, default False
        The run was stopped by Ctrl-C.

    Returns
    -------
    OptimizeSummary
        What the folder now holds.
    """
    held = study.user_attrs.get(SETTINGS_ATTR) or {}
    names = [v["name"] for v in held.get("vary", [])]
    rows = trial_rows(study, names, objectives, max_flip)
    by_number = {r["trial"]: r for r in rows}
    # Optuna's own front: complete trials that no other feasible one dominates, feasible only
    front = [by_number[t.number] for t in study.best_trials]
    front.sort(key=lambda r: r["trial"])
    chosen = picks(front, objectives) if front else {}
    write_tables(folder, rows, [{**r, "pick": " ".join(k for k, c in chosen.items() if c is r)} for r in front])
    robots = {}
    for pick, r in chosen.items():
        design = design_robot(robot, {n: r[n] for n in names}).renamed(f"optimize {pick} of {folder}")
        robots[pick] = save_robot(design, folder / f"{pick}.toml")
    done = [r for r in rows if r["state"] == "complete"]
    pruned = [r for r in rows if r["state"] == "pruned"]
    atomic_write_json(folder / "optimize.json", {
        "study": study.study_name, "settings": held, "trials": len(rows), "complete": len(done),
        "pruned": len(pruned), "feasible": sum(r["feasible"] for r in rows), "front": front,
        "picks": {k: r["trial"] for k, r in chosen.items()}, "robots": robots,
        "pruned_reasons": {r["trial"]: r["reason"] for r in pruned}})
    if done:
        title = f"{study.study_name}: {len(done)} designs, {len(front)} on the front"
        if held.get("robust"):
            title += f" (quantile {held['quantile']:g} of {held['robust']} draws)"
        plot_front(rows, front, chosen, objectives, max_flip, folder / "pareto.png", title)
        write_study_page(study, objectives, folder / STUDY_PAGE)
    return OptimizeSummary(study.study_name, len(rows), len(done), len(pruned), front, chosen, folder, computed,
                           interrupted, robots, tuple(names), tuple(objectives))
