"""The tracks CSV (``<video>.tracks.csv``): its one writer, its one reader, its typed object.

``locust track`` writes it; the report and the calibration layer read it back through
:func:`.importing.import_tracks` (which also takes Tracker's text export and a
``t,x,y`` CSV, in any unit, renamed or mirrored), built on :func:`read_tracks_csv`.
Layout: ``#`` comment lines (the file's own notes, e.g. ``# synthetic: ...``), then one
header line and one row per frame::

    frame,t_s,<m>_px,<m>_py,<m>_x_m,<m>_y_m,<m>_ok,<m>_vx_m_per_s,<m>_vy_m_per_s,<m>_ax_m_per_s2,<m>_ay_m_per_s2
                                                          (all but the first two once per marker)

- ``frame``: video frame index; ``t_s``: seconds since the clip's first frame (6 decimals);
- ``<m>_px``, ``<m>_py``: pixels in OpenCV's convention, origin at the centre of the
  top-left pixel, x right, y down (4 decimals);
- ``<m>_x_m``, ``<m>_y_m``: world metres, y up (6 decimals); ``nan`` without a calibration;
- ``<m>_ok``: 1 where the marker was found, 0 where not; its cells are then ``nan``;
- ``<m>_vx_m_per_s``, ``<m>_vy_m_per_s`` (4 decimals), ``<m>_ax_m_per_s2``,
  ``<m>_ay_m_per_s2`` (3 decimals): velocity and acceleration by Tracker's finite
  differences (:mod:`locust.derivatives`), ``nan`` where a neighbour they need is missing.
  They are derived columns: computed from the time and world columns *as written* (so the
  file's own numbers give them back), and on reading computed again from the columns read,
  never taken from the file (a file written before they existed reads as it did, and
  one converted to another unit or mirrored cannot keep a stale velocity).

The reader also takes what other programs make of the file (the tokenizer is
:mod:`.delimited`): ``true``/``false`` in ``_ok``, ``;`` or tab delimiters with decimal
commas, a marker with some of its columns left out (NaN; without ``_ok`` every row counts
as found), and columns of no marker (kept in :attr:`TracksCsv.other`). A row whose ``_ok``
is false is a lost frame: :meth:`TracksCsv.positions` gives NaN there, never a position.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..derivatives import acceleration, velocity
from ..errors import TrackError
from ..fileio import atomic_write_text
from .delimited import DelimitedText, check_names, check_text, read_text, split_text

if TYPE_CHECKING:
    from .tracker_text import TrackerExport

TRACKS_CSV_SUFFIX = ".tracks.csv"
MARKER_COLUMNS = ("px", "py", "x_m", "y_m", "ok")   # per marker, in the order written
# per marker after those: computed from the time and world columns, never stored (see above)
DERIVED_COLUMNS = ("vx_m_per_s", "vy_m_per_s", "ax_m_per_s2", "ay_m_per_s2")
_DERIVED_DIGITS = (4, 4, 3, 3)


def tracks_csv_in(folder: Path, source: Path) -> Path:
    """``folder``, ``.../hop.mp4`` -> ``folder/hop.tracks.csv``: the name ``locust track`` gives
    the tracks of ``source`` (a video, an image sequence's folder, a Tracker project or another
    program's tracks) in its output folder.

    Parameters
    ----------
    folder : pathlib.Path
        The output folder.
    source : pathlib.Path
        What was tracked or converted.

    Returns
    -------
    pathlib.Path
    """
    return folder / (source.stem + TRACKS_CSV_SUFFIX)


@dataclass(frozen=True, eq=False)
class TracksCsv:
    """A tracks CSV: per frame its index and time, per marker its columns, and the file's notes.

    A marker's columns are held by kind, as the file names them (``nose_x_m`` is
    ``x_m["nose"]``): ``px``, ``py`` in pixels (OpenCV convention), ``x_m``, ``y_m`` in world
    metres (y up) and ``ok`` (bool: found in that frame), each a dict over the same markers in
    the file's order. Equality compares the contents (NaN equal to NaN), not ``path`` or ``header``.
    """

    frame: np.ndarray                                       # int, video frame index
    t_s: np.ndarray                                         # seconds since the clip's first frame
    px: dict[str, np.ndarray] = field(default_factory=dict)
    py: dict[str, np.ndarray] = field(default_factory=dict)
    x_m: dict[str, np.ndarray] = field(default_factory=dict)
    y_m: dict[str, np.ndarray] = field(default_factory=dict)
    ok: dict[str, np.ndarray] = field(default_factory=dict)
    comments: tuple[str, ...] = ()                          # the ``#`` lines, without the ``#``
    other: dict[str, np.ndarray] = field(default_factory=dict)   # columns of no marker, as read
    path: Path | None = None                                # where it was read from
    header: tuple[str, ...] | None = None                   # the columns as read (None: as written)

    def __post_init__(self) -> None:
        names = list(self.ok)
        if any(list(getattr(self, kind)) != names for kind in MARKER_COLUMNS):
            raise TrackError("a tracks CSV's px, py, x_m, y_m and ok name different markers",
                             "give each marker all five columns, in one order")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TracksCsv):
            return NotImplemented
        return (same_array(self.frame, other.frame) and same_array(self.t_s, other.t_s)
                and set(self.markers) == set(other.markers) and self.comments == other.comments
                and all(same_array(getattr(self, kind)[m], getattr(other, kind)[m])
                        for kind in MARKER_COLUMNS for m in self.markers)
                and self.other.keys() == other.other.keys()
                and all(same_array(v, other.other[k]) for k, v in self.other.items()))

    __hash__ = None  # type: ignore[assignment]

    @property
    def markers(self) -> tuple[str, ...]:
        """The markers' names, in the file's order."""
        return tuple(self.ok)

    @property
    def n_rows(self) -> int:
        """The number of frames."""
        return len(self.t_s)

    @property
    def columns(self) -> tuple[str, ...]:
        """The file's columns: as read, or the layout :func:`tracks_csv_text` writes."""
        if self.header is not None:
            return self.header
        return ("frame", "t_s", *(f"{m}_{c}" for m in self.markers for c in (*MARKER_COLUMNS, *DERIVED_COLUMNS)),
                *self.other)

    def column(self, name: str) -> np.ndarray:
        """One column by its name in the file, as floats (``_ok`` as 1.0/0.0).

        Parameters
        ----------
        name : str
            A column of :attr:`columns`.

        Returns
        -------
        numpy.ndarray
            In the column's unit (px, m, s; m/s and m/s² for the derived columns, computed
            from the positions whether the file had them or not).

        Raises
        ------
        KeyError
            No such column.
        """
        if name == "frame":
            return self.frame.astype(float)
        if name == "t_s":
            return self.t_s
        if name in self.other:
            return self.other[name]
        marker, kind = _marker_column(name) or ("", "")
        if marker in self.markers:
            if kind in DERIVED_COLUMNS:
                return self.derived(marker)[kind]
            return getattr(self, kind)[marker].astype(float)
        raise KeyError(name)

    def markers_with_positions(self) -> list[str]:
        """Markers with both world columns in the file.

        Returns
        -------
        list of str
        """
        cols = set(self.columns)
        return [m for m in self.markers if f"{m}_x_m" in cols and f"{m}_y_m" in cols]

    def time_s(self) -> np.ndarray:
        """The ``t_s`` column; a file without one is refused.

        Returns
        -------
        numpy.ndarray
            [s].
        """
        if "t_s" not in self.columns:
            raise missing_time(self.path, self.columns)
        return self.t_s

    def positions(self, marker: str) -> tuple[np.ndarray, np.ndarray]:
        """``marker``'s world x and y (m), NaN in the frames where it was lost.

        Parameters
        ----------
        marker : str

        Returns
        -------
        x_m, y_m : numpy.ndarray

        Raises
        ------
        locust.errors.TrackError
            No such marker (the message names those there are).
        """
        if marker not in self.markers_with_positions():
            raise no_marker(self.path, marker, self.markers_with_positions())
        ok = self.ok[marker]
        return np.where(ok, self.x_m[marker], np.nan), np.where(ok, self.y_m[marker], np.nan)

    def derived(self, marker: str) -> dict[str, np.ndarray]:
        """``marker``'s velocity and acceleration (Tracker's finite differences on the world
        metres, :mod:`locust.derivatives`), NaN where a neighbour they need was lost.

        Parameters
        ----------
        marker : str

        Returns
        -------
        dict of str to numpy.ndarray
            :data:`DERIVED_COLUMNS`: ``vx_m_per_s``, ``vy_m_per_s`` [m/s], ``ax_m_per_s2``,
            ``ay_m_per_s2`` [m/s²].

        Raises
        ------
        locust.errors.TrackError
            No such marker (the message names those there are).
        """
        x, y = self.positions(marker)
        return _derived(self.t_s, x, y)

    def has_pixels(self, marker: str) -> bool:
        """Whether ``marker`` has a finite pixel position anywhere (tracked, even if not in metres).

        Parameters
        ----------
        marker : str

        Returns
        -------
        bool
        """
        return marker in self.px and bool(np.isfinite(self.px[marker]).any())

    @classmethod
    def from_delimited(cls, doc: DelimitedText) -> TracksCsv:
        """The tracks in a file already split by :func:`.delimited.split_text`.

        Parameters
        ----------
        doc : locust.io.delimited.DelimitedText

        Returns
        -------
        TracksCsv

        Raises
        ------
        locust.errors.TrackError
            The file cannot be read, or a line is not what the layout says (file and line named).
        """
        names = list(doc.header)
        check_names(names, doc.path, doc.header_line)
        data = doc.columns(names)
        n = len(data)
        cols = {name: data[:, j] for j, name in enumerate(names)}
        frame = cols.get("frame", np.arange(n, dtype=float))
        if not (np.isfinite(frame).all() and np.all(frame == np.round(frame))):
            bad = int(np.argmax(~np.isfinite(frame) | (frame != np.round(frame))))
            raise TrackError(f"{doc.path}, line {doc.rows[bad][0]}: frame {frame[bad]:g} is not a frame number",
                             "fix or delete that line")
        markers: dict[str, dict[str, np.ndarray]] = {}
        other: dict[str, np.ndarray] = {}
        for name, values in cols.items():
            if name in ("frame", "t_s"):
                continue
            split = _marker_column(name)
            if split is None:
                other[name] = values
            elif split[1] not in DERIVED_COLUMNS:       # derived: computed again from the positions
                markers.setdefault(split[0], {})[split[1]] = values
        nan = np.full(n, np.nan)
        kinds = {kind: {m: c.get(kind, nan.copy()) for m, c in markers.items()} for kind in ("px", "py", "x_m", "y_m")}
        ok = {m: c["ok"] > 0.5 if "ok" in c else np.ones(n, bool) for m, c in markers.items()}
        return cls(frame=frame.astype(int), t_s=cols.get("t_s", nan.copy()), **kinds, ok=ok,
                   comments=doc.comments, other=other, path=doc.path, header=tuple(names))


