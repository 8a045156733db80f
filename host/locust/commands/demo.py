"""``locust demo``: the whole toolkit end to end on the virtual robot, as a student runs it.

The options are :class:`locust.demo.options.DemoOptions`' (their defaults and ranges from
there); the demo is :func:`locust.demo.story.run_story`, the function :func:`locust.run_demo`
calls too. This module parses the options, calls it, and prints where the report is.
"""

from __future__ import annotations

from pathlib import Path

import click

from ..demo.options import DEFAULTS, RANGES, DemoOptions


def demo_options(**options) -> DemoOptions:
    """The demo's options from the command line's (``out``, ``cycles``, ... by their names).

    Parameters
    ----------
    **options
        The parsed value of each of ``locust demo``'s options.

    Returns
    -------
    DemoOptions
    """
    return DemoOptions(**options)


@click.command()
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=DEFAULTS.out,
              show_default=True, help="Parent folder; each demo goes into a new run/ (run-2/, ...) inside.")
@click.option("--cycles", type=click.IntRange(*RANGES["cycles"]), default=DEFAULTS.cycles, show_default=True,
              help="Hop cycles per trial.")
@click.option("--trials", type=click.IntRange(*RANGES["trials"]), default=DEFAULTS.trials, show_default=True,
              help="Hops filmed per leg set (repeated trials give the report its error bars).")
@click.option("--designs", type=click.IntRange(*RANGES["designs"]), default=DEFAULTS.designs, show_default=True,
              help="Designs in the sweep: scale from 0 to 30 mm added to every link.")
@click.option("--jobs", type=click.IntRange(*RANGES["jobs"]), default=DEFAULTS.jobs,
              help="Sweep workers, and hops filmed at once up to 2 (1 where the virtual robot gets no "
                   "real-time scheduling: its phases would be late) [every local core].")
@click.option("--fit-hops/--no-fit-hops", default=DEFAULTS.fit_hops, show_default=True,
              help="Fit what the bench cannot reach from the filmed hops of Medium and Large.")
def demo(**options):
    """Run the whole toolkit end to end on the virtual robot, then print where the report is.

    The virtual robot is the robot as built with its uncertain values drawn once (a draw whose
    Medium and Large rear and come back down, as the filmed robots did), hidden from every
    stage but the virtual board. Flash the firmware to it, hop Small, Medium and Large
    (filmed), track the videos, calibrate its parts from SYNTHETIC bench recordings of them,
    measure its stance from two side stills, say each leg set's outcome shares, fit what the
    bench cannot reach from the filmed hops, sweep the added link length, and compare the
    calibrated model with the measured hops in a report (the bench robot's prediction beside
    it). Everything it makes stays under --out; each command's output is in logs/.
    """
    from ..demo.story import run_story

    result = run_story(demo_options(**options))
    click.echo(f"report: {result.report}")
