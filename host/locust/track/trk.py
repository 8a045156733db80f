"""A tracking result as Tracker (Open Source Physics) files: a ``.trk`` project that opens the
video with one point mass per marker, and Tracker's text export.

Reading projects (and the pixel convention: Tracker's pixel centres are at i + 0.5, OpenCV's
at i) is :mod:`locust.io.trk`'s; the text export's layout, reader and typed object are
:mod:`locust.io.tracker_text`'s. This module turns a :class:`~.runner.TrackResult` into them.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from xml.sax.saxutils import escape

import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_text
from ..io.tracker_text import TrackerExport, TrackerTrack, tracker_export_text, write_tracker_export
from ..io.trk import TRACKER_TO_OPENCV_PX, TrackerProject, project_points
from .calib import Calibration
from .runner import MarkerTrack, TrackResult
from .video import Clip


def project_result(project: TrackerProject, names: list[str] | None = None) -> TrackResult:
    """The tracks of a Tracker project on its clip's frames (NaN where Tracker has no step)."""
    frames, t_s, points = project_points(project, names)
    tracks = [MarkerTrack(p.name, f"tracker:{p.tracker_name}", p.px, p.py, np.where(p.ok, 1.0, math.nan), p.ok)
              for p in points]
    c = project.clip
    return TrackResult(None, Clip(c.start, c.end, c.step, c.fps), frames, t_s, tracks, project.calibration,
                       source=f"tracker project {project.path}")


# --- Tracker's text export (the format itself: :mod:`locust.io.tracker_text`) --------

def tracker_export(result: TrackResult) -> TrackerExport:
    """Tracks as Tracker exports them: per track ``t``, ``x``, ``y`` in world units (m, s),
    NaN (an empty cell) where the marker was not found."""
    tracks = {}
    for tr in result.markers:
        x, y = result.world(tr)
        if not np.isfinite(result.calibration.m_per_px):
            x, y = tr.px, tr.py  # no scale: Tracker exports pixels then, too
        tracks[tr.name] = TrackerTrack(tr.name, np.where(tr.ok, result.t_s, np.nan), np.where(tr.ok, x, np.nan),
                                       np.where(tr.ok, y, np.nan))
    return TrackerExport(tracks)


def tracker_text(result: TrackResult) -> str:
    """Tracker's "Export Data" layout of ``result``: a row of track names, a row of ``t x y``
    per track, then tab-separated world values (m, s); a missing step is an empty cell."""
    return tracker_export_text(tracker_export(result))


def write_tracker_text(result: TrackResult, path: Path) -> Path:
    """Write ``result`` in Tracker's text export layout, atomically."""
    return write_tracker_export(path, tracker_export(result))


# --- Writing a Tracker project ---------------------------------------------------------

TRACKER_VERSION = "6.0.6"  # the schema written: that of the .trk files Tracker 6.0.6 saves
_CORE = "org.opensourcephysics.media.core"
_TRACKER = "org.opensourcephysics.cabrillo.tracker"
_TRACK_RGB = [(255, 0, 255), (0, 255, 255), (255, 255, 0), (255, 128, 0), (0, 128, 255), (0, 255, 128)]


def _p(name: str, kind: str, value, indent: int) -> str:
    text = repr(float(value)) if kind == "double" else (str(value).lower() if kind == "boolean" else str(value))
    return f'{" " * indent}<property name="{name}" type="{kind}">{escape(text)}</property>\n'


def _colour(rgb: tuple[int, int, int], indent: int) -> str:
    pad = " " * indent
    body = "".join(_p(c, "int", v, indent + 8) for c, v in zip(("red", "green", "blue", "alpha"), (*rgb, 255)))
    return (f'{pad}<property name="color" type="object">\n{pad}<object class="java.awt.Color">\n{body}'
            f"{pad}</object>\n{pad}</property>\n")


