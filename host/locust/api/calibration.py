"""The calibrations as functions: recordings in, a :class:`Fit` out (values with intervals, a plot,
and the robot with them applied)."""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..bundled import bundled_recording
from ..calibrate.fitstats import Estimate
from ..calibrate.ramp import READING_RESOLUTION_DEG
from ..calibrate.recordings import REAL_TIME, TimeOptions
from ..errors import CalibrationError
from ..io.importing import ImportOptions
from ..params import Robot
from ..tables import estimate_line, sig, split_unit

PathLike = str | Path


@dataclass(frozen=True)
class Fit:
    """One calibration's outcome: the robot values a recording determines, with intervals.

    Attributes
    ----------
    experiment : str
        ``beam``, ``static-beam``, ``hinge``, ``servo``, ``ramp`` or ``hops``.
    source : str
        The recording(s) fitted, ``+``-joined; the values' provenance ``fit:<source>``.
    parameters : dict of str to locust.calibrate.fitstats.Estimate
        Robot parameter (dotted name, unit in its suffix) -> ``.value``, ``.std`` (one standard
        deviation) and ``.ci95`` (the 95% interval), in the parameter's unit; only the values
        the recordings determine.
    result : object
        The experiment's own fit (every other quantity, ``.summary()``).
    note, subtitle : str
        The provenance note written with the values; the plot's subtitle (RMS per recording).
    warnings : list of str
        What looked wrong in the recording.
    input_note : str
        How the input was read (a unit or timing assumed), as the command line prints it.
    """

    experiment: str
    source: str
    parameters: dict[str, Estimate]
    result: object = field(repr=False)
    note: str = ""
    subtitle: str = ""
    warnings: list[str] = field(default_factory=list)
    input_note: str = ""

    def apply(self, robot: Robot) -> Robot:
        """``robot`` with the fitted values, each with its source ``fit:<recording>``, its
        uncertainty and the date, as ``locust calibrate --write`` records them.

        Parameters
        ----------
        robot : locust.params.Robot
            The robot the values are put into (left unchanged).

        Returns
        -------
        locust.params.Robot
            A copy with the fitted values.

        Raises
        ------
        locust.errors.CalibrationError
            A fitted value no desk hopper has (a recording read in the wrong unit).
        """
        from ..calibrate.write import check_plausible, with_fitted

        check_plausible(self.parameters)
        return with_fitted(robot, self.parameters, self.source, note=self.note)

    def summary(self) -> dict:
        """Everything the fit found, as ``locust calibrate --json`` prints it.

        Returns
        -------
        dict
            The experiment's figures by name (units in the names' suffixes).
        """
        return self.result.summary()

    def to_dataframe(self):
        """One row per fitted robot value.

        Returns
        -------
        pandas.DataFrame
            index ``key`` (dotted name); ``value``, ``std`` (1 sd), ``ci95_low``, ``ci95_high``,
            ``unit`` (from the key's name: ``N·m/rad`` for ``_nm_per_rad``).
        """
        import pandas as pd

        from ..tables import split_unit

        rows = [{"key": k, "value": e.value, "std": e.std, "ci95_low": e.ci95[0], "ci95_high": e.ci95[1],
                 "unit": split_unit(k)[1]} for k, e in self.parameters.items()]
        return pd.DataFrame(rows, columns=["key", "value", "std", "ci95_low", "ci95_high", "unit"]).set_index("key")

    def plot(self, run: int = 0):
        """Data and model above, residuals below (per recording); for a hop fit, run ``run``'s
        tracked markers against the fitted simulation.

        Parameters
        ----------
        run : int, default 0
            Which run of a hop fit to draw (ignored by the other fits).

        Returns
        -------
        matplotlib.figure.Figure
        """
        if self.experiment == "hops":
            from ..calibrate.hop import run_figure

            fit = self.result.runs[run]
            return run_figure(fit, f"RMS {1000 * fit.rms_m:.2f} mm")
        from ..calibrate.plots import fit_figure

        return fit_figure(self.result.curves, self.subtitle)

    def _rows(self) -> list[tuple[str, str, str, str, str]]:
        """(name, value to 4 figures, unit, ± 1 sd in %, 95 % interval) as the CLI prints them."""
        rows = []
        for key, e in self.parameters.items():
            name, unit = split_unit(key)
            rel = f"± {100 * e.std / abs(e.value):.1f} %" if e.value and math.isfinite(e.std) else "undetermined"
            rows.append((name, sig(e.value), unit, rel, f"{sig(e.ci95_low)} … {sig(e.ci95_high)}"))
        return rows

    def _source_name(self) -> str:
        """The recording's file name (its folder is the reader's own: not shown)."""
        return "+".join(Path(part).name for part in str(self.source).split("+"))

    def __repr__(self) -> str:
        lines = [f"Fit {self.experiment}: {self._source_name()}"]
        if self.subtitle:
            lines.append(f"  {self.subtitle}")
        lines += ["  " + estimate_line(k, e.value, e.std, e.ci95) for k, e in self.parameters.items()]
        figures = getattr(self.result, "figures", None)
        if figures is not None:         # a fit of no robot value: its own figures
            lines += ["  " + estimate_line(k, e.value, e.std, e.ci95) for k, e in figures().items()]
        if not self.parameters:
            lines.append("  no robot value determined")
        lines += [f"  warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        esc = html.escape
        head = "".join(f"<th>{c}</th>" for c in ("parameter", "value", "unit", "1 sd", "95 % interval"))
        body = "".join("<tr>" + "".join(f"<td>{esc(c)}</td>" for c in row) + "</tr>" for row in self._rows())
        warn = "".join(f"<p>warning: {esc(w)}</p>" for w in self.warnings)
        return (f"<b>Fit {esc(self.experiment)}</b>: {esc(self._source_name())}<br>{esc(self.subtitle)}"
                f"<table><tr>{head}</tr>{body}</table>{warn}")


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
    from ..calibrate import beam as B
    from ..calibrate.recordings import clean_samples, read_table

    imports = _imports(imports, units)
    _check_beam_options(static, beam_mass_kg, start_s, end_s, rest_s, settled_s, scale_std_pct)
    table = read_table(tracks, imports, timing)
    x, y = table.marker(marker)
    if static:
        return _static_beam(tracks, table, x, y, mass_kg, length_m, rest_s, settled_s, scale_std_pct)
    t, x, y = clean_samples(tracks, "the beam tip", table.time_s(), x, y, min_samples=B.MIN_SAMPLES)
    displacement = B.principal_displacement(x, y)
    warning = B.tip_swing_warning(float(np.ptp(displacement)), length_m, imports.units, source=str(tracks))
    fit = B.fit_beam(t, displacement, mass_kg, length_m=length_m, beam_mass_kg=beam_mass_kg,
                     start_s=start_s, end_s=end_s, source=str(tracks))
    values = {}
    if fit.hinge_stiffness_nm_per_rad is not None:
        values = {"compliance.hinge_stiffness_nm_per_rad": fit.hinge_stiffness_nm_per_rad,
                  "compliance.hinge_damping_nms_per_rad": fit.hinge_damping_nms_per_rad}
    return Fit("beam", str(tracks), values, fit, note=f"beam L={length_m} m, m={mass_kg} kg; {B.MAPPING}",
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
    """``calibrate_beam(static=True)``: the deflection, stiffness and bending stiffness."""
    from ..calibrate import beam_static as BS
    from ..calibrate.recordings import clean_samples
    from ..io.importing import is_project
    from ..io.trk import read_project

    t, x, y = clean_samples(tracks, "the beam tip", table.time_s(), x, y, min_samples=2 * BS.MIN_WINDOW)
    stick = read_project(tracks).stick if is_project(Path(tracks)) else None
    if scale_std_pct is not None:
        scale, scale_note = scale_std_pct / 100, f"{scale_std_pct:g} % (--scale-std-pct)"
    elif stick is not None:
        scale = BS.stick_scale_std(stick.length_px)
        scale_note = (f"{scale * 100:.2g} %, from Tracker's {stick.name!r} ({stick.length_px:.2f} px for "
                      f"{stick.length_m * 1000:g} mm), each end placed by hand to {BS.CLICK_SD_PX:g} px; its "
                      f"{stick.length_m * 1000:g} mm taken as exact (--scale-std-pct to say otherwise)")
    else:
        scale, scale_note = 0.0, "taken as exact: the track names no calibration stick (--scale-std-pct to give one)"
    fit = BS.fit_static_beam(t, x, y, mass_kg, scale_relative_std=scale, scale_note=scale_note, length_m=length_m,
                             rest_s=rest_s, settled_s=settled_s, source=str(tracks))
    return Fit("static-beam", str(tracks), {}, fit, note=f"static beam L={length_m} m, m={mass_kg} kg; {BS.MAPPING}",
               subtitle=f"deflection {fit.deflection_m.value * 1000:.3f} mm, k {fit.stiffness_n_per_m.value:.4g} N/m",
               input_note=table.input_note)


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
    from ..calibrate import hinge as HG
    from ..calibrate.recordings import clean_samples, read_table

    if gravity == "out-of-plane" and (mass_kg or com_m):
        raise CalibrationError("--mass-kg and --com-m act with --gravity in-plane only",
                               "leave them out, or give --gravity in-plane if the link swings in a vertical plane")
    rig = HG.HingeRig(inertia_kgm2, gravity, mass_kg or 0.0, com_m or 0.0)
    HG.check_rig(rig)              # before the recording is read: an impossible rig is no fit's question
    table = read_table(tracks, _imports(imports, units), timing)
    x, y = table.marker(marker)
    t, x, y = clean_samples(tracks, "the link's marker", table.time_s(), x, y, min_samples=HG.MIN_SAMPLES)
    fit = HG.fit_hinge(t, x, y, rig, pivot=pivot, start_s=start_s, end_s=end_s, coulomb=coulomb, source=str(tracks),
                       progress=progress)
    values = {f"compliance.{key}": getattr(fit, key) for key, ok in fit.identifiable.items() if ok}
    note = (f"hinge swing, I={inertia_kgm2:g} kg*m^2, gravity {gravity}"
            + (f", M={mass_kg:g} kg, D={com_m:g} m" if gravity == "in-plane" else "")
            + f", pivot {fit.pivot_source}; Coulomb friction {fit.coulomb_note}")
    return Fit("hinge", str(tracks), values, fit, note=note,
               subtitle=(f"fn {fit.natural_frequency_hz:.4g} Hz, zeta {fit.damping_ratio:.3g}, "
                         f"RMS {1000 * fit.rms_residual_m:.3g} mm"),
               input_note=table.input_note)


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
    from ..calibrate import ramp as R
    from ..calibrate.inputs import ramp_angles

    if into not in ("foot", "nose"):
        raise CalibrationError(f"into={into!r}: not a friction of the model", "choose foot or nose")
    warnings: list[str] = []
    if isinstance(data, (str, Path)):
        data = [data]
    if len(data) and all(isinstance(p, (str, Path)) for p in data):
        paths, angles, imports, tracks = [Path(p) for p in data], [], _imports(imports, units), 0
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
    fit = R.fit_ramp(np.array(angles), source=source, resolution_deg=resolution_deg)
    return Fit("ramp", source, {f"contact.{into}_friction": fit.mu_static}, fit,
               note=f"ramp, {fit.n_trials} trials, mean angle {fit.mean_angle_deg:.4g} deg",
               subtitle=f"mu {fit.mu_static.value:.4g} from {fit.n_trials} trials", warnings=warnings)


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
        its leg set), or runs already loaded (``locust.calibrate.hop.HopRun``).
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
    from ..calibrate import hop as H

    keys = tuple(keys or H.DEFAULT_KEYS)
    if isinstance(runs, Mapping):
        runs = [f"{name}={path}" for name, path in runs.items()]
    named: list[tuple[Path, str]] = []
    for item in runs:
        if isinstance(item, H.HopRun):
            continue
        path, leg_set = _run_folder(str(item))
        if path.resolve() in (p.resolve() for p, _ in named):
            raise CalibrationError(f"{item}: the run {path} is given twice; each run counts once in the fit",
                                   "give each run folder once (a repeat is another filmed hop, another folder)")
        named.append((path, leg_set))
    if robot is None:
        robot, _ = robot_of_runs([f"{leg}={path}" for path, leg in named])
    folders = iter(named)
    loaded = [item if isinstance(item, H.HopRun) else H.load_run(*next(folders), robot) for item in runs]
    fit = H.fit_hops(loaded, keys, max_iter=max_iter, progress=progress)
    values = {k: fit.estimates[k] for k in fit.keys if fit.identifiable[k]}
    note = "filmed hops " + ", ".join(f"{r.config}:{Path(r.source).name}" for r in fit.runs)
    return Fit("hops", H.PROVENANCE_NAME, values, fit, note=note,
               subtitle=f"{len(fit.runs)} runs, RMS {1000 * fit.rms_m:.2f} mm", warnings=[])


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
    from ..io.robot_toml import load_robot
    from ..io.run_record import RECORD_NAME, read_run_record
    from ..params import DEFAULT_PRESET, LEG_SETS, preset

    seen: dict[tuple[str, str], list[str]] = {}
    for item in runs:
        path, _ = _run_folder(str(item))
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


def _run_folder(item: str) -> tuple[Path, str]:
    """``NAME=FOLDER``, or a folder whose run.json names its leg set, else named after it
    (small-1/, large/)."""
    from ..trials.measured import config_of

    name, sep, rest = item.partition("=")
    if sep and name and "/" not in name and not Path(item).exists():
        return Path(rest), name
    path = Path(item)
    return path, config_of(path)[0]


def _tuple(value) -> tuple[float, ...]:
    return tuple(float(v) for v in value) if isinstance(value, Sequence) else (float(value),)


__all__ = ["Fit", "bundled_recording", "calibrate_beam", "calibrate_hinge", "calibrate_hops", "calibrate_ramp",
           "calibrate_servo", "fit_servo_recordings"]
