"""Pixels to metres through a known pinhole camera: ``<video>.camera.json``.

A simulated video (``locust sim --video``, the virtual robot's ``--video``) carries the
camera it was rendered with: intrinsics ``K``, the world-to-camera rotation and the camera
position (fixed, or one per frame for a camera that follows the robot), and the plane
``y = plane_y_m`` each marker's visible centre moves in. A pixel then names one ray from
the camera centre, and the ray meets the marker's plane in exactly one point: the
pixel -> (x, z) map is a plane homography, exact for a pinhole camera, with no scale to
click. World output: ``x_m`` along the floor, ``y_m`` up (the simulation's z), metres,
origin at the simulation's world origin (on the floor).

This module owns the file: :class:`CameraFile` is its typed form,
:func:`write_camera_json` its one writer, :func:`read_camera_json` its one reader and
:func:`camera_json_beside` its name beside a video; :func:`locust.track.camera.load` turns
it into the pixel -> world map that tracking uses.
"""

from __future__ import annotations

import json
import math
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_json
from .tracks_csv import same_array

CAMERA_JSON_SUFFIX = ".camera.json"
CAMERA_NOTE = ("simulated camera (MuJoCo free camera); OpenCV pinhole convention: camera x right, "
               "y down, z forward; pixel origin at the centre of the top-left pixel")
PLANES_NOTE = ("each marker's visible centre moves in the world plane y = plane_y_m (world: x along "
               "the floor, y toward the camera, z up); truth x_m, z_m are in that plane")
CHASSIS_MID_PLANE_Y_M = 0.0   # the robot's mid-plane, where a fixed camera's m/px is also given


def camera_json_beside(video: Path) -> Path:
    """``hop.mp4`` -> ``hop.camera.json`` (where the simulation writes it).

    Parameters
    ----------
    video : pathlib.Path

    Returns
    -------
    pathlib.Path
    """
    return video.with_name(video.stem + CAMERA_JSON_SUFFIX)


@dataclass(frozen=True)
class MarkerPlane:
    """The world plane ``y = plane_y_m`` a marker's visible centre moves in."""

    plane_y_m: float
    max_off_plane_m: float = math.nan      # how far the centre strays from it (nan: not given)


@dataclass(frozen=True, eq=False)
class CameraFile:
    """A ``camera.json``: the pinhole camera a video was rendered with, and each marker's plane.

    ``camera`` is ``fixed`` (one position) or ``track`` (it follows the robot: one position
    per frame, frame 0 first, each with its time in ``frame_t_s``). ``view`` is the
    simulation's framing (``lookat_m``, ``distance_m``, ``azimuth_deg``, ``elevation_deg``),
    kept for the reader's information. Equality compares every field (NaN equal to NaN).
    """

    camera: str
    width_px: int
    height_px: int
    K: np.ndarray                            # (3, 3) intrinsics, OpenCV pixel convention
    rotation: np.ndarray                     # (3, 3) world -> camera
    positions_m: np.ndarray                  # (F, 3) camera centre per frame, or (1, 3) for a fixed camera
    marker_planes: dict[str, MarkerPlane]
    fps: float | None = None
    frames: int | None = None
    frame_t_s: np.ndarray | None = None      # (F,) for a track camera
    view: dict | None = None

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, CameraFile):
            return NotImplemented
        arrays = ("K", "rotation", "positions_m", "frame_t_s")
        return (all(same_array(getattr(self, a), getattr(other, a)) for a in arrays)
                and all(getattr(self, f) == getattr(other, f) for f in ("camera", "width_px", "height_px", "fps",
                                                                       "frames", "view"))
                and self.marker_planes.keys() == other.marker_planes.keys()
                and all(same_array(np.array([p.plane_y_m, p.max_off_plane_m]),
                              np.array([other.marker_planes[n].plane_y_m, other.marker_planes[n].max_off_plane_m]))
                        for n, p in self.marker_planes.items()))

    __hash__ = None  # type: ignore[assignment]

    @property
    def planes_y_m(self) -> dict[str, float]:
        """Each marker's plane, its distance along the camera's depth axis y [m]."""
        return {n: p.plane_y_m for n, p in self.marker_planes.items()}

    def m_per_px_at(self, plane_y_m: float) -> float:
        """Metres per pixel at the plane ``y = plane_y_m``, seen from the first camera position.

        Parameters
        ----------
        plane_y_m : float
            The plane's place along the world y axis [m].

        Returns
        -------
        float
            [m/px].
        """
        depth = float(((np.atleast_2d([0.0, plane_y_m, 0.0]) - self.positions_m[0]) @ self.rotation.T)[0, 2])
        return depth / float(self.K[0, 0])

    def to_dict(self) -> dict:
        """The file's JSON document.

        Returns
        -------
        dict
        """
        R, K = self.rotation, self.K
        out: dict = {"note": CAMERA_NOTE, "camera": self.camera, "width_px": self.width_px, "height_px": self.height_px}
        if self.fps is not None:
            out["fps"] = self.fps
        if self.frames is not None:
            out["frames"] = self.frames
        if self.view is not None:
            out["view"] = self.view
        out["intrinsics"] = {"fx_px": float(K[0, 0]), "fy_px": float(K[1, 1]), "cx_px": float(K[0, 2]),
                             "cy_px": float(K[1, 2]), "K": K.tolist()}
        out["marker_planes"] = {"note": PLANES_NOTE, **{n: {"plane_y_m": p.plane_y_m,
                                                            "max_off_plane_m": p.max_off_plane_m}
                                                        for n, p in self.marker_planes.items()}}
        if self.camera == "fixed":
            pos = self.positions_m[0]
            out["extrinsics"] = {"rotation_world_to_camera": R.tolist(), "translation_m": (-R @ pos).tolist(),
                                 "position_m": pos.tolist()}
            planes = {"chassis_mid_plane": CHASSIS_MID_PLANE_Y_M,
                      **{f"{n}_plane": p.plane_y_m for n, p in self.marker_planes.items()}}
            out["m_per_px"] = {name: {"plane_y_m": y, "m_per_px": self.m_per_px_at(y)} for name, y in planes.items()}
        else:
            times = self.frame_t_s if self.frame_t_s is not None else np.full(len(self.positions_m), math.nan)
            out["rotation_world_to_camera"] = R.tolist()
            out["extrinsics_per_frame"] = [{"frame": k, "t_s": float(t), "position_m": p.tolist(),
                                            "translation_m": (-R @ p).tolist()}
                                           for k, (t, p) in enumerate(zip(times, self.positions_m))]
        return out