def project_xml(result: TrackResult, trk_path: Path, media: str | None = None) -> str:
    """``result`` as a Tracker 6 project (``.trk`` XML) saved at ``trk_path``: the video (or the
    image sequence's first file) by its path relative to the project, the clip's frames and
    frame interval, the calibration (scale, origin, axes) and one point mass per marker, with a
    step on every frame where the marker was found (pixels in Tracker's convention). ``media``
    overrides the video's path as written (a video inside a ``.trz``: ``project.trz!/videos/a.mp4``)."""
    info = result.video
    if info is None:
        raise TrackError("these tracks have no video to open in Tracker", "track a video to write a .trk")
    clip = result.clip
    rel = media or Path(os.path.relpath((info.images[0] if info.images else info.path).resolve(),
                                        trk_path.resolve().parent)).as_posix()
    dt_ms = 1000.0 / clip.fps
    if info.images:
        video = (f'        <object class="{_CORE}.ImageVideo">\n' + _p("path", "string", rel, 12)
                 + _p("delta_t", "double", dt_ms, 12) + "        </object>\n")
    else:
        video = ('        <object class="org.opensourcephysics.media.xuggle.XuggleVideo">\n'
                 + _p("path", "string", rel, 12) + "        </object>\n")
    count = len(result.frames)
    out = ['<?xml version="1.0" encoding="UTF-8"?>\n', f'<object class="{_TRACKER}.TrackerPanel">\n',
           _p("semantic_version", "string", TRACKER_VERSION, 4), _p("width", "double", info.width_px, 4),
           _p("height", "double", info.height_px, 4),
           f'    <property name="videoclip" type="object">\n    <object class="{_CORE}.VideoClip">\n',
           f'        <property name="video" type="object">\n{video}        </property>\n',
           _p("video_framecount", "int", info.frame_count, 8), _p("startframe", "int", clip.start, 8),
           _p("stepsize", "int", clip.step, 8), _p("stepcount", "int", count, 8), _p("starttime", "double", 0.0, 8),
           _p("readout", "string", "frame", 8), _p("playallsteps", "boolean", True, 8),
           "    </object>\n    </property>\n",
           f'    <property name="clipcontrol" type="object">\n    <object class="{_CORE}.StepperClipControl">\n',
           _p("rate", "double", 1.0, 8), _p("delta_t", "double", dt_ms, 8), _p("frame", "int", clip.start, 8),
           "    </object>\n    </property>\n"]
    cal = result.calibration
    if isinstance(cal, Calibration) and math.isfinite(cal.m_per_px):
        frame_data = "".join((_p("xorigin", "double", cal.origin_x_px - TRACKER_TO_OPENCV_PX, 16),
                              _p("yorigin", "double", cal.origin_y_px - TRACKER_TO_OPENCV_PX, 16),
                              _p("angle", "double", cal.angle_deg, 16), _p("xscale", "double", 1.0 / cal.m_per_px, 16),
                              _p("yscale", "double", 1.0 / cal.m_per_px, 16)))
        out += [f'    <property name="coords" type="object">\n    <object class="{_CORE}.ImageCoordSystem">\n',
                _p("fixedorigin", "boolean", True, 8), _p("fixedangle", "boolean", True, 8),
                _p("fixedscale", "boolean", True, 8), _p("locked", "boolean", False, 8),
                f'        <property name="framedata" type="array" class="[L{_CORE}.ImageCoordSystem$FrameData;">\n'
                f'            <property name="[0]" type="object">\n'
                f'            <object class="{_CORE}.ImageCoordSystem$FrameData">\n{frame_data}'
                "            </object>\n            </property>\n        </property>\n    </object>\n    </property>\n",
                _p("length_unit", "string", "m", 4)]
    out.append('    <property name="tracks" type="collection" class="java.util.ArrayList">\n')
    for k, tr in enumerate(result.markers):
        steps = "".join(
            f'                <property name="[{int(f)}]" type="object">\n'
            f'                <object class="{_TRACKER}.PointMass$FrameData">\n'
            + _p("x", "double", float(x) - TRACKER_TO_OPENCV_PX, 20)
            + _p("y", "double", float(y) - TRACKER_TO_OPENCV_PX, 20)
            + "                </object>\n                </property>\n"
            for f, x, y, ok in zip(result.frames, tr.px, tr.py, tr.ok) if ok)
        out += ['        <property name="item" type="object">\n', f'        <object class="{_TRACKER}.PointMass">\n',
                _p("mass", "double", 1.0, 12), _p("name", "string", tr.name, 12),
                _p("description", "string", f"locust track: {tr.spec}", 12),
                _colour(_TRACK_RGB[k % len(_TRACK_RGB)], 12), _p("footprint", "string", "Footprint.Diamond", 12),
                _p("visible", "boolean", True, 12), _p("trail", "boolean", True, 12),
                f'            <property name="framedata" type="array" class="[L{_TRACKER}.PointMass$FrameData;">\n',
                steps, "            </property>\n        </object>\n        </property>\n"]
    out += ["    </property>\n", "</object>\n"]
    return "".join(out)


def write_project(result: TrackResult, path: Path, media: str | None = None) -> Path:
    """Write ``result`` as a Tracker project ``path`` (see :func:`project_xml`), atomically."""
    return atomic_write_text(path, project_xml(result, Path(path), media))
