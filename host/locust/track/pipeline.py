"""The tracking job: a video in, its tracks out (the tracks file, its sidecar, an overlay and a
Tracker project, as asked).

``locust track video`` and :func:`locust.track_markers` both run :func:`track_job` with one
:class:`TrackOptions`, so the two doors take the same options and write the same files. The
job says what a person should see (the output folder, warnings) through ``say`` and shows its
progress through ``bars``; it prints nothing itself.

The steps: the Tracker project whose calibration is used (the video itself, or
``calibration_from``), the outputs' names (:mod:`.outputs`), the video probed and the clip
resolved, one calibration (a board or plane points, a project's, or by hand: a stick, an
ArUco marker's size, an origin and axes, or the pinhole camera of a simulated video), the
outputs claimed (locked, none an input, none existing without ``force``), the frame loop
(:func:`.runner.track_video`), then the files.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import TrackError, WriteError
from ..fileio import atomic_write_json, locked
from ..io import trk as trk_io
from ..io.camera_json import camera_json_beside
from ..io.importing import is_project
from ..progress import progress
from . import board, calib, camera, export, overlay, trk
from .aruco import DEFAULT_DICTIONARY, side_px_in_video
from .calib import typed_px
from .outputs import Say, media, named, outputs, quiet, refuse_inputs, refuse_overwrite, tracks_path
from .runner import TrackResult, track_video
from .spec import ModelOptions, parse_markers
from .upright import upside_down_warnings
from .video import Clip, VideoInfo, check_fps, probe

# progress over ``length`` steps under ``label``: a context whose value is called with the steps done
Bars = Callable[[int, str], AbstractContextManager[Callable[[int], None]]]
FORMATS = ("csv", "tracker")
OVERLAYS = ("png", "video", "none")


@dataclass(frozen=True)
class TrackOptions:
    """Every option of ``locust track video``, each checked as far as it can be alone.

    Calibration options hold the text the command line takes (``scale="X1,Y1,X2,Y2=LENGTH_M"``,
    ``scale_aruco="ID=SIDE_M"``, ``origin="X,Y"``, ``board="aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM"``,
    ``plane_points="PX,PY=X_M,Y_M;..."``): the job parses them as the clip needs them.

    Attributes
    ----------
    markers : tuple of str
        ``NAME=SPEC`` (``--marker``); empty: the robot's nose and foot colours.
    model : ModelOptions
        The marker models' settings and the convention of typed pixels (``--color-tol``,
        ``--search``, ``--template-radius``, ``--accept``, ``--likeness``, ``--evolve``, ``--pixels``).
    start, end, step : int
        The frames tracked (``end`` inclusive; None: the last).
    fps : float or None
        The true frame rate [1/s]; None: the file's (or the Tracker project's).
    scale, scale_aruco, aruco_dict, board, plane_points, origin : str or None
        The calibration, as the command line gives it.
    camera_json : pathlib.Path or None
        The pinhole camera of a simulated video; None: ``<video>.camera.json`` beside it.
    angle_deg : float
        Direction of the world x axis, counter-clockwise from the image's [deg].
    calibration_from : pathlib.Path or None
        A Tracker project whose calibration (and frame rate) is used.
    out : pathlib.Path or None
        The tracks file, or the folder it goes in; None: :func:`.outputs.default_folder`.
    files : bool
        Write the tracks file, its sidecar and the overlay (False: the result only, and ``trk``).
    force : bool
        Replace existing outputs.
    fmt : {"csv", "tracker"}
        The tracks file's layout.
    overlay : {"png", "video", "none"}
        The tracks drawn on the last frame, on the whole clip, or not.
    trk : pathlib.Path or None
        Also write a Tracker project (``.trk``) of the tracks.
    """

    markers: tuple[str, ...] = ()
    model: ModelOptions = field(default_factory=ModelOptions)
    start: int = 0
    end: int | None = None
    step: int = 1
    fps: float | None = None
    scale: str | None = None
    scale_aruco: str | None = None
    aruco_dict: str = DEFAULT_DICTIONARY
    board: str | None = None
    plane_points: str | None = None
    camera_json: Path | None = None
    origin: str | None = None
    angle_deg: float = 0.0
    calibration_from: Path | None = None
    out: Path | None = None
    files: bool = True
    force: bool = False
    fmt: str = "csv"
    overlay: str = "png"
    trk: Path | None = None

    def __post_init__(self) -> None:
        self.models()   # a bad --marker is refused before any work
        if not math.isfinite(self.angle_deg):
            raise TrackError(f"--angle {self.angle_deg}: not a finite number", "give --angle as a plain number")
        if self.trk is not None and Path(self.trk).suffix.lower() != ".trk":
            raise TrackError(f"--trk {self.trk}: a Tracker project is written as a .trk file", "e.g. --trk redo.trk")
        check_fps(self.fps)
        if self.fmt not in FORMATS or self.overlay not in OVERLAYS:
            raise TrackError(f"format {self.fmt!r}, overlay {self.overlay!r}: not known",
                             f"the format is one of {', '.join(FORMATS)}, the overlay one of {', '.join(OVERLAYS)}")

    @property
    def pixels(self) -> str:
        """The convention of typed pixel positions (``tracker`` or ``opencv``)."""
        return self.model.pixels

    def models(self) -> list:
        """Fresh marker models for one run (a model learns the marker as it goes).

        Returns
        -------
        list
            One model per marker (:func:`.spec.parse_markers`).
        """
        return parse_markers(list(self.markers), self.model)


@contextlib.contextmanager
def no_bars(length: int, label: str) -> Iterator[Callable[[int], None]]:
    """:data:`Bars` that show nothing.

    Parameters
    ----------
    length : int
    label : str

    Yields
    ------
    callable
        Takes the steps done, and ignores them.
    """
    yield lambda steps: None


@contextlib.contextmanager
def progress_bars(length: int, label: str) -> Iterator[Callable[[int], None]]:
    """:data:`Bars` on stderr (:func:`locust.progress.progress`): a bar on a terminal, a
    plain line every ~10 s elsewhere.

    Parameters
    ----------
    length : int
    label : str

    Yields
    ------
    callable
        Takes the steps done.
    """
    with progress(length=length, label=label) as bar:
        yield bar.update


def track_job(video: str | Path, options: TrackOptions, say: Say = quiet, bars: Bars = no_bars) -> TrackResult:
    """Track the markers of ``video`` and write what ``options`` ask for.

    Parameters
    ----------
    video : path-like
        A video file, an image sequence's folder or first file, or a Tracker project that opens one.
    options : TrackOptions
        The markers, the clip, the calibration and the outputs.
    say : callable
        Told, in order, the output folder and any warning (a line each).
    bars : callable
        Progress over the frames tracked (and drawn, for an overlay video).

    Returns
    -------
    TrackResult
        The tracks, with ``written``: the files written, in order.

    Raises
    ------
    locust.errors.TrackError
        Bad input or options, a marker never found, or an output that may not be written.
    """
    video = named(Path(video))
    project = _project(video, options)
    fps = options.fps
    if project is not None and fps is None and math.isfinite(project.clip.fps):
        fps = project.clip.fps
    with media(video, project) as path:
        paths = outputs(tracks_path(options.out, video, say), options.fmt, options.overlay) if options.files else {}
        if options.trk is not None:
            paths["trk"] = Path(options.trk)
        info = probe(path)
        clip = Clip(options.start, options.end, options.step, fps).resolved(info)
        calibration = _calibration(info, clip, options, project)
        refuse_inputs(paths, [p for p in (path, video, options.camera_json, project and project.path) if p], info)
        with _claimed(paths, options.force):
            result = _track(path, video, options, info, clip, calibration, say, bars)
            return replace(result, written=tuple(_write_all(result, paths, options, project, video, bars)))


def _project(video: Path, options: TrackOptions) -> trk_io.TrackerProject | None:
    """The Tracker project whose calibration is used: ``video`` itself when it is one, else
    ``calibration_from``; refused beside another calibration."""
    if is_project(video):
        if options.calibration_from is not None:
            raise TrackError("VIDEO is a Tracker project: its calibration is used, leave out --calibration-from",
                             "or give the video itself as VIDEO")
        project = trk_io.read_project(video)
    elif options.calibration_from is not None:
        project = trk_io.read_project(options.calibration_from)
    else:
        return None
    if any((options.scale, options.scale_aruco, options.origin, options.camera_json, options.board,
            options.plane_points)):
        raise TrackError("a Tracker project's calibration, or --scale/--scale-aruco/--origin/--camera-json/--board, "
                         "not both", "one calibration per run")
    return project


def _calibration(info: VideoInfo, clip: Clip, options: TrackOptions, project):
    """The one calibration of a run: a board or plane points, a Tracker project's, or by hand."""
    o = options
    if o.board or o.plane_points:
        if o.scale or o.scale_aruco or o.origin or o.camera_json:
            raise TrackError("give --board/--plane-points or --scale/--scale-aruco/--origin/--camera-json, not both",
                             "one calibration per run")
        if o.board and o.plane_points:
            raise TrackError("give --board or --plane-points, not both", "one calibration per run")
        if o.plane_points:
            return board.parse_plane_points(o.plane_points, o.pixels)
        return board.board_homography(info, clip, board.parse_board(o.board))
    if project is not None:
        return project.calibration
    return _by_hand(info, clip, options)


