"""Pixels to metres through a known pinhole camera (a ``<video>.camera.json``).

A pixel names one ray from the camera centre, and the ray meets the marker's plane in exactly
one point: the pixel -> (x, z) map is a plane homography, exact for a pinhole camera, with no
scale to click. World output: ``x_m`` along the floor, ``y_m`` up (the simulation's z),
metres, origin at the simulation's world origin (on the floor). The file itself (its typed
form, writer and reader) is :mod:`locust.io.camera_json`'s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import TrackError
from ..io.camera_json import read_camera_json


@dataclass(frozen=True)
class PlaneCalibration:
    """World (x, z) of a marker from its pixel, through a pinhole camera and the marker's plane."""

    path: str
    K: np.ndarray                       # (3, 3) intrinsics, OpenCV pixel convention
    rotation: np.ndarray                # (3, 3) world -> camera
    positions_m: np.ndarray             # (F, 3) camera centre per frame, or (1, 3) for a fixed camera
    planes_y_m: dict[str, float]        # marker name -> plane y = const
    camera: str = "fixed"
    source: str = "camera.json"
    K_inv: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "K_inv", np.linalg.inv(self.K))

    @property
    def m_per_px(self) -> float:
        """Metres per pixel at the first marker's plane, seen from the (first) camera position: a guide only."""
        y = next(iter(self.planes_y_m.values()), 0.0)
        depth = float((self.rotation @ (np.array([0.0, y, 0.0]) - self.positions_m[0]))[2])
        return abs(depth) / float(self.K[0, 0])

    def to_world(self, px: np.ndarray, py: np.ndarray, marker: str | None = None,
                 frames: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Pixels of ``marker`` (on video ``frames``) -> world x and height, metres. NaN stays NaN;
        a marker without a known plane gives NaN.

        Parameters
        ----------
        px, py : ndarray
            Pixel positions, OpenCV convention [px].
        marker : str, optional
            The marker whose plane the points lie in.
        frames : ndarray, optional
            The video frame of each point (a camera that moves has a position per frame).

        Returns
        -------
        x_m, y_m : ndarray
            World x along the floor and height [m].

        Raises
        ------
        TrackError
            A frame beyond the camera file's positions.
        """
        px, py = np.asarray(px, float), np.asarray(py, float)
        if marker not in self.planes_y_m:
            nan = np.full(px.shape, math.nan)
            return nan, nan.copy()
        rays = np.stack([px, py, np.ones_like(px)], axis=-1) @ self.K_inv.T @ self.rotation   # world directions
        if len(self.positions_m) == 1:
            centre = np.broadcast_to(self.positions_m[0], rays.shape)
        else:
            index = np.asarray(frames if frames is not None else np.arange(px.size), dtype=int)
            if index.size and (index.min() < 0 or index.max() >= len(self.positions_m)):
                raise TrackError(f"{self.path} holds camera positions for frames 0..{len(self.positions_m) - 1}, "
                                 f"but frame {int(index.max())} was tracked",
                                 "track the video the camera file came with")
            centre = self.positions_m[index]
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (self.planes_y_m[marker] - centre[..., 1]) / rays[..., 1]
        world = centre + s[..., None] * rays
        return world[..., 0], world[..., 2]

    def axes_px(self) -> tuple[tuple[float, float], tuple[float, float], tuple[float, float]]:
        """The world origin (on the first marker's plane) in pixels, and the on-screen unit
        directions of world x and height, as the first frame's camera sees them.

        Returns
        -------
        origin : tuple of float
            The world origin [px].
        x_dir, y_dir : tuple of float
            Unit vectors in the image of world +x and up.
        """
        y = next(iter(self.planes_y_m.values()), 0.0)
        pts = np.array([[0.0, y, 0.0], [0.01, y, 0.0], [0.0, y, 0.01]]) - self.positions_m[0]
        cam = pts @ self.rotation.T @ self.K.T
        uv = cam[:, :2] / cam[:, 2:]
        dirs = [(uv[k] - uv[0]) / np.linalg.norm(uv[k] - uv[0]) for k in (1, 2)]
        return tuple(uv[0]), tuple(dirs[0]), tuple(dirs[1])  # type: ignore[return-value]

    def summary(self) -> str:
        """One line saying which camera file and marker planes [mm] give the world positions.

        Returns
        -------
        str
            The line.
        """
        planes = ", ".join(f"{n} y = {y * 1000:.1f} mm" for n, y in self.planes_y_m.items())
        return (f"world from {Path(self.path).name} ({self.camera} pinhole camera; marker planes {planes}): "
                f"x along the floor, y up, metres")

    def as_dict(self) -> dict:
        """The calibration as the tracks' JSON sidecar records it.

        Returns
        -------
        dict
            Source, camera file, K [px], rotation, position [m] (or per frame), marker planes [m].
        """
        return {"source": self.source, "camera_json": self.path, "model": "pinhole camera, plane homography per marker",
                "camera": self.camera, "K": self.K.tolist(), "rotation_world_to_camera": self.rotation.tolist(),
                "position_m": self.positions_m[0].tolist() if len(self.positions_m) == 1 else "per frame (camera_json)",
                "marker_planes_y_m": dict(self.planes_y_m),
                "world": "x_m along the floor, y_m up (the simulation's z), origin at the simulation's world origin",
                "m_per_px_at_first_plane": self.m_per_px}


def load(path: str | Path, width_px: int, height_px: int) -> PlaneCalibration:
    """Read a ``camera.json`` written by the simulation, checked against the video's size.

    Parameters
    ----------
    path : str or Path
        The ``camera.json``.
    width_px, height_px : int
        The video's size [px].

    Returns
    -------
    PlaneCalibration
        Pixels to world metres through that camera.

    Raises
    ------
    TrackError
        An unreadable file, or a camera of another size than the video.
    """
    camera = read_camera_json(path)
    if (camera.width_px, camera.height_px) != (width_px, height_px):
        raise TrackError(f"{path} describes a {camera.width_px}x{camera.height_px} camera, but the video is "
                         f"{width_px}x{height_px}",
                         "track the video the camera file came with, or give --scale instead")
    return PlaneCalibration(str(path), camera.K, camera.rotation, camera.positions_m, camera.planes_y_m,
                            camera=camera.camera)
