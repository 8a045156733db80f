"""The options every ``locust calibrate`` experiment shares: where its outputs go (``--write``,
``--out``, ``--plot``, ``--json``), checked before anything is read, and the robot a new
``--write`` file starts from, named on the first line."""

from __future__ import annotations

import functools
from pathlib import Path

import click

from ...calibrate.inputs import parse_floats
from ...calibrate.write import DEFAULT_ROBOT_TOML
from ...errors import CalibrationError
from ...fileio import check_distinct
from ...io.robot_toml import default_robot, resolve_robot
from ...params import PRESETS
from ...plotting import check_figure_path


def output_options(func):
    """--write [PATH], --json, --out DIR, --plot PATH / --no-plot, --force: shared by the
    experiments. Before anything is read or fitted, the outputs are checked: each its own file,
    none an input (TRACKS, DATA, --validate), the plot an image path that replaces no user file."""

    command = func

    @functools.wraps(command)
    def wrapper(*args, preset, config, **kwargs):
        kwargs["write_path"] = write_target(kwargs["write_path"])
        start_robot(kwargs["write_path"], preset, config)
        inputs = [p for name in ("tracks", "data", "validate") for p in _paths(kwargs.get(name))]
        plot = None if kwargs["no_plot"] else kwargs["plot_path"]
        check_distinct({"--plot": plot, "--write": kwargs["write_path"]}, inputs)
        if plot is not None:
            check_figure_path(plot, kwargs["force"])
        out_folder(kwargs.pop("out_dir"), plot.parent if plot is not None else None, kwargs["no_plot"],
                   kwargs["as_json"])
        return command(*args, **kwargs)

    func = wrapper
    func = click.option("--force", is_flag=True,
                        help="Replace an existing file at --plot that is not a figure this toolkit wrote.")(func)
    func = click.option("--no-plot", is_flag=True, help="Do not draw the fit plot.")(func)
    func = click.option("--plot", "plot_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help="Fit plot (data, model, residuals; .png, .svg or .pdf) [default: "
                             "<recording>-<experiment>-fit.png in --out]. An existing file is replaced only "
                             "when it is a figure this toolkit wrote.")(func)
    func = out_option(func, "<recording>-<experiment>-fit.png")
    func = click.option("--json", "as_json", is_flag=True, help="Print the results as JSON.")(func)
    func = write_option(func, "Update this robot.toml with the fitted values only. Other values are kept; a new "
                              "file starts from the robot --config or --preset names, else the one every command "
                              "runs on (calibration/robot.toml here, else the robot as built), named on the first "
                              "line.")
    func = click.option("--config", type=click.Path(dir_okay=False, path_type=Path), default=None,
                        help="With --write to a new file: the robot.toml it starts from.")(func)
    func = click.option("--preset", type=click.Choice(list(PRESETS)), default=None,
                        help="With --write to a new file: the preset it starts from.")(func)
    return func


_START_KEY = "locust.calibrate.start"


def start_robot(write_path: Path | None, preset: str | None, config: Path | None) -> None:
    """The robot ``--write`` changes, said on the first line (stderr): the --write file when
    it exists, else the robot a new one starts from (--config, --preset, else the one rule of
    :func:`locust.io.robot_toml.default_robot`), kept for :func:`_finish`."""
    if write_path is None:
        if preset is not None or config is not None:
            raise CalibrationError("--preset and --config name the robot a new --write file starts from",
                                   "add --write NEW.toml, or leave them out")
        return
    if Path(write_path).exists():
        if preset is not None or config is not None:
            raise CalibrationError(f"{write_path} exists: --write updates it, and --preset/--config would not be "
                                   "used", "leave them out, or --write a new file")
        click.echo(f"robot: {write_path} (the --write file, updated)", err=True)
        return
    robot = resolve_robot(preset, config, ())
    if config is not None:
        line = f"robot: {config}"
    elif preset is not None:
        line = f"robot: {preset}"
    else:
        line = default_robot().line
    click.echo(f"{line}; the new {write_path} starts from it", err=True)
    click.get_current_context().meta[_START_KEY] = robot


def write_option(func, help_text: str):
    """``--write [PATH]``: bare, ``calibration/robot.toml`` under the current folder (see :func:`write_target`)."""
    return click.option("--write", "write_path", type=click.Path(dir_okay=False, path_type=Path),
                        is_flag=False, flag_value=_BARE_WRITE, default=None,
                        help=f"{help_text} [bare --write: {DEFAULT_ROBOT_TOML} in the current folder, which "
                             "must hold a calibration/ folder].")(func)


def out_option(func, what: str):
    """``--out DIR``: the one folder the fit plots go to, named on the first line (stderr)."""
    return click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path), default=None,
                        help=f"Folder for the fit plots ({what}), made if missing; named on the first line "
                             "[default: the current folder; never the recordings' folder].")(func)


