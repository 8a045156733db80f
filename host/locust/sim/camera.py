"""The simulated camera: where MuJoCo's free camera stands, and the pinhole model it renders with.

The camera looks at the robot's left side (the left leg is at +y, the foot marker on its
+y face) from +y, horizontally, with the floor in view. ``track`` follows the chassis in x;
``fixed`` holds still where the whole run stays in view, the camera ``locust track`` wants.

:func:`pinhole_from_scene` reads the camera MuJoCo itself rendered with
(``renderer.scene.camera`` after ``update_scene``) as an OpenCV pinhole model, so pixels
projected through it agree with the image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..errors import SimError

CAMERAS = ("track", "fixed")
AZIMUTH_DEG = -90.0                        # look along -y: from the robot's left side
ELEVATION_DEG = 0.0                        # horizontal
MARGIN_M = 0.04                            # empty border around the robot in the fixed view
TRACK_HALF_WIDTH_OF_BODY = 2.0             # track view: half the image width, in body lengths


@dataclass(frozen=True)
class CameraView:
    """Where MuJoCo's free camera stands: it looks at ``lookat_m`` from ``distance_m``."""

    lookat_m: tuple[float, float, float]
    distance_m: float
    azimuth_deg: float = AZIMUTH_DEG
    elevation_deg: float = ELEVATION_DEG

    def at_x(self, x_m: float) -> CameraView:
        """The same view moved along the floor to look at ``x_m``.

        Parameters
        ----------
        x_m : float
            The new look-at point's x [m].

        Returns
        -------
        CameraView
            The view with ``lookat_m[0] = x_m``.
        """
        return CameraView((x_m, self.lookat_m[1], self.lookat_m[2]), self.distance_m,
                          self.azimuth_deg, self.elevation_deg)

    def mjv_camera(self) -> mujoco.MjvCamera:
        """The view as MuJoCo's free camera.

        Returns
        -------
        mujoco.MjvCamera
            A free camera at this look-at point, distance, azimuth and elevation.
        """
        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.lookat[:] = self.lookat_m
        cam.distance = self.distance_m
        cam.azimuth = self.azimuth_deg
        cam.elevation = self.elevation_deg
        return cam


@dataclass(frozen=True)
class PinholeCamera:
    """OpenCV pinhole model of one rendered frame: ``uv ~ K (R X + t)``.

    Camera frame: x right, y down, z forward (into the scene); pixels: origin at the centre
    of the top-left pixel.
    """

    width_px: int
    height_px: int
    fx_px: float
    fy_px: float
    cx_px: float
    cy_px: float
    rotation: np.ndarray      # (3, 3) world -> camera
    position_m: np.ndarray    # (3,) camera centre in the world

    @property
    def translation_m(self) -> np.ndarray:
        """The translation t of ``X_cam = R X + t`` [m]."""
        return -self.rotation @ self.position_m

    def to_camera(self, points_m: np.ndarray) -> np.ndarray:
        """World points in the camera's frame.

        Parameters
        ----------
        points_m : ndarray
            (N, 3) or (3,) world points [m].

        Returns
        -------
        ndarray
            (N, 3) points in the camera frame (x right, y down, z forward) [m].
        """
        return (np.atleast_2d(points_m) - self.position_m) @ self.rotation.T

    def project(self, points_m: np.ndarray) -> np.ndarray:
        """World points (N, 3) in metres -> pixel centres (N, 2).

        Parameters
        ----------
        points_m : ndarray
            (N, 3) or (3,) world points [m], in front of the camera.

        Returns
        -------
        ndarray
            (N, 2) pixel coordinates [px], origin at the centre of the top-left pixel.
        """
        pc = self.to_camera(points_m)
        return np.column_stack([self.fx_px * pc[:, 0] / pc[:, 2] + self.cx_px,
                                self.fy_px * pc[:, 1] / pc[:, 2] + self.cy_px])

    def intrinsics(self) -> dict:
        """The intrinsics as a JSON object.

        Returns
        -------
        dict
            ``fx_px``, ``fy_px``, ``cx_px``, ``cy_px`` [px] and the 3x3 matrix ``K``.
        """
        return {"fx_px": self.fx_px, "fy_px": self.fy_px, "cx_px": self.cx_px, "cy_px": self.cy_px,
                "K": [[self.fx_px, 0.0, self.cx_px], [0.0, self.fy_px, self.cy_px], [0.0, 0.0, 1.0]]}

    def extrinsics(self) -> dict:
        """The extrinsics as a JSON object.

        Returns
        -------
        dict
            ``rotation_world_to_camera`` (3x3), ``translation_m`` and ``position_m`` [m].
        """
        return {"rotation_world_to_camera": self.rotation.tolist(),
                "translation_m": self.translation_m.tolist(), "position_m": self.position_m.tolist()}


