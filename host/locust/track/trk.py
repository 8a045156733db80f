"""A tracking result as Tracker (Open Source Physics) files: a ``.trk`` project that opens the
video with one point mass per marker, and Tracker's text export.

Both formats are read and written by their owners, :mod:`locust.io.trk` (with the pixel
convention: Tracker's pixel centres are at i + 0.5, OpenCV's at i) and
:mod:`locust.io.tracker_text`; this module turns a :class:`~.runner.TrackResult` into their
typed objects and back.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import TrackError
from ..io import trk as trk_io
from ..io.tracker_text import TrackerExport, tracker_export_text, write_tracker_export
from ..io.trk import ProjectVideo, TrackerClip, TrackerProject, project_points
from .calib import Calibration
from .runner import TrackResult
from .video import TIMES_FROM_FILE, Clip


def project_result(project: TrackerProject, names: list[str] | None = None) -> TrackResult:
    """The tracks of a Tracker project on its clip's frames (NaN where Tracker has no step).

    Parameters
    ----------
    project : TrackerProject
        A project read by :mod:`locust.io.trk`.
    names : list of str, optional
        The tracks to take; default every point mass.

    Returns
    -------
    TrackResult
        Its tracks [px] with its calibration; no video.
    """
    frames, t_s, points = project_points(project, names)
    c = project.clip
    specs = {p.name: f"tracker:{p.tracker_name}" for p in points}
    return TrackResult.from_pixels(frames, t_s, {p.name: p.px for p in points}, {p.name: p.py for p in points},
                                   {p.name: p.ok for p in points}, specs,
                                   {p.name: np.where(p.ok, 1.0, math.nan) for p in points}, project.calibration,
                                   Clip(c.start, c.end, c.step, c.fps), source=f"tracker project {project.path}")


# --- Tracker's text export (the format itself: :mod:`locust.io.tracker_text`) --------

def tracker_export(result: TrackResult) -> TrackerExport:
    """Tracks as Tracker exports them: per track ``t``, ``x``, ``y`` in world units (m, s),
    NaN (an empty cell) where the marker was not found.

    Parameters
    ----------
    result : TrackResult
        The tracks.

    Returns
    -------
    TrackerExport
        One track per marker.
    """
    t = result.tracks
    scaled = np.isfinite(result.calibration.m_per_px)   # no scale: Tracker exports pixels then, too
    x = {m: np.where(t.ok[m], t.x_m[m] if scaled else t.px[m], np.nan) for m in t.markers}
    y = {m: np.where(t.ok[m], t.y_m[m] if scaled else t.py[m], np.nan) for m in t.markers}
    return TrackerExport({m: m for m in t.markers}, {m: np.where(t.ok[m], t.t_s, np.nan) for m in t.markers}, x, y)


def tracker_text(result: TrackResult) -> str:
    """Tracker's "Export Data" layout of ``result``: a row of track names, a row of ``t x y``
    per track, then tab-separated world values (m, s); a missing step is an empty cell.

    Parameters
    ----------
    result : TrackResult
        The tracks.

    Returns
    -------
    str
        The tab-separated text.
    """
    return tracker_export_text(tracker_export(result))


def write_tracker_text(result: TrackResult, path: Path) -> Path:
    """Write ``result`` in Tracker's text export layout, atomically.

    Parameters
    ----------
    result : TrackResult
        The tracks.
    path : Path
        The file to write.

    Returns
    -------
    Path
        The file written.
    """
    return write_tracker_export(path, tracker_export(result))


# --- A Tracker project (the format itself: :mod:`locust.io.trk`) ------------------------

def check_even_times(result: TrackResult) -> None:
    """Refuse to write ``result`` as a Tracker project when its frames are not evenly spaced: a
    project times every frame as ``frame x delta_t``, which would contradict the video's own
    timestamps (:func:`.video.frame_times_s`).

    Parameters
    ----------
    result : TrackResult

    Raises
    ------
    TrackError
        The times are the video file's uneven timestamps.
    """
    if result.times == TIMES_FROM_FILE:
        raise TrackError(f"{result.video.path if result.video else 'these tracks'}: its frames are not evenly spaced "
                         "(a variable frame rate), and a Tracker project times every frame as frame x delta_t; "
                         "nothing was written", "leave out --trk: the tracks CSV has each frame's own time")


def as_project(result: TrackResult, trk_path: Path, media: str | None = None) -> tuple[TrackerProject, ProjectVideo]:
    """``result`` as the Tracker project saved at ``trk_path``: the video (or the image
    sequence's first file) by its path relative to the project, the clip, the calibration
    (a plane's homography has none in Tracker) and a step on every frame where a marker was
    found. ``media`` overrides the video's path as written (a video inside a ``.trz``:
    ``project.trz!/videos/a.mp4``).

    Parameters
    ----------
    result : TrackResult
        The tracks, with their video.
    trk_path : Path
        Where the project will be saved.
    media : str, optional
        The video's path as written.

    Returns
    -------
    project : TrackerProject
        The project.
    video : ProjectVideo
        The video it opens.

    Raises
    ------
    TrackError
        The tracks have no video, or frames not evenly spaced (:func:`check_even_times`).
    """
    info = result.video
    if info is None:
        raise TrackError("these tracks have no video to open in Tracker", "track a video to write a .trk")
    check_even_times(result)
    clip = result.clip
    rel = media or Path(os.path.relpath((info.images[0] if info.images else info.path).resolve(),
                                        Path(trk_path).resolve().parent)).as_posix()
    t = result.tracks
    frames = [int(f) for f in t.frame]
    end = frames[-1] if frames else clip.start - clip.step
    points = {m: {int(f): (float(x), float(y)) for f, x, y, ok in zip(t.frame, t.px[m], t.py[m], t.ok[m]) if ok}
              for m in t.markers}
    cal = result.calibration if isinstance(result.calibration, Calibration) else None
    project = TrackerProject(Path(trk_path), rel, TrackerClip(clip.start, end, clip.step, clip.fps), cal, points,
                             {m: f"locust track: {result.specs[m]}" for m in t.markers})
    return project, ProjectVideo(rel, bool(info.images), info.width_px, info.height_px, info.frame_count)


def project_xml(result: TrackResult, trk_path: Path, media: str | None = None) -> str:
    """``result`` as a Tracker 6 project's XML (:func:`locust.io.trk.project_xml` of :func:`as_project`).

    Parameters
    ----------
    result : TrackResult
        The tracks, with their video.
    trk_path : Path
        Where the project will be saved.
    media : str, optional
        The video's path as written.

    Returns
    -------
    str
        The XML.
    """
    return trk_io.project_xml(*as_project(result, trk_path, media))


def write_project(result: TrackResult, path: Path, media: str | None = None) -> Path:
    """Write ``result`` as the Tracker project ``path``, atomically (:func:`as_project`).

    Parameters
    ----------
    result : TrackResult
        The tracks, with their video.
    path : Path
        The ``.trk`` to write.
    media : str, optional
        The video's path as written.

    Returns
    -------
    Path
        The file written.
    """
    return trk_io.write_project(*as_project(result, path, media))
