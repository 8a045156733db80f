"""``locust.optimize``: Optuna's TPE search of continuous ranges for the farthest valid hop."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from ..params import Robot
from ..sweep.design import Bound, parse_bound
from ..sweep.optimize import OptimizeSummary, run_optimize
from .sweeps import varied


def optimize_bounds(base: Robot, vary: Mapping[str, tuple[float, float] | str] | Sequence[str | Bound]) -> list[Bound]:
    """The searched ranges: ``{"geometry.leg_m": (0.05, 0.09)}``, ``{"schedule.push_s": "0.15:0.4"}``
    or ``["geometry.leg_m=0.05:0.09", ...]`` (the command line's ``--vary``), each name once."""
    return varied(base, vary, parse_bound, Bound, '{"geometry.leg_m": (0.05, 0.09)}')


def optimize(robot: Robot, vary: Mapping[str, tuple[float, float] | str] | Sequence[str | Bound], trials: int = 50,
             cycles: int = 3, *, out: str | Path, storage: str | None = None, study_name: str = "locust",
             seed: int = 0, jobs: int = 1, progress: Callable[[int], None] | None = None) -> OptimizeSummary:
    """Search continuous ranges for the farthest hop, as ``locust optimize`` does (Optuna TPE).

    Each trial's design is checked and audited as a sweep's is; an invalid one is pruned with
    its reason and never becomes the best. Running again into the same ``out`` (or
    ``storage``) continues the study.

    Parameters
    ----------
    robot : Robot
        The base design (:func:`locust.robot`).
    vary : dict or list of str
        Name -> ``(low, high)`` (or ``"low:high"``): a numeric parameter's dotted name or
        ``scale`` (metres added to all four links); integer parameters draw whole numbers.
    trials : int, default 50
        Trials to run now (added to those the study already holds).
    cycles : int, default 3
        Hop cycles per design.
    out : path-like
        Folder for ``trials.csv``, ``optimize.json``, ``history.png``, ``best.toml`` and, by
        default, the study's journal.
    storage : str, optional
        An Optuna storage URL (e.g. ``sqlite:///study.db``) instead of ``out/study.journal``.
    study_name : str, default "locust"
        The study's name in the storage.
    seed : int, default 0
        The sampler's seed.
    jobs : int, default 1
        Trials run at once in this process.
    progress : callable, optional
        Called with 1 as each trial finishes.

    Returns
    -------
    locust.sweep.optimize.OptimizeSummary
        ``trials``, ``complete``, ``pruned``, ``best`` (its values, ``distance_m``,
        ``max_nose_height_m``; None when no trial was valid), ``best_robot`` (``best.toml``).

    Examples
    --------
    >>> import locust
    >>> res = locust.optimize(locust.robot("small"), {"schedule.push_s": (0.15, 0.4)}, trials=3,
    ...                       cycles=1, out="opt")                     # doctest: +SKIP
    >>> res.best["distance_m"]                                        # doctest: +SKIP
    """
    bounds = optimize_bounds(robot, vary)
    return run_optimize(robot, bounds, trials, cycles, Path(out), storage=storage, study_name=study_name,
                        seed=seed, jobs=jobs, progress=progress)
