"""Render the simulated hop to an MP4, with the true marker pixels beside it.

The camera looks at the robot's left side (the left leg is at +y, the foot marker on its
+y face) from +y, horizontally, with the floor in view. ``track`` follows the chassis in x;
``fixed`` holds still where the whole run stays in view, the camera ``locust track`` wants.

Beside ``<stem>.mp4`` go two sidecars, both simulated ground truth:

- ``<stem>.truth.csv``: per frame, each marker's true pixel centre (OpenCV convention:
  origin at the centre of the top-left pixel, x right, y down), the share of it the camera
  sees (``seen_frac``: a marker lying on the floor or behind a link is partly hidden, and a
  colour blob's centroid is then off its true centre), ``visible`` (at least half seen), and
  its true world position (the centre of the disc's camera-facing face: x forward along the
  floor, z up, metres);
- ``<stem>.camera.json``: the pinhole camera (intrinsics, extrinsics per frame or fixed),
  the plane ``y = const`` each marker's visible centre moves in (``marker_planes``: the
  markers are flat discs facing the camera), with which ``locust track`` maps pixels to
  metres exactly, and, for the fixed camera, metres per pixel at the robot's planes.

The pixels are projected through the camera MuJoCo itself rendered with
(``renderer.scene.camera`` after ``update_scene``), so the truth and the image agree.
"""

from __future__ import annotations

import os

# Offscreen GL must be chosen before MuJoCo loads its GL bindings: OSMesa needs no display.
os.environ.setdefault("MUJOCO_GL", "osmesa")

import math  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from ..errors import SimError  # noqa: E402
from ..fileio import atomic_write_json, atomic_write_text, temp_beside  # noqa: E402
from ..markers import MARKER_COLOURS  # noqa: E402
from ..params import Robot  # noqa: E402
from ..progress import progress  # noqa: E402
from .audit import audit  # noqa: E402
from .model import build  # noqa: E402
from .rollout import simulate  # noqa: E402

CAMERAS = ("track", "fixed")
MARKERS = tuple(MARKER_COLOURS)           # ("nose", "foot"): geoms "marker_<name>"
AZIMUTH_DEG = -90.0                        # look along -y: from the robot's left side
ELEVATION_DEG = 0.0                        # horizontal
MARGIN_M = 0.04                            # empty border around the robot in the fixed view
TRACK_HALF_WIDTH_OF_BODY = 2.0             # track view: half the image width, in body lengths
VISIBLE_FRAC = 0.5                         # truth says a marker is visible when this much of it is seen
# sample points on a unit disc for the seen fraction: the centre and three rings of twelve
_DISC_SAMPLES = np.vstack([[[0.0, 0.0]]] + [
    [[r * math.cos(a), r * math.sin(a)] for a in np.arange(12) * math.pi / 6] for r in (0.35, 0.65, 0.95)])


@dataclass(frozen=True)
class CameraView:
    """Where MuJoCo's free camera stands: it looks at ``lookat_m`` from ``distance_m``."""

    lookat_m: tuple[float, float, float]
    distance_m: float
    azimuth_deg: float = AZIMUTH_DEG
    elevation_deg: float = ELEVATION_DEG

    def at_x(self, x_m: float) -> "CameraView":
        return CameraView((x_m, self.lookat_m[1], self.lookat_m[2]), self.distance_m,
                          self.azimuth_deg, self.elevation_deg)

    def mjv_camera(self) -> mujoco.MjvCamera:
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
        return -self.rotation @ self.position_m

    def to_camera(self, points_m: np.ndarray) -> np.ndarray:
        return (np.atleast_2d(points_m) - self.position_m) @ self.rotation.T

    def project(self, points_m: np.ndarray) -> np.ndarray:
        """World points (N, 3) in metres -> pixel centres (N, 2)."""
        pc = self.to_camera(points_m)
        return np.column_stack([self.fx_px * pc[:, 0] / pc[:, 2] + self.cx_px,
                                self.fy_px * pc[:, 1] / pc[:, 2] + self.cy_px])

    def m_per_px_at_depth(self, depth_m: float) -> float:
        return depth_m / self.fx_px

    def intrinsics(self) -> dict:
        return {"fx_px": self.fx_px, "fy_px": self.fy_px, "cx_px": self.cx_px, "cy_px": self.cy_px,
                "K": [[self.fx_px, 0.0, self.cx_px], [0.0, self.fy_px, self.cy_px], [0.0, 0.0, 1.0]]}

    def extrinsics(self) -> dict:
        return {"rotation_world_to_camera": self.rotation.tolist(),
                "translation_m": self.translation_m.tolist(), "position_m": self.position_m.tolist()}