def write_camera_json(path: Path, camera: CameraFile) -> Path:
    """Write ``camera`` to ``path`` (e.g. :func:`camera_json_beside` a video) atomically.

    Parameters
    ----------
    path : pathlib.Path
    camera : CameraFile

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    locust.errors.WriteError
        The file cannot be written.
    """
    return atomic_write_json(path, camera.to_dict())


# A camera.json is kB (fixed) to a few MB (a moving camera's pose on every frame of minutes).
MAX_CAMERA_JSON_BYTES = 64 * 2**20


def read_camera_json(path: str | Path) -> CameraFile:
    """Read a ``camera.json``; a :class:`~locust.errors.TrackError` says what is missing or malformed.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    CameraFile

    Raises
    ------
    locust.errors.TrackError
        Not a readable camera file, a value missing, or matrices that are not 3x3 finite numbers.
    """
    path = Path(path)
    try:
        if not stat.S_ISREG(path.stat().st_mode) or path.stat().st_size > MAX_CAMERA_JSON_BYTES:
            raise TrackError(f"{path}: not a camera file (not a regular file, or over {MAX_CAMERA_JSON_BYTES:,} bytes)",
                             "re-render the video, or move the file away and give --scale")
        doc = json.loads(path.read_text())
    except RecursionError:
        raise TrackError(f"{path}: not a camera file (its lists or objects are nested too deep to read)",
                         "re-render the video, or move the file away and give --scale") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise TrackError(f"{path}: not a readable camera file ({exc})",
                         "re-render the video, or move the file away and give --scale") from None
    try:
        K = np.array(doc["intrinsics"]["K"], dtype=float)
        planes = {str(n): MarkerPlane(float(p["plane_y_m"]), _float(p.get("max_off_plane_m")))
                  for n, p in doc["marker_planes"].items() if isinstance(p, dict)}
        times = None
        if doc["camera"] == "fixed":
            rotation = np.array(doc["extrinsics"]["rotation_world_to_camera"], dtype=float)
            positions = np.array([doc["extrinsics"]["position_m"]], dtype=float)
        else:
            rotation = np.array(doc["rotation_world_to_camera"], dtype=float)
            per_frame = sorted(doc["extrinsics_per_frame"], key=lambda e: int(e["frame"]))
            positions = np.array([e["position_m"] for e in per_frame], dtype=float)
            times = np.array([_float(e.get("t_s")) for e in per_frame])
        camera = CameraFile(camera=str(doc["camera"]), width_px=int(doc["width_px"]), height_px=int(doc["height_px"]),
                            K=K, rotation=rotation, positions_m=positions, marker_planes=planes,
                            fps=_number(doc, "fps"), frames=None if doc.get("frames") is None else int(doc["frames"]),
                            frame_t_s=times, view=_mapping(doc, "view"))
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise TrackError(f"{path}: camera file without {exc} (or with a malformed value)",
                         "use the camera.json the simulation wrote beside the video, or give --scale") from None
    if K.shape != (3, 3) or rotation.shape != (3, 3) or positions.ndim != 2 or positions.shape[1] != 3 \
            or not (np.isfinite(K).all() and np.isfinite(rotation).all() and np.isfinite(positions).all()):
        raise TrackError(f"{path}: the camera matrices are not 3x3 finite numbers", "re-render the video")
    return camera


def _float(value) -> float:
    return math.nan if value is None else float(value)


def _number(doc: dict, key: str) -> float | None:
    """``doc[key]`` as written (an int stays an int), None when absent; anything else is malformed."""
    value = doc.get(key)
    if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))):
        raise ValueError(key)
    return value


def _mapping(doc: dict, key: str) -> dict | None:
    value = doc.get(key)
    if value is not None and not isinstance(value, dict):
        raise ValueError(key)
    return value
