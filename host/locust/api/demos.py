"""``locust.run_demo``: the whole toolkit end to end on the virtual robot, as ``locust demo`` runs it."""

from __future__ import annotations

from pathlib import Path
from typing import TextIO

from ..demo.options import DEFAULTS, DemoOptions
from ..demo.story import DemoResult, run_story


def demo_options(out: str | Path = DEFAULTS.out, cycles: int = DEFAULTS.cycles, trials: int = DEFAULTS.trials,
                 designs: int = DEFAULTS.designs, jobs: int | None = DEFAULTS.jobs,
                 fit_hops: bool = DEFAULTS.fit_hops) -> DemoOptions:
    """The options :func:`run_demo` runs with, checked (its arguments, as ``locust demo``'s).

    Parameters
    ----------
    out : path-like, default "demo-out"
        Parent folder; the demo goes into a new ``run/`` (``run-2/``, ...) inside (``--out``).
    cycles : int, default 3
        Hop cycles per trial, 1 to 6 (``--cycles``).
    trials : int, default 2
        Hops filmed per leg set, 1 to 5: repeated trials give the report its error bars
        (``--trials``).
    designs : int, default 7
        Designs in the sweep, 2 to 61: scale from 0 to 30 mm added to every link
        (``--designs``).
    jobs : int, optional
        Sweep workers, 1 to 64, and hops filmed at once up to 2 (1 where the virtual robot gets
        no real-time scheduling: its phases would be late); default every local core
        (``--jobs``).
    fit_hops : bool, default True
        Fit what the bench cannot reach from the filmed hops of Medium and Large
        (``--fit-hops/--no-fit-hops``).

    Returns
    -------
    locust.demo.options.DemoOptions

    Raises
    ------
    locust.errors.ReportError
        A size that is not a whole number in its range, or ``fit_hops`` not a bool.
    """
    return DemoOptions(out=Path(out), cycles=cycles, trials=trials, designs=designs, jobs=jobs, fit_hops=fit_hops)


def run_demo(out: str | Path = DEFAULTS.out, cycles: int = DEFAULTS.cycles, trials: int = DEFAULTS.trials,
             designs: int = DEFAULTS.designs, jobs: int | None = DEFAULTS.jobs, fit_hops: bool = DEFAULTS.fit_hops,
             *, stderr: TextIO | None = None) -> DemoResult:
    """Run the whole toolkit end to end on the virtual robot, as ``locust demo`` does.

    The virtual robot is the robot as built with its uncertain values drawn once (a draw
    whose Medium and Large rear and come back down, as the filmed robots did), hidden from
    every stage but the virtual board. Each stage runs the real command in a child process:
    flash the firmware to it, hop Small, Medium and Large (filmed), track the videos,
    calibrate its parts from SYNTHETIC bench recordings, measure its stance from two side
    stills, say each leg set's outcome shares, fit what the bench cannot reach from the
    filmed hops, sweep the added link length, and compare the calibrated model with the
    measured hops in a report. It takes minutes (about 3 on 2 cores with the defaults);
    Ctrl-C ends every command it started and raises a ``ReportError`` saying where it stopped.

    Parameters
    ----------
    out : path-like, default "demo-out"
        Parent folder; the demo goes into a new ``run/`` (``run-2/``, ...) inside.
    cycles : int, default 3
        Hop cycles per trial, 1 to 6.
    trials : int, default 2
        Hops filmed per leg set, 1 to 5.
    designs : int, default 7
        Designs in the sweep, 2 to 61: scale from 0 to 30 mm added to every link.
    jobs : int, optional
        Sweep workers, 1 to 64, and hops filmed at once up to 2; default every local core.
    fit_hops : bool, default True
        Fit what the bench cannot reach from the filmed hops of Medium and Large.
    stderr : text stream, optional
        Where the stage lines and bars go (default ``sys.stderr``).

    Returns
    -------
    locust.demo.story.DemoResult
        ``folder`` (the run's), ``report`` (the HTML page), ``stage_wall_s`` (each stage's
        wall time [s]) and ``total_s``.

    Raises
    ------
    locust.errors.ReportError
        An option out of its range (before anything is written), a command that failed (with
        its log's path), or the demo stopped.
    """
    return run_story(demo_options(out, cycles, trials, designs, jobs, fit_hops), stderr)