def _by_hand(info: VideoInfo, clip: Clip, options: TrackOptions):
    """A stick or an ArUco marker's size, an origin and axes; or a simulated video's camera."""
    o = options
    if o.scale and o.scale_aruco:
        raise TrackError("give --scale or --scale-aruco, not both", "one calibration per run")
    by_hand = bool(o.scale or o.scale_aruco or o.origin)
    if o.camera_json is not None:
        if by_hand:
            raise TrackError("give --camera-json or --scale/--scale-aruco/--origin, not both",
                             "one calibration per run")
        return camera.load(o.camera_json, info.width_px, info.height_px)
    beside = camera_json_beside(info.path)
    if not by_hand and beside.is_file():
        return camera.load(beside, info.width_px, info.height_px)
    m_per_px, source = math.nan, "none"
    if o.scale:
        x1, y1, x2, y2, length = calib.parse_scale(o.scale)
        m_per_px, source = calib.m_per_px_from_stick(x1, y1, x2, y2, length), f"stick {o.scale}"
    elif o.scale_aruco:
        marker_id, side_m = calib.parse_aruco_scale(o.scale_aruco)
        frame, side = side_px_in_video(info, clip, marker_id, o.aruco_dict)
        m_per_px, source = side_m / side, f"aruco {marker_id} side {side_m} m = {side:.3f} px on frame {frame}"
    point = typed_px(*calib.parse_point(o.origin, "--origin"), o.pixels) if o.origin else None
    return calib.build(info.height_px, m_per_px, point, o.angle_deg, source)


