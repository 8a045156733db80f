"""``locust calibrate beam|servo|ramp``: recordings in, fitted values (and robot.toml) out."""

from __future__ import annotations

import contextlib
import functools
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import click

from ..calibrate import hinge as HG
from ..calibrate import hop as H
from ..calibrate import inputs
from ..calibrate import ramp as R
from ..calibrate import servo as S
from ..calibrate.fitstats import Estimate
from ..calibrate.plots import plot_fit
from ..calibrate.write import DEFAULT_ROBOT_TOML, check_plausible, implausible, write_fitted
from ..errors import CalibrationError
from ..fileio import check_distinct, json_text, make_folder
from ..io.importing import ImportOptions
from ..io.robot_toml import default_robot, resolve_robot
from ..params import PRESETS
from ..plotting import check_figure_path
from ..progress import format_duration, progress
from ..tables import estimate_line, value_line
from .options import FINITE, POSITIVE, import_options, time_options


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


@click.group()
def calibrate() -> None:
    """Identify the robot's physics from the Part 2 experiments.

    \b
    beam   cardstock cantilever, dropped tip mass  -> hinge stiffness, damping
    hinge  a link swinging on a flexure hinge     -> hinge stiffness, damping (large angles)
    servo  servo steps: filmed angle, gyro on the horn -> no-load speed, armature, kp
    ramp   ramp tilted until the robot slides      -> static friction mu
    hop    filmed hops of one or more leg sets     -> any parameters, jointly

    Each prints the fitted values with 95% confidence intervals, draws a fit plot, and with
    --write updates robot.toml (only the fitted values, each with source fit:<file>, its
    uncertainty and the date). How to film each experiment: calibration/protocols/.
    """


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


def _window_option(value: str | None, option: str) -> tuple[float, float] | None:
    return tuple(inputs.parse_floats(value, 2, option, f"two times in s, e.g. {option} 0,1.5")) if value else None


