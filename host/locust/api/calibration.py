"""The calibrations as functions: recordings in, a :class:`Fit` out (values with intervals, a plot,
and the robot with them applied). Each runs the job ``locust calibrate`` runs
(:mod:`locust.calibrate.jobs`), with every option the command has."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from ..arucoboard import DEFAULT_BOARD
from ..bundled import bundled_recording
from ..calibrate import jobs
from ..calibrate.ramp import READING_RESOLUTION_DEG
from ..calibrate.recordings import REAL_TIME, TimeOptions
from ..calibrate.result import Fit
from ..io.importing import ImportOptions
from ..params import Robot

PathLike = str | Path


def _imports(imports: ImportOptions | None, units: str) -> ImportOptions:
    return imports if imports is not None else ImportOptions.parse(units)


def calibrate_beam(tracks: PathLike, mass_kg: float, *, length_m: float | None = None, beam_mass_kg: float = 0.0,
                   marker: str | None = None, start_s: float | None = None, end_s: float | None = None,
                   units: str = "m", imports: ImportOptions | None = None,
                   timing: TimeOptions = REAL_TIME, static: bool = False,
                   rest_s: tuple[float, float] | None = None, settled_s: tuple[float, float] | None = None,
                   scale_std_pct: float | None = None) -> Fit:
    """Fit a cantilever's damped oscillation after a tip mass is dropped on it; with
    ``static``, read its static deflection under the mass instead.

    Parameters
    ----------
    tracks : path-like
        A track of the beam tip: a ``locust track`` CSV, a Tracker project or export, or t,x,y.
    mass_kg : float
        The dropped tip mass.
    length_m : float, optional
        The beam's free length, clamp to mass: needed for the hinge values (k L², b L²).
    beam_mass_kg : float, default 0
        The beam's own mass (33/140 of it oscillates with the tip).
    marker : str, optional
        The tip's marker (default: the only one).
    start_s, end_s : float, optional
        The fit window (default: from the first swing after the drop to the end).
    units : {"m", "cm", "mm"}
        The track's unit.
    imports : locust.io.importing.ImportOptions, optional
        ``--units``, ``--rename``, ``--mirror`` already parsed (instead of ``units``).
    timing : locust.calibrate.recordings.TimeOptions
        ``--time-scale`` / ``--clip-fps``: a slow-motion recording back on real time.
    static : bool, default False
        The track is of the tip at rest, loaded by hand, and settled (no ring-down):
        :mod:`locust.calibrate.beam_static` reads the deflection from rest to settled, the
        stiffness ``m*g/delta`` and, with ``length_m``, the bending stiffness ``k*L^3/3``.
    rest_s, settled_s : (float, float), optional
        With ``static``: the rest and settled windows [s] (default: found from the track).
    scale_std_pct : float, optional
        With ``static``: the scale's standard uncertainty [%] (default: from a Tracker
        project's calibration stick, its ends placed to 0.25 px; else the scale taken as exact).

    Returns
    -------
    Fit
        ``compliance.hinge_stiffness_nm_per_rad`` and ``compliance.hinge_damping_nms_per_rad``
        (with ``length_m``); ``.result`` has the frequency, damping ratio and stiffness. With
        ``static``: no robot value (a cardstock beam's bending is no hinge's stiffness), and
        ``.result`` a :class:`locust.calibrate.beam_static.StaticBeamFit`.

    Examples
    --------
    From the repository's root, on its synthetic recording:

    >>> import locust
    >>> fit = locust.calibrate_beam("calibration/recordings/synthetic_beam.csv", 0.01, length_m=0.05)
    >>> [round(v, 4) for v in fit.parameters["compliance.hinge_stiffness_nm_per_rad"].ci95]
    [0.0545, 0.0572]
    """
    return jobs.beam(tracks, mass_kg, length_m=length_m, beam_mass_kg=beam_mass_kg, marker=marker, start_s=start_s,
                     end_s=end_s, imports=_imports(imports, units), timing=timing, static=static, rest_s=rest_s,
                     settled_s=settled_s, scale_std_pct=scale_std_pct)


def calibrate_hinge(tracks: PathLike, inertia_kgm2: float, gravity: str, *, mass_kg: float | None = None,
                    com_m: float | None = None, pivot: tuple[float, float] | None = None, marker: str | None = None,
                    start_s: float | None = None, end_s: float | None = None, coulomb: str = "auto",
                    units: str = "m", imports: ImportOptions | None = None,
                    timing: TimeOptions = REAL_TIME, progress=None) -> Fit:
    """Fit a link's free swing on a flexure hinge: stiffness, damping, neutral angle.

    Parameters
    ----------
    tracks : path-like
        A track of one marker on the swinging link.
    inertia_kgm2 : float
        The link's moment of inertia about the hinge axis, marker included.
    gravity : {"in-plane", "out-of-plane"}
        Whether the link swings in a vertical plane (its weight pulls it) or about a vertical axis.
    mass_kg, com_m : float, optional
        With ``gravity="in-plane"``: the link's mass and hinge-to-centre-of-mass distance.
    pivot : (x, y), optional
        The hinge in the track's metres, held fixed (default: fitted).
    marker : str, optional
        The link's marker (default: the only one).
    start_s, end_s : float, optional
        The fit window [s] (default: from the first turning point after the release to the end).
    coulomb : {"auto", "off", "on"}
        Coulomb friction: fitted only when the swing shows it (auto).
    units : {"m", "cm", "mm"}
        The track's unit.
    imports : locust.io.importing.ImportOptions, optional
        The track's options already parsed (instead of ``units``).
    timing : locust.calibrate.recordings.TimeOptions
        The slow-motion time scale.
    progress : callable, optional
        ``progress(stage, evaluations)``: the fit's stage and the evaluations of the swing done.

    Returns
    -------
    Fit
        ``compliance.hinge_stiffness_nm_per_rad`` and ``compliance.hinge_damping_nms_per_rad``,
        those the swing determines (never one not identifiable, nor any where the model does
        not follow the swing).
    """
    return jobs.hinge(tracks, inertia_kgm2, gravity, mass_kg=mass_kg, com_m=com_m, pivot=pivot, marker=marker,
                      start_s=start_s, end_s=end_s, coulomb=coulomb, imports=_imports(imports, units), timing=timing,
                      progress=progress)


def calibrate_servo(recordings: PathLike | Sequence[PathLike], inertia_kgm2: float | Sequence[float], *,
                    stall_torque_nm: float | None = None, kv_nms_per_rad: float = 0.0, fit_kv: bool = False,
                    gravity_moment_nm: float | Sequence[float] = 0.0, timing: TimeOptions = REAL_TIME,
                    progress=None) -> Fit:
    """Identify the hobby servo (no-load speed, armature, kp) from step responses.

    Parameters
    ----------
    recordings : path-like or list of them
        Angle recordings (CSV ``t_s,angle_deg,command_deg``) and/or gyro logs on the horn
        (``millis,command_deg,gyro``), fitted together to one servo.
    inertia_kgm2 : float or list of float
        The load's inertia about the servo axis: once, or once per recording.
    stall_torque_nm : float, optional
        From a stall test or the datasheet (SG90: about 0.15); splits what one load gives.
    kv_nms_per_rad : float, default 0
        Velocity feedback held at this value (unless ``fit_kv``).
    fit_kv : bool, default False
        Fit the velocity feedback as well.
    gravity_moment_nm : float or list of float, default 0
        The load's weight moment with the horn horizontal: once, or once per recording.
    timing : locust.calibrate.recordings.TimeOptions
        The slow-motion time scale of filmed recordings.
    progress : callable, optional
        Called with each progress line of the fit.

    Returns
    -------
    Fit
        The ``servo.*`` values the recordings determine (never those not identifiable).

    Examples
    --------
    Not run as a doctest: the fit takes about ten seconds.

    >>> import locust
    >>> fit = locust.calibrate_servo("calibration/recordings/synthetic_servo.csv", 1.5e-5,
    ...                              stall_torque_nm=0.15)            # doctest: +SKIP
    >>> fit.parameters["servo.noload_speed_rad_per_s"].value          # doctest: +SKIP
    """
    from ..calibrate.inputs import per_recording, servo_recording
    from ..calibrate.servo import ServoRig

    paths = [Path(recordings)] if isinstance(recordings, (str, Path)) else [Path(p) for p in recordings]
    inertias = per_recording(_tuple(inertia_kgm2), len(paths), "--inertia-kgm2")
    moments = per_recording(_tuple(gravity_moment_nm), len(paths), "--gravity-moment-nm")
    recs = [servo_recording(path, ServoRig(inertia, moment), None, None, None, ImportOptions(), timing)
            for path, inertia, moment in zip(paths, inertias, moments)]
    return fit_servo_recordings(recs, stall_torque_nm, kv_nms_per_rad=kv_nms_per_rad, fit_kv=fit_kv,
                                progress=progress)


def fit_servo_recordings(recs: list, stall_torque_nm: float | None = None, *, kv_nms_per_rad: float = 0.0,
                         fit_kv: bool = False, progress=None) -> Fit:
    """:func:`calibrate_servo` on recordings already read (``locust.calibrate.servo.StepRecording``,
    ``RateRecording``: a horn track through its pivot, as ``locust calibrate servo --pivot`` makes).

    Parameters
    ----------
    recs : list of StepRecording or RateRecording
        The recordings, each with its rig (load inertia [kg·m²], gravity moment [N·m]).
    stall_torque_nm : float, optional
        The stall torque [N·m] held at this value (from a datasheet); default: fitted.
    kv_nms_per_rad : float, default 0
        Velocity feedback [N·m·s/rad] held at this value (unless ``fit_kv``).
    fit_kv : bool, default False
        Fit the velocity feedback as well.
    progress : callable, optional
        Called with each progress line of the fit.

    Returns
    -------
    Fit
        The ``servo.*`` values the recordings determine (never those not identifiable).
    """
    from ..calibrate.servo import KEYS, fit_servo

    inertias = [r.rig.inertia_kgm2 for r in recs]
    moments = [r.rig.gravity_moment_nm for r in recs]
    fit = fit_servo(recs, stall_torque_nm, kv_nms_per_rad=None if fit_kv else kv_nms_per_rad, progress=progress)
    values = {key: fit.estimates[key] for key in KEYS if fit.identifiable[key] and key not in fit.given}
    kinds = ",".join(r.kind for r in recs)
    note = (f"servo steps ({kinds}), J={','.join(map(str, inertias))} kg*m^2, M={','.join(map(str, moments))} N*m"
            + (f", stall torque {stall_torque_nm} N*m given" if stall_torque_nm else "")
            + ("" if fit_kv else f", kv {kv_nms_per_rad} N*m*s/rad held"))
    subtitle = ", ".join(f"{Path(r.source).name} RMS {rms:.3g} {'deg' if r.kind == 'angle' else 'rad/s'}"
                         for r, rms in zip(recs, fit.rms_per_recording))
    return Fit("servo", fit.source, values, fit, note=note, subtitle=subtitle)


def calibrate_ramp(data: PathLike | Sequence[PathLike] | np.ndarray, *, into: str = "foot",
                   ramp_markers: str = "ramp_a,ramp_b", robot_marker: str = "robot", units: str = "m",
                   imports: ImportOptions | None = None, timing: TimeOptions = REAL_TIME,
                   resolution_deg: float = READING_RESOLUTION_DEG) -> Fit:
    """Static friction from the angles at which the robot starts to slide down a tilted board.

    Parameters
    ----------
    data : path-like, list of them, or array of angles in degrees
        CSVs with an ``angle_deg`` column (one trial a row), side-view tracks of a tilting ramp
        (markers ``ramp_markers`` on the board's ends and ``robot_marker``), or the angles.
    into : {"foot", "nose"}
        Which friction the result is: ``contact.foot_friction`` or ``contact.nose_friction``.
    ramp_markers : str
        ``A,B``: a track's markers on the board's hinge end and far end.
    robot_marker : str
        A track's marker on the robot.
    units : {"m", "cm", "mm"}
        A track's unit.
    imports : locust.io.importing.ImportOptions, optional
        A track's options already parsed (instead of ``units``).
    timing : locust.calibrate.recordings.TimeOptions
        The slow-motion time scale of a filmed track.
    resolution_deg : float, default 1.0
        How finely each angle was read (a protractor's 1 degree graduation): the trials' spread
        is taken as at least ``resolution_deg / sqrt(12)``, so trials read alike still give an
        interval.

    Returns
    -------
    Fit
        ``mu = tan(mean angle)`` with its 95% interval.

    Examples
    --------
    >>> import locust
    >>> round(locust.calibrate_ramp([59.5, 60.1, 58.7]).parameters["contact.foot_friction"].value, 3)
    1.693
    """
    return jobs.ramp(data, into=into, ramp_markers=ramp_markers, robot_marker=robot_marker,
                     imports=_imports(imports, units), timing=timing, resolution_deg=resolution_deg)


def calibrate_fold(unloaded: PathLike, loaded: PathLike, fold: str, *, coin_arm_m: float, coin: str | None = None,
                   coin_mass_kg: float | None = None, robot: Robot | None = None, side: str = "both",
                   link_mass_kg: float | None = None, link_length_m: float | None = None,
                   board: str = DEFAULT_BOARD) -> Fit:
    """A fold's stiffness and rest offset from a static test: one link clamped, a photo of the
    fold settled under the free link's weight and one with a coin taped on it.

    Parameters
    ----------
    unloaded, loaded : path-like
        The fold without and with the coin: each a photo, a folder of photos or a clip, with the
        three fold stickers (``locust.markers.FOLD_STICKER_COLOURS``) and the ArUco board upright
        in their plane.
    fold : {"servo", "knee", "ankle", "loop"}
        Which fold (the servo and loop folds with the ground link clamped, the knee with the
        crank, the ankle with the coupler).
    coin_arm_m : float
        From the fold line to the coin's centre along the free link [m] (a ruler reading, ±0.5 mm).
    coin : str, optional
        A coin by name, its published mass (``eur-1c``, ``usd-1c``, ``gbp-1p``, ...:
        ``locust.calibrate.coins.COINS``).
    coin_mass_kg : float, optional
        Instead: the coin weighed on a 0.01 g scale [kg].
    robot : Robot, optional
        The robot whose fold it is (its link's size and density, its assembled fold angle);
        default: the one every door runs on (``calibration/robot.toml`` here, else ``small``).
    side : {"both", "left", "right"}, default "both"
        Which leg's fold: ``both`` writes the ``folds`` section, ``left``/``right`` that leg's
        (a right fold photographed from the robot's right is read mirrored).
    link_mass_kg : float, optional
        The free link weighed [kg] (default: its size times the laminate's density).
    link_length_m : float, optional
        The free link from the fold line to its end [m] (default: the robot's link).
    board : str
        The ArUco board in the photos (``aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM``).

    Returns
    -------
    Fit
        ``folds.<fold>_stiffness_nm_per_rad`` and ``folds.<fold>_rest_offset_deg`` (``left.``/
        ``right.`` with one side), ``.result`` a :class:`locust.calibrate.foldfit.FoldFit` (the rest
        angle, each photo's fold angle, the deflection, the moments).
    """
    return jobs.fold(unloaded, loaded, fold, coin_arm_m=coin_arm_m, robot=robot, coin=coin, coin_mass_kg=coin_mass_kg,
                     side=side, link_mass_kg=link_mass_kg, link_length_m=link_length_m, board=board)


def calibrate_hops(robot: Robot | None, runs: Mapping[str, PathLike] | Sequence[PathLike | object],
                   keys: Sequence[str] | None = None, *, max_iter: int = 30, progress=None) -> Fit:
    """Fit the model to filmed hops of one or more leg sets at once (the physics is shared).

    Parameters
    ----------
    robot : Robot or None
        The starting values (e.g. the bench-calibrated robot); each run's leg set is built on it.
        None: the robot the runs' run.json record (:func:`robot_of_runs`; runs on different
        robots are refused).
    runs : dict or list
        Leg set -> a ``locust hop --out`` folder (its ``run.json`` and the track of its video),
        or the command line's ``["small=runs/s1", "runs/large-1", ...]`` (a folder named after
        its leg set), or runs already loaded (``locust.trials.measured.Trial``, as ``locust.calibrate.hopruns.load_run``
        loads them).
    keys : list of str, optional
        The robot values fitted (default: foot friction, hinge stiffness, servo no-load speed).
    max_iter : int, default 30
        Solver iterations.
    progress : callable, optional
        ``progress(done, planned)``: the simulations done and planned, after each batch.

    Returns
    -------
    Fit
        The identifiable values; ``.plot(run)`` the tracked markers against the fitted simulation.
    """
    return jobs.hops(robot, runs, keys, max_iter=max_iter, progress=progress)


def robot_of_runs(runs: Sequence[PathLike]) -> tuple[Robot, str]:
    """The robot the runs were hopped on, as their run.json files record it, and a line
    saying so: the robot file, or the preset (a leg-set preset's runs share the robot as
    built, the ``small`` preset, on which each run's own leg set is built).

    Parameters
    ----------
    runs : sequence of path-like
        Run folders (or their ``run.json``); those without a record are passed over.

    Returns
    -------
    robot : locust.params.Robot
        The recorded robot; ``small`` when no record says which.
    line : str
        Where the robot came from, as the command line prints it.

    Raises
    ------
    locust.errors.CalibrationError
        The runs record different robots: which values they share is not known.
    """
    return jobs.robot_of_runs(runs)


def _tuple(value) -> tuple[float, ...]:
    return tuple(float(v) for v in value) if isinstance(value, Sequence) else (float(value),)


__all__ = ["Fit", "bundled_recording", "calibrate_beam", "calibrate_fold", "calibrate_hinge", "calibrate_hops",
           "calibrate_ramp", "calibrate_servo", "fit_servo_recordings"]