@contextlib.contextmanager
def _claimed(paths: dict[str, Path], force: bool) -> Iterator[None]:
    """The outputs' names claimed for this run (a second ``locust track`` onto them now is
    refused), and none existing without ``force``."""
    if not paths:
        yield
        return
    first = paths.get("tracks", next(iter(paths.values())))
    try:
        with locked(first, wait_s=0):
            refuse_overwrite(paths, force)
            yield
    except WriteError as exc:
        if ".lock beside" not in exc.message:
            raise
        raise TrackError(f"{first} is being written by another `locust track` now",
                         "wait for it to finish (then --force replaces what it wrote), or give this run another "
                         "--out") from None


def _track(path: Path, video: Path, options: TrackOptions, info: VideoInfo, clip: Clip, calibration, say: Say,
           bars: Bars) -> TrackResult:
    """The frame loop over ``path`` (``video`` as named: the video, or a Tracker project that
    opens it), with its warnings said."""
    with bars(len(clip.frames()), f"tracking {path.name}") as update:
        result = track_video(info, clip, options.models(), calibration, progress=update)
    if video != path:   # a Tracker project's video, unpacked from it for this run
        result = replace(result, source=f"locust track of the video in {video}")
    for warning in upside_down_warnings(result):
        say(f"warning: {warning}")
    if options.trk is not None:
        trk.check_even_times(result)   # before anything is written
    return result


def _write_all(result: TrackResult, paths: dict[str, Path], options: TrackOptions, project, video: Path,
               bars: Bars) -> list[Path]:
    """Write the tracks file and sidecar, the Tracker project and the overlay, as ``paths`` name them."""
    written = write_tracks(result, paths, options.fmt) if "tracks" in paths else []
    if options.trk is not None:
        in_zip = trk_io.media_in_zip(project, paths["trk"]) if project is not None and is_project(video) else None
        written.append(trk.write_project(result, paths["trk"], in_zip))
    if "overlay" in paths:
        if options.overlay == "png":
            written.append(overlay.write_png(result, paths["overlay"]))
        else:
            with bars(len(result.tracks.frame), "overlay video") as update:
                written.append(overlay.write_video(result, paths["overlay"], update))
    return written


def write_tracks(result: TrackResult, paths: dict[str, Path], fmt: str) -> list[Path]:
    """Write the tracks file ``paths["tracks"]`` in layout ``fmt`` and its sidecar.

    Parameters
    ----------
    result : TrackResult
    paths : dict of str to pathlib.Path
        ``tracks`` and ``sidecar`` (:func:`.outputs.outputs`).
    fmt : {"csv", "tracker"}

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    if fmt == "tracker":
        trk.write_tracker_text(result, paths["tracks"])
        atomic_write_json(paths["sidecar"], export.sidecar(result, paths["tracks"]))
        return [paths["tracks"], paths["sidecar"]]
    return list(export.write_tracks(result, paths["tracks"]))

