"""Read calibration recordings: plain CSV, ``locust track`` CSV, Tracker's text export or project.

All four become one :class:`Table` of numeric columns, with marker positions under the
``locust track`` names (``<marker>_x_m``, ``<marker>_y_m``) and time as ``t_s``:

- plain CSV (``t_s,angle_deg,command_deg`` or ``angle_deg``), ``#`` lines are comments:
  this module's own format;
- ``locust track`` CSV (``frame,t_s,<m>_px,<m>_py,<m>_x_m,<m>_y_m,<m>_ok``: any header
  naming marker columns), read by :mod:`locust.io.tracks_csv`; a row whose ``<m>_ok``
  is false counts as *not found* (NaN), never as a position;
- Tracker (Open Source Physics) *File > Export > Data*, read by
  :mod:`locust.io.tracker_text`: an optional title line (the track name) or Tracker 6's
  ``#multi:`` line followed by a row of track names, then a header (``t x y ...``), tab
  separated, possibly with decimal commas; or a plain ``t,x,y`` CSV of one marker (``nose``).
  Tracker writes positions in its calibration unit: ``--units cm`` for a Tracker in cm.

- a Tracker project (``.trk``, or a ``.trz`` zip holding one), read by
  :mod:`locust.io.trk`: its point tracks in metres through the project's own calibration.

Every track (the last three) goes through :func:`locust.io.importing.import_tracks`'s
conversion, so ``--units``, ``--rename`` and ``--mirror`` act here as in ``locust track
import``; a plain CSV has no positions and is read as it is. The three share one tokenizer
(:mod:`locust.io.delimited`). Every problem is a :class:`~locust.errors.CalibrationError`
naming the file, and the line or column, with a hint.

Slow motion: a clip filmed at 240 frames/s and exported (or played) at 30 has times 8 times
too long. :class:`TimeOptions` (``--time-scale S``: real time = file time * S, or
``--clip-fps F``: the rate the clip was filmed at, the file's own rate read from its median
time step) puts every recording back on real time, tracks and plain CSVs alike. Times
printed to too few digits (they repeat) are rebuilt from the row order (:func:`regular_time`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import CalibrationError, TrackError
from ..io.delimited import check_names, read_text, split_text
from ..io.importing import AS_IS, ImportOptions, import_project, is_project, track_layout, tracks_from_delimited
from ..io.tracks_csv import TracksCsv


@dataclass(frozen=True)
class Table:
    """Numeric columns of one recording, by name, and the file they came from."""

    path: Path
    columns: dict[str, np.ndarray]
    kind: str = "csv"                        # csv | tracker
    comments: tuple[str, ...] = field(default=())
    tracks: TracksCsv | None = field(default=None, compare=False, repr=False)   # marker files, in metres
    units: str = "m"                         # the unit the file's positions were in (--units)
    time_note: str = ""                      # how the times were rescaled (slow motion), if they were

    @property
    def n_rows(self) -> int:
        """The number of samples."""
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def has(self, *names: str) -> bool:
        """Whether every column in ``names`` is present.

        Parameters
        ----------
        *names : str
            Column names.

        Returns
        -------
        bool
        """
        return all(n in self.columns for n in names)

    def require(self, *names: str, purpose: str = "") -> list[np.ndarray]:
        """The columns ``names``, in order.

        Parameters
        ----------
        *names : str
            Column names (unit in their suffix).
        purpose : str
            What they are for, named in the message when one is missing.

        Returns
        -------
        list of numpy.ndarray

        Raises
        ------
        locust.errors.CalibrationError
            A column is missing.
        """
        missing = [n for n in names if n not in self.columns]
        if missing:
            what = f" for {purpose}" if purpose else ""
            raise CalibrationError(
                f"{self.path}: missing column{'s' if len(missing) > 1 else ''} "
                f"{', '.join(missing)}{what} (found: {', '.join(self.columns) or 'none'})",
                f"the file needs the columns {', '.join(names)}",
            )
        return [self.columns[n] for n in names]

    def markers(self) -> list[str]:
        """The markers with both ``<name>_x_m`` and ``<name>_y_m`` columns.

        Returns
        -------
        list of str
        """
        return [c[:-4] for c in self.columns if c.endswith("_x_m") and c[:-4] + "_y_m" in self.columns]

    def marker(self, name: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Positions of one marker; NaN where it was not found.

        Parameters
        ----------
        name : str, optional
            The marker; default the table's only one.

        Returns
        -------
        x_m, y_m : numpy.ndarray
            Positions [m].

        Raises
        ------
        locust.errors.CalibrationError
            No such marker, or no name given and not exactly one marker.
        """
        names = self.markers()
        if name is None:
            if len(names) != 1:
                raise CalibrationError(
                    f"{self.path}: {'no marker columns' if not names else 'several markers: ' + ', '.join(names)}",
                    "choose one with --marker NAME" if names else
                    "give a `locust track` CSV (<name>_x_m, <name>_y_m) or a Tracker export (t, x, y)",
                )
            name = names[0]
        if self.tracks is None:
            raise CalibrationError(f"{self.path}: no marker {name!r} (markers: none)",
                                   "check the name given with --marker")
        try:
            return self.tracks.positions(name)
        except TrackError as exc:
            raise CalibrationError(exc.message, exc.hint) from None

    def time_s(self) -> np.ndarray:
        """The ``t_s`` column [s] (a CalibrationError when there is none).

        Returns
        -------
        numpy.ndarray
            [s].
        """
        (t,) = self.require("t_s", purpose="time")
        return t


    @property
    def input_note(self) -> str:
        """How the file was read: its layout's conversion note (scale, units), and the time scale."""
        notes = [c.strip() for c in (self.tracks.comments if self.tracks is not None else ())
                 if c.strip().startswith(("imported from", "converted from"))]
        return "; ".join(notes + ([self.time_note] if self.time_note else []))