def pinhole_from_scene(scene: mujoco.MjvScene, width_px: int, height_px: int) -> PinholeCamera:
    """The pinhole camera MuJoCo renders ``scene`` with, in a ``width_px`` x ``height_px`` viewport.

    OpenGL maps the near-plane window [left, right] x [bottom, top] onto the viewport, with
    left/right = ``frustum_center`` -/+ ``frustum_width`` (MuJoCo's renderer reads it as the
    half-width; 0: the width follows the viewport's aspect ratio). Pixel i spans window
    coordinates [i, i + 1], so its centre is at i + 0.5: OpenCV's index is window - 0.5.
    :func:`set_scene_pinhole` is the inverse.

    Parameters
    ----------
    scene : mujoco.MjvScene
        A scene after ``update_scene``.
    width_px, height_px : int
        The viewport's size [px].

    Returns
    -------
    PinholeCamera
        Intrinsics [px] and pose (world-to-camera rotation, centre [m]).

    Raises
    ------
    SimError
        An orthographic render camera.
    """
    cams = [scene.camera[0], scene.camera[1]]   # the two eyes coincide without stereo
    gl = cams[0]
    if gl.orthographic:
        raise SimError("the render camera is orthographic", "use a perspective (free) camera")
    pos = np.mean([c.pos for c in cams], axis=0).astype(float)
    forward = np.asarray(gl.forward, dtype=float)
    up = np.asarray(gl.up, dtype=float)
    right = np.cross(forward, up)
    rotation = np.vstack([right, -up, forward])
    near, top, bottom, centre = float(gl.frustum_near), float(gl.frustum_top), float(gl.frustum_bottom), \
        float(gl.frustum_center)
    height_n = top - bottom
    width_n = 2 * float(gl.frustum_width) or height_n * width_px / height_px
    fx = width_px * near / width_n
    fy = height_px * near / height_n
    cx = (width_px - 1) / 2 - width_px * centre / width_n
    cy = (height_px - 1) / 2 + height_px * (top + bottom) / (2 * height_n)
    return PinholeCamera(width_px, height_px, fx, fy, cx, cy, rotation, pos)


def free_camera_at(cam: PinholeCamera, distance_m: float = 1.0) -> CameraView:
    """MuJoCo's free camera standing where ``cam`` stands and looking where it looks.

    The free camera has no roll and its own field of view: :func:`set_scene_pinhole` then
    puts ``cam``'s exact orientation and intrinsics on the scene. Rendering through this view
    first places what follows the camera (the headlight) where ``cam`` is.

    Parameters
    ----------
    cam : PinholeCamera
        The camera to stand in for.
    distance_m : float
        How far ahead of the camera the look-at point is put [m].

    Returns
    -------
    CameraView
        The free camera's look-at point [m], distance [m], azimuth and elevation [deg].
    """
    f = np.asarray(cam.rotation[2], dtype=float)
    azimuth = math.degrees(math.atan2(f[1], f[0]))
    elevation = math.degrees(math.asin(max(-1.0, min(1.0, float(f[2])))))
    lookat = np.asarray(cam.position_m, dtype=float) + distance_m * f
    return CameraView(tuple(float(v) for v in lookat), distance_m, azimuth, elevation)


def set_scene_pinhole(scene: mujoco.MjvScene, cam: PinholeCamera) -> None:
    """Make ``scene`` (after ``update_scene``) render through ``cam`` in a ``cam.width_px`` x
    ``cam.height_px`` viewport: its pose (world -> camera rotation, centre) and intrinsics
    (fx, fy, cx, cy), the inverse of :func:`pinhole_from_scene`. The near and far planes stay
    MuJoCo's.

    Parameters
    ----------
    scene : mujoco.MjvScene
        The scene; both eyes of its camera are set.
    cam : PinholeCamera
        The camera to render through.
    """
    w, h = cam.width_px, cam.height_px
    for gl in (scene.camera[0], scene.camera[1]):
        near = float(gl.frustum_near)
        gl.pos[:] = cam.position_m
        gl.forward[:] = cam.rotation[2]
        gl.up[:] = -np.asarray(cam.rotation[1])
        gl.frustum_center = ((w - 1) / 2 - cam.cx_px) * near / cam.fx_px
        gl.frustum_width = w * near / cam.fx_px / 2           # the half-width, as MuJoCo reads it
        middle = (cam.cy_px - (h - 1) / 2) * near / cam.fy_px
        gl.frustum_top = middle + h * near / cam.fy_px / 2
        gl.frustum_bottom = middle - h * near / cam.fy_px / 2