def pinhole_from_scene(scene: mujoco.MjvScene, width_px: int, height_px: int) -> PinholeCamera:
    """The pinhole camera MuJoCo renders ``scene`` with, in a ``width_px`` x ``height_px`` viewport.

    OpenGL maps the near-plane window [left, right] x [bottom, top] onto the viewport; with
    ``frustum_width`` 0 the width follows the viewport's aspect ratio. Pixel i spans window
    coordinates [i, i + 1], so its centre is at i + 0.5: OpenCV's index is window - 0.5.
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
    width_n = float(gl.frustum_width) or height_n * width_px / height_px
    fx = width_px * near / width_n
    fy = height_px * near / height_n
    cx = (width_px - 1) / 2 - width_px * centre / width_n
    cy = (height_px - 1) / 2 + height_px * (top + bottom) / (2 * height_n)
    return PinholeCamera(width_px, height_px, fx, fy, cx, cy, rotation, pos)


# -- framing -----------------------------------------------------------------------
def _distance_to_fit(half_width_m: float, half_height_m: float, fovy_deg: float, aspect: float) -> float:
    tan_half = math.tan(math.radians(fovy_deg) / 2)
    return max(half_height_m / tan_half, half_width_m / (tan_half * aspect))


def frame_views(points_m: np.ndarray, chassis_x_m: np.ndarray, body_length_m: float, plane_y_m: float,
                fovy_deg: float, aspect: float) -> tuple[CameraView, CameraView]:
    """The fixed view that holds every point of the run, and the tracking view (at x = 0).

    ``points_m`` (N, 3): positions the robot reaches (nose, foot, chassis ...). Both views
    look horizontally at the plane ``y = plane_y_m``; the floor (z = 0) stays in the frame.
    """
    x_lo, x_hi = float(np.min(points_m[:, 0])) - MARGIN_M, float(np.max(points_m[:, 0])) + MARGIN_M
    z_lo = min(0.0, float(np.min(points_m[:, 2]))) - MARGIN_M
    z_hi = float(np.max(points_m[:, 2])) + MARGIN_M
    z_mid = (z_lo + z_hi) / 2
    # the camera stands at +y: what is nearer to it than the plane needs the wider view
    nearer_m = max(0.0, float(np.max(points_m[:, 1])) - plane_y_m) + MARGIN_M
    fixed = CameraView(((x_lo + x_hi) / 2, plane_y_m, z_mid),
                       nearer_m + _distance_to_fit((x_hi - x_lo) / 2, (z_hi - z_lo) / 2, fovy_deg, aspect))
    track_half_w = TRACK_HALF_WIDTH_OF_BODY * body_length_m
    track = CameraView((float(chassis_x_m[0]), plane_y_m, z_mid),
                       nearer_m + _distance_to_fit(track_half_w, (z_hi - z_lo) / 2, fovy_deg, aspect))
    return fixed, track


# -- one clip: frames, truth rows, sidecars ------------------------------------------
@dataclass
class VideoInfo:
    video_path: Path
    truth_path: Path
    frames: int
    fps: int
    width: int
    height: int
    camera_path: Path | None = None
    camera: str = "track"


def sidecar_paths(path: Path) -> tuple[Path, Path]:
    stem = path.with_suffix("")
    return stem.with_name(stem.name + ".truth.csv"), stem.with_name(stem.name + ".camera.json")


def check_video_path(path: str | os.PathLike) -> Path:
    """Refuse names OpenCV cannot write as MP4 and never overwrite an earlier render."""
    path = Path(path)
    if path.suffix.lower() != ".mp4":
        raise SimError(f"video path {path} does not end in .mp4", "name the video <something>.mp4")
    for p in (path, *sidecar_paths(path)):
        if p.exists():
            raise SimError(f"{p} exists already; not overwriting it", "choose another video name, or move it away")
    if path.parent.exists() and not path.parent.is_dir():
        raise SimError(f"{path.parent} is not a folder", "choose a video path inside a folder")
    return path


@dataclass
class _TruthRow:
    frame: int
    t_s: float
    px: dict[str, tuple[float, float]]
    seen_frac: dict[str, float]
    world_m: dict[str, np.ndarray]


@dataclass
class ClipRecorder:
    """Renders frames from model states into a temporary MP4, collecting the truth.

    ``add_frame(qpos, t_s)`` poses a private ``MjData`` (positions only; the physics' own
    data is never touched), renders, projects the markers and appends the frame;
    ``finish()`` writes the sidecars and moves the video into place; ``abort()`` leaves
    nothing behind.
    """

    model: mujoco.MjModel
    path: Path
    fps: int
    width: int
    height: int
    camera: str
    view: CameraView
    robot_name: str = ""
    shadows: bool = True      # two shadow maps cost about two thirds of an OSMesa frame
    rows: list[_TruthRow] = field(default_factory=list)
    cameras: list[PinholeCamera] = field(default_factory=list)

    def __post_init__(self) -> None:
        m = self.model
        m.vis.global_.offwidth = max(int(m.vis.global_.offwidth), self.width)
        m.vis.global_.offheight = max(int(m.vis.global_.offheight), self.height)
        self.data = mujoco.MjData(m)
        self.marker_ids = {n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"marker_{n}") for n in MARKERS}
        self.chassis_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "chassis")
        try:
            self.renderer = mujoco.Renderer(m, height=self.height, width=self.width)
        except Exception as exc:  # GL backends raise many types (ImportError, RuntimeError, mujoco.FatalError)
            raise SimError(f"cannot open an offscreen OpenGL context ({type(exc).__name__}: {exc})",
                           "install OSMesa (apt-get install libosmesa6) and run with MUJOCO_GL=osmesa, "
                           "or MUJOCO_GL=egl on a GPU") from None
        fd, self.tmp_path = temp_beside(self.path, suffix=".mp4")
        os.close(fd)
        self.writer = cv2.VideoWriter(self.tmp_path, cv2.VideoWriter_fourcc(*"mp4v"), float(self.fps),
                                      (self.width, self.height))
        if not self.writer.isOpened():
            self.abort()
            raise SimError(f"OpenCV cannot write an MP4 at {self.path}",
                           "check the folder is writable and OpenCV has its video backend")

    @property
    def frames(self) -> int:
        return len(self.rows)

    def add_frame(self, qpos: np.ndarray, t_s: float) -> None:
        d = self.data
        d.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_comPos(self.model, d)
        mujoco.mj_camlight(self.model, d)   # lights are placed here, not in mj_kinematics
        view = self.view.at_x(float(d.xpos[self.chassis_id][0])) if self.camera == "track" else self.view
        self.renderer.update_scene(d, camera=view.mjv_camera())
        # No floor reflections: a mirrored marker is a second blob of the marker's colour,
        # which a matte table does not show and which would merge with a foot on the floor.
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = int(self.shadows)
        cam = pinhole_from_scene(self.renderer.scene, self.width, self.height)
        rgb = self.renderer.render()
        self.writer.write(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        world = {n: self._marker_face_m(g) for n, g in self.marker_ids.items()}
        px = {n: tuple(float(v) for v in cam.project(world[n])[0]) for n in MARKERS}
        seen = {n: self._seen_fraction(cam, world[n], self.marker_ids[n]) if self._in_image(px[n]) else 0.0
                for n in MARKERS}
        self.rows.append(_TruthRow(len(self.rows), float(t_s), px, seen, world))
        self.cameras.append(cam)

    def _marker_face_m(self, geom_id: int) -> np.ndarray:
        """Centre of what the camera sees of a marker: a disc's camera-facing face, a sphere's centre."""
        centre = self.data.geom_xpos[geom_id].copy()
        if self.model.geom_type[geom_id] == mujoco.mjtGeom.mjGEOM_CYLINDER:
            axis = self.data.geom_xmat[geom_id].reshape(3, 3)[:, 2]
            centre += np.sign(axis[1]) * axis * float(self.model.geom_size[geom_id][1])  # the +y face
        return centre

    def _in_image(self, px: tuple[float, float]) -> bool:
        return -0.5 <= px[0] <= self.width - 0.5 and -0.5 <= px[1] <= self.height - 0.5

    def _seen_fraction(self, cam: PinholeCamera, centre_m: np.ndarray, geom_id: int) -> float:
        """Share of the marker (as the camera sees it) that no other geom hides.

        Rays go from the camera centre to points spread over what the camera sees of the
        marker (``_DISC_SAMPLES``): a disc's face, or a sphere's disc across the line of
        sight; a ray that meets the marker first sees it.
        """
        radius = float(self.model.geom_size[geom_id][0])
        if self.model.geom_type[geom_id] == mujoco.mjtGeom.mjGEOM_CYLINDER:
            axes = self.data.geom_xmat[geom_id].reshape(3, 3)[:, :2].T   # the face's own two axes
        else:
            sight = centre_m - cam.position_m
            sight /= np.linalg.norm(sight)
            across = np.cross(sight, cam.rotation[1])
            across /= np.linalg.norm(across)
            axes = np.vstack([across, np.cross(sight, across)])
        seen, hit = 0, np.array([-1], dtype=np.int32)
        for target in centre_m + radius * _DISC_SAMPLES @ axes:
            ray = target - cam.position_m
            mujoco.mj_ray(self.model, self.data, cam.position_m, ray / np.linalg.norm(ray), None, 1, -1, hit)
            seen += int(hit[0]) == geom_id
        return seen / len(_DISC_SAMPLES)

    def truth_csv(self) -> str:
        lines = [f"# simulated ground truth: MuJoCo render of robot {self.robot_name!r}, camera {self.camera}; "
                 "pixels in the OpenCV convention (origin at the centre of the top-left pixel, x right, y down); "
                 "world x along the floor, z up, metres",
                 ",".join(["frame", "t_s"] + [f"{n}_{c}" for n in MARKERS
                                              for c in ("px", "py", "visible", "seen_frac", "x_m", "z_m")])]
        for r in self.rows:
            cells = [str(r.frame), f"{r.t_s:.6f}"]
            for n in MARKERS:
                cells += [f"{r.px[n][0]:.4f}", f"{r.px[n][1]:.4f}", str(int(r.seen_frac[n] >= VISIBLE_FRAC)),
                          f"{r.seen_frac[n]:.3f}",
                          f"{r.world_m[n][0]:.6f}", f"{r.world_m[n][2]:.6f}"]
            lines.append(",".join(cells))
        return "\n".join(lines) + "\n"

    def camera_json(self) -> dict:
        first = self.cameras[0]
        out = {
            "note": "simulated camera (MuJoCo free camera); OpenCV pinhole convention: camera x right, "
                    "y down, z forward; pixel origin at the centre of the top-left pixel",
            "camera": self.camera, "width_px": self.width, "height_px": self.height, "fps": self.fps,
            "frames": self.frames, "view": {"lookat_m": list(self.view.lookat_m), "distance_m": self.view.distance_m,
                                            "azimuth_deg": self.view.azimuth_deg,
                                            "elevation_deg": self.view.elevation_deg},
            "intrinsics": first.intrinsics(),
        }
        planes = self.marker_planes()
        out["marker_planes"] = {
            "note": "each marker's visible centre moves in the world plane y = plane_y_m (world: x along "
                    "the floor, y toward the camera, z up); truth x_m, z_m are in that plane",
            **planes}
        if self.camera == "fixed":
            out["extrinsics"] = first.extrinsics()
            out["m_per_px"] = self._m_per_px(first, planes)
        else:
            out["rotation_world_to_camera"] = first.rotation.tolist()
            out["extrinsics_per_frame"] = [{"frame": r.frame, "t_s": r.t_s, "position_m": c.position_m.tolist(),
                                            "translation_m": c.translation_m.tolist()}
                                           for r, c in zip(self.rows, self.cameras)]
        return out

    def marker_planes(self) -> dict:
        """The plane y = const each marker's visible centre moves in, and how far it strays from it."""
        out = {}
        for n in MARKERS:
            y = np.array([r.world_m[n][1] for r in self.rows])
            out[n] = {"plane_y_m": float(np.mean(y)), "max_off_plane_m": float(np.max(np.abs(y - np.mean(y))))}
        return out

    def _m_per_px(self, cam: PinholeCamera, planes: dict) -> dict:
        """Metres per pixel where each marker moves, and at the chassis mid-plane."""
        ys = {"chassis_mid_plane": 0.0, **{f"{n}_plane": p["plane_y_m"] for n, p in planes.items()}}
        return {name: {"plane_y_m": y, "m_per_px": cam.m_per_px_at_depth(float(cam.to_camera([0.0, y, 0.0])[0, 2]))}
                for name, y in ys.items()}

    def finish(self) -> VideoInfo:
        try:
            self.writer.release()
            self.renderer.close()
            if not self.rows:
                raise SimError(f"no frames to write to {self.path}", "simulate for at least one frame period")
            truth_path, camera_path = sidecar_paths(self.path)
            atomic_write_text(truth_path, self.truth_csv())
            atomic_write_json(camera_path, self.camera_json())
            os.replace(self.tmp_path, self.path)
        except BaseException:
            self.abort()
            raise
        return VideoInfo(video_path=self.path, truth_path=truth_path, frames=self.frames, fps=self.fps,
                         width=self.width, height=self.height, camera_path=camera_path, camera=self.camera)

    def abort(self) -> None:
        if getattr(self, "writer", None) is not None:
            self.writer.release()
        if getattr(self, "renderer", None) is not None:
            self.renderer.close()
        try:
            os.unlink(self.tmp_path)
        except (FileNotFoundError, AttributeError):
            pass


