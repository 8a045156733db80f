"""Imports: any track file, in any length unit, with its markers renamed and x mirrored.

The one conversion every track input goes through (:func:`import_tracks`):
``locust track import``, ``locust calibrate`` (beam, servo ``--pivot``, ramp tracks) and
``locust report`` (``--measured`` tracks) all read their tracks here, with the same options:

- ``--units m|cm|mm``: the unit of the file's positions; they are divided by 1, 100 or 1000
  (a division, so a value in cm becomes exactly ``value / 100`` in metres);
- ``--rename OLD=NEW`` (repeatable): a marker's new name. OLD is the marker's name (a
  Tracker name made a marker name: ``cm A`` -> ``cm_A``) or the Tracker name as written
  (``"cup 3=nose"``); NEW is a plain name (letters, digits, ``_``);
- ``--mirror``: x becomes -x, so a hop filmed right-to-left reads left-to-right (y stays up).

Three text layouts are read (the tokenizer is :mod:`.delimited`), and Tracker's projects:

- locust's tracks CSV (:mod:`.tracks_csv`): ``<m>_x_m`` / ``<m>_y_m`` hold the file's unit;
  pixel columns are kept as they are;
- Tracker's text export (:mod:`.tracker_text`): every track with ``x`` and ``y`` becomes a
  marker; its other columns (``v``, ``vx`` ...) are dropped (their units are Tracker's);
- a plain CSV of one marker: ``t,x,y`` (or ``t_s``/``time`` for ``t``). Like an export
  without a title line, its track has no name: it is ``nose`` (``--rename nose=NEW``).

- a Tracker project, ``.trk`` or a ``.trz`` zip holding one (:mod:`.trk`): its point tracks
  through the project's own calibration (scale, origin, axes, length unit), in metres; its
  times from the clip's frame rate. ``--units`` does not apply (the project says its unit),
  ``--rename`` and ``--mirror`` do; a project without a scale is refused.

Time stays in seconds (Tracker's ``t``), positions become metres, y up. A file of none of
these layouts, an unknown unit, or a rename of a marker the file does not have, is a
:class:`~locust.errors.TrackError` with a hint.

:func:`likely_units` and :func:`units_hint` are the other half: when a track's size is
not plausible for what it shows (a beam tip swinging 0.9 m), which ``--units`` would make it so.
"""

from __future__ import annotations

import math
import re
import zipfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import TrackError
from .delimited import DelimitedText, check_names, read_text, split_text
from .tracker_text import DEFAULT_TRACK, TrackerExport
from .tracks_csv import TracksCsv, _marker_column, is_tracks_header

UNITS: dict[str, int] = {"m": 1, "cm": 100, "mm": 1000}   # the file's unit -> that many to a metre
UNNAMED = "nose"                                          # the marker of a track with no name
TIME_NAMES = ("t", "t_s", "time")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
UNITS_HINT = "--units takes m, cm or mm: the unit of the file's positions"
FORMATS_HINT = ("give a Tracker text export (File > Export > Data: t, x, y), a CSV with the columns t,x,y, "
                "or a `locust track` CSV (<marker>_x_m, <marker>_y_m)")


@dataclass(frozen=True)
class ImportOptions:
    """``--units``, ``--rename``, ``--mirror``, checked: what :func:`import_tracks` does to a file."""

    units: str = "m"
    rename: tuple[tuple[str, str], ...] = ()
    mirror: bool = False

    @classmethod
    def parse(cls, units: str | None = "m", rename: Iterable[str] | Mapping[str, str] = (),
              mirror: bool = False) -> ImportOptions:
        """The options checked, from the command line's spelling.

        Parameters
        ----------
        units : {"m", "cm", "mm"} or None
            The file's unit of length (None: metres).
        rename : iterable of "OLD=NEW", or mapping OLD -> NEW
            Marker renames.
        mirror : bool
            Flip x (a hop filmed going left).

        Returns
        -------
        ImportOptions

        Raises
        ------
        locust.errors.TrackError
            An unknown unit or a malformed rename.
        """
        return cls(parse_units(units), parse_rename(rename), bool(mirror))

    @property
    def identity(self) -> bool:
        """Nothing to convert: metres, no renames, not mirrored."""
        return self.units == "m" and not self.rename and not self.mirror

    @property
    def divisor(self) -> int:
        """What a position in ``units`` is divided by to be in metres (1, 100 or 1000)."""
        return UNITS[self.units]

    def describe(self) -> str:
        """``cm -> m, renamed A -> nose, x mirrored``.

        Returns
        -------
        str
        """
        parts = [f"positions in {self.units}" + ("" if self.units == "m" else " -> m")]
        parts += [f"renamed {old} -> {new}" for old, new in self.rename]
        if self.mirror:
            parts.append("x mirrored")
        return ", ".join(parts)

    def options_text(self) -> str:
        """The command-line options that give these settings (empty for the identity).

        Returns
        -------
        str
        """
        parts = [] if self.units == "m" else [f"--units {self.units}"]
        parts += [f"--rename {_quote(f'{old}={new}')}" for old, new in self.rename]
        return " ".join(parts + (["--mirror"] if self.mirror else []))