def tracks_csv_text(tracks: TracksCsv) -> str:
    """The file's text: comments, header, one row per frame (``nan`` for a missing value).

    Parameters
    ----------
    tracks : TracksCsv

    Returns
    -------
    str
    """
    out = io.StringIO()
    for line in tracks.comments:
        out.write(f"# {line}\n")
    head = ["frame", "t_s"]
    t_text = _cells(tracks.t_s, 6)
    cols = [[str(int(f)) for f in np.asarray(tracks.frame).tolist()], t_text]
    t_written = _parsed(t_text)
    for m in tracks.markers:
        head += [f"{m}_{c}" for c in (*MARKER_COLUMNS, *DERIVED_COLUMNS)]
        x_text, y_text = _cells(tracks.x_m[m], 6), _cells(tracks.y_m[m], 6)
        ok = ["1" if v else "0" for v in np.asarray(tracks.ok[m]).tolist()]
        cols += [_cells(tracks.px[m], 4), _cells(tracks.py[m], 4), x_text, y_text, ok]
        # from the positions as written, so that reading the file gives these very numbers back
        x, y = (np.where(tracks.ok[m], _parsed(c), np.nan) for c in (x_text, y_text))
        cols += [_cells(v, digits) for v, digits in zip(_derived(t_written, x, y).values(), _DERIVED_DIGITS)]
    for name, values in tracks.other.items():
        head.append(name)
        cols.append(_cells(values, 6))
    out.write(",".join(head) + "\n")
    out.writelines(",".join(row) + "\n" for row in zip(*cols))
    return out.getvalue()


