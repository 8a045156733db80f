"""One trial of a ``locust optimize`` study, in this process or a worker: what each process
maps over the trials' indices (:class:`TrialOf`), its sampler, and the design it suggests.

A trial loads the study from its storage, draws a design with its own seeded sampler, has the
study's judge score it and records the figures (or the reason it was pruned) as the trial's
user attributes, so processes and Dask workers that share the storage share the study.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .design import Bound
from .objectives import Judgement, Objective
from .storage import open_storage

# states of a trial that is over: the study holds its result (or its reason)
FINISHED = ("COMPLETE", "PRUNED")


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
