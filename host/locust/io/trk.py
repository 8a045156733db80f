"""Tracker (Open Source Physics) projects: read ``.trk``/``.trz`` files into a typed object.

A project's point tracks come out on its clip's frames (:func:`project_points`), in metres
through its own calibration (:func:`project_tracks`, a :class:`~.tracks_csv.TracksCsv`).
A project is written here too (:func:`project_xml`, :func:`write_project`) from the same
typed object and a :class:`ProjectVideo`, so what is written reads back as it was given.
The text export's layout, reader and typed object are :mod:`.tracker_text`'s; turning a
tracking result into either is :mod:`locust.track.trk`'s.

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
from dataclasses import asdict, dataclass, field
from pathlib import Path, PurePosixPath
from xml.sax.saxutils import escape

import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_text
from .tracks_csv import TracksCsv
from .trz import MAX_TRK_BYTES, open_trz, read_member, unpack_members

TRACKER_TO_OPENCV_PX = -0.5
# a pixel position typed in each convention, plus this, is OpenCV's (Tracker's is the default a
# person copies from its table)
PIXEL_CONVENTIONS = {"tracker": TRACKER_TO_OPENCV_PX, "opencv": 0.0}
POINT_CLASSES = ("PointMass",)  # Tracker's point tracks; vectors, tapes, axes are not tracks of a marker
FPS_MIN, FPS_MAX = 1.0, 10000.0   # frames/s a camera films: a time-lapse at 1/s to a high-speed camera's 10 000/s
# An entity declaration, in the encodings an XML file may have: a Tracker tab has none, and a
# billion laughs or an external entity needs one (expat would expand 8 MB of it before its
# amplification limit stops it)
_ENTITY_MARKS = tuple("<!ENTITY".encode(e) for e in ("utf-8", "utf-16-le", "utf-16-be", "utf-32-le", "utf-32-be"))
# A clip's frames: 0 to a million, an hour at 240 frames/s or 100 s at 10 000 (a hop
# experiment is seconds); the clip's frames and each track are arrays of that length.
MAX_CLIP_FRAMES = 1_000_000
_CLIP_REASON = "an hour at 240 frames/s"
_RESAVE = "open the project in Tracker and save it again, or export its data (File > Export > Data)"
LENGTH_UNITS_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "km": 1000.0, "in": 0.0254, "ft": 0.3048}


@dataclass(frozen=True)
class Calibration:
    """Pixels to world metres as Tracker's calibration stick and axes: a scale, an origin (a
    pixel, OpenCV convention) and the direction of the world x axis, ``angle_deg``
    counter-clockwise on screen from the image x axis (Tracker's ``ImageCoordSystem``)."""

    m_per_px: float  # NaN: no scale given, world columns stay empty
    origin_x_px: float
    origin_y_px: float
    angle_deg: float = 0.0
    source: str = "none"

    def to_world(self, px: np.ndarray, py: np.ndarray, marker: str | None = None,
                 frames: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Image pixels -> world metres (y up). NaN stays NaN. One scale serves every marker and frame.

        Parameters
        ----------
        px, py : numpy.ndarray
            Pixels, OpenCV's convention.
        marker, frames
            Not used by this calibration (the interface of calibrations that depend on them).

        Returns
        -------
        x_m, y_m : numpy.ndarray
            World metres, x along the calibrated axis, y up.
        """
        a = math.radians(self.angle_deg)
        dx = np.asarray(px, float) - self.origin_x_px
        dy = -(np.asarray(py, float) - self.origin_y_px)
        x = self.m_per_px * (dx * math.cos(a) + dy * math.sin(a))
        y = self.m_per_px * (-dx * math.sin(a) + dy * math.cos(a))
        return x, y

    def axes_px(self) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
        """World origin in pixels, and the on-screen unit directions of the world x and y axes.

        Returns
        -------
        origin_px : (float, float)
            The world origin [px].
        x_axis, y_axis : (float, float)
            Unit directions on screen.
        """
        a = math.radians(self.angle_deg)
        return (self.origin_x_px, self.origin_y_px), (math.cos(a), -math.sin(a)), (-math.sin(a), -math.cos(a))

    def summary(self) -> str:
        """The calibration in one line (scale in mm/px, origin in px, x axis in deg).

        Returns
        -------
        str
        """
        if not math.isfinite(self.m_per_px):
            return "no scale given (--scale or --scale-aruco): the *_x_m/*_y_m columns are nan"
        return (f"scale {self.m_per_px * 1000:.5g} mm/px ({self.source}), origin ({self.origin_x_px:.2f}, "
                f"{self.origin_y_px:.2f}) px, x axis {self.angle_deg:g} deg")

    def as_dict(self) -> dict:
        """For the JSON sidecar (no scale: ``m_per_px`` nan, written ``null``).

        Returns
        -------
        dict
        """
        return asdict(self)


@dataclass(frozen=True)
class TrackerClip:
    """A project's clip: frames ``start`` to ``end`` (inclusive) every ``step``, at ``fps``
    (NaN: the project gives no frame interval); time is zero at ``start``, as in Tracker."""

    start: int
    end: int
    step: int
    fps: float


@dataclass(frozen=True)
class ScaleStick:
    """The calibration stick a project's scale was set from: its two ends as placed by hand
    and the length typed for it (Tracker's ``TapeMeasure`` in stick mode).

    Attributes
    ----------
    name : str
        The stick's name in Tracker (``calibration stick A``).
    length_px : float
        Its length on the image [px].
    length_m : float
        The world length given it [m].
    """

    name: str
    length_px: float
    length_m: float


STICK_AGREES = 1e-3    # a stick whose px per m is this far from the axes' scale is not the one that set it


@dataclass
class TrackerProject:
    """A Tracker project (``.trk``) as read or to be written.

    Attributes
    ----------
    path : pathlib.Path
        The project file.
    video_path : str or None
        The video as the project names it.
    clip : TrackerClip
    calibration : Calibration or None
        Scale, origin and axes; None for a project written without one (a plane's homography).
    points : dict of str to dict of int to (float, float)
        Track name -> frame -> (px, py) in pixels, OpenCV's convention.
    descriptions : dict of str to str
        Track name -> its description in Tracker.
    stick : ScaleStick or None
        The calibration stick that set the scale, as read (None: none, or not the one that set it).
    """

    path: Path
    video_path: str | None
    clip: TrackerClip
    calibration: Calibration | None   # None: written without a Tracker calibration (a plane's homography)
    points: dict[str, dict[int, tuple[float, float]]]  # name -> frame -> (px, py), OpenCV convention
    descriptions: dict[str, str] = field(default_factory=dict)   # name -> the track's description in Tracker
    stick: ScaleStick | None = None   # the calibration stick the scale came from, as read


def read_project(path: str | Path) -> TrackerProject:
    """Parse a Tracker ``.trk`` file, or the ``.trk`` inside a ``.trz`` project zip.

    Parameters
    ----------
    path : path-like
        A ``.trk`` or ``.trz``.

    Returns
    -------
    TrackerProject

    Raises
    ------
    locust.errors.TrackError
        No such file, a zip without a ``.trk``, a file over the size limit, XML that is not a
        Tracker project (or declares entities).
    """
    path = Path(path)
    if not path.is_file():
        raise TrackError(f"{path}: no such file", "give the path of a Tracker .trk or .trz file")
    try:
        if zipfile.is_zipfile(path):
            with open_trz(path) as z:
                names = sorted(n for n in z.namelist() if n.lower().endswith(".trk"))
                if not names:
                    raise TrackError(f"{path}: a zip without a .trk file",
                                     "give a Tracker project (.trz) or tab (.trk)")
                text = read_member(path, z, names[0])
        elif path.stat().st_size > MAX_TRK_BYTES:
            raise TrackError(f"{path}: {path.stat().st_size:,} bytes, over the limit of {MAX_TRK_BYTES:,} for a "
                             "Tracker tab", _RESAVE)
        else:
            text = path.read_bytes()
        if any(mark in text for mark in _ENTITY_MARKS):
            raise TrackError(f"{path}: not a Tracker file: it declares XML entities (<!ENTITY), which Tracker never "
                             "writes; refused before any is expanded", "give a .trk saved by Tracker")
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


def _check_clip_settings(path: Path, start: int, step: int, count: int | None) -> None:
    """A clip's frames count up from a frame >= 0 in steps >= 1, at least one of them."""
    for name, value, low in (("startframe", start, 0), ("stepsize", step, 1), ("stepcount", count, 1)):
        if value is not None and value < low:
            raise TrackError(f"{path}: the clip's {name} is {value}; it must be at least {low}",
                             "set the clip again in Tracker (Video > Clip Settings) and save the project")


def _project(path: Path, root: ET.Element) -> TrackerProject:
    clip_obj = _object(_prop(root, "videoclip"))
    control = _object(_prop(root, "clipcontrol"))
    start = _value(clip_obj, "startframe", int, 0)
    step = _value(clip_obj, "stepsize", int, 1)
    count = _value(clip_obj, "stepcount", int, None)
    dt_ms = _value(control, "delta_t", float, None)
    _check_clip_settings(path, start, step, count)
    video = _object(_prop(clip_obj, "video"))
    video_path = _value(video, "path", str, None)

    coords = _object(_prop(root, "coords"))
    frame0 = None
    if coords is not None:
        fd = _prop(coords, "framedata")
        frame0 = _object(fd.find("property")) if fd is not None and fd.find("property") is not None else None
    unit = LENGTH_UNITS_M.get((_value(root, "length_unit", str, "m") or "m").strip(), math.nan)
    px_per_unit = _value(frame0, "xscale", float, math.nan)
    if px_per_unit is not None and px_per_unit <= 0:   # (NaN: no scale, read as pixels)
        raise TrackError(f"{path}: the coordinate system's scale (xscale) is {px_per_unit:g} px per unit; it must be "
                         "above 0 (a negative one would mirror every position)",
                         "set the scale again in Tracker (a calibration stick or tape) and save the project")
    calibration = Calibration(
        m_per_px=unit / px_per_unit if px_per_unit and math.isfinite(px_per_unit) else math.nan,
        origin_x_px=_finite(path, frame0, "xorigin") + TRACKER_TO_OPENCV_PX,
        origin_y_px=_finite(path, frame0, "yorigin") + TRACKER_TO_OPENCV_PX,
        angle_deg=_finite(path, frame0, "angle"),  # degrees in the file
        source=f"tracker:{path.name}")

    points: dict[str, dict[int, tuple[float, float]]] = {}
    tracks = _prop(root, "tracks")
    stick = None
    for item in (tracks.findall("property") if tracks is not None else []):
        obj = item.find("object")
        if obj is not None and stick is None and (obj.get("class") or "").endswith(".TapeMeasure"):
            stick = _stick(obj, unit, calibration.m_per_px)
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
            frame = _frame(path, name, entry.get("name", ""))
            pts[frame] = (x + TRACKER_TO_OPENCV_PX, y + TRACKER_TO_OPENCV_PX)
            if len(pts) > MAX_CLIP_FRAMES:
                raise TrackError(f"{path}: track {name!r} has over {MAX_CLIP_FRAMES:,} steps, the most a clip has "
                                 f"({_CLIP_REASON})", _RESAVE)
        points[name] = pts
    if not points:
        raise TrackError(f"{path}: no point-mass tracks in this Tracker file", "mark a point mass in Tracker first")
    if not count and not any(points.values()):
        raise TrackError(f"{path}: its point-mass tracks ({', '.join(points)}) have no marked steps and the clip "
                         "gives no step count", "mark the point mass on its frames in Tracker and save again")
    end = start + step * (count - 1) if count else max(max(p) for p in points.values() if p)
    _check_clip(path, start, end, step)
    if dt_ms is not None and not 1000.0 / FPS_MAX <= dt_ms <= 1000.0 / FPS_MIN:
        raise TrackError(f"{path}: the clip's frame interval (clip control delta_t) is {dt_ms:g} ms; a camera's is "
                         f"{1000.0 / FPS_MAX:g} to {1000.0 / FPS_MIN:g} ms ({FPS_MIN:g} to {FPS_MAX:g} frames/s), "
                         "and times are frame x delta_t",
                         "set the clip's frame rate in Tracker (Video > Clip Settings) and save the project again")
    fps = 1000.0 / dt_ms if dt_ms else math.nan
    return TrackerProject(path, video_path, TrackerClip(start, end, step, fps), calibration, points, stick=stick)


def _stick(obj: ET.Element, unit_m: float, m_per_px: float) -> ScaleStick | None:
    """A tape in stick mode whose first step's ends and world length give the axes' scale
    (to :data:`STICK_AGREES`); None for a measuring tape, or a stick the scale was not set from."""
    if _value(obj, "stickmode", str, "false") != "true":
        return None
    fd = _prop(obj, "framedata")
    first = _object(fd.find("property")) if fd is not None and fd.find("property") is not None else None
    ends = [_value(first, k) for k in ("x1", "y1", "x2", "y2")]
    lengths = _prop(obj, "worldlengths")
    typed = _value(lengths, "[0]") if lengths is not None else None
    if None in ends or typed is None or not (typed > 0 and math.isfinite(m_per_px)):
        return None
    length_px = math.hypot(ends[2] - ends[0], ends[3] - ends[1])
    length_m = typed * unit_m
    if not (length_px > 0 and abs(length_m / length_px / m_per_px - 1) <= STICK_AGREES):
        return None
    return ScaleStick(_value(obj, "name", str, "calibration stick"), length_px, length_m)


def _finite(path: Path, obj, name: str) -> float:
    """The axes' number ``name`` (0 where not given); :class:`TrackError` if it is not finite."""
    value = _value(obj, name, float, 0.0)
    if not math.isfinite(value):
        raise TrackError(f"{path}: the axes' {name} is {value}, not a finite number", _RESAVE)
    return value


def _frame(path: Path, track: str, name: str) -> int:
    """A step's frame number from its property name ``[N]``: a whole number 0 to the largest frame."""
    text = name.strip()
    digits = text[1:-1].strip() if text.startswith("[") and text.endswith("]") else ""
    if not digits.isdigit() or len(digits) > 12 or int(digits) > MAX_CLIP_FRAMES:
        raise TrackError(f"{path}: track {track!r} has a step on frame {name[:40]!r}; a frame is a whole number "
                         f"0 to {MAX_CLIP_FRAMES:,} ({_CLIP_REASON})", _RESAVE)
    return int(digits)


def _check_clip(path: Path, start: int, end: int, step: int) -> None:
    """:class:`TrackError` unless the clip's frames ``start:end:step`` are whole numbers 0 to
    :data:`MAX_CLIP_FRAMES` in order."""
    if not (0 <= start <= end <= MAX_CLIP_FRAMES and 1 <= step <= MAX_CLIP_FRAMES):
        raise TrackError(f"{path}: the clip runs from frame {start} to {end} every {step}; frames are 0 to "
                         f"{MAX_CLIP_FRAMES:,} ({_CLIP_REASON}), the step at least 1", _RESAVE)


@dataclass(frozen=True)
class ProjectPoints:
    """One point track of a project on its clip's frames: pixels (OpenCV convention), NaN and
    ``ok`` False where Tracker has no step; ``name`` made a plain column name, ``tracker_name``
    as Tracker shows it."""

    name: str
    tracker_name: str
    px: np.ndarray
    py: np.ndarray
    ok: np.ndarray


def project_points(project: TrackerProject, names: list[str] | None = None
                   ) -> tuple[np.ndarray, np.ndarray, list[ProjectPoints]]:
    """The clip's frames, their times (s; NaN without a frame rate) and the point tracks
    ``names`` (default: all) on those frames.

    Parameters
    ----------
    project : TrackerProject
    names : list of str, optional
        The point tracks, by their names (default: all).

    Returns
    -------
    frames : numpy.ndarray
        The clip's frame numbers.
    t_s : numpy.ndarray
        Their times [s], zero at the clip's start.
    tracks : list of ProjectPoints

    Raises
    ------
    locust.errors.TrackError
        A name the project does not hold.
    """
    names = names or list(project.points)
    unknown = [n for n in names if n not in project.points]
    if unknown:
        raise TrackError(f"{project.path.name}: no track named {', '.join(unknown)}",
                         f"its point tracks are: {', '.join(project.points)}")
    clip = project.clip
    frames = np.arange(clip.start, clip.end + 1, clip.step, dtype=int)
    t_s = (frames - clip.start) / clip.fps if math.isfinite(clip.fps) else frames * math.nan
    tracks = []
    for name in names:
        pts = project.points[name]
        px = np.array([pts.get(int(f), (math.nan, math.nan))[0] for f in frames])
        py = np.array([pts.get(int(f), (math.nan, math.nan))[1] for f in frames])
        tracks.append(ProjectPoints(_safe_name(name), name, px, py, np.isfinite(px)))
    return frames, t_s, tracks


def project_tracks(project: TrackerProject, names: list[str] | None = None) -> TracksCsv:
    """A project's point tracks as a tracks CSV: pixels, and world metres through its calibration.

    Parameters
    ----------
    project : TrackerProject
    names : list of str, optional
        The point tracks, by their names (default: all).

    Returns
    -------
    locust.io.tracks_csv.TracksCsv
        Pixels and, with a calibration, metres.

    Raises
    ------
    locust.errors.TrackError
        A name the project does not hold.
    """
    frames, t_s, tracks = project_points(project, names)
    world = {tr.name: project.calibration.to_world(tr.px, tr.py) for tr in tracks}
    return TracksCsv(frame=frames, t_s=t_s, px={tr.name: tr.px for tr in tracks}, py={tr.name: tr.py for tr in tracks},
                     x_m={m: w[0] for m, w in world.items()}, y_m={m: w[1] for m, w in world.items()},
                     ok={tr.name: tr.ok for tr in tracks})


def _safe_name(name: str) -> str:
    out = "".join(c if c.isalnum() else "_" for c in name.strip())
    return out if out and out[0].isalpha() else f"m_{out}"


def media_in_zip(project: TrackerProject, trk_path: Path) -> str | None:
    """How a project written at ``trk_path`` names the video inside ``project``'s ``.trz``
    (OSP's ``zip!/entry`` path); None for a plain ``.trk``, whose video is a file of its own.

    Parameters
    ----------
    project : TrackerProject
        A project read from a ``.trz``, or a plain ``.trk``.
    trk_path : pathlib.Path
        Where the new project is written.

    Returns
    -------
    str or None
    """
    if not zipfile.is_zipfile(project.path) or not project.video_path:
        return None
    with open_trz(project.path) as z:
        trk_name = next(n for n in sorted(z.namelist()) if n.lower().endswith(".trk"))
    entry = (PurePosixPath(trk_name).parent / project.video_path.replace("\\", "/")).as_posix()
    zip_rel = Path(os.path.relpath(project.path.resolve(), Path(trk_path).resolve().parent)).as_posix()
    return f"{zip_rel}!/{entry}"


@contextmanager
def project_media(project: TrackerProject) -> Iterator[Path]:
    """The video (or the image sequence's first file) a project opens, as a local path for the
    duration of the ``with``: beside the ``.trk``, or unpacked from the ``.trz`` into a
    temporary folder removed afterwards.

    Parameters
    ----------
    project : TrackerProject

    Yields
    ------
    pathlib.Path

    Raises
    ------
    locust.errors.TrackError
        The project names no video, or one that is not where it says.
    """
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
    if rel.is_absolute() or ".." in rel.parts:
        raise TrackError(f"{project.path.name} opens {project.video_path}, which is outside the project zip",
                         "give the video itself as VIDEO, with --calibration-from the project")
    with tempfile.TemporaryDirectory(prefix="locust-trz-") as tmp:
        with open_trz(project.path) as z:
            trk_dirs = {PurePosixPath(n).parent for n in z.namelist() if n.lower().endswith(".trk")}
            wanted = [n for n in z.namelist() if not n.endswith("/")
                      and any(PurePosixPath(n).parent == (d / rel).parent for d in trk_dirs)]
            unpack_members(project.path, z, wanted, Path(tmp))
        candidates = [Path(tmp, *d.parts) / rel for d in sorted(trk_dirs)]
        media = next((c for c in candidates if c.is_file()), None)
        if media is None:
            raise TrackError(f"{project.path.name} opens {project.video_path}, which is not inside it",
                             "give the video itself as VIDEO, with --calibration-from the project")
        yield media


# --- Writing a Tracker project ---------------------------------------------------------

TRACKER_VERSION = "6.0.6"  # the schema written: that of the .trk files Tracker 6.0.6 saves
_CORE = "org.opensourcephysics.media.core"
_TRACKER = "org.opensourcephysics.cabrillo.tracker"
_TRACK_RGB = [(255, 0, 255), (0, 255, 255), (255, 255, 0), (255, 128, 0), (0, 128, 255), (0, 255, 128)]


@dataclass(frozen=True)
class ProjectVideo:
    """The media a written project opens: its path as written (relative to the project, or inside
    a ``.trz``), whether it is an image sequence (its first file), its size and frame count."""

    media: str
    images: bool
    width_px: int
    height_px: int
    frame_count: int


def _p(name: str, kind: str, value, indent: int) -> str:
    text = repr(float(value)) if kind == "double" else (str(value).lower() if kind == "boolean" else str(value))
    return f'{" " * indent}<property name="{name}" type="{kind}">{escape(text)}</property>\n'


def _colour(rgb: tuple[int, int, int], indent: int) -> str:
    pad = " " * indent
    body = "".join(_p(c, "int", v, indent + 8) for c, v in zip(("red", "green", "blue", "alpha"), (*rgb, 255)))
    return (f'{pad}<property name="color" type="object">\n{pad}<object class="java.awt.Color">\n{body}'
            f"{pad}</object>\n{pad}</property>\n")


def project_xml(project: TrackerProject, video: ProjectVideo) -> str:
    """``project`` as a Tracker 6 project (``.trk`` XML): ``video``'s media, the clip's frames and
    frame interval, the calibration (scale, origin, axes; none when it is None or has no scale)
    and one point mass per track with a step on each of its frames (pixels in Tracker's
    convention: the OpenCV pixels of ``project.points`` less :data:`TRACKER_TO_OPENCV_PX`).

    Parameters
    ----------
    project : TrackerProject
    video : ProjectVideo
        The media it opens.

    Returns
    -------
    str
    """
    clip = project.clip
    dt_ms = 1000.0 / clip.fps
    if video.images:
        media = (f'        <object class="{_CORE}.ImageVideo">\n' + _p("path", "string", video.media, 12)
                 + _p("delta_t", "double", dt_ms, 12) + "        </object>\n")
    else:
        media = ('        <object class="org.opensourcephysics.media.xuggle.XuggleVideo">\n'
                 + _p("path", "string", video.media, 12) + "        </object>\n")
    count = (clip.end - clip.start) // clip.step + 1
    out = ['<?xml version="1.0" encoding="UTF-8"?>\n', f'<object class="{_TRACKER}.TrackerPanel">\n',
           _p("semantic_version", "string", TRACKER_VERSION, 4), _p("width", "double", video.width_px, 4),
           _p("height", "double", video.height_px, 4),
           f'    <property name="videoclip" type="object">\n    <object class="{_CORE}.VideoClip">\n',
           f'        <property name="video" type="object">\n{media}        </property>\n',
           _p("video_framecount", "int", video.frame_count, 8), _p("startframe", "int", clip.start, 8),
           _p("stepsize", "int", clip.step, 8), _p("stepcount", "int", count, 8), _p("starttime", "double", 0.0, 8),
           _p("readout", "string", "frame", 8), _p("playallsteps", "boolean", True, 8),
           "    </object>\n    </property>\n",
           f'    <property name="clipcontrol" type="object">\n    <object class="{_CORE}.StepperClipControl">\n',
           _p("rate", "double", 1.0, 8), _p("delta_t", "double", dt_ms, 8), _p("frame", "int", clip.start, 8),
           "    </object>\n    </property>\n"]
    cal = project.calibration
    if cal is not None and math.isfinite(cal.m_per_px):
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
    for k, (name, steps_px) in enumerate(project.points.items()):
        steps = "".join(
            f'                <property name="[{int(f)}]" type="object">\n'
            f'                <object class="{_TRACKER}.PointMass$FrameData">\n'
            + _p("x", "double", float(x) - TRACKER_TO_OPENCV_PX, 20)
            + _p("y", "double", float(y) - TRACKER_TO_OPENCV_PX, 20)
            + "                </object>\n                </property>\n"
            for f, (x, y) in steps_px.items())
        out += ['        <property name="item" type="object">\n', f'        <object class="{_TRACKER}.PointMass">\n',
                _p("mass", "double", 1.0, 12), _p("name", "string", name, 12),
                _p("description", "string", project.descriptions.get(name, ""), 12),
                _colour(_TRACK_RGB[k % len(_TRACK_RGB)], 12), _p("footprint", "string", "Footprint.Diamond", 12),
                _p("visible", "boolean", True, 12), _p("trail", "boolean", True, 12),
                f'            <property name="framedata" type="array" class="[L{_TRACKER}.PointMass$FrameData;">\n',
                steps, "            </property>\n        </object>\n        </property>\n"]
    out += ["    </property>\n", "</object>\n"]
    return "".join(out)


def write_project(project: TrackerProject, video: ProjectVideo) -> Path:
    """Write ``project`` to ``project.path`` (see :func:`project_xml`), atomically.

    Parameters
    ----------
    project : TrackerProject
    video : ProjectVideo

    Returns
    -------
    pathlib.Path
        ``project.path``.

    Raises
    ------
    locust.errors.WriteError
        The file cannot be written.
    """
    return atomic_write_text(project.path, project_xml(project, video))