AS_IS = ImportOptions()    # metres, names as they are, not mirrored


def parse_units(units: str | None) -> str:
    """``"CM"`` -> ``"cm"``; anything but m, cm, mm is a TrackError.

    Parameters
    ----------
    units : str or None
        None: metres.

    Returns
    -------
    str
        ``m``, ``cm`` or ``mm``.

    Raises
    ------
    locust.errors.TrackError
        Another unit.
    """
    key = (units or "m").strip().lower()
    if key not in UNITS:
        raise TrackError(f"unknown unit {units!r} for --units", UNITS_HINT)
    return key


def parse_rename(items: Iterable[str] | Mapping[str, str]) -> tuple[tuple[str, str], ...]:
    """``["cm A=nose"]`` (or ``{"cm A": "nose"}``) -> ``(("cm A", "nose"),)``, each checked.

    Parameters
    ----------
    items : iterable of "OLD=NEW", or mapping OLD -> NEW

    Returns
    -------
    tuple of (str, str)

    Raises
    ------
    locust.errors.TrackError
        A new name that is not a marker name, or a marker renamed twice.
    """
    pairs = list(items.items()) if isinstance(items, Mapping) else [_split_rename(i) for i in items]
    seen: set[str] = set()
    for old, new in pairs:
        if not _NAME.match(new):
            raise TrackError(f"--rename {old}={new}: {new!r} is not a marker name",
                             "a new name is letters, digits and _, e.g. --rename 'cm A=nose'")
        if old in seen:
            raise TrackError(f"--rename {old}=...: {old!r} is renamed twice", "rename each marker once")
        seen.add(old)
    return tuple((old, new) for old, new in pairs)


def _split_rename(item: str) -> tuple[str, str]:
    old, sep, new = item.rpartition("=")
    if not sep or not old.strip() or not new.strip():
        raise TrackError(f"--rename {item!r} is not OLD=NEW", "e.g. --rename A=nose (repeatable)")
    return old.strip(), new.strip()


def import_tracks(path: str | Path, units: str = "m", rename: Iterable[str] | Mapping[str, str] = (),
                  mirror: bool = False, *, options: ImportOptions | None = None) -> TracksCsv:
    """A track file in any of the three layouts, as locust's tracks in metres (see the module).

    ``units``, ``rename`` and ``mirror`` as on the command line (``rename``: ``["A=nose"]`` or
    ``{"A": "nose"}``), or ``options`` already parsed.

    Parameters
    ----------
    path : path-like
        A tracks CSV, a Tracker text export or project, or a t,x,y CSV.
    units : {"m", "cm", "mm"}
        The file's unit of length.
    rename : iterable of str or mapping
    mirror : bool
        Flip x.
    options : ImportOptions, optional
        Instead of the three above.

    Returns
    -------
    TracksCsv
        Positions in metres, time in seconds.

    Raises
    ------
    locust.errors.TrackError
        A file in no known layout, a bad option, or time that does not increase.
    """
    options = options or ImportOptions.parse(units, rename, mirror)
    if is_project(path):
        return import_project(path, options)
    doc = split_text(read_text(path), path)
    tracks = tracks_from_delimited(doc, options)
    check_times(doc, tracks.t_s)
    return tracks


PROJECT_SUFFIXES = (".trk", ".trz")


def is_project(path: str | Path) -> bool:
    """Whether ``path`` names a Tracker project: a ``.trk``, a ``.trz`` zip holding one, or a
    ``.zip`` holding one (Tracker's own examples are handed out so, e.g. ``CupsClips.zip``:
    the frames and the ``.trk``; only the zip's list of members is read here).

    Parameters
    ----------
    path : path-like

    Returns
    -------
    bool
    """
    path = Path(path)
    if path.suffix.lower() in PROJECT_SUFFIXES:
        return True
    if path.suffix.lower() != ".zip" or not path.is_file():
        return False
    try:
        with zipfile.ZipFile(path) as z:
            return any(name.lower().endswith(".trk") for name in z.namelist())
    except (zipfile.BadZipFile, EOFError, ValueError, OSError):
        return False   # not a readable zip: whoever reads it says so


