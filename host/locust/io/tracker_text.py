"""Tracker's text export (*File > Export > Data*): its one writer, its one reader, its typed object.

Tracker (Open Source Physics) exports a data table as tab-separated text:

- an optional title line (the track's name), or Tracker 6's ``#multi:`` line followed by
  a row of track names, each above the first column of its track;
- a header of Tracker's column names (``t x y ...``);
- one row per step; an empty cell is a step the track does not have (NaN here). In a
  decimal-comma locale the numbers have decimal commas.

Tracker writes positions in its calibration unit: calibrate Tracker in metres, and the
``x``/``y`` columns read as ``x_m``/``y_m``. ``locust track --format tracker`` writes the
same layout (:func:`tracker_export_text`): a row of track names, then ``t x y`` for every
track, with ``t`` empty where that track has no step.

A track is known by its *marker name*: its Tracker name with every run of characters other
than letters, digits and ``_`` made one ``_`` (``cm A`` -> ``cm_A``), as in the tracks CSV.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_text
from .delimited import DelimitedText, check_names, check_text, read_text, split_text
from .tracks_csv import missing_time, no_marker, same_array

DEFAULT_TRACK = "track"   # the name of columns no title or names row claims


@dataclass(frozen=True, eq=False)
class TrackerExport:
    """A Tracker text export: its tracks by marker name, and its ``#`` comment lines.

    A track's columns are held by kind, each a dict over the same marker names in the file's
    order: ``names`` its name as Tracker wrote it (``cup 3`` for the marker ``cup_3``),
    ``t_s`` its own ``t`` column or the table's shared one, ``x_m``, ``y_m`` (NaN where
    empty; None for a column the export does not have), and ``other`` its further columns
    (``v``, ``vx``, ``theta`` ...) under Tracker's header names. Equality compares the
    contents (NaN equal to NaN), not ``path``.
    """

    names: dict[str, str]
    t_s: dict[str, np.ndarray | None]
    x_m: dict[str, np.ndarray | None]
    y_m: dict[str, np.ndarray | None]
    other: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    comments: tuple[str, ...] = ()
    path: Path | None = None

    def __post_init__(self) -> None:
        markers = list(self.names)
        if any(list(kind) != markers for kind in (self.t_s, self.x_m, self.y_m)) or \
                not set(self.other) <= set(markers):
            raise TrackError("a Tracker export's names, t_s, x_m and y_m name different tracks",
                             "give each track its name and its t, x and y (None for a column it has not)")
        object.__setattr__(self, "other", {m: dict(self.other.get(m, {})) for m in markers})   # one per track

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TrackerExport):
            return NotImplemented
        return (self.names == other.names and self.comments == other.comments
                and all(same_array(getattr(self, kind)[m], getattr(other, kind)[m])
                        for kind in ("t_s", "x_m", "y_m") for m in self.names)
                and all(self.other[m].keys() == other.other[m].keys()
                        and all(same_array(v, other.other[m][k]) for k, v in self.other[m].items())
                        for m in self.names))

    __hash__ = None  # type: ignore[assignment]

    @property
    def markers(self) -> tuple[str, ...]:
        """The tracks' marker names, in the file's order."""
        return tuple(self.names)

    @property
    def n_rows(self) -> int:
        """The longest track's number of rows."""
        lengths = [len(a) for m in self.names
                   for a in (self.t_s[m], self.x_m[m], self.y_m[m], *self.other[m].values()) if a is not None]
        return max(lengths, default=0)

    @property
    def columns(self) -> tuple[str, ...]:
        """The export's columns under locust's names: ``t_s`` (the tracks' times as one
        column), then per track ``<marker>_x_m``, ``<marker>_y_m`` and ``<marker>_<column>``."""
        return tuple(self._labelled())

    def column(self, name: str) -> np.ndarray:
        """One column by its name in :attr:`columns`.

        Parameters
        ----------
        name : str

        Returns
        -------
        numpy.ndarray
        """
        return self._labelled()[name]

    def markers_with_positions(self) -> list[str]:
        """Tracks with both an ``x`` and a ``y`` column.

        Returns
        -------
        list of str
        """
        return [m for m in self.names if self.x_m[m] is not None and self.y_m[m] is not None]

    def time_s(self) -> np.ndarray:
        """The time of each row: the tracks' ``t`` columns as one, which must agree where
        two have a value; an export without ``t`` is refused.

        Returns
        -------
        numpy.ndarray
            [s].
        """
        times: list[np.ndarray] = []
        for t in self.t_s.values():
            if t is not None and not any(t is s for s in times):
                times.append(t)
        if not times:
            raise missing_time(self.path, self.columns)
        out = times[0].copy()
        for t in times[1:]:
            both = np.isfinite(out) & np.isfinite(t)
            clash = both & ~np.isclose(out, t, rtol=1e-9, atol=0.0)
            if clash.any():
                row = int(np.argmax(clash))
                raise TrackError(f"{self.path}: the tracks' times disagree in data row {row + 1} "
                                 f"({out[row]:g} s and {t[row]:g} s)", "export the tracks from one data table")
            out = np.where(np.isfinite(out), out, t)
        return out

    def positions(self, marker: str) -> tuple[np.ndarray, np.ndarray]:
        """``marker``'s x and y (Tracker's unit: metres when calibrated so), NaN where it has no step.

        Parameters
        ----------
        marker : str

        Returns
        -------
        x, y : numpy.ndarray

        Raises
        ------
        locust.errors.TrackError
            No such marker.
        """
        if marker not in self.markers_with_positions():
            raise no_marker(self.path, marker, self.markers_with_positions())
        return self.x_m[marker].copy(), self.y_m[marker].copy()

    def has_pixels(self, marker: str) -> bool:
        """Always False: a text export holds world values only.

        Parameters
        ----------
        marker : str

        Returns
        -------
        bool
        """
        return False

    def _labelled(self) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        if any(t is not None for t in self.t_s.values()):
            out["t_s"] = self.time_s()
        for marker in self.names:
            if self.x_m[marker] is not None:
                out[f"{marker}_x_m"] = self.x_m[marker]
            if self.y_m[marker] is not None:
                out[f"{marker}_y_m"] = self.y_m[marker]
            out.update({f"{marker}_{marker_name(h)}": v for h, v in self.other[marker].items()})
        return out

    @classmethod
    def from_delimited(cls, doc: DelimitedText) -> TrackerExport:
        """The tracks in a file already split by :func:`.delimited.split_text`.

        Parameters
        ----------
        doc : locust.io.delimited.DelimitedText

        Returns
        -------
        TrackerExport

        Raises
        ------
        locust.errors.TrackError
            The file cannot be read, or a line is not what the layout says (file and line named).
        """
        header, names_row = doc.header, doc.names_row
        current = DEFAULT_TRACK
        if names_row is not None and len(names_row) == 1 and names_row[0].strip():
            current, names_row = names_row[0].strip(), None          # a title line: the track's name
        owners = []
        for j in range(len(header)):
            if names_row is not None and j < len(names_row) and names_row[j].strip():
                current = names_row[j].strip()
            owners.append(current)
        markers = [marker_name(o) for o in owners]
        labels = ["t_s" if h == "t" else f"{m}_{h}_m" if h in ("x", "y") else f"{m}_{marker_name(h)}"
                  for h, m in zip(header, markers)]
        check_names([f"{m}_t_s" if h == "t" else lab for h, m, lab in zip(header, markers, labels)],
                    doc.path, doc.header_line)
        data = doc.columns(labels)
        shared = next((data[:, j] for j, h in enumerate(header) if h == "t"), None)
        groups: dict[str, dict] = {}
        for j, (h, owner, m) in enumerate(zip(header, owners, markers)):
            g = groups.setdefault(m, {"name": owner, "other": {}})
            if h in ("t", "x", "y"):
                g[h] = data[:, j]
            else:
                g["other"][h] = data[:, j]
        kept = [m for m, g in groups.items() if "x" in g or "y" in g or g["other"]]   # not a lone shared t
        return cls(names={m: groups[m]["name"] for m in kept}, t_s={m: groups[m].get("t", shared) for m in kept},
                   x_m={m: groups[m].get("x") for m in kept}, y_m={m: groups[m].get("y") for m in kept},
                   other={m: groups[m]["other"] for m in kept}, comments=doc.comments, path=doc.path)


