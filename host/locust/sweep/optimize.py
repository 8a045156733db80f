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
from .views import STUDY_PAGE, write_study_page

SAMPLERS = ("tpe", "nsga2")
# states of a trial that is over: the study holds its result (or its reason)
FINISHED = ("COMPLETE", "PRUNED")


def settings(base: Robot, bounds: list[Bound], cycles: int, objectives: list[Objective] | None = None,
             draws: int = 0, quantile: float | None = None, max_flip: float | None = None,
             sampler: str = "tpe") -> dict[str, Any]:
    """What a study searches, as JSON holds it: a rerun must ask for exactly this.

    Parameters
    ----------
    base : Robot
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
        ``base``, ``parameters``, ``vary``, ``cycles``, ``objectives``, ``robust``,
        ``quantile``, ``max_flip`` and ``sampler``, as a JSON round trip gives them back.
    """
    return json.loads(json.dumps({
        "base": base.name, "parameters": base.flat(), "vary": [b.to_dict() for b in bounds], "cycles": cycles,
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


@dataclass(frozen=True)
class StudySpec:
    """Everything a process needs to run one trial of the study (picklable).

    Attributes
    ----------
    storage : str or None
        The ``--storage`` URL or path; None for ``study.journal`` in ``folder``.
    folder : Path
        The optimisation's folder.
    study_name : str
        The study's name in the storage.
    bounds : tuple of Bound
        The design variables and their ranges.
    integers : frozenset of str
        The variables that are whole numbers.
    objectives : tuple of Objective
        What is maximised.
    judge : callable
        ``judge(values) -> Judgement``.
    max_flip : float or None
        The largest share of draws that may go over.
    sampler : str
        ``tpe`` or ``nsga2``.
    seed : int
        The sampler's base seed (each trial adds its index).
    trials : int
        Finished trials the study should hold.
    """

    storage: str | None
    folder: Path
    study_name: str
    bounds: tuple[Bound, ...]
    integers: frozenset[str]
    objectives: tuple[Objective, ...]
    judge: Callable[[dict[str, Any]], Judgement]
    max_flip: float | None
    sampler: str
    seed: int
    trials: int


def make_sampler(name: str, seed: int):
    """The Optuna sampler ``name``: NSGA-II (population 12), or multivariate TPE with 8 random
    start-up trials and the constant liar (trials under way elsewhere are not proposed again).

    Parameters
    ----------
    name : str
        ``tpe`` or ``nsga2``.
    seed : int
        The sampler's seed.

    Returns
    -------
    optuna.samplers.BaseSampler
        The sampler.
    """
    import optuna

    if name == "nsga2":
        return optuna.samplers.NSGAIISampler(seed=seed, population_size=12)
    # constant_liar: trials under way in other processes are not proposed again
    return optuna.samplers.TPESampler(seed=seed, n_startup_trials=8, multivariate=True, constant_liar=True)


def finished_trials(study) -> list:
    """The study's trials that are over (complete or pruned).

    Parameters
    ----------
    study : optuna.Study
        The study.

    Returns
    -------
    list of optuna.trial.FrozenTrial
        Those trials.
    """
    return [t for t in study.get_trials(deepcopy=False) if t.state.name in FINISHED]


def run_trial(spec: StudySpec, index: int) -> int:
    """Run one trial of the study (in this process or a worker).

    Parameters
    ----------
    spec : StudySpec
        The study.
    index : int
        The trial's index in this run; the sampler's seed is ``spec.seed + index``.

    Returns
    -------
    int
        The trial's number, or -1 when the study already holds ``spec.trials`` finished trials.
    """
    import optuna

    optuna.logging.set_verbosity(optuna.logging.ERROR)
    storage = open_storage(spec.storage, spec.folder)
    sampler = make_sampler(spec.sampler, spec.seed + index)
    study = optuna.load_study(study_name=spec.study_name, storage=storage, sampler=sampler)
    if len(finished_trials(study)) >= spec.trials:
        return -1
    numbers = []

    def objective(trial: optuna.Trial) -> list[float]:
        numbers.append(trial.number)
        values = {b.name: suggest(trial, b, spec.integers) for b in spec.bounds}
        judged = spec.judge(values)
        trial.set_user_attr("draws", judged.draws)
        trial.set_user_attr("draws_valid", judged.draws_valid)
        if not judged.valid:
            trial.set_user_attr("reason", judged.reason)
            raise optuna.TrialPruned(judged.reason)
        trial.set_user_attr("means", judged.means)
        trial.set_user_attr("outcome_shares", judged.outcome_shares)
        trial.set_user_attr("flip_share", judged.flip_share)
        if spec.max_flip is not None:
            trial.set_constraint("flip_share", judged.flip_share - spec.max_flip)
        return [judged.figures[o.column] for o in spec.objectives]

    study.optimize(objective, n_trials=1, catch=())
    return numbers[0] if numbers else -1


def suggest(trial, b: Bound, integers: frozenset[str]) -> float | int:
    """The trial's value for one design variable: a categorical, a whole number, or a float
    (stepped when the bound has a step).

    Parameters
    ----------
    trial : optuna.Trial
        The trial.
    b : Bound
        The variable.
    integers : frozenset of str
        The variables that are whole numbers.

    Returns
    -------
    float or int
        The suggested value, in the parameter's unit.
    """
    if b.choices is not None:
        return trial.suggest_categorical(b.name, list(b.choices))
    if b.name in integers:
        return trial.suggest_int(b.name, math.ceil(b.low), math.floor(b.high))
    return trial.suggest_float(b.name, b.low, b.high, step=b.step)


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

    @property
    def best(self) -> dict[str, Any] | None:
        """The first objective's best design on the front."""
        return next(iter(self.picks.values()), None)


def run_optimize(base: Robot, bounds: list[Bound], trials: int, cycles: int, folder: Path,
                 storage: str | None = None, study_name: str = "locust", seed: int = 0, jobs: int = 1,
                 progress: Callable[[int], None] | None = None, objectives: list[Objective] | None = None,
                 judge: Callable[[dict[str, Any]], Judgement] | None = None, draws: int = 0,
                 quantile: float = 0.1, max_flip: float | None = None, sampler: str = "tpe",
                 scheduler: str = "local") -> OptimizeSummary:
    """Run (or resume) the study into ``folder`` until it holds ``trials`` finished trials.

    Parameters
    ----------
    base : Robot
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
        ``progress(n)`` as trials finish (first with those finished before this run).
    objectives : list of Objective
        What is maximised (default: distance_per_hop).
    judge : callable, optional
        ``judge(values) -> Judgement``; default :class:`~locust.sweep.robust.DesignJudge` of
        ``base`` with ``draws`` and ``quantile``.
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

    from .execute import check_scheduler, mapper, plan_jobs, probe_dask_scheduler
    from .robust import DesignJudge

    optuna.logging.set_verbosity(optuna.logging.ERROR)
    objectives = objectives or [OBJECTIVES[DEFAULT]]
    if sampler not in SAMPLERS:
        raise SweepError(f"--sampler {sampler!r}: not one of {', '.join(SAMPLERS)}", "use tpe or nsga2")
    check_scheduler(scheduler)
    if scheduler.startswith("tcp://"):
        probe_dask_scheduler(scheduler)
    check_folder(folder)
    if storage is None:
        check_journal_file(folder / "study.journal")
    check_storage(storage)
    integers = frozenset(b.name for b in bounds if is_integer(base, b.name))
    for b in bounds:
        if b.name in integers and math.floor(b.high) < math.ceil(b.low):
            raise SweepError(f"--vary {b.name}={b.low:g}:{b.high:g} holds no whole number, and {b.name} is one",
                             f"give a range with at least one integer, e.g. {b.name}={math.floor(b.low)}:"
                             f"{math.floor(b.low) + 2}")
    make_folder(folder)
    storage_obj = open_storage(storage, folder)
    wanted = settings(base, bounds, cycles, objectives, draws, quantile, max_flip, sampler)
    where = storage or str(folder / "study.journal")
    try:
        held = optuna.load_study(study_name=study_name, storage=storage_obj)
    except KeyError:
        held = None
    if held is not None:
        check_settings(held, wanted, where)
    study = optuna.create_study(study_name=study_name, storage=storage_obj, load_if_exists=True,
                                directions=["maximize"] * len(objectives))
    if held is None:
        study.set_user_attr(SETTINGS_ATTR, wanted)
        # the columns' names, units included: what Optuna's views and optuna-dashboard label
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)   # stable since Optuna 3.2
            study.set_metric_names([o.column for o in objectives])
    before = len(study.trials)
    left = max(0, trials - len(finished_trials(study)))
    judge = judge or DesignJudge(base, cycles, tuple(objectives), draws, quantile)
    spec = StudySpec(storage, folder, study_name, tuple(bounds), integers, tuple(objectives), judge, max_flip,
                     sampler, seed, trials)
    # a resumed study must not draw its first samples again: each trial's sampler seed moves on
    # with the trials the study held before it
    items = [before + k for k in range(left)]
    if not scheduler.startswith("tcp://"):
        jobs, _ = plan_jobs(jobs, len(items))
    computed = 0
    if progress and trials > left:
        progress(trials - left)   # finished before this run
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
        return summarise(optuna.load_study(study_name=study_name, storage=storage_obj), folder, base, objectives,
                         max_flip, computed, interrupted=True)
    return summarise(optuna.load_study(study_name=study_name, storage=storage_obj), folder, base, objectives,
                     max_flip, computed)


@dataclass(frozen=True)
class TrialOf:
    """A picklable ``run_trial`` of one study: what each process maps over trial indices.

    Attributes
    ----------
    spec : StudySpec
        The study.
    """

    spec: StudySpec

    def __call__(self, index: int) -> int:
        """Run trial ``index`` of the study (:func:`run_trial`).

        Parameters
        ----------
        index : int
            The trial's index in this run.

        Returns
        -------
        int
            The trial's number, or -1 when the study already holds enough finished trials.
        """
        return run_trial(self.spec, index)


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


def summarise(study, folder: Path, base: Robot, objectives: list[Objective], max_flip: float | None,
              computed: int = 0, interrupted: bool = False) -> OptimizeSummary:
    """Write trials.csv, pareto.csv, pareto.png, study.html (Optuna's own views of the study),
    optimize.json and a robot file for each pick.

    Parameters
    ----------
    study : optuna.Study
        The study, loaded after the run.
    folder : Path
        The output folder.
    base : Robot
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
        robot = design_robot(base, {n: r[n] for n in names}).renamed(f"optimize {pick} of {folder}")
        robots[pick] = save_robot(robot, folder / f"{pick}.toml")
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
                           interrupted, robots)