def import_project(path: str | Path, options: ImportOptions = AS_IS) -> TracksCsv:
    """A Tracker project's point tracks in metres through its own calibration (:mod:`.trk`),
    renamed and mirrored by ``options``; a comment says which scale, origin and rate were used.

    Parameters
    ----------
    path : path-like
        A ``.trk`` or ``.trz``.
    options : ImportOptions
        ``--units``, ``--rename``, ``--mirror``, parsed.

    Returns
    -------
    TracksCsv

    Raises
    ------
    locust.errors.TrackError
        ``--units`` given, or a project without a scale or a frame rate.
    """
    from .trk import project_tracks, read_project

    path = Path(path)
    if options.units != "m":
        raise TrackError(f"{path}: --units {options.units} does not apply to a Tracker project",
                         "the project's own calibration gives metres: leave --units out")
    project = read_project(path)
    cal, clip = project.calibration, project.clip
    if not math.isfinite(cal.m_per_px):
        raise TrackError(f"{path}: the Tracker project has no scale (no calibration stick or tape)",
                         "calibrate it in Tracker, or export its data in pixels and convert them")
    if not math.isfinite(clip.fps):
        raise TrackError(f"{path}: the Tracker project has no frame rate (clip control delta_t)",
                         "set the clip's frame rate in Tracker, or export its data (File > Export > Data)")
    note = (f"imported from {path.name} (Tracker project): scale {1 / cal.m_per_px:.6g} px/m, origin "
            f"({cal.origin_x_px + 0.5:.6g}, {cal.origin_y_px + 0.5:.6g}) px, x axis {cal.angle_deg:g} deg, "
            f"{clip.fps:.6g} frames/s")
    tracks = replace(project_tracks(project), comments=(note,), path=path)
    return tracks if options.identity else _convert_tracks_csv(tracks, options)


def track_layout(doc: DelimitedText) -> str | None:
    """``tracker``, ``tracks`` (locust's CSV), ``txy`` (a plain CSV of one marker), or None.

    Parameters
    ----------
    doc : locust.io.delimited.DelimitedText

    Returns
    -------
    str or None
    """
    if doc.tracker_layout:
        return "tracker"
    if is_tracks_header(doc.header):
        return "tracks"
    if _txy_columns(doc.header) is not None:
        return "txy"
    return None


LAYOUT_NAMES = {"tracker": "Tracker text export", "tracks": "tracks CSV", "txy": "t,x,y CSV"}


def tracks_from_delimited(doc: DelimitedText, options: ImportOptions = AS_IS) -> TracksCsv:
    """The tracks of a file already split by :func:`.delimited.split_text`, converted by ``options``.

    Parameters
    ----------
    doc : locust.io.delimited.DelimitedText
    options : ImportOptions
        ``--units``, ``--rename``, ``--mirror``, parsed.

    Returns
    -------
    TracksCsv

    Raises
    ------
    locust.errors.TrackError
        A layout that is none of the three, or no x and y columns.
    """
    layout = track_layout(doc)
    if layout is None:
        raise TrackError(f"{doc.path}: neither a Tracker text export, a t,x,y CSV nor a tracks CSV "
                         f"(columns: {', '.join(doc.header)})", FORMATS_HINT)
    if layout == "tracks":
        tracks = TracksCsv.from_delimited(doc)
        return tracks if options.identity else _convert_tracks_csv(tracks, options)
    columns, dropped = _tracker_markers(doc) if layout == "tracker" else _txy_markers(doc)
    if not columns:
        raise TrackError(f"{doc.path}: no track with x and y columns (columns: {', '.join(doc.header)})",
                         FORMATS_HINT)
    t_s = columns.pop(0)
    markers = _apply(doc.path, columns, options)
    plain = layout == "txy" or (doc.delimiter == "," and doc.names_row is None and not doc.multi)
    note = f"imported from {doc.path.name} ({LAYOUT_NAMES['txy' if plain else layout]}): {options.describe()}"
    if dropped:
        note += f"; not imported: {', '.join(dropped)}"
    return TracksCsv(frame=np.arange(len(t_s)), t_s=t_s, **markers, comments=(*doc.comments, note), path=doc.path)