# -- framing -----------------------------------------------------------------------
def _distance_to_fit(half_width_m: float, half_height_m: float, fovy_deg: float, aspect: float) -> float:
    tan_half = math.tan(math.radians(fovy_deg) / 2)
    return max(half_height_m / tan_half, half_width_m / (tan_half * aspect))


def side_azimuth_deg(side: str) -> float:
    """The camera's azimuth for a side view of the robot's left (``L``: from +y, the default)
    or right (``R``: from -y, looking along +y).

    Parameters
    ----------
    side : str
        ``L`` or ``R``.

    Returns
    -------
    float
        [deg].

    Raises
    ------
    SimError
        Not a side.
    """
    if side not in ("L", "R"):
        raise SimError(f"side {side!r} is not known", "choose L (the robot's left) or R (its right)")
    return AZIMUTH_DEG if side == "L" else -AZIMUTH_DEG


def frame_views(points_m: np.ndarray, chassis_x_m: np.ndarray, body_length_m: float, plane_y_m: float,
                fovy_deg: float, aspect: float, azimuth_deg: float = AZIMUTH_DEG) -> tuple[CameraView, CameraView]:
    """The fixed view that holds every point of the run, and the tracking view (at x = 0).

    ``points_m`` (N, 3): positions the robot reaches (nose, foot, chassis ...). Both views
    look horizontally at the plane ``y = plane_y_m``; the floor (z = 0) stays in the frame.
    ``azimuth_deg``: -90 looks along -y from +y (the robot's left), +90 along +y from -y.

    Parameters
    ----------
    points_m : ndarray
        (N, 3) world positions the robot reaches [m].
    chassis_x_m : ndarray
        The chassis' x over the run [m]; the tracking view starts at its first value.
    body_length_m : float
        The plate's length [m]; the tracking view is four body lengths wide.
    plane_y_m : float
        The plane both views look at [m].
    fovy_deg : float
        The camera's vertical field of view [deg].
    aspect : float
        Width over height of the frame.
    azimuth_deg : float
        The views' azimuth [deg] (:func:`side_azimuth_deg`).

    Returns
    -------
    fixed, track : CameraView
        The fixed view and the tracking view.
    """
    x_lo, x_hi = float(np.min(points_m[:, 0])) - MARGIN_M, float(np.max(points_m[:, 0])) + MARGIN_M
    z_lo = min(0.0, float(np.min(points_m[:, 2]))) - MARGIN_M
    z_hi = float(np.max(points_m[:, 2])) + MARGIN_M
    z_mid = (z_lo + z_hi) / 2
    # the camera stands at +y (azimuth -90) or -y (+90): what is nearer to it than the plane
    # needs the wider view
    toward = -math.sin(math.radians(azimuth_deg))
    nearer_m = max(0.0, float(np.max(toward * (points_m[:, 1] - plane_y_m)))) + MARGIN_M
    fixed = CameraView(((x_lo + x_hi) / 2, plane_y_m, z_mid),
                       nearer_m + _distance_to_fit((x_hi - x_lo) / 2, (z_hi - z_lo) / 2, fovy_deg, aspect),
                       azimuth_deg)
    track_half_w = TRACK_HALF_WIDTH_OF_BODY * body_length_m
    track = CameraView((float(chassis_x_m[0]), plane_y_m, z_mid),
                       nearer_m + _distance_to_fit(track_half_w, (z_hi - z_lo) / 2, fovy_deg, aspect), azimuth_deg)
    return fixed, track


__all__ = ["CAMERAS", "CameraView", "PinholeCamera", "frame_views", "free_camera_at", "pinhole_from_scene",
           "set_scene_pinhole", "side_azimuth_deg"]
