"""Each experiment's recordings read into its fit's inputs: a servo recording (gyro log, angle
table or horn track) as a :class:`~locust.calibrate.servo.StepRecording` or
:class:`~locust.calibrate.servo.RateRecording`, a ramp file as its trials' critical angles, and
the per-recording option values. The command line and :mod:`locust.api` read them here."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import CalibrationError
from ..io.importing import ImportOptions
from . import ramp
from . import servo as servo_fit
from .gyro_log import looks_like_gyro_log, parse_gyro_log
from .recordings import REAL_TIME, TimeOptions, clean_samples, read_recording_text, read_table


def servo_recording(path: Path, rig, pivot, step, marker, imports: ImportOptions, timing: TimeOptions = REAL_TIME):
    """One servo recording, of the kind its layout says: a gyro log (rate) or an angle table.

    Parameters
    ----------
    path : pathlib.Path
        The recording.
    rig : locust.calibrate.servo.ServoRig
        The load it carried (inertia [kg·m²], gravity moment [N·m]).
    pivot, step, marker : str or None
        A horn track only: the horn's pivot ``X,Y`` [m], the step ``FROM,TO,AT_S`` [deg, deg, s]
        and the tip's marker name (the command line's options).
    imports : locust.io.importing.ImportOptions
        How a track file is read (unit, renaming, mirroring).
    timing : TimeOptions
        The time scale (slow motion) of a filmed recording.

    Returns
    -------
    StepRecording or RateRecording

    Raises
    ------
    locust.errors.CalibrationError
        ``pivot`` given for a gyro log, or a recording that cannot be read as a servo step.
    """
    text = read_recording_text(path)
    if looks_like_gyro_log(text):
        if pivot is not None:
            raise CalibrationError(
                f"{path}: --pivot is for a horn track, and this is a gyro log",
                "leave out --pivot and --step for a gyro log",
            )
        log = parse_gyro_log(text, path)
        return servo_fit.RateRecording(log.t_s, log.rate_units, log.command_deg, rig, source=str(path))
    t, angle, command = servo_series(path, pivot, step, marker, imports, timing)
    return servo_fit.StepRecording(t, angle, command, rig, source=str(path))


def per_recording(values: tuple[float, ...], n: int, option: str) -> list[float]:
    """An option's values, one per recording: given once for all, or once for each.

    Parameters
    ----------
    values : tuple of float
        The option's values as given.
    n : int
        The number of recordings.
    option : str
        The option's name, for the message.

    Returns
    -------
    list of float
        ``n`` values.

    Raises
    ------
    locust.errors.CalibrationError
        Neither once nor ``n`` times.
    """
    if len(values) == 1:
        return list(values) * n
    if len(values) != n:
        raise CalibrationError(
            f"{option} given {len(values)} times for {n} recordings",
            f"give {option} once (for every recording) or once per recording, in order",
        )
    return list(values)


def servo_series(
    data: Path,
    pivot: str | None,
    step: str | None,
    marker: str | None,
    imports: ImportOptions,
    timing: TimeOptions = REAL_TIME,
):
    """A servo step's time, angle and command from a table or a horn track.

    Parameters
    ----------
    data : pathlib.Path
        A table with ``t_s``, ``angle_deg`` and ``command_deg`` columns, or (with ``pivot``) a
        track of the horn's tip.
    pivot : str or None
        The horn's pivot ``X,Y`` [m] in the track's frame.
    step : str or None
        ``FROM,TO,AT_S``: the commanded step [deg] and when it was sent [s] (needed with ``pivot``).
    marker : str or None
        The tip's marker (default: the track's only one).
    imports, timing
        As for :func:`servo_recording`.

    Returns
    -------
    t_s, angle_deg, command_deg : numpy.ndarray
        The cleaned samples [s, deg, deg].

    Raises
    ------
    locust.errors.CalibrationError
        A missing column or option, or too few samples.
    """
    table = read_table(data, imports, timing)
    if pivot is None:
        t, angle, command = table.require("t_s", "angle_deg", "command_deg", purpose="a servo step")
        return clean_samples(data, "the servo angle", t, angle, command, min_samples=servo_fit.MIN_SAMPLES)
    px, py = parse_floats(pivot, 2, "--pivot", "X,Y in metres, e.g. --pivot 0.10,0.05")
    if step is None:
        raise CalibrationError(
            "--pivot needs --step FROM,TO,AT_S (the track holds no command)",
            "e.g. --step 0,180,0.05 for a 0->180 deg step sent at t = 0.05 s",
        )
    a_from, a_to, at_s = parse_floats(step, 3, "--step", "FROM,TO,AT_S, e.g. --step 0,180,0.05")
    x, y = table.marker(marker)
    t, x, y = clean_samples(data, "the horn tip", table.time_s(), x, y, min_samples=servo_fit.MIN_SAMPLES)
    return t, servo_fit.horn_angle_deg(x, y, px, py), np.where(t < at_s, a_from, a_to)


def ramp_angles(
    path: Path, ramp_markers: str, robot_marker: str, imports: ImportOptions, timing: TimeOptions = REAL_TIME
) -> tuple[list[float], str | None, bool]:
    """The trials' angles in ``path``, a plausibility warning, and whether it was a track.

    Parameters
    ----------
    path : pathlib.Path
        A table with an ``angle_deg`` column (one trial a row) or a side-view track of the ramp.
    ramp_markers : str
        ``A,B``: the markers on the board's two ends.
    robot_marker : str
        The robot's marker.
    imports, timing
        As for :func:`servo_recording`.

    Returns
    -------
    angles_deg : list of float
        The critical angles [deg].
    warning : str or None
        The board's length is not a board's (a wrong unit), naming the likely one.
    tracked : bool
        Whether ``path`` was a track.

    Raises
    ------
    locust.errors.CalibrationError
        Neither angles nor the named markers, or no slide in the track.
    """
    table = read_table(path, imports, timing)
    if table.has("angle_deg"):
        return [float(a) for a in table.columns["angle_deg"] if np.isfinite(a)], None, table.tracks is not None
    names = [n.strip() for n in ramp_markers.split(",")]
    if len(names) != 2 or not table.markers():
        table.require("angle_deg", purpose="ramp trials (or a track with ramp and robot markers)")
    a, b = table.marker(names[0]), table.marker(names[1])
    onset = ramp.critical_angle_from_track(table.time_s(), a, b, table.marker(robot_marker), source=str(path))
    board = np.hypot(b[0] - a[0], b[1] - a[1])
    board_m = float(np.median(board[np.isfinite(board)])) if np.isfinite(board).any() else float("nan")
    return [onset.critical_angle_deg], ramp.board_length_warning(board_m, imports.units, str(path)), True


def parse_floats(text: str, n: int, option: str, hint: str) -> list[float]:
    """``n`` comma-separated numbers of an option.

    Parameters
    ----------
    text : str
        The option's value.
    n : int
        How many numbers it must hold.
    option, hint : str
        The option's name and the hint shown when it is wrong.

    Returns
    -------
    list of float

    Raises
    ------
    locust.errors.CalibrationError
        Not ``n`` numbers.
    """
    try:
        vals = [float(v) for v in text.split(",")]
    except ValueError:
        vals = []
    if len(vals) != n:
        raise CalibrationError(f"{option} {text!r}: expected {n} numbers", hint)
    return vals