def check_times(doc: DelimitedText, t_s) -> None:
    """Refuse rows whose time repeats the row before or goes back (rows without a time are
    skipped): velocities, onsets and fits all divide by the step. Names the file's lines.
    :func:`import_tracks` applies it; the calibration layer reads through
    :func:`tracks_from_delimited` and rebuilds times rounded to repeating values from the row
    order itself (``locust.calibrate.recordings.regular_time``).

    Parameters
    ----------
    doc : locust.io.delimited.DelimitedText
        The file, for its line numbers.
    t_s : numpy.ndarray
        Its times [s].

    Raises
    ------
    locust.errors.TrackError
        A time that repeats or goes back.
    """
    t = np.asarray(t_s, dtype=float)
    rows = np.flatnonzero(np.isfinite(t))
    step = np.diff(t[rows])
    bad = rows[1:][step <= 0]
    if not bad.size:
        return
    repeats, back = int((step == 0).sum()), int((step < 0).sum())
    lines = [doc.rows[k][0] for k in bad]
    where = ", ".join(str(n) for n in lines[:6]) + (f" and {len(lines) - 6} more" if len(lines) > 6 else "")
    raise TrackError(f"{doc.path}: time does not increase on {len(bad)} of {len(rows)} rows ({repeats} repeat the "
                     f"time before, {back} go back), line {where}; first at t = {t[bad[0]]:g} s",
                     "sort the rows by time and remove duplicate frames; times that repeat only after rounding "
                     "(e.g. 3 significant digits) need an export with more digits")


# -- the layouts -------------------------------------------------------------------
# each gives [t_s, (marker, its Tracker name as written or None, x, y), ...] ([] for no marker)
# and the columns not imported

def _tracker_markers(doc: DelimitedText):
    export = TrackerExport.from_delimited(doc)
    written_names = {c.strip() for c in (doc.names_row or [])}
    columns, dropped = [], []
    for key, name in export.names.items():
        if export.x_m[key] is None or export.y_m[key] is None:
            dropped.append(f"{name} (no x and y)")
            continue
        unnamed = name == DEFAULT_TRACK and DEFAULT_TRACK not in written_names
        columns.append((UNNAMED if unnamed else key, None if unnamed else name, export.x_m[key], export.y_m[key]))
        dropped += [f"{name} {h}" for h in export.other[key]]
    return ([export.time_s(), *columns] if columns else []), dropped


def _txy_columns(header: list[str]) -> tuple[int, int, int] | None:
    low = [h.strip().lower() for h in header]
    t = next((low.index(n) for n in TIME_NAMES if n in low), None)
    if t is None or "x" not in low or "y" not in low:
        return None
    return t, low.index("x"), low.index("y")


def _txy_markers(doc: DelimitedText):
    check_names(doc.header, doc.path, doc.header_line)
    t, x, y = _txy_columns(doc.header)
    data = doc.columns(doc.header)
    dropped = [h for j, h in enumerate(doc.header) if j not in (t, x, y)]
    return [data[:, t], (UNNAMED, None, data[:, x], data[:, y])], dropped


# -- the conversion ----------------------------------------------------------------
def _renames(path: Path, names: list[tuple[str, str | None]], options: ImportOptions) -> list[str]:
    """The final name of each marker (``names``: its name and its Tracker name as written)."""
    final = [name for name, _ in names]
    for old, new in options.rename:
        hits = [i for i, (name, written) in enumerate(names)
                if old == name or (written is not None and old == written.strip())]
        if not hits:
            have = ", ".join(n if w in (None, n) else f"{n} ({w!r} in Tracker)" for n, w in names) or "none"
            raise TrackError(f"{path}: --rename {old}={new}: the file has no marker {old!r} (markers: {have})",
                             "--rename OLD=NEW takes the name of a marker the file has")
        final[hits[0]] = new
    for name in final:
        if final.count(name) > 1:
            clash = [names[j][0] for j, n in enumerate(final) if n == name]
            raise TrackError(f"{path}: two markers would be named {name!r} ({', '.join(clash)})",
                             "give each marker its own name with --rename OLD=NEW")
    return final


def _apply(path: Path, columns: list, options: ImportOptions) -> dict[str, dict[str, np.ndarray]]:
    """The markers' columns (px, py, x_m, y_m, ok: :class:`.tracks_csv.TracksCsv`'s), renamed, in metres."""
    final = _renames(path, [(name, written) for name, written, _, _ in columns], options)
    out: dict[str, dict[str, np.ndarray]] = {"px": {}, "py": {}, "x_m": {}, "y_m": {}, "ok": {}}
    for new, (_, _, x, y) in zip(final, columns):
        x_m, y_m = _to_metres(x, options), np.asarray(y, dtype=float) / options.divisor
        out["px"][new], out["py"][new] = np.full(len(x_m), np.nan), np.full(len(x_m), np.nan)
        out["x_m"][new], out["y_m"][new] = x_m, y_m
        out["ok"][new] = np.isfinite(x_m) | np.isfinite(y_m)        # a step with either value, as Tracker wrote it
    return out