@dataclass(frozen=True)
class TimeOptions:
    """``--time-scale`` / ``--clip-fps``: a slow-motion recording back on real time."""

    time_scale: float | None = None     # real time = file time * time_scale
    clip_fps: float | None = None       # the rate the clip was filmed at [frames/s]

    def factor(self, t_s: np.ndarray, path: Path) -> tuple[float, str]:
        """The factor on the file's times, and what to say about it ('' when 1).

        Parameters
        ----------
        t_s : numpy.ndarray
            The file's times [s] (for ``clip_fps``: the rate the file says).
        path : pathlib.Path
            The recording, for messages.

        Returns
        -------
        factor : float
            Real time = file time × factor.
        note : str
            What was done, as the command line says it.

        Raises
        ------
        locust.errors.CalibrationError
            Both options given, a scale that is not positive, or ``clip_fps`` without a usable rate.
        """
        if self.time_scale is not None and self.clip_fps is not None:
            raise CalibrationError("give --time-scale or --clip-fps, not both",
                                   "--clip-fps F: the clip was filmed at F frames/s; --time-scale S: t_real = t*S")
        if self.time_scale is not None:
            if not self.time_scale > 0:
                raise CalibrationError(f"--time-scale must be positive (got {self.time_scale})",
                                       "e.g. --time-scale 0.125 for a 240 frames/s clip exported at 30")
            return self.time_scale, f"times x {self.time_scale:g} (--time-scale)"
        if self.clip_fps is not None:
            steps = np.diff(np.asarray(t_s, dtype=float)[np.isfinite(t_s)])
            steps = steps[steps > 0]
            if not self.clip_fps > 0 or len(steps) == 0:
                raise CalibrationError(f"{path}: --clip-fps {self.clip_fps:g} needs a positive rate and a time column "
                                       "that advances", "the rate the clip was filmed at, e.g. --clip-fps 240")
            file_fps = 1.0 / float(np.median(steps))
            return file_fps / self.clip_fps, (f"times x {file_fps / self.clip_fps:.6g}: the file's "
                                              f"{file_fps:.5g} frames/s made the clip's {self.clip_fps:g}")
        return 1.0, ""


REAL_TIME = TimeOptions()


# What a calibration recording holds: a few seconds to minutes of video (24-240 frames/s) or of
# a sensor log. Longer files are refused before they are parsed (a fit's start grid grows with
# the samples), with what to do.
MAX_ROWS = 50_000                   # lines: 3.5 minutes at 240 frames/s
MAX_BYTES = 64 * 2**20
LONGEST_STEP_S = 1.0                # a camera or a logger samples faster than once a second
# the largest magnitude a value may have, by its column's unit: positions within a lab
LARGEST = {"_m": 1e3, "t_s": 1e6}
LARGEST_OTHER = 1e9
SIZE_HINT = ("cut the recording to the experiment (a few seconds to minutes), e.g. keep its header and the rows "
             "you need, or export it again at the rate it was filmed")