def frame_times_s(duration_s: float, fps: int) -> np.ndarray:
    """One frame every 1/fps from t = 0: ``round(duration * fps)`` frames."""
    return np.arange(int(round(duration_s * fps))) / fps




def validate_size(fps: int, width: int, height: int) -> None:
    if not (isinstance(fps, int) and 1 <= fps <= 1000):
        raise SimError(f"video fps = {fps!r} is not a whole number of frames per second in 1..1000",
                       "use e.g. fps=30")
    for name, v in (("width", width), ("height", height)):
        if not (isinstance(v, int) and 16 <= v <= 4096) or v % 2:
            raise SimError(f"video {name} = {v!r} px is not an even whole number in 16..4096",
                           "use e.g. 1280x720 or 320x240")


def render_video(robot: Robot, path: str | os.PathLike, cycles: int | None = None, camera: str = "track",
                 fps: int = 30, width: int = 1280, height: int = 720) -> VideoInfo:
    """Simulate settle + ``cycles`` hops and render them to ``path`` (MP4), with truth sidecars.

    Frames sample the same rollout ``locust sim`` audits, at t = k / fps from the start of
    the simulation (the settle phase included); the frame count is duration x fps.
    """
    if camera not in CAMERAS:
        raise SimError(f"camera {camera!r} is not known", f"choose one of {', '.join(CAMERAS)}")
    validate_size(fps, width, height)
    path = check_video_path(path)
    built = build(robot)
    traj = simulate(robot, cycles=cycles, built=built, keep_states=True)
    verdict = audit(traj)
    if not verdict.valid:
        raise SimError(f"not rendering an invalid simulation: {'; '.join(verdict.reasons)}",
                       "run `locust sim` on the same robot and fix the reasons it lists")
    model, s = built.model, built.sensors
    dt, nq = traj.timestep_s, model.nq
    times = frame_times_s(traj.plan.duration_s, fps)
    # state row i is the state after step i + 1, at t = (i + 1) dt; t = 0 is the built pose
    rows = np.rint(times / dt).astype(int) - 1
    qpos0 = model.qpos0.copy()

    sd = traj.sensordata
    points = np.vstack([sd[:, s.nose_pos], sd[:, s.foot_pos], sd[:, s.chassis_pos], sd[:, s.com_pos]])
    fixed, track = frame_views(points, sd[:, s.chassis_pos][:, 0], robot.geometry.body_length_m, 0.0,
                               float(model.vis.global_.fovy), width / height)
    rec = ClipRecorder(model, path, fps, width, height, camera, fixed if camera == "fixed" else track,
                       robot_name=robot.name)
    try:
        with progress(length=len(times), label="rendering") as bar:
            for t, row in zip(times, rows):
                rec.add_frame(qpos0 if row < 0 else traj.states[row, 1:1 + nq], float(t))
                bar.update(1)
    except BaseException:
        rec.abort()
        raise
    return rec.finish()


__all__ = ["CameraView", "ClipRecorder", "PinholeCamera", "VideoInfo", "render_video", "pinhole_from_scene",
           "frame_times_s", "check_video_path", "validate_size"]