def write_tracks_csv(path: Path, tracks: TracksCsv) -> Path:
    """Write ``tracks`` to ``path`` atomically.

    Parameters
    ----------
    path : pathlib.Path
    tracks : TracksCsv

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    locust.errors.TrackError
        More rows than a track file may hold (:func:`.delimited.check_size`).
    locust.errors.WriteError
        The file cannot be written.
    """
    return atomic_write_text(path, check_text(path, tracks_csv_text(tracks)))


def parse_tracks_csv(text: str, path: str | Path) -> TracksCsv:
    """The tracks in ``text`` (the contents of ``path``).

    Parameters
    ----------
    text : str
    path : path-like
        For messages.

    Returns
    -------
    TracksCsv

    Raises
    ------
    locust.errors.TrackError
        The file cannot be read, or a line is not what the layout says (file and line named).
    """
    return TracksCsv.from_delimited(split_text(text, path))


def read_tracks_csv(path: str | Path) -> TracksCsv:
    """Read a tracks CSV; a :class:`~locust.errors.TrackError` names the file and line of any fault.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    TracksCsv

    Raises
    ------
    locust.errors.TrackError
        The file cannot be read, or a line is not what the layout says (file and line named).
    """
    return parse_tracks_csv(read_text(path), path)


def read_track_file(path: str | Path) -> TracksCsv | TrackerExport:
    """A marker track in either layout ``locust track`` writes: a tracks CSV
    (:class:`TracksCsv`) or Tracker's text export (:class:`.tracker_text.TrackerExport`).
    Both answer ``time_s()``, ``positions(marker)``, ``has_pixels(marker)`` and ``n_rows``.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    TracksCsv or locust.io.tracker_text.TrackerExport

    Raises
    ------
    locust.errors.TrackError
        The file cannot be read, or a line is not what the layout says (file and line named).
    """
    from . import tracker_text  # it builds on this module's errors

    doc = split_text(read_text(path), path)
    return tracker_text.TrackerExport.from_delimited(doc) if doc.tracker_layout else TracksCsv.from_delimited(doc)