def _to_metres(x, options: ImportOptions) -> np.ndarray:
    x_m = np.asarray(x, dtype=float) / options.divisor
    return -x_m if options.mirror else x_m


def _convert_tracks_csv(tracks: TracksCsv, options: ImportOptions) -> TracksCsv:
    names = list(tracks.markers)
    final = dict(zip(names, _renames(tracks.path, [(n, None) for n in names], options)))
    renamed = {kind: {final[n]: column for n, column in getattr(tracks, kind).items()}
               for kind in ("px", "py", "ok")}
    renamed["x_m"] = {final[n]: _to_metres(x, options) for n, x in tracks.x_m.items()}
    renamed["y_m"] = {final[n]: y / options.divisor for n, y in tracks.y_m.items()}
    header = None
    if tracks.header is not None:
        header = tuple(f"{final[mk[0]]}_{mk[1]}" if (mk := _marker_column(h)) and mk[0] in final else h
                       for h in tracks.header)
    return replace(tracks, **renamed, header=header,
                   comments=(*tracks.comments, f"converted from {tracks.path.name if tracks.path else 'tracks'}: "
                                               f"{options.describe()}"))


# -- plausibility ------------------------------------------------------------------
DESK_SPAN_M = 5.0        # locust's experiments (a hop, a beam, a ramp) fit on a desk
TYPICAL_SPAN_M = 0.3


def span_warnings(tracks: TracksCsv, options: ImportOptions = AS_IS) -> list[str]:
    """A warning for each marker whose positions span more than :data:`DESK_SPAN_M`, with the
    ``--units`` that would bring it back to a desk's size.

    Parameters
    ----------
    tracks : TracksCsv
    options : ImportOptions
        ``--units``, ``--rename``, ``--mirror``, parsed.

    Returns
    -------
    list of str
    """
    out = []
    for name in tracks.markers_with_positions():
        x, y = tracks.positions(name)
        ok = np.isfinite(x) & np.isfinite(y)
        if ok.sum() < 2:
            continue
        span = float(max(np.ptp(x[ok]), np.ptp(y[ok])))
        if span > DESK_SPAN_M:
            where = tracks.path.name if tracks.path else "tracks"
            out.append(f"{where}: marker {name} spans {_fmt(span)} m, more than the {DESK_SPAN_M:g} m of a desk "
                       f"experiment: {units_hint(span, 1e-3, DESK_SPAN_M, TYPICAL_SPAN_M, options.units)}")
    return out


def likely_units(size_m: float, low_m: float, high_m: float, typical_m: float, given: str = "m") -> str | None:
    """The ``--units`` under which a length read as ``size_m`` (with ``--units given``) would
    lie in ``[low_m, high_m]``, the one nearest ``typical_m``; None when no other unit does.

    Parameters
    ----------
    size_m : float
        The length as read [m].
    low_m, high_m, typical_m : float
        The plausible range and the typical size [m].
    given : str
        The ``--units`` it was read with.

    Returns
    -------
    str or None
    """
    if not (math.isfinite(size_m) and size_m > 0):
        return None
    raw = size_m * UNITS[given]                 # the number in the file
    fits = [u for u in UNITS if u != given and low_m <= raw / UNITS[u] <= high_m]
    return min(fits, key=lambda u: abs(math.log(raw / UNITS[u] / typical_m)), default=None)


def units_hint(size_m: float, low_m: float, high_m: float, typical_m: float, given: str = "m") -> str:
    """What to say about a size out of ``[low_m, high_m]``: the unit that fits, or to check the scale.

    Parameters
    ----------
    size_m, low_m, high_m, typical_m : float
        As for :func:`likely_units` [m].
    given : str

    Returns
    -------
    str
    """
    unit = likely_units(size_m, low_m, high_m, typical_m, given)
    read = "read as metres" if given == "m" else f"read in {given} (--units {given})"
    if unit is None:
        return f"positions {read}; no other unit makes it plausible: check the track's scale"
    return (f"the track is likely in {unit}, not {given} ({_fmt(size_m * UNITS[given] / UNITS[unit])} m then): "
            f"give --units {unit}")


def _fmt(value: float) -> str:
    return f"{value:.3g}"


def _quote(text: str) -> str:
    return text if re.fullmatch(r"[\w=.,:/+-]+", text) else f"'{text}'"
