"""Tracker (Open Source Physics) files: read ``.trk``/``.trz`` projects, write its text export.

The text export's layout, reader and typed object are :mod:`.tracker_text`'s; this module
turns a :class:`~.runner.TrackResult` into one.

Pixel convention. Tracker's image coordinates are measured from the top-left *corner*
of the image (``ImageCoordSystem``: "pixel position relative to the top left corner";
Java2D draws pixel (i, j) over the square [i, i+1) x [j, j+1)), so the centre of pixel i
is at i + 0.5. OpenCV puts it at i. Reading a project therefore subtracts 0.5 px from
every point and from the axes origin; world coordinates are unchanged.

Tracker's world frame (``ImageCoordSystem.updateTransforms``): ``xorigin, yorigin``
(image px), ``angle`` (world x axis counter-clockwise on screen from the image x axis;
stored in the file in *degrees* -- ``FrameDataLoader`` converts to radians on load),
``xscale`` (image px per world length unit).
"""

from __future__ import annotations

import io
import math
import xml.etree.ElementTree as ET
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import TrackError
from .calib import Calibration
from .runner import MarkerTrack, TrackResult
from .tracker_text import TrackerExport, TrackerTrack, tracker_export_text, write_tracker_export
from .video import Clip

TRACKER_TO_OPENCV_PX = -0.5
POINT_CLASSES = ("PointMass",)  # Tracker's point tracks; vectors, tapes, axes are not tracks of a marker
LENGTH_UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "km": 1000.0, "in": 0.0254, "ft": 0.3048}


@dataclass
class TrackerProject:
    path: Path
    video_path: str | None
    clip: Clip
    calibration: Calibration
    points: dict[str, dict[int, tuple[float, float]]]  # name -> frame -> (px, py), OpenCV convention


def read_project(path: str | Path) -> TrackerProject:
    """Parse a Tracker ``.trk`` file, or the ``.trk`` inside a ``.trz`` project zip."""
    path = Path(path)
    if not path.is_file():
        raise TrackError(f"{path}: no such file", "give the path of a Tracker .trk or .trz file")
    try:
        if zipfile.is_zipfile(path):
            with zipfile.ZipFile(path) as z:
                names = sorted(n for n in z.namelist() if n.lower().endswith(".trk"))
                if not names:
                    raise TrackError(f"{path}: a zip without a .trk file",
                                     "give a Tracker project (.trz) or tab (.trk)")
                text = z.read(names[0])
        else:
            text = path.read_bytes()
        root = ET.parse(io.BytesIO(text)).getroot()
    except ET.ParseError as exc:
        raise TrackError(f"{path}: not a Tracker file (XML error: {exc})", "give a .trk saved by Tracker") from None
    except (zipfile.BadZipFile, OSError) as exc:
        raise TrackError(f"{path}: cannot read ({exc})", "check the file is a complete Tracker project") from None
    if "TrackerPanel" not in (root.get("class") or ""):
        raise TrackError(f"{path}: an XML file but not a Tracker tab (root is {root.get('class')!r})",
                         "give a .trk saved by Tracker")
    return _project(path, root)


def _prop(obj: ET.Element | None, name: str):
    if obj is None:
        return None
    for p in obj.findall("property"):
        if p.get("name") == name:
            return p
    return None


def _value(obj, name, cast=float, default=None):
    p = _prop(obj, name)
    if p is None or p.text is None:
        return default
    try:
        return cast(p.text.strip())
    except ValueError:
        return default


def _object(p: ET.Element | None) -> ET.Element | None:
    return None if p is None else p.find("object")


def _project(path: Path, root: ET.Element) -> TrackerProject:
    clip_obj = _object(_prop(root, "videoclip"))
    control = _object(_prop(root, "clipcontrol"))
    start = _value(clip_obj, "startframe", int, 0)
    step = _value(clip_obj, "stepsize", int, 1)
    count = _value(clip_obj, "stepcount", int, None)
    dt_ms = _value(control, "delta_t", float, None)
    video = _object(_prop(clip_obj, "video"))
    video_path = _value(video, "path", str, None)

    coords = _object(_prop(root, "coords"))
    frame0 = None
    if coords is not None:
        fd = _prop(coords, "framedata")
        frame0 = _object(fd.find("property")) if fd is not None and fd.find("property") is not None else None
    unit = LENGTH_UNITS_M.get((_value(root, "length_unit", str, "m") or "m").strip(), math.nan)
    px_per_unit = _value(frame0, "xscale", float, math.nan)
    calibration = Calibration(
        m_per_px=unit / px_per_unit if px_per_unit and math.isfinite(px_per_unit) else math.nan,
        origin_x_px=_value(frame0, "xorigin", float, 0.0) + TRACKER_TO_OPENCV_PX,
        origin_y_px=_value(frame0, "yorigin", float, 0.0) + TRACKER_TO_OPENCV_PX,
        angle_deg=_value(frame0, "angle", float, 0.0),  # degrees in the file
        source=f"tracker:{path.name}")

    points: dict[str, dict[int, tuple[float, float]]] = {}
    tracks = _prop(root, "tracks")
    for item in (tracks.findall("property") if tracks is not None else []):
        obj = item.find("object")
        if obj is None or not (obj.get("class") or "").endswith(POINT_CLASSES):
            continue
        name = _value(obj, "name", str, f"track{len(points) + 1}")
        fd = _prop(obj, "framedata")
        pts = {}
        for entry in (fd.findall("property") if fd is not None else []):
            step_obj = entry.find("object")
            x, y = _value(step_obj, "x"), _value(step_obj, "y")
            if x is None or y is None:
                continue
            frame = int(entry.get("name", "[-1]").strip("[]"))
            pts[frame] = (x + TRACKER_TO_OPENCV_PX, y + TRACKER_TO_OPENCV_PX)
        points[name] = pts
    if not points:
        raise TrackError(f"{path}: no point-mass tracks in this Tracker file", "mark a point mass in Tracker first")
    end = start + step * (count - 1) if count else max(max(p) for p in points.values() if p)
    fps = 1000.0 / dt_ms if dt_ms else math.nan
    return TrackerProject(path, video_path, Clip(start, end, step, fps), calibration, points)


def project_result(project: TrackerProject, names: list[str] | None = None) -> TrackResult:
    """The tracks of a Tracker project on its clip's frames (NaN where Tracker has no step)."""
    names = names or list(project.points)
    unknown = [n for n in names if n not in project.points]
    if unknown:
        raise TrackError(f"{project.path.name}: no track named {', '.join(unknown)}",
                         f"its point tracks are: {', '.join(project.points)}")
    clip = project.clip
    frames = np.array(list(clip.frames()), dtype=int)
    t_s = np.array([clip.time_s(int(f)) for f in frames]) if math.isfinite(clip.fps) else frames * math.nan
    tracks = []
    for name in names:
        pts = project.points[name]
        px = np.array([pts.get(int(f), (math.nan, math.nan))[0] for f in frames])
        py = np.array([pts.get(int(f), (math.nan, math.nan))[1] for f in frames])
        ok = np.isfinite(px)
        tracks.append(MarkerTrack(_safe_name(name), f"tracker:{name}", px, py, np.where(ok, 1.0, math.nan), ok))
    return TrackResult(None, clip, frames, t_s, tracks, project.calibration, source=f"tracker project {project.path}")


def _safe_name(name: str) -> str:
    out = "".join(c if c.isalnum() else "_" for c in name.strip())
    return out if out and out[0].isalpha() else f"m_{out}"


# --- Tracker's text export (the format itself: :mod:`.tracker_text`) ------------------

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
