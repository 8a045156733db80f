"""``locust.optimize``: Optuna's search of design ranges by named objectives, robust to what is not measured."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from ..params import Robot
from ..sweep.design import Bound, parse_bound
from ..sweep.objectives import objectives_named
from ..sweep.optimize import OptimizeSummary, run_optimize
from .sweeps import varied


def optimize_bounds(base: Robot, vary: Mapping[str, tuple[float, float] | str] | Sequence[str | Bound]) -> list[Bound]:
    """The searched ranges: ``{"geometry.leg_m": (0.05, 0.09)}``, ``{"schedule.push_s": "0.15:0.4"}``
    or ``["geometry.leg_m=0.05:0.09", ...]`` (the command line's ``--vary``), each name once.

    Parameters
    ----------
    base : locust.params.Robot
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
    return varied(base, vary, parse_bound, Bound, '{"geometry.leg_m": (0.05, 0.09)}')


def optimize(robot: Robot, vary: Mapping[str, tuple[float, float] | str] | Sequence[str | Bound], trials: int = 50,
             cycles: int = 3, *, out: str | Path, objectives: Sequence[str] = ("distance_per_hop",), robust: int = 0,
             quantile: float = 0.1, max_flip: float | None = None, sampler: str = "tpe",
             storage: str | None = None, study_name: str = "locust", seed: int = 0, jobs: int = 1,
             progress: Callable[[int], None] | None = None) -> OptimizeSummary:
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
        Name -> ``(low, high)`` (or ``"low:high"``): a numeric parameter's dotted name or
        ``scale`` (metres added to all four links); integer parameters draw whole numbers.
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
        Trials run at once, each in its own process.
    progress : callable, optional
        Called with 1 as each trial finishes.

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
    bounds = optimize_bounds(robot, vary)
    return run_optimize(robot, bounds, trials, cycles, Path(out), storage=storage, study_name=study_name,
                        seed=seed, jobs=jobs, progress=progress, objectives=objectives_named(list(objectives)),
                        draws=robust, quantile=quantile, max_flip=max_flip, sampler=sampler)