_OUT_KEY = "locust.calibrate.out"


def out_folder(out_dir: Path | None, plot_folder: Path | None, no_plot: bool, as_json: bool) -> Path | None:
    """The folder the command's plots go to (--plot's, else --out, else the current folder), named
    on stderr as the first line (with --json the JSON names each plot instead), made when the
    first plot is drawn; None with --no-plot."""
    if no_plot:
        return None
    folder = plot_folder if plot_folder is not None else (out_dir or Path("."))
    click.get_current_context().meta[_OUT_KEY] = folder
    if not as_json:
        click.echo(f"output folder: {folder.resolve()}", err=True)
    return folder


_BARE_WRITE = ":bare --write:"


def write_target(write_path: Path | None) -> Path | None:
    """The file ``--write`` updates: a bare ``--write`` is ``calibration/robot.toml`` under the
    current folder, refused when that folder has no ``calibration/`` (a run from elsewhere
    would make one there unasked); a path given is used as given."""
    if write_path is None or str(write_path) != _BARE_WRITE:
        return write_path
    target = Path.cwd() / DEFAULT_ROBOT_TOML
    if not target.parent.is_dir():
        raise CalibrationError(f"a bare --write writes {target}, and {target.parent} does not exist",
                               f"give the file: --write PATH (e.g. --write robot.toml), or run from the folder "
                               f"that holds {DEFAULT_ROBOT_TOML.parent}/")
    return target


def _paths(value) -> list[Path]:
    if value is None:
        return []
    return [Path(v) for v in value] if isinstance(value, (tuple, list)) else [Path(value)]


_STATIC_WRITE_KEY = "locust.calibrate.static_write"


def static_writes_nothing(func):
    """``beam --static --write``: robot.toml holds no value a cardstock beam's bending gives (the
    model's links are rigid, its hinges are folds: docs/servo.md, "Hinges and links"), so the
    write is taken out before the robot line that would name a file to update, and the
    command says at its end that nothing was written."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        if kwargs.get("static") and kwargs.get("write_path") is not None:
            given = kwargs["write_path"]
            click.get_current_context().meta[_STATIC_WRITE_KEY] = DEFAULT_ROBOT_TOML if str(given) == _BARE_WRITE \
                else given
            kwargs["write_path"] = None
        return func(*args, **kwargs)

    return wrapper


def unwritten_static() -> Path | None:
    """The ``--write`` file ``beam --static`` took out (:func:`static_writes_nothing`); None without one."""
    return click.get_current_context().meta.get(_STATIC_WRITE_KEY)


def start_of_write():
    """The robot a new ``--write`` file starts from (:func:`start_robot`); None for an existing file."""
    return click.get_current_context().meta.get(_START_KEY)


def plot_folder() -> Path:
    """The folder the command's plots go to (:func:`out_folder`), the current one by default."""
    return click.get_current_context().meta.get(_OUT_KEY, Path("."))


def window_option(value: str | None, option: str) -> tuple[float, float] | None:
    """``--rest-s A,B`` and the like: two times [s], or None when not given."""
    return tuple(parse_floats(value, 2, option, f"two times in s, e.g. {option} 0,1.5")) if value else None