def read_recording_text(path: str | Path) -> str:
    """The text of a recording (a CSV, a Tracker export, a gyro log): refused
    (:class:`CalibrationError`) before parsing when it is larger than a recording can be.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    str

    Raises
    ------
    locust.errors.CalibrationError
        The file cannot be read, or holds more bytes or lines than a recording can.
    """
    path = Path(path)
    try:
        size = path.stat().st_size
    except OSError:
        size = 0   # read_text says what is wrong
    if size > MAX_BYTES:
        raise CalibrationError(f"{path}: {size / 2**20:.0f} MB, more than a calibration recording holds "
                               f"({MAX_BYTES / 2**20:.0f} MB and {MAX_ROWS:,} lines at most)", SIZE_HINT)
    try:
        text = read_text(path)
    except TrackError as exc:
        raise CalibrationError(exc.message, exc.hint) from None
    lines = text.count("\n")
    if lines > MAX_ROWS:
        raise CalibrationError(f"{path}: {lines:,} lines, more than the {MAX_ROWS:,} a calibration recording "
                               f"holds ({MAX_ROWS / 240 / 60:.1f} minutes at 240 frames/s)", SIZE_HINT)
    return text


def check_values(table: Table) -> Table:
    """``table`` if every value is a number a recording can hold: NaN (not found) is kept, an
    infinite or absurdly large one (1e308 in a position in metres) is a :class:`CalibrationError`
    naming its column and row.

    Parameters
    ----------
    table : Table
        A recording read.

    Returns
    -------
    Table
        ``table`` itself.

    Raises
    ------
    locust.errors.CalibrationError
        An infinite or absurdly large value.
    """
    for name, col in table.columns.items():
        limit = next((v for k, v in LARGEST.items() if name.endswith(k)), LARGEST_OTHER)
        bad = np.flatnonzero(np.abs(np.nan_to_num(col, nan=0.0)) > limit)
        if len(bad):
            row = int(bad[0])
            raise CalibrationError(
                f"{table.path}: column {name!r}, data row {row + 1}: {float(col[row])!r} is not a value a recording "
                f"can hold (|value| <= {limit:g}){f'; {len(bad) - 1} more such rows' if len(bad) > 1 else ''}",
                "fix or delete that row (an empty cell reads as not found), and check the file's units")
    return table


def read_table(path: str | Path, imports: ImportOptions = AS_IS, timing: TimeOptions = REAL_TIME) -> Table:
    """Read a recording; see the module docstring for the formats understood. ``imports``
    (``--units``, ``--rename``, ``--mirror``) converts a track; a plain CSV is read as it is;
    ``timing`` rescales a slow-motion recording's times.

    Parameters
    ----------
    path : path-like
        The recording.
    imports : locust.io.importing.ImportOptions
        How a track is converted.
    timing : TimeOptions
        The slow-motion time scale.

    Returns
    -------
    Table
        Columns in SI units (``t_s`` [s], ``<marker>_x_m`` [m], ...).

    Raises
    ------
    locust.errors.CalibrationError
        A file that cannot be read as any of the formats, or holds impossible values.
    """
    path = Path(path)
    try:
        if is_project(path):
            tracks = import_project(path, imports)
            table = Table(path=path, columns={n: tracks.column(n) for n in tracks.columns}, kind="tracker",
                          comments=tracks.comments, tracks=tracks)
        else:
            table = parse_table(read_recording_text(path), path, imports)
    except TrackError as exc:
        raise CalibrationError(exc.message, exc.hint) from None
    return rescale_time(regular_time(check_values(table)), timing)


def regular_time(table: Table) -> Table:
    """A recording whose times repeat because they were printed to too few digits (Tracker with
    3 significant digits: 10.5, 10.5, 10.5, 10.6 at 30 frames/s) gets them back from the row
    order, one frame a row, when a line through (row, time) stays within half the printed step
    plus half a frame of every time; the note says so. Other recordings are returned as they are
    (a real step back in time is :func:`clean_samples`' error).

    Parameters
    ----------
    table : Table
        A recording read.

    Returns
    -------
    Table
    """
    if "t_s" not in table.columns:
        return table
    t = table.columns["t_s"]
    rows = np.nonzero(np.isfinite(t))[0]
    steps = np.diff(t[rows])
    if len(rows) < 3 or np.all(steps > 0) or np.any(steps < 0):
        return table
    slope, offset = np.polyfit(rows, t[rows], 1)
    printed = float(steps.max())
    if not slope > 0 or np.max(np.abs(t[rows] - (offset + slope * rows))) > 0.5 * printed + 0.5 * slope:
        return table
    rebuilt = np.where(np.isfinite(t), offset + slope * np.arange(len(t)), np.nan)
    note = (f"times rebuilt from the row order at {1 / slope:.5g} frames/s: the file's repeat "
            f"({int(np.sum(steps == 0))} repeated, printed to {printed:g} s)")
    tracks = None if table.tracks is None else replace(table.tracks, t_s=rebuilt)
    return replace(table, columns={**table.columns, "t_s": rebuilt}, tracks=tracks, time_note=note)