def marker_name(name: str) -> str:
    """A Tracker name as a marker name: ``cm A`` -> ``cm_A`` (``track`` when nothing is left).

    Parameters
    ----------
    name : str

    Returns
    -------
    str
    """
    return re.sub(r"\W+", "_", name.strip()).strip("_") or DEFAULT_TRACK


def tracker_export_text(export: TrackerExport) -> str:
    """Tracker's layout: a row of track names, a row of Tracker's column names, then
    tab-separated values (6 significant digits); a NaN is an empty cell.

    Parameters
    ----------
    export : TrackerExport

    Returns
    -------
    str
    """
    names: list[str] = []
    heads: list[str] = []
    cols: list[np.ndarray] = []
    for m, name in export.names.items():
        parts = [(h, v) for h, v in (("t", export.t_s[m]), ("x", export.x_m[m]), ("y", export.y_m[m]),
                                     *export.other[m].items()) if v is not None]
        names += [name] + [""] * (len(parts) - 1)
        heads += [h for h, _ in parts]
        cols += [np.asarray(v, dtype=float) for _, v in parts]
    lines = [f"# {c}" for c in export.comments] + ["\t".join(names), "\t".join(heads)]
    for i in range(export.n_rows):
        lines.append("\t".join("" if not math.isfinite(c[i]) else f"{c[i]:.6g}" for c in cols))
    return "\n".join(lines) + "\n"


def write_tracker_export(path: Path, export: TrackerExport) -> Path:
    """Write ``export`` to ``path`` atomically.

    Parameters
    ----------
    path : pathlib.Path
    export : TrackerExport

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
    return atomic_write_text(path, check_text(path, tracker_export_text(export)))


def parse_tracker_export(text: str, path: str | Path) -> TrackerExport:
    """The tracks in ``text`` (the contents of ``path``).

    Parameters
    ----------
    text : str
    path : path-like
        For messages.

    Returns
    -------
    TrackerExport

    Raises
    ------
    locust.errors.TrackError
        The file cannot be read, or a line is not what the layout says (file and line named).
    """
    return TrackerExport.from_delimited(split_text(text, path))


def read_tracker_export(path: str | Path) -> TrackerExport:
    """Read a Tracker text export; a :class:`~locust.errors.TrackError` names the file and line of any fault.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    TrackerExport

    Raises
    ------
    locust.errors.TrackError
        The file cannot be read, or a line is not what the layout says (file and line named).
    """
    return parse_tracker_export(read_text(path), path)