def is_tracks_header(names: list[str]) -> bool:
    """Whether a header names marker columns (``<m>_px``, ``<m>_py``, ``<m>_x_m``, ``<m>_y_m``).

    Parameters
    ----------
    names : list of str

    Returns
    -------
    bool
    """
    kinds = [_marker_column(n) for n in names]
    return any(k is not None and k[1] != "ok" for k in kinds)


def missing_time(path: Path | None, columns) -> TrackError:
    """The error for a track file without a time column.

    Parameters
    ----------
    path : pathlib.Path or None
    columns : iterable of str
        The columns the file has.

    Returns
    -------
    locust.errors.TrackError
    """
    return TrackError(f"{path}: missing column t_s for time (found: {', '.join(columns) or 'none'})",
                      "the file needs the columns t_s")


def no_marker(path: Path | None, marker: str, names: list[str]) -> TrackError:
    """The error for a marker the file has no positions of (``names``: the markers it has).

    Parameters
    ----------
    path : pathlib.Path or None
    marker : str
    names : list of str

    Returns
    -------
    locust.errors.TrackError
    """
    return TrackError(f"{path}: no marker {marker!r} (markers: {', '.join(names) or 'none'})",
                      "check the name given with --marker")


def _derived(t_s: np.ndarray, x_m: np.ndarray, y_m: np.ndarray) -> dict[str, np.ndarray]:
    return dict(zip(DERIVED_COLUMNS, (velocity(t_s, x_m), velocity(t_s, y_m),
                                      acceleration(t_s, x_m), acceleration(t_s, y_m))))


def _cells(values: np.ndarray, digits: int) -> list[str]:
    """A column's cells: ``digits`` decimals, ``nan`` for a value that is not finite."""
    return [f"{v:.{digits}f}" if math.isfinite(v) else "nan" for v in np.asarray(values, dtype=float).tolist()]


def _parsed(cells: list[str]) -> np.ndarray:
    """A column as the reader gets it back from its cells."""
    return np.array([float(c) for c in cells], dtype=float)


def _marker_column(name: str) -> tuple[str, str] | None:
    for kind in (*DERIVED_COLUMNS, "x_m", "y_m", "px", "py", "ok"):
        if name.endswith("_" + kind) and len(name) > len(kind) + 1:
            return name[: -len(kind) - 1], kind
    return None


def same_array(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    """Equal arrays, NaN equal to NaN (and None equal to None): how the track formats' typed
    objects compare their columns.

    Parameters
    ----------
    a, b : numpy.ndarray or None

    Returns
    -------
    bool
    """
    if a is None or b is None:
        return a is None and b is None
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind in "fc" or b.dtype.kind in "fc":
        return a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))
