"""The study job: what ``locust optimize`` and :func:`locust.optimize` both run.

:class:`OptimizeOptions` holds every setting of ``locust optimize`` but the robot;
:func:`optimize_study` reads the ranges and objectives it names, mends a torn journal when
asked (``repair``), then runs (or resumes) the study with :func:`.optimize.run_optimize`.
The command line only parses its options into one, and prints what comes back.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SweepError
from ..params import Robot
from .design import Bound, parse_bound
from .objectives import DEFAULT, objectives_named
from .optimize import OptimizeSummary, run_optimize


@dataclass(frozen=True, kw_only=True)
class OptimizeOptions:
    """The settings of one study, as ``locust optimize`` takes them (its robot aside).

    Attributes
    ----------
    out : Path
        Folder for ``trials.csv``, ``pareto.csv``, ``pareto.png``, ``study.html``,
        ``optimize.json``, the picks' robot files and, by default, the journal.
    vary : tuple of str or Bound
        The searched ranges: ``NAME=LOW:HIGH`` or ``NAME=A,B,C`` (``--vary``), or bounds
        already read; each name once.
    steps : mapping of str to float
        A range's step by its name, in the parameter's unit (``--step``).
    objectives : tuple of str
        Maximised, each a figure per hop (``--objective``; none: ``distance_per_hop``).
    robust : int
        Draws of the robot's uncertain values each design is judged over (0: its nominal run).
    quantile : float
        With ``robust``: the quantile of the draws taken as the figure.
    max_flip : float or None
        The largest share of draws that may go over.
    trials : int
        Finished trials the study should hold.
    cycles : int
        Hop cycles each design runs.
    storage : str or None
        A journal file or a database URL (None: ``out/study.journal``).
    study_name : str
        The study's name in the storage.
    sampler : str
        ``tpe`` or ``nsga2``.
    seed : int
        The sampler's seed.
    jobs : int
        Trials run at once.
    scheduler : str
        ``local``, ``dask-local`` or ``tcp://HOST:PORT``.
    repair : bool
        First cut the torn last line of the study's journal (saved beside it first).
    """

    out: Path
    vary: tuple[str | Bound, ...]
    steps: Mapping[str, float] = field(default_factory=dict)
    objectives: tuple[str, ...] = (DEFAULT,)
    robust: int = 0
    quantile: float = 0.1
    max_flip: float | None = None
    trials: int = 50
    cycles: int = 3
    storage: str | None = None
    study_name: str = "locust"
    sampler: str = "tpe"
    seed: int = 0
    jobs: int = 1
    scheduler: str = "local"
    repair: bool = False


def parse_steps(items: Sequence[str]) -> dict[str, float]:
    """Read ``--step NAME=STEP`` texts.

    Parameters
    ----------
    items : sequence of str
        The texts.

    Returns
    -------
    dict of str to float
        Each range's step by its name, in the parameter's unit.

    Raises
    ------
    SweepError
        A text not of the form ``NAME=STEP``.
    """
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


def study_bounds(robot: Robot, vary: Sequence[str | Bound], steps: Mapping[str, float]) -> list[Bound]:
    """The design variables searched: each ``--vary`` read against ``robot``, with its step.

    Parameters
    ----------
    robot : Robot
        The robot the designs start from.
    vary : sequence of str or Bound
        ``NAME=LOW:HIGH`` or ``NAME=A,B,C`` texts, or bounds.
    steps : mapping of str to float
        A range's step by its name.

    Returns
    -------
    list of Bound
        One per varied name, in the order given.

    Raises
    ------
    SweepError
        Nothing varied, a range that cannot be read, a name varied twice, or a step for a
        name not varied.
    """
    if not vary:
        raise SweepError("nothing to vary", 'give a range to search, e.g. --vary scale=0:0.02 '
                                            '(vary={"scale": (0.0, 0.02)} in Python)')
    bounds = [v if isinstance(v, Bound) else parse_bound(v, robot, steps.get(v.partition("=")[0].strip()))
              for v in vary]
    if len({b.name for b in bounds}) != len(bounds):
        raise SweepError("--vary names a parameter twice", "give each parameter one --vary")
    unknown = sorted(set(steps) - {b.name for b in bounds})
    if unknown:
        raise SweepError(f"--step {unknown[0]}: no --vary range of that name", "give --vary NAME=LOW:HIGH with it")
    return bounds


def repair_journal(storage: str | None, out: Path) -> str:
    """``--repair``: cut the torn last line of the study's journal file (saved beside it first).

    Parameters
    ----------
    storage : str or None
        The study's storage (None: ``out/study.journal``).
    out : Path
        The study's folder.

    Returns
    -------
    str
        What was cut and kept, as one line for the user.

    Raises
    ------
    SweepError
        The storage is a database, or there is no such journal.
    """
    from .journal import repair
    from .storage import RDB_PREFIXES

    if storage is not None and storage.startswith(RDB_PREFIXES):
        raise SweepError(f"--repair mends a journal file; --storage {storage} is a database",
                         "leave --repair off (a database is not torn by a full disk)")
    journal = Path(storage.removeprefix("journal:")) if storage else out / "study.journal"
    if not journal.is_file():
        raise SweepError(f"--repair: there is no journal {journal}", "give the --out (or --storage) of the study")
    return repair(journal).line()


def optimize_study(robot: Robot, options: OptimizeOptions, progress: Callable[[int], None] | None = None,
                   say: Callable[[str], None] | None = None) -> OptimizeSummary:
    """Run (or resume) the study ``options`` describe on designs of ``robot``.

    Everything the options name is read and checked before the study is touched; with
    ``repair`` the journal is mended first.

    Parameters
    ----------
    robot : Robot
        The robot every design starts from.
    options : OptimizeOptions
        The study's settings.
    progress : callable, optional
        ``progress(n)`` as trials finish (first with those finished before this run).
    say : callable, optional
        Told, as a line of text, what ``repair`` did.

    Returns
    -------
    OptimizeSummary
        The front, the picks and the robot files written; after Ctrl-C, what was finished.

    Raises
    ------
    SweepError
        A setting that cannot be read or run (:func:`study_bounds`,
        :func:`~.objectives.objectives_named`, :func:`repair_journal`,
        :func:`~.optimize.run_optimize`).
    """
    bounds = study_bounds(robot, options.vary, options.steps)
    objectives = objectives_named(list(options.objectives))
    if options.repair:
        line = repair_journal(options.storage, options.out)
        if say:
            say(line)
    return run_optimize(robot, bounds, options.trials, options.cycles, options.out, storage=options.storage,
                        study_name=options.study_name, seed=options.seed, jobs=options.jobs, progress=progress,
                        objectives=objectives, draws=options.robust, quantile=options.quantile,
                        max_flip=options.max_flip, sampler=options.sampler, scheduler=options.scheduler)


__all__ = ["OptimizeOptions", "optimize_study", "parse_steps", "repair_journal", "study_bounds"]