@calibrate.command()
@click.argument("tracks", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--mass-kg", type=POSITIVE, required=True, help="Dropped tip mass [kg] (with --static: the tip load).")
@click.option("--marker", default=None, help="Marker of the beam tip in the track [default: the only one].")
@click.option("--length-m", type=POSITIVE, default=None,
              help="Free length of the beam, clamp to mass [m]; needed for the hinge values (k*L^2, b*L^2), "
                   "with --static for the bending stiffness E*I = k*L^3/3.")
@click.option("--beam-mass-kg", type=FINITE, default=0.0, show_default=True,
              help="The beam's own mass [kg]; 33/140 of it is added to the oscillating mass.")
@click.option("--start-s", type=FINITE, default=None,
              help="Fit from this time [default: the first swing after the drop].")
@click.option("--end-s", type=FINITE, default=None, help="Fit up to this time [default: end of the track].")
@click.option("--static", is_flag=True,
              help="A static deflection test, not a ring-down: the tip at rest, loaded, and settled; the "
                   "deflection from rest to settled, the stiffness m*g/deflection and (with --length-m) the "
                   "bending stiffness, each with a 95% interval. Nothing of it goes into robot.toml.")
@click.option("--rest-s", default=None, metavar="A,B",
              help="With --static: the rest window [s] [default: the start to where the loading begins].")
@click.option("--settled-s", default=None, metavar="A,B",
              help="With --static: the settled window [s] [default: where the loading ends to the end].")
@click.option("--scale-std-pct", type=FINITE, default=None, metavar="P",
              help="With --static: the scale's standard uncertainty [%] [default: a Tracker project's "
                   "calibration stick, its two ends placed to 0.25 px; else the scale taken as exact].")
@import_options
@time_options
@static_writes_nothing
@output_options
def beam(tracks, mass_kg, marker, length_m, beam_mass_kg, start_s, end_s, static, rest_s, settled_s, scale_std_pct,
         imports, timing, write_path, as_json, plot_path, no_plot, force):
    """Fit the beam tip's damped oscillation: stiffness, damping, and the model's hinge values.

    TRACKS is a `locust track` CSV, a Tracker project (.trk, .trz) or text export, or a
    t,x,y CSV of the beam tip (metres, or --units cm|mm). With --static, read the tip's
    static deflection under the load instead (the course's deflection test):

    \b
      locust calibrate beam Deflection_test.trk --static --mass-kg 0.095 --length-m 0.048
    """
    from ..api.calibration import calibrate_beam

    fit = calibrate_beam(tracks, mass_kg, length_m=length_m, beam_mass_kg=beam_mass_kg, marker=marker,
                         start_s=start_s, end_s=end_s, imports=imports, timing=timing, static=static,
                         rest_s=_window_option(rest_s, "--rest-s"), settled_s=_window_option(settled_s, "--settled-s"),
                         scale_std_pct=scale_std_pct)
    if static:
        notes = fit.result.notes()
        unwritten = click.get_current_context().meta.get(_STATIC_WRITE_KEY)
        if unwritten is not None:
            notes.append(f"nothing written to {unwritten}: no value of a robot file holds a cardstock beam's "
                         "stiffness (the model's links are rigid and its hinges are folds, whose stiffness "
                         "`locust calibrate hinge` measures: docs/servo.md, Hinges and links)")
        _finish(fit.result, tracks, {}, fit.note, None, as_json, plot_path, no_plot, force, subtitle=fit.subtitle,
                warnings=fit.warnings, input_note=fit.input_note, extra={"notes": notes})
        return
    if not fit.parameters and write_path:
        raise CalibrationError("--write needs --length-m: the hinge values are k*L^2 and b*L^2",
                               "measure the beam's free length from the clamp to the mass")
    _finish(fit.result, tracks, fit.parameters, fit.note, write_path, as_json, plot_path, no_plot, force,
            subtitle=fit.subtitle, warnings=fit.warnings, input_note=fit.input_note)


@calibrate.command()
@click.argument("tracks", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--inertia-kgm2", type=POSITIVE, required=True,
              help="The swinging link's moment of inertia about the hinge axis [kg*m^2], marker included "
                   "(calibration/protocols/hinge.md: a bar of mass m and length L hinged at one end: m*L^2/3).")
@click.option("--gravity", type=click.Choice(HG.GRAVITY_CHOICES), required=True,
              help="in-plane: the link swings in a vertical plane (its weight pulls it down, -M*g*D*cos(angle), "
                   "straight down being the track's -y); out-of-plane: the hinge axis is vertical (no moment).")
@click.option("--mass-kg", type=POSITIVE, default=None, help="With --gravity in-plane: the swinging link's mass [kg].")
@click.option("--com-m", type=POSITIVE, default=None,
              help="With --gravity in-plane: hinge to the link's centre of mass [m], taken on the line from the "
                   "hinge to the marker.")
@click.option("--pivot", default=None, metavar="X,Y",
              help="The hinge's position in the track [m, after --units], held fixed [default: fitted with the "
                   "swing, from the centre of the circle through the marker's arc].")
@click.option("--marker", default=None, help="Marker on the swinging link [default: the only one].")
@click.option("--start-s", type=FINITE, default=None,
              help="Fit from this time [s] [default: the first turning point after the release, the end of "
                   "the first free swing].")
@click.option("--end-s", type=FINITE, default=None, help="Fit up to this time [s] [default: end of the track].")
@click.option("--coulomb", type=click.Choice(["auto", "off", "on"]), default="auto", show_default=True,
              help="Coulomb friction torque [N*m]: auto fits it only when the swing shows it (score test "
                   "p < 0.001, and its 95% interval excludes zero).")
@import_options
@time_options
@output_options
def hinge(tracks, inertia_kgm2, gravity, mass_kg, com_m, pivot, marker, start_s, end_s, coulomb, imports, timing,
          write_path, as_json, plot_path, no_plot, force):
    """Fit a link's free swing on a flexure hinge: stiffness, damping, neutral angle.

    TRACKS is a track of one marker on the swinging link: a Tracker project (.trk, .trz;
    its own calibration gives metres), a Tracker text export (a title line such as mass_A
    accepted), a `locust track` CSV or a t,x,y CSV (--units for cm or mm). The angle about
    the hinge is taken from the marker's x, y, at any size of swing; the model is
    I*theta'' = -k*(theta - theta0) - b*theta' [- M*g*D*cos(theta)] [- tau_c*sign(theta')].
    Prints k [N*m/rad], b [N*m*s/rad] with 95% intervals, the RMS residual of the marker
    position [m]; --write sets compliance.hinge_stiffness_nm_per_rad and
    compliance.hinge_damping_nms_per_rad, those the swing determines (a value NOT
    IDENTIFIABLE, or any where the model does not follow the swing, is never written). With
    --gravity in-plane, --inertia-kgm2 is at least --mass-kg x --com-m^2.

    \b
    Example (the course's film hinge, the link clamped with its hinge axis vertical):
      locust calibrate hinge Damping_test.trk --inertia-kgm2 8.5e-7 --gravity out-of-plane
    """
    from ..api.calibration import calibrate_hinge

    centre = tuple(inputs.parse_floats(pivot, 2, "--pivot", "X,Y in metres, e.g. --pivot 0.0,0.0")) if pivot else None
    with (progress(label=HINGE_LABEL.format(stage="reading")) as bar,
          interruptible("the hinge fit", "run it again; a long recording fits sooner in a window of it "
                                         "(--start-s, --end-s)")):
        def told(stage: str, evaluations: int) -> None:
            bar.label = HINGE_LABEL.format(stage=stage)
            bar.update(evaluations - bar.pos)

        fit = calibrate_hinge(tracks, inertia_kgm2, gravity, mass_kg=mass_kg, com_m=com_m, pivot=centre,
                              marker=marker, start_s=start_s, end_s=end_s, coulomb=coulomb, imports=imports,
                              timing=timing, progress=told)
    _finish(fit.result, tracks, fit.parameters, fit.note, write_path, as_json, plot_path, no_plot, force,
            subtitle=fit.subtitle, input_note=fit.input_note)


HINGE_LABEL = "fitting hinge swing ({stage}): evaluations of the swing"


@contextlib.contextmanager
def interruptible(what: str, hint: str = "run it again") -> Iterator[None]:
    """Ctrl-C during a fit: one clear error (exit 2) saying nothing was written, not click's
    bare ``Aborted!``."""
    started = time.monotonic()
    try:
        yield
    except KeyboardInterrupt:
        raise CalibrationError(f"interrupted: {what} stopped after {format_duration(time.monotonic() - started)}; "
                               "nothing was fitted or written", hint) from None


@calibrate.command()
@click.argument("data", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--inertia-kgm2", type=POSITIVE, multiple=True, required=True,
              help="Load inertia about the servo axis [kg*m^2]; once, or once per DATA in the same order.")
@click.option("--stall-torque-nm", type=POSITIVE, default=None,
              help="Stall torque [N*m] from a stall test or the datasheet (SG90: about 0.15). It splits the "
                   "ratios one load gives; leave it out when DATA holds loads of very different inertia (beside the "
                   "armature: a few 1e-4 kg*m^2 for an SG90) or a load held against gravity.")
@click.option("--kv-nms-per-rad", type=FINITE, default=0.0, show_default=True,
              help="Velocity feedback inside the drive's clamp [N*m*s/rad], held at this value: the SG90's real "
                   "recordings do not ask for it (docs/servo.md).")
@click.option("--fit-kv", is_flag=True,
              help="Fit kv too (steps of several sizes, as a gyro log holds, are needed to tell it from kp).")
@click.option("--gravity-moment-nm", type=FINITE, multiple=True,
              help="Moment of the load's weight with the horn horizontal (angle 0) [N*m]; once, or once per DATA "
                   "[default: 0, a horizontal rig].")
@click.option("--pivot", default=None, metavar="X,Y",
              help="Servo axis in the track's coordinates [m]: DATA is then a track of the horn tip.")
@click.option("--step", "step", default=None, metavar="FROM,TO,AT_S",
              help="With --pivot: the commanded step, degrees from the horizontal, and when it was sent [s].")
@click.option("--marker", default=None, help="With --pivot: marker of the horn tip [default: the only one].")
@click.option("--validate", "validate", multiple=True, type=click.Path(dir_okay=False, path_type=Path),
              help="A recording not fitted (repeatable): predict it with the fitted servo, report its RMS and "
                   "each step's peak speed, measured and predicted, and draw it.")
@click.option("--validate-inertia-kgm2", type=POSITIVE, multiple=True,
              help="Load inertia of the --validate recordings; once, or once per --validate [default: that of "
                   "the first fitted recording of the same kind].")
@import_options
@time_options
@output_options
def servo(data, inertia_kgm2, stall_torque_nm, kv_nms_per_rad, fit_kv, gravity_moment_nm, pivot, step, marker, validate,
          validate_inertia_kgm2, imports, timing, write_path, as_json, plot_path, no_plot, force):
    """Identify the hobby servo (no-load speed, armature, kp; kv with --fit-kv) from step responses.

    Each DATA is one of two kinds, told apart by its layout:

    \b
    angle  a CSV with a header t_s,angle_deg,command_deg (degrees from the horizontal;
           a square-wave command's steps are fitted together), or with --pivot and
           --step a track of the horn tip;
    rate   a gyro log on the horn: rows millis,command_deg,gyro with no header (the
           controller's clock in ms, the command, the gyro in its own unit). The gyro's
           gain [units per rad/s] is fitted; between steps the horn must rest.

    Recordings of both kinds, each with its own --inertia-kgm2, are fitted together to one
    servo. The rig is simulated in MuJoCo with the robot model's servo (docs/servo.md); the
    timing of each recording (a delay and, for an angle recording of three or more command
    edges, the ratio of camera and firmware clocks) is fitted beside it and reported.
    Parameters the recordings cannot determine are reported as not identifiable and never
    written. --validate predicts other recordings with the fitted servo (their own delay,
    and the fitted gyro gain, are the only things fitted to them).

    \b
    Examples (real SG90s: an AA battery swung 0 <-> 180 deg; a gyro on an unloaded horn):
      locust calibrate servo sg90_aa_battery_step.csv --inertia-kgm2 3.3e-6 --stall-torque-nm 0.15
      locust calibrate servo sg90_aa_battery_step.csv sg90_unloaded_gyro_steps.txt \\
          --inertia-kgm2 3.3e-6 --inertia-kgm2 1e-6 --stall-torque-nm 0.15 --validate other_steps.txt
    """
    inertias = inputs.per_recording(inertia_kgm2, len(data), "--inertia-kgm2")
    moments = inputs.per_recording(gravity_moment_nm or (0.0,), len(data), "--gravity-moment-nm")
    if pivot is not None and len(data) > 1:
        raise CalibrationError("--pivot takes one horn track", "fit tracks one at a time, or give angle CSVs")
    recordings = [inputs.servo_recording(path, S.ServoRig(inertia, moment), pivot, step, marker, imports, timing)
                  for path, inertia, moment in zip(data, inertias, moments)]
    if pivot is None and not imports.identity:
        raise CalibrationError("--units, --rename and --mirror apply to a horn track (--pivot), not to angles",
                               "leave them out for t_s,angle_deg,command_deg recordings and gyro logs")
    from ..api.calibration import fit_servo_recordings

    with (progress(length=S.progress_steps(len(recordings)), label="fitting servo") as bar,
          interruptible("the servo fit")):
        facade_fit = fit_servo_recordings(recordings, stall_torque_nm, kv_nms_per_rad=kv_nms_per_rad, fit_kv=fit_kv,
                                          progress=bar.update)
    fit = facade_fit.result
    validations = []
    if validate:
        v_inertias = inputs.per_recording(validate_inertia_kgm2, len(validate), "--validate-inertia-kgm2") \
            if validate_inertia_kgm2 else [None] * len(validate)
        for path, inertia in zip(validate, v_inertias):
            rec = inputs.servo_recording(path, S.ServoRig(inertias[0]), None, None, None, ImportOptions(), timing)
            if inertia is None:
                inertia = next((r.rig.inertia_kgm2 for r in recordings if r.kind == rec.kind), inertias[0])
            rec = replace(rec, rig=S.ServoRig(inertia))
            validations.append(S.validate(fit.servo, rec, gain=fit.rate_gain))
    values, note = facade_fit.parameters, facade_fit.note
    extra = {}
    if validations:
        extra["validation"] = [v.summary() for v in validations]
        if not no_plot:
            target = plot_path.with_name(plot_path.stem + "-validate.png") if plot_path else \
                default_plot_path(validate[0], "servo").with_name(f"{validate[0].stem}-validate.png")
            extra["validation_plot"] = str(plot_fit([v.curves for v in validations], target,
                                                    "predicted by the fitted servo (not fitted to it)", force))
    _finish(fit, data[0], values, note, write_path, as_json, plot_path, no_plot, force,
            subtitle=facade_fit.subtitle, source_name=Path(fit.source).name, extra=extra)


@calibrate.command()
@click.argument("data", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--ramp-markers", default="ramp_a,ramp_b", show_default=True, metavar="A,B",
              help="For a ramp video track: markers at the two ends of the board.")
@click.option("--robot-marker", default="robot", show_default=True, help="For a ramp video track: the robot's marker.")
@click.option("--into", type=click.Choice(["foot", "nose"]), default="foot", show_default=True,
              help="Which friction the result is written to (contact.foot_friction or contact.nose_friction).")
@click.option("--resolution-deg", type=POSITIVE, default=R.READING_RESOLUTION_DEG, show_default=True,
              help="How finely each angle was read [deg] (a protractor's graduation); the trials' spread is "
                   "taken as at least resolution/sqrt(12), so trials read alike give an interval, not a point.")
@import_options
@time_options
@output_options
def ramp(data, ramp_markers, robot_marker, into, resolution_deg, imports, timing, write_path, as_json, plot_path,
         no_plot, force):
    """Static friction from critical ramp angles: mu = tan(mean angle), with a 95% interval.

    DATA: CSVs with an angle_deg column (one trial a row, degrees), and/or side-view
    tracks of a tilting ramp (one trial each; --units, --rename, --mirror act on them).
    """
    from ..api.calibration import calibrate_ramp

    fit = calibrate_ramp(list(data), into=into, ramp_markers=ramp_markers, robot_marker=robot_marker,
                         imports=imports, timing=timing, resolution_deg=resolution_deg)
    _finish(fit.result, data[0], fit.parameters, fit.note, write_path, as_json, plot_path, no_plot, force,
            subtitle=fit.subtitle, recording_name=Path(fit.source), several=len(data) > 1,
            source_name=Path(fit.source).name, warnings=fit.warnings)


@calibrate.command()
@click.argument("runs", nargs=-1, required=True)
@click.option("--fit", "fit_keys", default=",".join(H.DEFAULT_KEYS), show_default=True, metavar="KEY[,KEY...]",
              help="Robot parameters to fit, shared by every run (any real-valued key of `locust params`).")
@click.option("--config", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Robot to start from, the values every run shares [default: the --write file if it exists, "
                   "else the robot the runs' run.json record; runs on different robots are refused].")
@click.option("--set", "sets", multiple=True, metavar="KEY=VALUE", help="Override a starting value (repeatable).")
@click.option("--max-iter", type=click.IntRange(1, 200), default=30, show_default=True, help="Solver iterations.")
@click.option("--json", "as_json", is_flag=True, help="Print the results as JSON.")
@click.option("--no-plot", is_flag=True, help="Do not draw the fit plots.")
@functools.partial(out_option, what="<run>-hops-fit.png")
@functools.partial(write_option, help_text="Update this robot.toml with the identifiable fitted values only, "
                                           "source fit:hops.")
def hop(runs, fit_keys, config, sets, max_iter, as_json, no_plot, out_dir, write_path):
    """Fit the model to filmed hops: friction, hinge stiffness, servo speed on the robot.

    Each RUN is a `locust hop --out` folder holding its run.json and the track of its video
    (`locust track`), as NAME=FOLDER or a folder named after its leg set (small-1/, large/).
    Runs of different leg sets are fitted together: their geometry differs, the fitted
    physics is shared. The firmware's measured phase times drive each simulation; the
    tracked nose and foot are compared with the simulated markers, both aligned on the first
    push. Prints each value with its 95% interval and the RMS residual per run, and draws
    <run>-hops-fit.png in --out (tracked against the fitted simulation).

    \b
    Example:
      locust calibrate hop small=runs/s1 large=runs/l1 --write calibration/robot.toml
    """
    from ..api.calibration import calibrate_hops

    keys = [k.strip() for k in fit_keys.split(",") if k.strip()]
    H.check_fittable(keys)
    write_path = write_target(write_path)
    start_from = config or (write_path if write_path and Path(write_path).exists() else None)
    if start_from is not None:
        base = resolve_robot(None, start_from, sets)
        click.echo(f"robot: {start_from}" + (" (the --write file)" if start_from != config else ""), err=True)
    else:        # the robot the runs were hopped on, as their records say
        from ..api.calibration import robot_of_runs
        from ..params import check_robot, parse_set_options

        base, said = robot_of_runs(list(runs))
        overrides = parse_set_options(sets)
        base = check_robot(base.with_values(overrides, "override") if overrides else base)
        new = write_path is not None and not Path(write_path).exists()
        click.echo(said + (f"; the new {write_path} starts from it" if new else ""), err=True)
    folder = out_folder(out_dir, None, no_plot, as_json)
    with progress(label="fitting hops: simulations") as bar, interruptible("the hop fit"):
        def done(n: int, planned: int) -> None:
            bar.length = planned
            bar.update(n - bar.pos)

        facade_fit = calibrate_hops(base, list(runs), keys, max_iter=max_iter, progress=done)
    fit = facade_fit.result
    out = fit.summary()
    if not no_plot:
        out["plots"] = []
        for run in fit.runs:
            if run.curves:
                plot = make_folder(folder) / f"{Path(run.source).name}-hops-fit.png"
                out["plots"].append(str(H.plot_run(run, plot, f"RMS {1000 * run.rms_m:.2f} mm")))
    if write_path:
        values = facade_fit.parameters
        if values:
            write_fitted(write_path, values, H.PROVENANCE_NAME, note=facade_fit.note, start=base)
        out["written"] = {"path": str(Path(write_path).resolve()), "keys": list(values)}
    if as_json:
        click.echo(json_text(out), nl=False)
        return
    click.echo(f"# hops: {len(fit.runs)} runs, {fit.simulations} simulations, {fit.wall_s:.1f} s")
    click.echo(f"# 95% intervals: {fit.interval}")
    for key, val in out["parameters"].items():
        _print_text_value(key, val)
    for run in fit.runs:
        click.echo(f"{run.config:8s} {run.source}: RMS residual {1000 * run.rms_m:.3f} mm")
    for note in fit.notes:
        click.echo(f"note: {note}")
    for plot in out.get("plots", []):
        click.echo(f"plot: {plot}")
    if "written" in out:
        keys = out["written"]["keys"]
        click.echo(f"wrote {', '.join(keys)} to {out['written']['path']}" if keys
                   else f"nothing written to {out['written']['path']}: no value was identifiable")


def default_plot_path(recording: Path | None, experiment: str) -> Path:
    """``<recording>-<experiment>-fit.png`` (``<experiment>-fit.png`` for several recordings) in
    the command's output folder (:func:`out_folder`), never beside the recording (a data
    folder, maybe someone else's): each experiment's own name, so a beam fit and a hinge fit of
    one recording keep both plots."""
    folder = make_folder(click.get_current_context().meta.get(_OUT_KEY, Path(".")))
    return folder / (f"{Path(recording).stem}-{experiment}-fit.png" if recording is not None
                     else f"{experiment}-fit.png")


def _finish(fit, recording: Path, values: dict[str, Estimate], note: str, write_path: Path | None,
            as_json: bool, plot_path: Path | None, no_plot: bool, force: bool, *, subtitle: str,
            recording_name: Path | None = None, several: bool = False, source_name: str | None = None,
            warnings: list[str] | None = None, extra: dict | None = None, input_note: str = "") -> None:
    recording_name = recording_name or recording
    out = {**fit.summary(), **(extra or {})}
    if input_note:
        out["input"] = input_note
    odd = implausible(values)
    out["warnings"] = list(warnings or []) + odd
    for warning in out["warnings"]:
        click.echo(f"warning: {warning}", err=True)
    if not no_plot:
        plot_path = plot_path or default_plot_path(None if several else recording_name, out["experiment"])
        out["plot"] = str(plot_fit(fit.curves, plot_path, subtitle, force))
    if write_path and odd:   # show the fit, then refuse to write it
        if as_json:
            click.echo(json_text(out), nl=False)
        else:
            _print_text(out)
        check_plausible(values)
    if write_path:
        if values:
            write_fitted(write_path, values, source_name or recording.name, note=note,
                         start=click.get_current_context().meta.get(_START_KEY))
        out["written"] = {"path": str(Path(write_path).resolve()), "keys": list(values)}
    if as_json:
        click.echo(json_text(out), nl=False)
        return
    _print_text(out)


HINGE_MODEL_ERROR_M = 0.0002   # hinge residual beyond ~3x a video's tracking noise: model error (docs/calibrate.md)


def _print_text(out: dict) -> None:
    click.echo(f"# {out['experiment']}: {out['source']}")
    click.echo(f"{'':28s} {'value':>10s}  {'unit':10s} ± 1 sd    (95 % interval)")
    narrow = ""
    if out["experiment"] == "hinge" and (out.get("rms_residual_m") or 0) > HINGE_MODEL_ERROR_M:
        narrow = (f"   TOO NARROW: the residual ({1000 * out['rms_residual_m']:.2f} mm RMS) is model error, "
                  "not tracking noise (docs/calibrate.md, Hinge)")
    for key, val in out.items():
        if key in ("experiment", "source", "notes", "warnings", "written", "plot", "angles_deg", "validation",
                   "validation_plot", "gyro_gain_units_per_rad_per_s"):
            continue
        if isinstance(val, dict) and "value" in val:
            _print_text_value(key, val, narrow if key.startswith("hinge_") and val.get("identifiable", True) else "")
        elif val is not None:
            click.echo(value_line(key, val))
    for k, gain in enumerate(out.get("gyro_gain_units_per_rad_per_s") or []):
        if gain is not None:
            _print_text_value(f"gyro_gain_units_per_rad_per_s[{k}]", gain)
    for note in out.get("notes", []):
        click.echo(f"note: {note}")
    if "plot" in out:
        click.echo(f"plot: {out['plot']}")
    for v in out.get("validation", []):
        click.echo(f"# validation: {v['source']}: RMS {v['rms']:.3g} {v['rms_unit']} (not fitted to it)")
        click.echo(f"{'step_deg':>10s} {'peak measured':>15s} {'peak predicted':>15s} {'error':>8s}  [rad/s]")
        for st in v["steps"]:
            click.echo(f"{st['step_deg']:10.4g} {st['peak_speed_measured_rad_per_s']:15.3f} "
                       f"{st['peak_speed_predicted_rad_per_s']:15.3f} {100 * st['error']:+7.1f}%")
    if "validation_plot" in out:
        click.echo(f"plot: {out['validation_plot']}")
    if "written" in out:
        keys = out["written"]["keys"]
        click.echo(f"wrote {', '.join(keys)} to {out['written']['path']}" if keys
                   else f"nothing written to {out['written']['path']}: no value was identifiable")


def _print_text_value(key: str, val: dict, note: str = "") -> None:
    flag = "" if val.get("identifiable", True) else "   NOT IDENTIFIABLE"
    if val.get("given"):
        click.echo(value_line(key, val["value"]) + "  (given)")
    else:
        click.echo(estimate_line(key, val["value"], val["std"], val.get("ci95"), flag + note))
