"""The ``locust`` command: a thin table of verbs, each in its own module of this package.

Commands are imported only when used, so ``locust --help`` and the quick commands
start fast even though the simulation, vision and CAD libraries are heavy. Any
:class:`~locust.errors.LocustError` is turned here, once, into one clear message.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys

import click

from ..errors import LocustError
from ..version import __version__

# verb -> (module, attribute, one-line help shown by `locust --help`)
COMMANDS: dict[str, tuple[str, str, str]] = {
    "params": ("locust.commands.params", "params", "Show or write robot parameters (presets, robot.toml, --set)."),
    "sim": ("locust.commands.sim", "sim", "Simulate the hop schedule in MuJoCo, audited."),
    "sweep": ("locust.commands.sweep", "sweep", "Sweep design parameters over a grid, in parallel."),
    "optimize": ("locust.commands.optimize", "optimize", "Designs that hop far and high without going over (Optuna)."),
    "ports": ("locust.commands.ports", "ports", "List serial ports and mark the likely ESP32."),
    "flash": ("locust.commands.flash", "flash", "Copy the MicroPython firmware to the board (mpremote)."),
    "hop": ("locust.commands.hop", "hop", "Run the bang-bang hop schedule on the robot; save a run record."),
    "config": ("locust.commands.config", "board_config",
               "Read the board's servo config back, or set a trim (no flashing)."),
    "pose": ("locust.commands.pose", "pose", "Move the servos to an angle and hold it (centring, trim)."),
    "repl": ("locust.commands.repl", "repl", "Open MicroPython's REPL on the robot (mpremote)."),
    "virtual": ("locust.commands.virtual", "virtual", "Start a virtual robot on a pseudo-terminal."),
    "track": ("locust.commands.track", "track", "Marker tracks from video, or converted from Tracker (5 subcommands)."),
    "calibrate": ("locust.commands.calibrate", "calibrate", "Fit stiffness, damping, servo gains, friction."),
    "report": ("locust.commands.report", "report", "Compare simulation and measurement in an HTML report."),
    "demo": ("locust.commands.demo", "demo", "Run the whole toolkit end to end on the virtual robot."),
    "fab": ("locust.commands.fab", "fab", "Generate the five-layer laminate cut files (DXF)."),
    "measure": ("locust.commands.measure", "measure", "Measure the robot: photos, a scale, clips, a multimeter."),
}


# An error is a line or two a person reads: the longest the toolkit writes on purpose is a hint
# listing every fittable key (1,144 characters). Beyond this a message quotes what it was given
# (a 60,000-character cell of a CSV, a robot.toml string, a results.csv header of 10,000
# columns) and is cut in its middle: what and where come first, the reason last.
MAX_ERROR_CHARS = 1200


def bounded(text: str, limit: int = MAX_ERROR_CHARS) -> str:
    """``text`` whole when it has at most ``limit`` characters; else its start and its end with
    how many characters were left out between them.

    Parameters
    ----------
    text : str
    limit : int

    Returns
    -------
    str
        At most about ``limit`` characters.
    """
    if len(text) <= limit:
        return text
    head, tail = limit * 3 // 4, limit // 5
    return f"{text[:head]} … [{len(text) - head - tail:,} characters left out] … {text[-tail:]}"


class LazyGroup(click.Group):
    def list_commands(self, ctx: click.Context) -> list[str]:
        return [name for name in COMMANDS if _available(name)]

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in COMMANDS:
            return None
        module, attr, _ = COMMANDS[name]
        try:
            return getattr(importlib.import_module(module), attr)
        except ModuleNotFoundError as exc:
            if exc.name and exc.name.startswith("locust"):
                return None
            raise

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        rows = [(name, COMMANDS[name][2]) for name in self.list_commands(ctx)]
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except click.UsageError as exc:   # a bad option value, a missing argument: the same two lines
            sub = exc.ctx.command_path if exc.ctx else "locust"
            click.secho(f"error: {bounded(exc.format_message())}", fg="red", err=True)
            click.echo(f"  hint: see `{sub} --help`", err=True)
            ctx.exit(exc.exit_code)
        except LocustError as exc:
            click.secho(f"error: {bounded(exc.message)}", fg="red", err=True)
            if exc.hint:
                click.echo(f"  hint: {bounded(exc.hint)}", err=True)
            ctx.exit(exc.exit_code)
        except OSError as exc:  # a file or folder the job's own checks did not foresee
            where = f"{exc.filename}: " if exc.filename else ""
            click.secho(f"error: {bounded(f'{where}{exc.strerror or exc}')}", fg="red", err=True)
            click.echo("  hint: check that the path exists and is readable, that the output folder is "
                       "writable and that the disk has space", err=True)
            ctx.exit(2)


def _available(name: str) -> bool:
    try:
        return importlib.util.find_spec(COMMANDS[name][0]) is not None
    except ModuleNotFoundError:  # its package is not there yet
        return False


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="locust")
def cli() -> None:
    """locust: firmware-plus-host toolkit for the foldable four-bar hopping robot.

    \b
    Typical flow:
      locust flash --port sim            put the firmware on a board (or the virtual robot)
      locust hop --port sim --cycles 6   run the hop schedule, save a run record
      locust track video.mp4             nose and foot tracks from video
      locust calibrate beam tracks.csv   identify the physics, update robot.toml
      locust sim --preset seed --json    simulate the hop, audited
      locust sweep --vary scale=0:0.05:30 --out sweep/
      locust report --measured ...       simulation against reality
      locust fab --from-robot seed       laminate cut files
    """


# the load-testing tool published on PyPI as "locust" installs the same package and command
SHADOWING_DISTRIBUTION = "locust"


OUR_SUMMARY = "Firmware-plus-host toolkit for a foldable four-bar hopping robot"


def shadowing_install() -> str | None:
    """The version of the unrelated "locust" distribution installed beside this one, if any
    (an old install of this toolkit under that name is not it)."""
    import importlib.metadata as md

    try:
        meta = md.metadata(SHADOWING_DISTRIBUTION)
    except md.PackageNotFoundError:
        return None
    return None if (meta.get("Summary") or "").startswith(OUR_SUMMARY) else meta.get("Version", "?")


def main() -> None:
    other = shadowing_install()
    if other is not None:
        click.secho(f"error: the load-testing tool 'locust' {other} is installed in this environment; it and "
                    "this toolkit (locust-hopper) share the package and command name `locust`", fg="red", err=True)
        click.echo("  hint: install locust-hopper in its own virtual environment (`make install` makes one), "
                   "or `pip uninstall locust` here", err=True)
        sys.exit(2)
    from ..fileio import unwind_on_termination

    unwind_on_termination()   # a kill (TERM) unwinds: no temporary file is left behind
    cli(prog_name="locust")
