"""Each calibration as one job: its recordings read, fitted, and returned as a
:class:`~.result.Fit` (the robot values the recordings determine, each under its robot key).
``locust calibrate beam|hinge|ramp|fold|hop`` and ``locust.calibrate_beam/hinge/ramp/fold/hops`` both run
these, so the command line and the API cannot drift apart; :mod:`locust.api.calibration`
documents every option.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from ..arucoboard import DEFAULT_BOARD
from ..errors import CalibrationError
from ..io.importing import AS_IS, ImportOptions
from ..params import Robot
from . import beam as beam_fit
from . import beam_static as static_fit
from . import hinge as hinge_fit
from . import ramp as ramp_fit
from .hingeswing import HingeRig, check_rig
from .inputs import ramp_angles
from .recordings import REAL_TIME, TimeOptions, clean_samples, read_table
from .result import Fit, identified

PathLike = str | Path


def beam(tracks: PathLike, mass_kg: float, *, length_m: float | None = None, beam_mass_kg: float = 0.0,
         marker: str | None = None, start_s: float | None = None, end_s: float | None = None,
         imports: ImportOptions = AS_IS, timing: TimeOptions = REAL_TIME, static: bool = False,
         rest_s: tuple[float, float] | None = None, settled_s: tuple[float, float] | None = None,
         scale_std_pct: float | None = None) -> Fit:
    """A cantilever's ring-down after a tip mass is dropped on it (with ``static``: its static
    deflection under the mass), read from a track of the tip and fitted.

    Parameters
    ----------
    tracks : path-like
        A track of the beam tip.
    mass_kg : float
        The tip mass [kg].
    length_m, beam_mass_kg, marker, start_s, end_s, static, rest_s, settled_s, scale_std_pct
        As :func:`locust.api.calibration.calibrate_beam` takes them.
    imports : locust.io.importing.ImportOptions
        How the track is read (``--units``, ``--rename``, ``--mirror``).
    timing : locust.calibrate.recordings.TimeOptions
        A slow-motion recording's time scale.

    Returns
    -------
    Fit
        ``compliance.hinge_stiffness_nm_per_rad`` and ``compliance.hinge_damping_nms_per_rad``
        with ``length_m``; none with ``static``.
    """
    _check_beam_options(static, beam_mass_kg, start_s, end_s, rest_s, settled_s, scale_std_pct)
    table = read_table(tracks, imports, timing)
    x, y = table.marker(marker)
    if static:
        return _static_beam(tracks, table, x, y, mass_kg, length_m, rest_s, settled_s, scale_std_pct)
    t, x, y = clean_samples(tracks, "the beam tip", table.time_s(), x, y, min_samples=beam_fit.MIN_SAMPLES)
    displacement = beam_fit.principal_displacement(x, y)
    warning = beam_fit.tip_swing_warning(float(np.ptp(displacement)), length_m, imports.units, source=str(tracks))
    fit = beam_fit.fit_beam(t, displacement, mass_kg, length_m=length_m, beam_mass_kg=beam_mass_kg,
                            start_s=start_s, end_s=end_s, source=str(tracks))
    return Fit("beam", str(tracks), identified(fit), fit,
               note=f"beam L={length_m} m, m={mass_kg} kg; {beam_fit.MAPPING}",
               subtitle=f"fn {fit.natural_frequency_hz.value:.4g} Hz, zeta {fit.damping_ratio.value:.3g}",
               warnings=[warning] if warning else [], input_note=table.input_note)


def _check_beam_options(static: bool, beam_mass_kg: float, start_s, end_s, rest_s, settled_s, scale_std_pct) -> None:
    """Each mode's options only: the ring-down's window and beam mass, or the static windows and scale."""
    if static:
        given = [name for name, v in (("--beam-mass-kg", beam_mass_kg or None), ("--start-s", start_s),
                                      ("--end-s", end_s)) if v is not None]
        if given:
            raise CalibrationError(f"{', '.join(given)}: the ring-down's, not a static deflection's",
                                   "with --static give --rest-s A,B and --settled-s A,B (or leave them out)")
    else:
        given = [name for name, v in (("--rest-s", rest_s), ("--settled-s", settled_s),
                                      ("--scale-std-pct", scale_std_pct)) if v is not None]
        if given:
            raise CalibrationError(f"{', '.join(given)}: a static deflection's (--static), not a ring-down's",
                                   "add --static for a tip loaded and left to settle, or leave them out")


def _static_beam(tracks: PathLike, table, x, y, mass_kg: float, length_m: float | None, rest_s, settled_s,
                 scale_std_pct: float | None) -> Fit:
    """``beam(static=True)``: the deflection, stiffness and bending stiffness."""
    from ..io.importing import is_project
    from ..io.trk import read_project

    t, x, y = clean_samples(tracks, "the beam tip", table.time_s(), x, y, min_samples=2 * static_fit.MIN_WINDOW)
    stick = read_project(tracks).stick if is_project(Path(tracks)) else None
    if scale_std_pct is not None:
        scale, scale_note = scale_std_pct / 100, f"{scale_std_pct:g} % (--scale-std-pct)"
    elif stick is not None:
        scale = static_fit.stick_scale_std(stick.length_px)
        scale_note = (f"{scale * 100:.2g} %, from Tracker's {stick.name!r} ({stick.length_px:.2f} px for "
                      f"{stick.length_m * 1000:g} mm), each end placed by hand to {static_fit.CLICK_SD_PX:g} px; its "
                      f"{stick.length_m * 1000:g} mm taken as exact (--scale-std-pct to say otherwise)")
    else:
        scale, scale_note = 0.0, "taken as exact: the track names no calibration stick (--scale-std-pct to give one)"
    fit = static_fit.fit_static_beam(t, x, y, mass_kg, scale_relative_std=scale, scale_note=scale_note,
                                     length_m=length_m, rest_s=rest_s, settled_s=settled_s, source=str(tracks))
    return Fit("static-beam", str(tracks), {}, fit,
               note=f"static beam L={length_m} m, m={mass_kg} kg; {static_fit.MAPPING}",
               subtitle=f"deflection {fit.deflection_m.value * 1000:.3f} mm, k {fit.stiffness_n_per_m.value:.4g} N/m",
               input_note=table.input_note)


def hinge(tracks: PathLike, inertia_kgm2: float, gravity: str, *, mass_kg: float | None = None,
          com_m: float | None = None, pivot: tuple[float, float] | None = None, marker: str | None = None,
          start_s: float | None = None, end_s: float | None = None, coulomb: str = "auto",
          imports: ImportOptions = AS_IS, timing: TimeOptions = REAL_TIME,
          progress: Callable[[str, int], None] | None = None) -> Fit:
    """A link's free swing on a flexure hinge, read from a track of one marker on it and fitted.

    Parameters
    ----------
    tracks : path-like
        A track of one marker on the swinging link.
    inertia_kgm2 : float
        The link's moment of inertia about the hinge [kg·m²].
    gravity : {"in-plane", "out-of-plane"}
        Whether the link's weight pulls it round.
    mass_kg, com_m, pivot, marker, start_s, end_s, coulomb, progress
        As :func:`locust.api.calibration.calibrate_hinge` takes them.
    imports : locust.io.importing.ImportOptions
        How the track is read.
    timing : locust.calibrate.recordings.TimeOptions
        A slow-motion recording's time scale.

    Returns
    -------
    Fit
        The hinge's stiffness and damping the swing determines.
    """
    if gravity == "out-of-plane" and (mass_kg or com_m):
        raise CalibrationError("--mass-kg and --com-m act with --gravity in-plane only",
                               "leave them out, or give --gravity in-plane if the link swings in a vertical plane")
    rig = HingeRig(inertia_kgm2, gravity, mass_kg or 0.0, com_m or 0.0)
    check_rig(rig)              # before the recording is read: an impossible rig is no fit's question
    table = read_table(tracks, imports, timing)
    x, y = table.marker(marker)
    t, x, y = clean_samples(tracks, "the link's marker", table.time_s(), x, y, min_samples=hinge_fit.MIN_SAMPLES)
    fit = hinge_fit.fit_hinge(t, x, y, rig, pivot=pivot, start_s=start_s, end_s=end_s, coulomb=coulomb,
                              source=str(tracks), progress=progress)
    note = (f"hinge swing, I={inertia_kgm2:g} kg*m^2, gravity {gravity}"
            + (f", M={mass_kg:g} kg, D={com_m:g} m" if gravity == "in-plane" else "")
            + f", pivot {fit.pivot_source}; Coulomb friction {fit.coulomb_note}")
    return Fit("hinge", str(tracks), identified(fit), fit, note=note,
               subtitle=(f"fn {fit.natural_frequency_hz:.4g} Hz, zeta {fit.damping_ratio:.3g}, "
                         f"RMS {1000 * fit.rms_residual_m:.3g} mm"),
               input_note=table.input_note)


def ramp(data: PathLike | Sequence[PathLike] | np.ndarray, *, into: str = "foot",
         ramp_markers: str = "ramp_a,ramp_b", robot_marker: str = "robot", imports: ImportOptions = AS_IS,
         timing: TimeOptions = REAL_TIME, resolution_deg: float = ramp_fit.READING_RESOLUTION_DEG) -> Fit:
    """Static friction from the angles at which the robot starts to slide down a tilted board.

    Parameters
    ----------
    data : path-like, list of them, or array of angles in degrees
        Angle tables, side-view tracks of a tilting ramp, or the angles themselves.
    into : {"foot", "nose"}
        Which friction the result is: ``contact.foot_friction`` or ``contact.nose_friction``.
    ramp_markers, robot_marker, resolution_deg
        As :func:`locust.api.calibration.calibrate_ramp` takes them.
    imports : locust.io.importing.ImportOptions
        How a track is read.
    timing : locust.calibrate.recordings.TimeOptions
        A filmed track's time scale.

    Returns
    -------
    Fit
        ``mu = tan(mean angle)`` under the friction's key, with its 95% interval.
    """
    if into not in ("foot", "nose"):
        raise CalibrationError(f"into={into!r}: not a friction of the model", "choose foot or nose")
    warnings: list[str] = []
    if isinstance(data, (str, Path)):
        data = [data]
    if len(data) and all(isinstance(p, (str, Path)) for p in data):
        paths, angles, tracks = [Path(p) for p in data], [], 0
        for path in paths:
            found, warning, is_track = ramp_angles(path, ramp_markers, robot_marker, imports, timing)
            angles.extend(found)
            warnings += [warning] if warning else []
            tracks += is_track
        if tracks == 0 and not imports.identity:
            raise CalibrationError("--units, --rename and --mirror apply to ramp tracks; these are angle tables",
                                   "leave them out for angle_deg recordings")
        source = str(paths[0]) if len(paths) == 1 else "+".join(p.name for p in paths)
    else:
        angles, source = [float(a) for a in np.asarray(data, dtype=float).ravel()], "ramp"
    key = f"contact.{into}_friction"
    fit = ramp_fit.fit_ramp(np.array(angles), source=source, resolution_deg=resolution_deg, key=key)
    mu = fit.estimates[key]
    return Fit("ramp", source, identified(fit), fit,
               note=f"ramp, {fit.n_trials} trials, mean angle {fit.mean_angle_deg:.4g} deg",
               subtitle=f"mu {mu.value:.4g} from {fit.n_trials} trials", warnings=warnings)


def fold(unloaded: PathLike, loaded: PathLike, fold: str, *, coin_arm_m: float, robot: Robot | None = None,
         coin: str | None = None, coin_mass_kg: float | None = None, side: str = "both",
         link_mass_kg: float | None = None, link_length_m: float | None = None, board: str = DEFAULT_BOARD) -> Fit:
    """A fold's static test: its photos unloaded and with a coin on, fitted (:mod:`.fold`).

    Parameters
    ----------
    unloaded, loaded : path-like
        A photo, a folder of photos or a clip of each state.
    fold : {"servo", "knee", "ankle", "loop"}
    coin_arm_m : float
        The coin's lever arm from the fold line [m].
    robot : locust.params.Robot, optional
        The robot whose fold it is; None: the one every door runs on
        (:func:`locust.io.robot_toml.resolve_robot`).
    coin, coin_mass_kg, side, link_mass_kg, link_length_m, board
        As :func:`locust.api.calibration.calibrate_fold` takes them.

    Returns
    -------
    Fit
        ``folds.<fold>_stiffness_nm_per_rad`` and ``folds.<fold>_rest_offset_deg`` (``left.``/``right.``
        for one side); ``.result`` the :class:`~.foldfit.FoldFit`.
    """
    from ..io.robot_toml import resolve_robot
    from .fold import fold_test

    robot = resolve_robot() if robot is None else robot
    fit = fold_test(unloaded, loaded, fold, robot, coin_arm_m=coin_arm_m, coin_name=coin, coin_mass_kg=coin_mass_kg,
                    side=side, link_mass_kg=link_mass_kg, link_length_m=link_length_m, board=board)
    k = fit.stiffness_nm_per_rad
    note = (f"fold test, {fold} fold ({side}), coin {fit.load.what} at {coin_arm_m * 1000:.1f} mm, link "
            f"{fit.link.what}; rest {fit.rest_deg.value:.2f} deg, assembled {fit.assembled_deg:.2f} deg")
    return Fit("fold", fit.source, identified(fit), fit, note=note,
               subtitle=f"k {k.value:.4g} N*m/rad, rest {fit.rest_deg.value:.2f} deg, deflection "
                        f"{fit.deflection_deg.value:.2f} deg", warnings=list(fit.warnings))


def hops(robot: Robot | None, runs: Mapping[str, PathLike] | Sequence[PathLike | object],
         keys: Sequence[str] | None = None, *, max_iter: int = 30,
         progress: Callable[[int, int], None] | None = None) -> Fit:
    """The model fitted to filmed hops of one or more leg sets at once (the physics is shared).

    Parameters
    ----------
    robot : locust.params.Robot or None
        The starting values; None: the robot the runs' run.json record (:func:`robot_of_runs`).
    runs : dict or list
        Leg set -> run folder, the command line's ``NAME=FOLDER`` or folders named after their
        leg set, or runs already loaded (:class:`locust.trials.measured.Trial`).
    keys, max_iter, progress
        As :func:`locust.api.calibration.calibrate_hops` takes them.

    Returns
    -------
    Fit
        The identifiable values; ``.result`` the :class:`~.hop.HopFit`.

    Raises
    ------
    locust.errors.CalibrationError
        A run given twice, or one that cannot be fitted.
    """
    from ..trials.measured import Trial
    from . import hop as hop_fit  # MuJoCo: imported by the one job that simulates
    from .hopruns import load_run

    keys = tuple(keys or hop_fit.DEFAULT_KEYS)
    if isinstance(runs, Mapping):
        runs = [f"{name}={path}" for name, path in runs.items()]
    named: list[tuple[Path, str]] = []
    for item in runs:
        if isinstance(item, Trial):
            continue
        path, leg_set = run_folder(str(item))
        if path.resolve() in (p.resolve() for p, _ in named):
            raise CalibrationError(f"{item}: the run {path} is given twice; each run counts once in the fit",
                                   "give each run folder once (a repeat is another filmed hop, another folder)")
        named.append((path, leg_set))
    if robot is None:
        robot, _ = robot_of_runs([f"{leg}={path}" for path, leg in named])
    folders = iter(named)
    loaded = [item if isinstance(item, Trial) else load_run(*next(folders), robot) for item in runs]
    fit = hop_fit.fit_hops(loaded, keys, max_iter=max_iter, progress=progress)
    note = "filmed hops " + ", ".join(f"{r.config}:{Path(r.source).name}" for r in fit.runs)
    return Fit("hops", hop_fit.PROVENANCE_NAME, identified(fit), fit, note=note,
               subtitle=f"{len(fit.runs)} runs, RMS {1000 * fit.rms_m:.2f} mm", warnings=[])


def hop_start(runs: Sequence[PathLike], config: PathLike | None = None, sets: Sequence[str] = (),
              write_path: PathLike | None = None) -> tuple[Robot, str]:
    """The robot a hop fit starts from, and the line saying which: ``config``, else the
    ``write_path`` file where it exists, else the robot the runs record (:func:`robot_of_runs`),
    with the ``KEY=VALUE`` overrides ``sets``.

    Parameters
    ----------
    runs : sequence of path-like
        The runs, as :func:`hops` takes them.
    config : path-like, optional
        A robot.toml to start from (``--config``).
    sets : sequence of str
        ``KEY=VALUE`` overrides (``--set``).
    write_path : path-like, optional
        The robot.toml the fit updates (``--write``).

    Returns
    -------
    robot : locust.params.Robot
    line : str
        Where it came from, as the command line prints it first.
    """
    from ..io.robot_toml import resolve_robot
    from ..params import check_robot, parse_set_options

    start_from = config or (write_path if write_path and Path(write_path).exists() else None)
    if start_from is not None:
        robot = resolve_robot(None, start_from, sets)
        return robot, f"robot: {start_from}" + (" (the --write file)" if start_from != config else "")
    robot, said = robot_of_runs(runs)          # the robot the runs were hopped on, as their records say
    overrides = parse_set_options(sets)
    robot = check_robot(robot.with_values(overrides, "override") if overrides else robot)
    new = write_path is not None and not Path(write_path).exists()
    return robot, said + (f"; the new {write_path} starts from it" if new else "")


def robot_of_runs(runs: Sequence[PathLike]) -> tuple[Robot, str]:
    """The robot the runs were hopped on, as their run.json files record it, and a line saying
    so (:func:`locust.api.calibration.robot_of_runs` documents the rule).

    Parameters
    ----------
    runs : sequence of path-like
        Run folders (or their ``run.json``), as ``NAME=FOLDER`` or plain.

    Returns
    -------
    robot : locust.params.Robot
        The recorded robot; ``small`` when no record says which.
    line : str
        Where the robot came from, as the command line prints it.

    Raises
    ------
    locust.errors.CalibrationError
        The runs record different robots, or a robot file that is not there.
    """
    from ..io.robot_toml import load_robot
    from ..io.run_record import RECORD_NAME, read_run_record
    from ..params import DEFAULT_PRESET, LEG_SETS, preset

    seen: dict[tuple[str, str], list[str]] = {}
    for item in runs:
        path, _ = run_folder(str(item))
        record = path / RECORD_NAME if path.is_dir() else path
        if not record.is_file():
            continue            # load_run says what is missing
        src = read_run_record(record).robot
        if src.robot_file:       # as given to `locust hop --config`
            key = ("file", src.robot_file)
        elif src.preset:
            # the leg-set presets are one robot, the robot as built, with different legs on it
            key = ("preset", DEFAULT_PRESET if src.preset in LEG_SETS else src.preset)
        else:
            continue            # an older record: it does not say
        seen.setdefault(key, []).append(str(path))
    if len(seen) > 1:
        said = "; ".join(f"{', '.join(paths)}: {kind} {name}" for (kind, name), paths in seen.items())
        raise CalibrationError(f"the runs record different robots ({said}): a fit shares their values",
                               "give --config ROBOT.toml (in the API: robot=) with the values the runs share, "
                               "or fit the runs of each robot apart")
    if not seen:
        return preset(DEFAULT_PRESET), (f"robot: {DEFAULT_PRESET}, the robot as built (the runs' run.json do not "
                                        "say which robot)")
    ((kind, name), paths), = seen.items()
    if kind == "file":
        if not Path(name).is_file():
            raise CalibrationError(f"the runs record robot file {name}, which is not there",
                                   "give --config with that robot.toml (or the values the runs shared)")
        return load_robot(name), f"robot: {name}, as the runs' run.json record"
    what = "the robot as built, each run's leg set on it" if name == DEFAULT_PRESET else f"preset {name}"
    return preset(name), f"robot: {name} ({what}), as the runs' run.json record"


def run_folder(item: str) -> tuple[Path, str]:
    """A run as the command line names it: ``NAME=FOLDER``, or a folder whose run.json names its
    leg set, else named after it (small-1/, large/).

    Parameters
    ----------
    item : str
        ``NAME=FOLDER`` or a folder.

    Returns
    -------
    path : pathlib.Path
        The run folder (or its run.json).
    leg_set : str
        Its leg set.
    """
    from ..trials.measured import config_of

    name, sep, rest = item.partition("=")
    if sep and name and "/" not in name and not Path(item).exists():
        return Path(rest), name
    path = Path(item)
    return path, config_of(path)[0]