def rescale_time(table: Table, timing: TimeOptions) -> Table:
    """``table`` with its times (``t_s``, and its tracks') multiplied as ``timing`` says.

    Parameters
    ----------
    table : Table
        A recording read.
    timing : TimeOptions

    Returns
    -------
    Table

    Raises
    ------
    locust.errors.CalibrationError
        Options that contradict each other (see :meth:`TimeOptions.factor`).
    """
    if "t_s" not in table.columns:
        return table
    factor, note = timing.factor(table.columns["t_s"], table.path)
    if factor == 1.0:
        return table
    columns = {**table.columns, "t_s": table.columns["t_s"] * factor}
    tracks = None if table.tracks is None else replace(table.tracks, t_s=table.tracks.t_s * factor)
    return replace(table, columns=columns, tracks=tracks, time_note="; ".join(filter(None, (table.time_note, note))))


def parse_table(text: str, path: Path, imports: ImportOptions = AS_IS) -> Table:
    """The recording in ``text`` (the contents of ``path``), in whichever of the three formats.

    Parameters
    ----------
    text : str
        The recording's contents.
    path : pathlib.Path
        Where it came from (for messages, and a Tracker project's own reading).
    imports : locust.io.importing.ImportOptions
        How a track is converted.

    Returns
    -------
    Table

    Raises
    ------
    locust.errors.CalibrationError
        Not a table of numbers in any of the formats.
    """
    try:
        doc = split_text(text, path)
        layout = track_layout(doc)
        if layout is None:
            check_names(doc.header, path, doc.header_line)
            data = doc.columns(doc.header)
            return Table(path=path, columns={n: data[:, j] for j, n in enumerate(doc.header)},
                         comments=doc.comments)
        tracks = tracks_from_delimited(doc, imports)
        return Table(path=path, columns={n: tracks.column(n) for n in tracks.columns},
                     kind="tracker" if layout == "tracker" else "csv", comments=doc.comments, tracks=tracks,
                     units=imports.units)
    except TrackError as exc:
        raise CalibrationError(exc.message, exc.hint) from None


def clean_samples(path: Path, what: str, t_s: np.ndarray, *series: np.ndarray,
                  min_samples: int) -> tuple[np.ndarray, ...]:
    """Rows where time and every series are finite, time increasing; enough of them.

    Parameters
    ----------
    path : pathlib.Path
        The recording, for messages.
    what : str
        What the series are (``the servo angle``), for messages.
    t_s : numpy.ndarray
        Time [s].
    *series : numpy.ndarray
        The series sampled at ``t_s``, each in its own unit.
    min_samples : int
        How many rows a fit needs.

    Returns
    -------
    tuple of numpy.ndarray
        ``t_s`` and each series, on the rows kept.

    Raises
    ------
    locust.errors.CalibrationError
        Too few rows, or time that does not increase.
    """
    t_s = np.asarray(t_s, dtype=float)
    keep = np.isfinite(t_s)
    for s in series:
        keep &= np.isfinite(s)
    out = [t_s[keep], *[np.asarray(s, dtype=float)[keep] for s in series]]
    n = len(out[0])
    if n < min_samples:
        raise CalibrationError(
            f"{path}: only {n} usable samples of {what} (need at least {min_samples}; "
            f"{len(t_s) - n} rows are empty or NaN)",
            "record longer or at a higher frame rate, or check that the marker was found",
        )
    if np.any(np.diff(out[0]) <= 0):
        bad = int(np.argmax(np.diff(out[0]) <= 0)) + 1
        raise CalibrationError(f"{path}: time does not increase at sample {bad} (t_s = {out[0][bad]:g})",
                               "sort the rows by time and remove duplicate frames")
    step = float(np.median(np.diff(out[0])))
    if step > LONGEST_STEP_S:
        raise CalibrationError(
            f"{path}: {what}: the samples are {step:g} s apart (median), slower than any camera or logger "
            f"(24-240 frames/s: 0.004-0.04 s); the times are not in seconds",
            f"times in milliseconds: add --time-scale 0.001 (real time = file time * {0.001:g})")
    return tuple(out)
