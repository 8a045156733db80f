"""Tracker (Open Source Physics) files: read ``.trk``/``.trz`` projects, write ``.trk`` projects
and its text export.

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
import os
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from xml.sax.saxutils import escape

import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_text
from .calib import Calibration
from .runner import MarkerTrack, TrackResult
from .tracker_text import TrackerExport, TrackerTrack, tracker_export_text, write_tracker_export
from .video import FPS_MAX, FPS_MIN, Clip

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
    if dt_ms is not None and not 1000.0 / FPS_MAX <= dt_ms <= 1000.0 / FPS_MIN:
        raise TrackError(f"{path}: the clip's frame interval (clip control delta_t) is {dt_ms:g} ms; a camera's is "
                         f"{1000.0 / FPS_MAX:g} to {1000.0 / FPS_MIN:g} ms ({FPS_MIN:g} to {FPS_MAX:g} frames/s), "
                         "and times are frame x delta_t",
                         "set the clip's frame rate in Tracker (Video > Clip Settings) and save the project again")
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


def media_in_zip(project: TrackerProject, trk_path: Path) -> str | None:
    """How a project written at ``trk_path`` names the video inside ``project``'s ``.trz``
    (OSP's ``zip!/entry`` path); None for a plain ``.trk``, whose video is a file of its own."""
    if not zipfile.is_zipfile(project.path) or not project.video_path:
        return None
    with zipfile.ZipFile(project.path) as z:
        trk_name = next(n for n in sorted(z.namelist()) if n.lower().endswith(".trk"))
    entry = (PurePosixPath(trk_name).parent / project.video_path.replace("\\", "/")).as_posix()
    zip_rel = Path(os.path.relpath(project.path.resolve(), Path(trk_path).resolve().parent)).as_posix()
    return f"{zip_rel}!/{entry}"


@contextmanager
def project_media(project: TrackerProject) -> Iterator[Path]:
    """The video (or the image sequence's first file) a project opens, as a local path for the
    duration of the ``with``: beside the ``.trk``, or unpacked from the ``.trz`` into a
    temporary folder removed afterwards."""
    if not project.video_path:
        raise TrackError(f"{project.path}: the project names no video", "give the video itself as VIDEO")
    rel = Path(project.video_path.replace("\\", "/"))
    if not zipfile.is_zipfile(project.path):
        media = rel if rel.is_absolute() else project.path.parent / rel
        if not media.is_file():
            raise TrackError(f"{project.path.name} opens {project.video_path}, which is not at {media}",
                             "put the video where the project expects it, or give the video as VIDEO "
                             f"with --calibration-from {project.path.name}")
        yield media
        return
    with tempfile.TemporaryDirectory(prefix="locust-trz-") as tmp:
        with zipfile.ZipFile(project.path) as z:
            trk_dirs = {PurePosixPath(n).parent for n in z.namelist() if n.lower().endswith(".trk")}
            wanted = [n for n in z.namelist() if not n.endswith("/")
                      and any(PurePosixPath(n).parent == (d / rel).parent for d in trk_dirs)]
            for name in wanted:
                target = Path(tmp, *PurePosixPath(name).parts)
                if ".." in PurePosixPath(name).parts:
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(z.read(name))
        candidates = [Path(tmp, *d.parts) / rel for d in sorted(trk_dirs)]
        media = next((c for c in candidates if c.is_file()), None)
        if media is None:
            raise TrackError(f"{project.path.name} opens {project.video_path}, which is not inside it",
                             "give the video itself as VIDEO, with --calibration-from the project")
        yield media
