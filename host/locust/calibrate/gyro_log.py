"""Read a gyro log of a servo horn: ``millis,command_deg,gyro`` rows, no header.

The layout of a microcontroller logging a rate gyro (an IMU) taped to the servo horn while it
steps the servo: each row is the controller's clock in milliseconds, the command it sent
[deg] and the gyro's reading about the servo axis in the gyro's own unit (raw counts, deg/s,
...: the scale is established by the fit, never assumed). Command and gyro share the
controller's clock. ``#`` lines are comments; the delimiter is a comma, a semicolon or a tab.

:func:`looks_like_gyro_log` tells the layout apart from the calibration CSVs (which have a
header): the first data line is three numbers. Every problem is a
:class:`~locust.errors.CalibrationError` naming the file and line, with a hint.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import CalibrationError, TrackError
from ..io.delimited import read_text

_SPLIT = re.compile(r"[,;\t]")
HINT = "a gyro log has rows millis,command_deg,gyro (three numbers, no header)"


@dataclass(frozen=True)
class GyroLog:
    """One gyro log: sample times [s], the command [deg] and the gyro reading (its own unit)."""

    path: Path
    t_s: np.ndarray
    command_deg: np.ndarray
    rate_units: np.ndarray
    comments: tuple[str, ...] = ()


def _data_lines(text: str) -> tuple[list[tuple[int, str]], list[str]]:
    rows, comments = [], []
    for lineno, line in enumerate(text.splitlines(), 1):
        line = line.strip().lstrip("\ufeff")
        if not line:
            continue
        if line.startswith("#"):
            comments.append(line)
        else:
            rows.append((lineno, line))
    return rows, comments


def _numbers(line: str) -> list[float] | None:
    try:
        return [float(v) for v in _SPLIT.split(line)]
    except ValueError:
        return None


def looks_like_gyro_log(text: str) -> bool:
    """Whether ``text`` is laid out as a gyro log: its first data line is three numbers.

    Parameters
    ----------
    text : str
        A recording's contents.

    Returns
    -------
    bool
    """
    rows, _ = _data_lines(text)
    if not rows:
        return False
    first = _numbers(rows[0][1])
    return first is not None and len(first) == 3


def parse_gyro_log(text: str, path: str | Path) -> GyroLog:
    """The gyro log in ``text`` (the contents of ``path``).

    Parameters
    ----------
    text : str
        The log's contents.
    path : str or path-like
        Where it came from, for messages.

    Returns
    -------
    GyroLog
        Time [s], command [deg] and gyro rate (the gyro's own unit), with the comment lines.

    Raises
    ------
    locust.errors.CalibrationError
        A line that is not three finite numbers, no rows, or a clock that does not increase.
    """
    path = Path(path)
    rows, comments = _data_lines(text)
    data = []
    for lineno, line in rows:
        vals = _numbers(line)
        if vals is None or len(vals) != 3:
            raise CalibrationError(f"{path}, line {lineno}: expected three numbers, got {line[:60]!r}", HINT)
        data.append(vals)
    if not data:
        raise CalibrationError(f"{path}: no rows", HINT)
    arr = np.array(data)
    if not np.all(np.isfinite(arr)):
        bad = rows[int(np.argmax(~np.all(np.isfinite(arr), axis=1)))][0]
        raise CalibrationError(f"{path}, line {bad}: not a finite number", HINT)
    t_s = arr[:, 0] / 1000.0
    back = np.flatnonzero(np.diff(t_s) <= 0)
    if back.size:
        lineno = rows[int(back[0]) + 1][0]
        raise CalibrationError(f"{path}, line {lineno}: time does not increase ({arr[back[0] + 1, 0]:g} ms)",
                               "the first column is the controller's clock in milliseconds, in order")
    return GyroLog(path, t_s, arr[:, 1], arr[:, 2], tuple(comments))


def read_gyro_log(path: str | Path) -> GyroLog:
    """Read a controller's gyro log.

    Parameters
    ----------
    path : path-like
        The log: milliseconds, gyro rate and command per line (see :func:`parse_gyro_log`).

    Returns
    -------
    GyroLog

    Raises
    ------
    locust.errors.CalibrationError
        The file cannot be read, or its clock does not increase.
    """
    try:
        text = read_text(path)
    except TrackError as exc:
        raise CalibrationError(exc.message, exc.hint) from None
    return parse_gyro_log(text, path)
