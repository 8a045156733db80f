"""``locust.optimize``: Optuna's search of design ranges by named objectives, robust to what is not measured."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from ..params import Robot
from ..sweep.design import Bound
from ..sweep.optimize import OptimizeSummary
from ..sweep.study import OptimizeOptions, optimize_study, parse_steps, study_bounds
from .sweeps import vary_texts


def optimize_bounds(robot: Robot, vary: Mapping[str, tuple[float, float] | str] | Sequence[str | Bound]) -> list[Bound]:
    """The searched ranges: ``{"geometry.leg_m": (0.05, 0.09)}``, ``{"schedule.push_s": "0.15:0.4"}``
    or ``["geometry.leg_m=0.05:0.09", ...]`` (the command line's ``--vary``), each name once.

    Parameters
    ----------
    robot : locust.params.Robot
        The robot optimised.
    vary : mapping or sequence
        Name -> (low, high) in the parameter's unit, or the same as text.

    Returns
    -------
    list of locust.sweep.design.Bound

    Raises
    ------
    locust.errors.SweepError
        Nothing varied, a name given twice, or a range that cannot be read.
    """
    return study_bounds(robot, vary_texts(vary), {})


def optimize(robot: Robot, vary: Mapping[str, tuple[float, float] | str] | Sequence[str | Bound], trials: int = 50,
             cycles: int = 3, *, out: str | Path, objectives: Sequence[str] = ("distance_per_hop",), robust: int = 0,
             quantile: float = 0.1, max_flip: float | None = None, sampler: str = "tpe",
             storage: str | None = None, study_name: str = "locust", seed: int = 0, jobs: int = 1,
             steps: Mapping[str, float] | Sequence[str] | None = None, scheduler: str = "local",
             repair: bool = False, progress: Callable[[int], None] | None = None,
             say: Callable[[str], None] | None = None) -> OptimizeSummary:
    """Search design ranges for the hops that go farthest and highest without going over, as
    ``locust optimize`` does (Optuna; a Pareto front with two objectives or more).

    Each trial's design is checked, simulated, audited and classified as a sweep's is; an
    invalid one is pruned with its reason, and a design that goes over scores 0. Running again
    into the same ``out`` (or ``storage``) resumes the study; other settings are refused.

    Parameters
    ----------
    robot : Robot
        The base design (:func:`locust.robot`).
    vary : dict or list of str
        Name -> ``(low, high)`` (or ``"low:high"``, or ``"a,b,c"``: those values alone): a
        numeric parameter's dotted name or ``scale`` (metres added to all four links); integer
        parameters draw whole numbers. A list holds ``--vary`` texts (``"scale=0:0.02"``).
    trials : int, default 50
        Finished trials the study should hold (a resumed study computes the rest).
    cycles : int, default 3
        Hop cycles per design.
    out : path-like
        Folder for ``trials.csv``, ``pareto.csv``, ``pareto.png``, ``optimize.json``, the
        robot files ``best-<objective>.toml`` and ``knee.toml`` and, by default, the journal.
    objectives : sequence of str, default ("distance_per_hop",)
        Maximised, each a figure per hop: ``distance_per_hop`` (m), ``nose_rise_per_hop`` (m),
        ``flight_per_hop`` (s).
    robust : int, default 0
        Judge each design over this many draws of the robot file's uncertain values (0: its
        nominal run); the objective is then the ``quantile`` of the draws.
    quantile : float, default 0.1
        With ``robust``: the figure that 1 - quantile of the draws beat.
    max_flip : float, optional
        The largest share of draws that may go over (an Optuna constraint).
    sampler : {"tpe", "nsga2"}, default "tpe"
        Optuna's multi-objective TPE or NSGA-II.
    storage : str, optional
        An Optuna storage URL (e.g. ``sqlite:///study.db``) instead of ``out/study.journal``.
    study_name : str, default "locust"
        The study's name in the storage.
    seed : int, default 0
        The sampler's seed.
    jobs : int, default 1
        Trials run at once, each in its own process (or Dask worker).
    steps : dict or list of str, optional
        A range's step by its name (``{"geometry.crank_start_deg": 18}``, or ``--step`` texts
        ``"NAME=STEP"``): the values low, low + step, ... up to high.
    scheduler : str, default "local"
        ``local`` (``jobs`` processes), ``dask-local`` or ``tcp://HOST:PORT`` of a Dask
        scheduler (its workers must reach ``storage``).
    repair : bool, default False
        First cut the torn last line of the study's journal, a full disk's (the file saved as
        ``study.journal.torn-N`` beside it; every whole trial kept).
    progress : callable, optional
        Called as the trials begin with those finished before (0 for a new study), then with 1
        as each trial finishes.
    say : callable, optional
        Told, as a line of text, what ``repair`` did.

    Returns
    -------
    locust.sweep.optimize.OptimizeSummary
        ``trials``, ``complete``, ``pruned``, ``front`` (the Pareto rows), ``picks`` (each
        objective's best and the knee), ``best`` (the first objective's best row; None when
        no design is valid within the flip limit) and ``robots`` (the picks' robot files).

    Examples
    --------
    >>> import locust, tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     res = locust.optimize(locust.robot("small"), {"schedule.push_s": (0.15, 0.4)}, trials=3,
    ...                           cycles=1, out=folder + "/opt")
    >>> res.trials, res.complete, res.pruned
    (3, 3, 0)
    """
    if steps is None or isinstance(steps, Mapping):
        steps = {name: float(step) for name, step in (steps or {}).items()}
    else:
        steps = parse_steps(list(steps))
    options = OptimizeOptions(out=Path(out), vary=tuple(vary_texts(vary)), steps=steps,
                              objectives=tuple(objectives), robust=robust, quantile=quantile, max_flip=max_flip,
                              trials=trials, cycles=cycles, storage=storage, study_name=study_name, sampler=sampler,
                              seed=seed, jobs=jobs, scheduler=scheduler, repair=repair)
    return optimize_study(robot, options, progress=progress, say=say)
