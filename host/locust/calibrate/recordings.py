"""Read calibration recordings: plain CSV, ``locust track`` CSV, or Tracker's text export.

All three become one :class:`Table` of numeric columns, with marker positions under the
``locust track`` names (``<marker>_x_m``, ``<marker>_y_m``) and time as ``t_s``:

- plain CSV (``t_s,angle_deg,command_deg`` or ``angle_deg``), ``#`` lines are comments:
  this module's own format;
- ``locust track`` CSV (``frame,t_s,<m>_px,<m>_py,<m>_x_m,<m>_y_m,<m>_ok``: any header
  naming marker columns), read by :mod:`locust.track.tracks_csv`; a row whose ``<m>_ok``
  is false counts as *not found* (NaN), never as a position;
- Tracker (Open Source Physics) *File > Export > Data*, read by
  :mod:`locust.track.tracker_text`: an optional title line (the track name) or Tracker 6's
  ``#multi:`` line followed by a row of track names, then a header (``t x y ...``), tab
  separated, possibly with decimal commas; or a plain ``t,x,y`` CSV of one marker (``nose``).
  Tracker writes positions in its calibration unit: ``--units cm`` for a Tracker in cm.

Every track (the last two) goes through :func:`locust.track.importing.import_tracks`'s
conversion, so ``--units``, ``--rename`` and ``--mirror`` act here as in ``locust track
--import``; a plain CSV has no positions and is read as it is. The three share one tokenizer
(:mod:`locust.track.delimited`). Every problem is a :class:`~locust.errors.CalibrationError`
naming the file, and the line or column, with a hint.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import CalibrationError, TrackError
from ..track.delimited import check_names, read_text, split_text
from ..track.importing import AS_IS, ImportOptions, track_layout, tracks_from_delimited
from ..track.tracks_csv import TracksCsv


@dataclass(frozen=True)
class Table:
    """Numeric columns of one recording, by name, and the file they came from."""

    path: Path
    columns: dict[str, np.ndarray]
    kind: str = "csv"                        # csv | tracker
    comments: tuple[str, ...] = field(default=())
    tracks: TracksCsv | None = field(default=None, compare=False, repr=False)   # marker files, in metres
    units: str = "m"                         # the unit the file's positions were in (--units)

    @property
    def n_rows(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def has(self, *names: str) -> bool:
        return all(n in self.columns for n in names)

    def require(self, *names: str, purpose: str = "") -> list[np.ndarray]:
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
        return [c[:-4] for c in self.columns if c.endswith("_x_m") and c[:-4] + "_y_m" in self.columns]

    def marker(self, name: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Positions (x_m, y_m) of one marker; NaN where it was not found."""
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
        (t,) = self.require("t_s", purpose="time")
        return t


def read_table(path: str | Path, imports: ImportOptions = AS_IS) -> Table:
    """Read a recording; see the module docstring for the formats understood. ``imports``
    (``--units``, ``--rename``, ``--mirror``) converts a track; a plain CSV is read as it is."""
    path = Path(path)
    try:
        text = read_text(path)
    except TrackError as exc:
        raise CalibrationError(exc.message, exc.hint) from None
    return parse_table(text, path, imports)


def parse_table(text: str, path: Path, imports: ImportOptions = AS_IS) -> Table:
    """The recording in ``text`` (the contents of ``path``), in whichever of the three formats."""
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
    """Rows where time and every series are finite, time increasing; enough of them."""
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
    return tuple(out)
