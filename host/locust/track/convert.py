"""Another program's tracks as locust's: ``locust track import`` and ``locust track from-trk``.

A Tracker project's point tracks go through its own calibration (:func:`convert_project`);
a Tracker text export, a ``t,x,y`` CSV or a tracks CSV through the one import of every track
file (:func:`locust.io.importing.import_tracks`: units, renames, mirror), into a tracks CSV
in metres (:func:`import_file`). Both write into the output folder of :mod:`.outputs`.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from ..errors import TrackError
from ..io import trk as trk_io
from ..io.importing import ImportOptions, import_tracks, is_project, span_warnings
from ..io.tracks_csv import write_tracks_csv
from ..tables import mm
from .export import report_lines
from .outputs import Say, outputs, quiet, refuse_inputs, refuse_overwrite, tracks_path
from .pipeline import write_tracks
from .runner import TrackResult
from .trk import project_result


def convert_project(path: Path, names: list[str], out: Path | None, fmt: str, force: bool,
                    say: Say = quiet) -> TrackResult:
    """Write the point tracks ``names`` (all when empty) of the Tracker project ``path`` as a
    tracks file in layout ``fmt``, in metres through the project's calibration.

    Parameters
    ----------
    path : pathlib.Path
        A ``.trk``, or a ``.trz``/``.zip`` holding one.
    names : list of str
        Its point tracks to take; empty: every one.
    out : pathlib.Path or None
        ``--out``.
    fmt : {"csv", "tracker"}
    force : bool
        Replace existing outputs.
    say : callable
        Told the output folder.

    Returns
    -------
    TrackResult
        The project's tracks, with the files written.

    Raises
    ------
    locust.errors.TrackError
        An unreadable project, a track it does not hold, or an output that may not be written.
    """
    paths = outputs(tracks_path(out, path, say), fmt, "none")
    result = project_result(trk_io.read_project(path), names or None)
    refuse_inputs(paths, [path])
    refuse_overwrite(paths, force)
    return replace(result, written=tuple(write_tracks(result, paths, fmt)))


def import_file(file: Path, imports: ImportOptions, trk_names: list[str], out: Path | None, force: bool,
                say: Say = quiet) -> list[str]:
    """Convert ``file`` (a Tracker text export, a t,x,y CSV, a tracks CSV or a Tracker project)
    into a tracks CSV in metres, as ``imports`` say.

    A Tracker project converted as it is (no renames, not mirrored) goes through
    :func:`convert_project`, ``trk_names`` its tracks; renamed or mirrored, through the import
    layer, which refuses ``--units`` for it.

    Parameters
    ----------
    file : pathlib.Path
    imports : ImportOptions
        ``--units``, ``--rename``, ``--mirror``.
    trk_names : list of str
        ``--track``: a Tracker project's tracks.
    out : pathlib.Path or None
        ``--out``.
    force : bool
        Replace an existing tracks CSV.
    say : callable
        Told the output folder and any warning.

    Returns
    -------
    list of str
        What to print: the rows converted, each marker's span in mm, the file written.

    Raises
    ------
    locust.errors.TrackError
        A file in no known layout, a bad option, or an output that may not be written.
    """
    if is_project(file) and imports.identity:
        return report_lines(convert_project(file, trk_names, out, "csv", force, say))
    if trk_names:
        raise TrackError("--track picks the tracks of a Tracker project converted as it is",
                         "leave out --rename and --mirror, or leave out --track")
    target = tracks_path(out, file, say)
    tracks = import_tracks(file, options=imports)
    if target.exists() and target.resolve() == file.resolve():
        raise TrackError(f"--out {target} is the file being imported", "write the tracks CSV to another --out")
    refuse_overwrite({"tracks": target}, force)
    for warning in span_warnings(tracks, imports):
        say(f"warning: {warning}")
    write_tracks_csv(target, tracks)
    lines = [f"{file.name}: {tracks.n_rows} rows, {imports.describe()}"]
    for name in tracks.markers_with_positions():
        x, y = tracks.positions(name)
        ok = np.isfinite(x) & np.isfinite(y)
        if ok.any():
            # the span a person checks the conversion by, in mm (the CSV keeps metres)
            lines.append(f"  {name}: {int(ok.sum())} rows with a position; x {mm(x[ok].min(), 1)} .. "
                         f"{mm(x[ok].max(), 1)} mm, y {mm(y[ok].min(), 1)} .. {mm(y[ok].max(), 1)} mm")
        else:
            lines.append(f"  {name}: no position")
    return [*lines, f"wrote {target}"]
