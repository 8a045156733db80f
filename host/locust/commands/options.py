"""The options several commands share, each defined once.

- ``FiniteFloat`` (``FINITE``, ``POSITIVE``): numbers that must be finite (and positive):
  ``click``'s own ``float`` takes ``nan`` and ``inf``, which would reach a fit or a drawing as
  nonsense, so these refuse them where the command line is read.
- ``robot_options``: ``--preset``, ``--config``, ``--set``, and the robot a command runs on when
  given neither (``locust.io.robot_toml.default_robot``: ``calibration/robot.toml`` here, else
  the robot as built).
- ``import_options``: ``--units``, ``--rename``, ``--mirror`` for foreign tracks.
- ``time_options``: ``--time-scale``, ``--clip-fps`` for slow-motion recordings.
- ``JobBar``: a job's progress bar, fed by the job's ``progress`` and ``say`` callbacks.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import click

from .. import params as robot_params
from ..calibrate.recordings import TimeOptions
from ..io.importing import ImportOptions
from ..io.robot_toml import ROBOT_FILE, default_robot
from ..progress import Progress, progress


class FiniteFloat(click.ParamType):
    """A finite number; with ``positive``, above zero; with ``low``/``high``, within them."""

    name = "number"

    def __init__(self, positive: bool = False, low: float | None = None, high: float | None = None):
        self.positive = positive
        self.low, self.high = low, high

    def convert(self, value, param, ctx):
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        if self.positive and not number > 0:
            self.fail(f"{value!r} must be above 0", param, ctx)
        if self.low is not None and number < self.low:
            self.fail(f"{value!r} is below {self.low:g}", param, ctx)
        if self.high is not None and number > self.high:
            self.fail(f"{value!r} is above {self.high:g}", param, ctx)
        return number


FINITE = FiniteFloat()
POSITIVE = FiniteFloat(positive=True)


DEFAULTED = "locust.robot_defaulted"              # click context meta: no --preset or --config was given


def robot_options(func=None, *, say: bool = True):
    """The shared --preset / --config / --set options of every command that needs a robot.

    With neither --preset nor --config the command runs on :func:`default_robot`, and its
    first line of output (on stderr) says which; ``say=False``: the command prints that line
    itself (the click context's meta ``DEFAULTED`` holds it), once it knows better."""
    if func is None:
        return functools.partial(robot_options, say=say)
    command = func

    @functools.wraps(command)
    def wrapper(*args, preset, config, **kwargs):
        if preset is None and config is None:
            choice = default_robot()
            preset, config, said = choice.preset, choice.robot_file, choice.line
            if say:
                click.echo(said, err=True)
            click.get_current_context().meta[DEFAULTED] = said
        return command(*args, preset=preset, config=config, **kwargs)

    func = click.option("--set", "sets", multiple=True, metavar="KEY=VALUE",
                        help="Override any parameter by its dotted name, "
                             "e.g. --set servo.kp_nm_per_rad=0.4. Repeatable.")(wrapper)
    func = click.option("--config", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help=f"A robot.toml (e.g. {ROBOT_FILE}); overrides --preset.")(func)
    func = click.option("--preset", type=click.Choice(list(robot_params.PRESETS)), default=None,
                        help=f"Built-in parameter set [default: {ROBOT_FILE} when the current folder has one, "
                             f"else {robot_params.DEFAULT_PRESET}, the robot as built].")(func)
    return func


def say_written_from(preset: str | None, config: Path | None, write: Path | None) -> None:
    """A command that writes a robot file says, first (stderr), which robot it starts from:
    the default robot's line (:func:`robot_options`) has said it already; a robot named on the
    command line is said here."""
    if write is None or click.get_current_context().meta.get(DEFAULTED):
        return
    click.echo(f"robot: {config if config is not None else preset}; {write} is written from it", err=True)


def import_options(func):
    """``--units``, ``--rename``, ``--mirror`` on a click command; the command gets them as one
    checked :class:`ImportOptions` argument, ``imports`` (a bad value is a TrackError)."""

    @functools.wraps(func)
    def wrapper(*args, units, rename, mirror, **kwargs):
        return func(*args, imports=ImportOptions.parse(units, rename, mirror), **kwargs)

    wrapper = click.option("--mirror", is_flag=True,
                           help="Flip x of the tracks (x -> -x): a hop filmed right-to-left reads left-to-right.")(
                               wrapper)
    wrapper = click.option("--rename", "rename", multiple=True, metavar="OLD=NEW",
                           help="Rename a marker of the tracks (its name, or its Tracker name as written: "
                                "'cm A=nose'); repeatable. A track with no name (a t,x,y CSV) is 'nose'.")(wrapper)
    wrapper = click.option("--units", "units", default="m", show_default=True, metavar="m|cm|mm",
                           help="Unit of the tracks' positions (Tracker's calibration unit), made metres.")(wrapper)
    return wrapper


def time_options(func):
    """``--time-scale``, ``--clip-fps`` on a click command, given to it as one :class:`TimeOptions`, ``timing``."""

    @functools.wraps(func)
    def wrapper(*args, time_scale, clip_fps, **kwargs):
        return func(*args, timing=TimeOptions(time_scale, clip_fps), **kwargs)

    wrapper = click.option("--clip-fps", type=float, default=None, metavar="FPS",
                           help="Slow motion: the rate the clip was filmed at [frames/s]; the file's own rate "
                                "(its median time step) is rescaled to it, e.g. a 240 frames/s clip exported "
                                "at 30: --clip-fps 240.")(wrapper)
    wrapper = click.option("--time-scale", type=float, default=None, metavar="S",
                           help="Slow motion: real time = the file's time * S [-], e.g. 0.125 for a 240 "
                                "frames/s clip exported at 30 [default: 1, times as they are].")(wrapper)
    return wrapper


class JobBar:
    """A job's progress bar on stderr (:func:`locust.progress.progress`), fed by the job's callbacks.

    The bar is drawn from the job's first ``update`` (a job reports ``update(0)`` as its long
    part begins), so what the job refuses before it starts is printed alone, and it is closed at
    its last step, so a bar the job draws next (a video's rendering) has a line of its own.
    ``say`` prints a line of the job's on stderr, on a line of its own beside the bar.

    Parameters
    ----------
    length : int
        The steps.
    label : str
        Shown before the bar.
    **options
        :func:`locust.progress.progress`'s options.
    """

    def __init__(self, length: int, label: str, **options):
        self.length, self.label, self.options = length, label, options
        self.bar: Progress | None = None
        self.done = False

    def __enter__(self) -> JobBar:
        return self

    def __exit__(self, *exc) -> bool:
        self.close()
        return False

    def update(self, n_steps: int = 1) -> None:
        """Count ``n_steps`` more steps done (0: the work begins), drawing the bar first.

        Parameters
        ----------
        n_steps : int
        """
        if self.done:
            return
        if self.bar is None:
            self.bar = progress(length=self.length, label=self.label, **self.options).__enter__()
        self.bar.update(n_steps)
        if self.bar.pos >= self.length:
            self.close()

    def say(self, line: str) -> None:
        """Print ``line`` on stderr, clearing the bar's line first on a terminal (the next step draws it again).

        Parameters
        ----------
        line : str
        """
        if self.bar is not None and not self.done and self.bar.tty:
            self.bar.file.write("\r\x1b[K")
        click.echo(line, err=True)

    def close(self) -> None:
        """End the bar (its last state and a new line, on a terminal), if it was drawn."""
        if self.bar is not None and not self.done:
            self.bar.__exit__(None, None, None)
        self.done = True
