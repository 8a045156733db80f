"""``locust measure stroke`` as one job: the outputs checked, the clips read beside the model's
push (:func:`.stroke.measure_stroke`), the CSV and plot written (:mod:`.strokeout`). The
command and :func:`locust.measure_stroke` both call :func:`stroke_job`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ..errors import MeasureError
from ..params import Robot
from ..track.pipeline import Bars, no_bars
from .stroke import BOOTSTRAP_DRAWS, StrokeResult, measure_stroke


@dataclass(frozen=True)
class StrokeOptions:
    """Every option of ``locust measure stroke``.

    Attributes
    ----------
    held_only : bool
        The one clip shows the push held up (no floor clip).
    side : str or None
        ``L`` or ``R``: the side the clips must show (None: whichever).
    fps : float or None
        The clips' true frame rate [1/s].
    csv : Path or None
        Where to write the crank's angle over time.
    plot : Path or None
        Where to draw the swing against the model's.
    force : bool
        Replace an existing CSV or plot.
    draws : int
        Bootstrap draws.
    seed : int
        The bootstrap's seed.
    """

    held_only: bool = False
    side: str | None = None
    fps: float | None = None
    csv: Path | None = None
    plot: Path | None = None
    force: bool = False
    draws: int = BOOTSTRAP_DRAWS
    seed: int = 0


@dataclass(frozen=True)
class StrokeJob:
    """The job's result: the reading and the files written.

    Attributes
    ----------
    result : StrokeResult
    written : tuple of Path
    """

    result: StrokeResult
    written: tuple[Path, ...] = ()


def check_outputs(options: StrokeOptions, clips: Sequence[Path]) -> None:
    """Refuse outputs that would replace a file or an input, before any work.

    Parameters
    ----------
    options : StrokeOptions
    clips : sequence of Path

    Raises
    ------
    MeasureError
        The CSV exists (without ``force``).
    WriteError
        The plot's path is not a figure's, or an output is an input or another output.
    """
    from ..fileio import check_distinct
    from ..plotting import check_figure_path

    if options.csv is not None and options.csv.exists() and not options.force:
        raise MeasureError(f"--csv {options.csv} exists", "choose another path, or add --force to replace it")
    if options.plot is not None:
        check_figure_path(options.plot, options.force)
    check_distinct({k: v for k, v in (("--csv", options.csv), ("--plot", options.plot)) if v is not None},
                   inputs=list(clips))


def stroke_job(robot: Robot, clips: Sequence[str | Path], options: StrokeOptions = StrokeOptions(),
               bars: Bars = no_bars) -> StrokeJob:
    """Read the push from each clip beside the model's, and write what ``options`` ask for.

    Parameters
    ----------
    robot : Robot
        The robot filmed, and the model compared with.
    clips : sequence of path
        The floor clip and the held one (or the held one alone, ``options.held_only``).
    options : StrokeOptions
    bars : callable
        Progress over each clip's frames.

    Returns
    -------
    StrokeJob

    Raises
    ------
    MeasureError
        Too many clips, a clip without the stickers or too short, or an output that exists.
    """
    clips = [Path(c) for c in clips]
    if options.held_only and len(clips) != 1:
        raise MeasureError(f"held only, with {len(clips)} clips", "give the held clip alone, or both without it")
    check_outputs(options, clips)
    result = measure_stroke(robot, clips, kinds=("held",) if options.held_only else ("floor", "held"),
                            side=options.side, fps=options.fps, draws=options.draws, seed=options.seed, bars=bars)
    from .strokeout import write_outputs

    written = write_outputs(result, options.csv, options.plot, force=options.force)
    return StrokeJob(result, tuple(written))


__all__ = ["StrokeJob", "StrokeOptions", "check_outputs", "stroke_job"]
