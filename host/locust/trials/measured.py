"""Measured inputs of a report or a hop fit: marker tracks and run records, grouped by configuration.

A filmed run is a :class:`Trial` (its tracks, each a :class:`Track`, and its run record): the
one type of a run as measured, beside its file's :class:`~locust.io.run_record.RunRecord`. The
hop fit fills in the robot it simulates a trial on and its phase times
(:func:`locust.calibrate.hopruns.load_run`), the report its trace on a prediction's clock and
its hops (:func:`locust.report.compare.measured`).

``--measured`` takes ``NAME=PATH[,PATH...]`` or plain paths. Each path is one trial:

- a folder holding a track (``*.tracks.csv``, or one CSV/Tracker export with marker columns)
  and/or a ``run.json`` (the record ``locust hop`` wrote, read with
  :func:`locust.io.run_record.read_run_record`);
- a track file (``locust track`` CSV or Tracker text export); a ``run.json`` beside it is
  its run record;
- a ``run.json``; a single ``*.tracks.csv`` beside it is its track.

A plain path's configuration is the leg set its run record names (``locust hop --leg-set``,
or a leg-set ``--preset``), else its folder's name (see :func:`.configs.name_from_path`);
the trial remembers which (``config_from``).
Tracks are read by the track layer's one import (:func:`locust.io.importing.import_tracks`:
a tracks CSV, a Tracker text export or a ``t,x,y`` CSV, with ``--units``, ``--rename`` and
``--mirror``), so the formats and conversions are the same everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import DeviceError, TrackError, TrialError
from ..io.importing import AS_IS, DESK_SPAN_M, TYPICAL_SPAN_M, ImportOptions, import_tracks, units_hint
from ..io.run_record import RECORD_NAME as RUN_NAME
from ..io.run_record import RunRecord, read_run_record
from ..io.tracks_csv import TRACKS_CSV_SUFFIX
from ..params import Robot
from .configs import check_name, name_from_path, sort_key
from .measure import Aligned, MeasuredHop

TRACK_GLOB = f"*{TRACKS_CSV_SUFFIX}"
CONFIG_GIVEN = "given"                   # --measured NAME=PATH
CONFIG_FROM_FOLDER = "folder name"       # guessed by name_from_path
CONFIG_FROM_RECORD = "run record"        # the leg set run.json names


@dataclass(frozen=True)
class Track:
    """One marker's positions, lost frames removed: time (s), x forward and y up (m).

    Attributes
    ----------
    t_s : numpy.ndarray
        The frames' times [s], on the camera's clock.
    x_m, y_m : numpy.ndarray
        The marker forward and up [m], in the track's frame (the board's, or the world's for
        a virtual robot's camera.json).
    marker : str
        The marker's name ("" for a track made, not read).
    path : pathlib.Path or None
        The file it was read from (None: made, not read).
    frames : int
        Rows in the file, lost ones included (0: not read from a file).
    units : str
        The unit the file's positions were in (``--units``).
    mirrored : bool
        Read with ``--mirror``.
    m_per_px : float
        Tracking resolution: one pixel at the marker [m] (nan: no pixels).
    """

    t_s: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    marker: str = ""
    path: Path | None = None
    frames: int = 0      # rows in the file, lost ones included
    units: str = "m"     # the unit the file's positions were in (--units)
    mirrored: bool = False
    m_per_px: float = math.nan   # tracking resolution: one pixel at the marker, in metres (nan: no pixels)

    def until(self, last_s: float) -> Track:
        """The frames up to camera time ``last_s``.

        Parameters
        ----------
        last_s : float
            The last time kept [s], on the track's clock.

        Returns
        -------
        Track
        """
        keep = self.t_s <= last_s
        return replace(self, t_s=self.t_s[keep], x_m=self.x_m[keep], y_m=self.y_m[keep])


@dataclass(frozen=True, eq=False)
class Trial:
    """One filmed run as measured: its configuration, its marker tracks and its run record,
    and, once put on a clock, when its phases started and where its hops went. The one type
    a run has beside its file's :class:`~locust.io.run_record.RunRecord`: the hop fit
    simulates it, the report measures it against a prediction.

    Attributes
    ----------
    config : str
        The configuration's key (a leg set's name).
    label : str
        The short name tables show: the trial's folder.
    tracks : dict of str to Track
        Marker -> its positions; the first is the marker the trial was read for (the nose by
        default); empty for a run without a track.
    run_path : pathlib.Path or None
        Its ``run.json``.
    record : locust.io.run_record.RunRecord or None
        The run record read.
    config_from : str
        How the configuration was known: given, from the run record, or from the folder's name.
    source : pathlib.Path or None
        The path it was given as: a run folder, its ``run.json`` or a track file.
    robot : locust.params.Robot or None
        The robot it is simulated on (the hop fit's: its leg set on the robot being fitted, at
        the run's own push angle); None where none is chosen.
    phase_s : numpy.ndarray or None
        The start of each phase as the firmware measured it, seconds from the first push.
    pushing : numpy.ndarray or None
        Per phase: a push (True) or a wait.
    onset_s : float
        The measured marker's first motion on the camera's clock [s] (nan: not found).
    trace : locust.trials.measure.Aligned or None
        The measured marker on a prediction's clock (t = 0 at the first push), from where it
        stood; None until it is put there.
    hops : tuple of locust.trials.measure.MeasuredHop
        Its hops on that clock, cut at the schedule's cycles.
    """

    config: str
    label: str                       # short name shown in tables: the trial's folder
    tracks: dict[str, Track] = field(default_factory=dict)
    run_path: Path | None = None
    record: RunRecord | None = None
    config_from: str = CONFIG_GIVEN      # how its configuration was known: given, its run record, or its folder
    source: Path | None = None
    robot: Robot | None = None
    phase_s: np.ndarray | None = None
    pushing: np.ndarray | None = None
    onset_s: float = math.nan
    trace: Aligned | None = None
    hops: tuple[MeasuredHop, ...] = ()

    @property
    def track(self) -> Track | None:
        """The marker the trial was read for (the first of :attr:`tracks`); None without a track."""
        return next(iter(self.tracks.values()), None)

    @property
    def end_s(self) -> float:
        """The last frame of any track, seconds after :attr:`onset_s`."""
        return max(float(tr.t_s[-1]) for tr in self.tracks.values()) - self.onset_s

    @property
    def marker_travel_m(self) -> float:
        """The marker's travel summed over :attr:`hops` [m]."""
        return float(sum(h.distance_m for h in self.hops))

    @property
    def marker_travel_per_hop_m(self) -> float:
        """The marker's mean travel per hop [m]; nan without hops."""
        return float(np.mean([h.distance_m for h in self.hops])) if self.hops else math.nan


def parse_measured(items: tuple[str, ...] | list[str], marker: str = "nose",
                   imports: ImportOptions = AS_IS) -> dict[str, list[Trial]]:
    """``--measured`` values -> trials per configuration, in leg-set order; ``imports``
    (``--units``, ``--rename``, ``--mirror``) converts every track.

    Parameters
    ----------
    items : sequence of str
        ``NAME=PATH[,PATH...]`` or plain paths (the configuration then from the run record or the
        folder's name).
    marker : str, default "nose"
        The marker read from each track.
    imports : locust.io.importing.ImportOptions
        How each track is converted (``--units``, ``--rename``, ``--mirror``).

    Returns
    -------
    dict of str to list of Trial
        Configuration -> its trials.

    Raises
    ------
    locust.errors.TrialError
        No items, a trial given twice, or a trial that cannot be read.
    """
    if not items:
        raise TrialError("no measured inputs", "give --measured small=runs/small-1,runs/small-2 (or plain paths)")
    groups: dict[str, list[Trial]] = {}
    for item in items:
        name, paths = _split_item(item)
        for raw in paths:
            path = Path(raw)
            if name:
                trial = load_trial(path, name, marker, imports)
            else:
                name, known_from = config_of(path)
                trial = load_trial(path, name, marker, imports, config_from=known_from)
            groups.setdefault(trial.config, []).append(trial)
    for name, trials in groups.items():
        seen: set[tuple] = set()
        for t in trials:
            key = (t.track.path.resolve() if t.track else None, t.run_path.resolve() if t.run_path else None)
            if key in seen:
                raise TrialError(f"configuration {name}: the trial {t.label} is given twice",
                                  "list each trial once")
            seen.add(key)
    return {k: groups[k] for k in sorted(groups, key=sort_key)}


def _split_item(item: str) -> tuple[str | None, list[str]]:
    name, sep, rest = item.partition("=")
    if sep and name and "/" not in name and not Path(item).exists():
        paths = [p for p in rest.split(",") if p.strip()]
        if not paths:
            raise TrialError(f"--measured {item!r} names no path", "e.g. --measured small=runs/s1,runs/s2")
        return check_name(name), [p.strip() for p in paths]
    return None, [item]


def _must_exist(path: Path) -> None:
    if not path.exists():
        raise TrialError(f"{path}: no such file or folder", "check the --measured path")


def _run_path(path: Path) -> Path | None:
    """The run record of the trial at ``path``: the run.json itself, the one in the folder, or
    the one beside the track."""
    if path.is_dir():
        return path / RUN_NAME if (path / RUN_NAME).is_file() else None
    if path.name.endswith(".json"):
        return path
    return path.parent / RUN_NAME if (path.parent / RUN_NAME).is_file() else None


def config_of(path: Path) -> tuple[str, str]:
    """(configuration, how it is known) of the trial at ``path`` given without a name: the leg
    set its run record names, else its folder's name.

    Parameters
    ----------
    path : pathlib.Path
        A run folder, its ``run.json`` or a track file.

    Returns
    -------
    config : str
        The configuration's key.
    known_from : str
        ``run record`` or ``folder name``.

    Raises
    ------
    locust.errors.TrialError
        Neither names a configuration.
    """
    _must_exist(path)
    run_path = _run_path(path)
    leg_set = read_run(run_path).robot.leg_set if run_path else None
    if leg_set:
        return check_name(leg_set), CONFIG_FROM_RECORD
    return name_from_path(path), CONFIG_FROM_FOLDER


def load_trial(path: Path, config: str, marker: str = "nose", imports: ImportOptions = AS_IS,
               config_from: str = CONFIG_GIVEN) -> Trial:
    """One trial from a run folder, its ``run.json`` or a track file.

    Parameters
    ----------
    path : pathlib.Path
        A folder (holding at most one ``*.tracks.csv`` and maybe a ``run.json``), a ``run.json``
        or a track file.
    config : str
        Its configuration's key.
    marker : str, default "nose"
        The marker read from the track.
    imports : locust.io.importing.ImportOptions
        How the track is converted (``--units``, ``--rename``, ``--mirror``).
    config_from : str
        How ``config`` was known.

    Returns
    -------
    Trial

    Raises
    ------
    locust.errors.TrialError
        No such path, several tracks or none where one is needed, or a track without the marker
        in metres.
    """
    _must_exist(path)
    run_path = _run_path(path)
    if path.is_dir():
        track_path = _one_track(path, required=run_path is None)
        label = path.name
    elif path.name.endswith(".json"):
        track_path, label = _one_track(path.parent, required=False), path.parent.name
    else:
        track_path, label = path, path.parent.name or path.stem
    record = read_run(run_path) if run_path else None
    tracks = {marker: read_track(track_path, marker, imports)} if track_path else {}
    return Trial(config=config, label=label, tracks=tracks, run_path=run_path, record=record, config_from=config_from,
                 source=path)


def _one_track(folder: Path, required: bool) -> Path | None:
    found = sorted(folder.glob(TRACK_GLOB))
    if len(found) > 1:
        raise TrialError(f"{folder}: several tracks ({', '.join(p.name for p in found)})",
                          "give the track file itself as the --measured path")
    if found:
        return found[0]
    if required:
        raise TrialError(f"{folder}: no track (*.tracks.csv) and no run.json",
                          "run `locust track VIDEO` there, or give the track file's path")
    return None


def read_track(path: Path, marker: str = "nose", imports: ImportOptions = AS_IS) -> Track:
    """The ``marker``'s positions in ``path`` (converted by ``imports``); lost frames dropped, time sorted.

    Parameters
    ----------
    path : pathlib.Path
        A track file.
    marker : str, default "nose"
    imports : locust.io.importing.ImportOptions
        How each track is converted (``--units``, ``--rename``, ``--mirror``).

    Returns
    -------
    Track
        Time [s], x forward and y up [m].

    Raises
    ------
    locust.errors.TrialError
        The file cannot be read, or has fewer than 10 frames with the marker in metres, or repeated
        times.
    """
    try:
        tracks = import_tracks(path, options=imports)
        t = tracks.time_s()
        x, y = tracks.positions(marker)
    except TrackError as exc:
        raise TrialError(exc.message, exc.hint) from None
    ok = np.isfinite(t) & np.isfinite(x) & np.isfinite(y)
    if not ok.any():
        scaled = tracks.has_pixels(marker)
        hint = ("the track has pixels but no metres: run `locust track` with --scale or --scale-aruco"
                if scaled else f"the {marker} marker was never found: check the video and the marker colour")
        raise TrialError(f"{path}: no {marker} position in metres in any frame", hint)
    if ok.sum() < 10:
        raise TrialError(f"{path}: only {int(ok.sum())} frames with a {marker} position",
                          "a report needs the whole hop: track the full clip")
    order = np.argsort(t[ok], kind="stable")
    tt = t[ok][order]
    if np.any(np.diff(tt) <= 0):
        raise TrialError(f"{path}: repeated time stamps in t_s",
                          "export the track again; each frame needs its own time")
    return Track(t_s=tt, x_m=x[ok][order], y_m=y[ok][order], marker=marker, path=path, frames=tracks.n_rows,
                 units=imports.units, mirrored=imports.mirror, m_per_px=metres_per_pixel(tracks, marker))


def metres_per_pixel(tracks, marker: str) -> float:
    """The track's own resolution: the median of (step in metres) / (step in pixels) over the
    frame-to-frame steps of at least a pixel; nan for a track without pixel columns.

    Parameters
    ----------
    tracks : locust.io.tracks_csv.TracksCsv
        The file's tracks.
    marker : str

    Returns
    -------
    float
        [m/px].
    """
    if marker not in getattr(tracks, "px", {}):   # a Tracker export has no pixel columns
        return math.nan
    step_px = np.hypot(np.diff(tracks.px[marker]), np.diff(tracks.py[marker]))
    step_m = np.hypot(np.diff(tracks.x_m[marker]), np.diff(tracks.y_m[marker]))
    use = np.isfinite(step_px) & np.isfinite(step_m) & (step_px >= 1.0)
    return float(np.median(step_m[use] / step_px[use])) if use.any() else math.nan


def read_run(path: Path) -> RunRecord:
    """A run record (``locust hop``), read by the device layer that writes it.

    Parameters
    ----------
    path : pathlib.Path
        A ``run.json``.

    Returns
    -------
    locust.io.run_record.RunRecord

    Raises
    ------
    locust.errors.TrialError
        A record that cannot be read.
    """
    try:
        return read_run_record(path)
    except DeviceError as exc:
        raise TrialError(exc.message, exc.hint) from None


def span_hint(track: Track) -> str | None:
    """What to say when a track spans more than a desk robot's camera sees (its units are off).

    Parameters
    ----------
    track : Track

    Returns
    -------
    str or None
        None when the span fits a desk.
    """
    span = float(max(np.ptp(track.x_m), np.ptp(track.y_m))) if len(track.x_m) else 0.0
    if span <= DESK_SPAN_M:
        return None
    return (f"the {track.marker} track spans {span:.3g} m, more than the {DESK_SPAN_M:g} m a camera on a desk "
            f"robot sees: {units_hint(span, 1e-3, DESK_SPAN_M, TYPICAL_SPAN_M, track.units)}")
