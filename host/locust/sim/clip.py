"""Record the simulated hop as an MP4, with the true marker pixels beside it.

Frames are rendered through a :class:`.camera.CameraView` (``track`` follows the chassis,
``fixed`` holds still). Beside ``<stem>.mp4`` go two sidecars, both simulated ground truth:

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
(:func:`.camera.pinhole_from_scene`), so the truth and the image agree.
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import mujoco
import numpy as np

from ..errors import SimError
from ..fileio import atomic_write_text, check_encoded, opencv_path, temp_beside
from ..io.camera_json import CameraFile, MarkerPlane, camera_json_beside, write_camera_json
from ..markers import MARKER_COLOURS
from ..params import Robot
from ..progress import progress
from .audit import audit
from .camera import (
    CAMERAS,
    CameraView,
    PinholeCamera,
    frame_views,
    free_camera_at,
    pinhole_from_scene,
    set_scene_pinhole,
)
from .gl import check_renderer
from .rollout import Trajectory, roll_out

MARKERS = tuple(MARKER_COLOURS)           # ("nose", "foot"): geoms "marker_<name>"
VISIBLE_FRAC = 0.5                         # truth says a marker is visible when this much of it is seen
# sample points on a unit disc for the seen fraction: the centre and three rings of twelve
_DISC_SAMPLES = np.vstack([[[0.0, 0.0]]] + [
    [[r * math.cos(a), r * math.sin(a)] for a in np.arange(12) * math.pi / 6] for r in (0.35, 0.65, 0.95)])


@dataclass(frozen=True)
class RenderQuality:
    """What an offscreen frame is rendered with, beside the model's own (its stills and photos,
    measured to a tenth of a pixel, keep the model's 4 MSAA samples and 2048 px shadow map).

    Attributes
    ----------
    msaa_samples : int
        Multisamples a pixel (0: none).
    shadow_map_px : int
        The shadow map's side [px].
    """

    msaa_samples: int
    shadow_map_px: int


# A video's frames, to be watched and tracked by colour (bench/video_speed.py): no multisampling
# and a 1024 px shadow map, 2.2x faster than the model's own under OSMesa, the markers tracked
# as close to their true pixels
VIDEO_QUALITY = RenderQuality(msaa_samples=0, shadow_map_px=1024)


# -- one frame: the model posed and rendered through a camera -------------------------
class PoseRenderer:
    """Renders the model, posed at given joint positions, offscreen through a camera.

    ``pose(qpos)`` poses a private ``MjData`` (positions only: kinematics, centres of mass,
    lights; a simulation's own data is never touched). ``render(camera)`` renders it through
    a :class:`.camera.CameraView` (MuJoCo's free camera, as :func:`.camera.frame_views`
    frames it) or a :class:`.camera.PinholeCamera` (any pose and intrinsics of a
    ``width`` x ``height`` camera, e.g. a filmed video's ``camera.json``), and returns the
    RGB image with the pinhole camera it was rendered through. No floor reflections: a
    mirrored marker is a second blob of the marker's colour, which a matte table does not
    show and which would merge with a foot on the floor.
    """

    def __init__(self, model: mujoco.MjModel, width: int, height: int, shadows: bool = True,
                 quality: RenderQuality | None = None):
        if quality is not None:    # on a copy: the model's own quality is every other render's
            model = copy.copy(model)
            model.vis.quality.offsamples = quality.msaa_samples
            model.vis.quality.shadowsize = quality.shadow_map_px
        self.model, self.width, self.height, self.shadows = model, width, height, shadows
        model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
        model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
        self.data = mujoco.MjData(model)
        check_renderer()
        try:
            self.renderer = mujoco.Renderer(model, height=height, width=width)
            release_context(self.renderer)
        except Exception as exc:
            raise SimError(f"cannot open an offscreen OpenGL context ({type(exc).__name__}: {exc})",
                           "install OSMesa (apt-get install libosmesa6) and run with MUJOCO_GL=osmesa, "
                           "or MUJOCO_GL=egl on a GPU") from None

    def pose(self, qpos: np.ndarray) -> mujoco.MjData:
        """Pose the private data at ``qpos`` (kinematics, centres of mass, lights; no step).

        Parameters
        ----------
        qpos : ndarray
            The model's joint positions, ``(nq,)`` [m, rad, quaternion as MuJoCo keeps them].

        Returns
        -------
        mujoco.MjData
            The posed private data.
        """
        d = self.data
        d.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, d)
        mujoco.mj_comPos(self.model, d)
        mujoco.mj_camlight(self.model, d)   # lights are placed here, not in mj_kinematics
        return d

    def render(self, camera: CameraView | PinholeCamera) -> tuple[np.ndarray, PinholeCamera]:
        """Render the posed model through ``camera``.

        Parameters
        ----------
        camera : CameraView or PinholeCamera
            The free camera's view, or a pinhole camera of this renderer's size.

        Returns
        -------
        rgb : ndarray
            ``(height, width, 3)`` uint8 image, RGB.
        pinhole : PinholeCamera
            The camera the frame was rendered through.

        Raises
        ------
        SimError
            A pinhole camera of another size than the renderer's.
        """
        pinhole = camera if isinstance(camera, PinholeCamera) else None
        if pinhole is not None and (pinhole.width_px, pinhole.height_px) != (self.width, self.height):
            raise SimError(f"a {pinhole.width_px}x{pinhole.height_px} camera cannot render a "
                           f"{self.width}x{self.height} frame", "render at the camera's own size")
        self.renderer.update_scene(self.data, camera=(free_camera_at(pinhole) if pinhole else camera).mjv_camera())
        if pinhole is not None:
            set_scene_pinhole(self.renderer.scene, pinhole)
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
        self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = int(self.shadows)
        cam = pinhole_from_scene(self.renderer.scene, self.width, self.height)
        try:
            return self.renderer.render(), cam
        finally:
            release_context(self.renderer)

    def close(self) -> None:
        """Free the offscreen renderer; closing twice is harmless."""
        if getattr(self, "renderer", None) is not None:
            self.renderer.close()
            self.renderer = None


# An OpenGL context is current per thread, and MuJoCo's Renderer leaves its own current on the
# thread that made or last used it. A clip is rendered on two threads (the virtual robot's first
# frames on the caller's, the rest on its plant thread), and a renderer may be closed, or
# collected, on any thread: a context freed while it is still current on another thread leaves
# that thread pointing at freed memory, and the next context made current there crashes
# (SIGSEGV in OSMesaMakeCurrent). So a renderer's context is current only while it renders:
# released after each frame, it can be used and freed on any thread.
def release_context(renderer: mujoco.Renderer) -> None:
    """Leave no OpenGL context current on this thread (after ``renderer`` made its own current).

    Parameters
    ----------
    renderer : mujoco.Renderer
        The renderer whose context was made current (on OSMesa, EGL or GLFW).
    """
    gl = getattr(renderer, "_gl_context", None)
    backend = next((k.__module__ for k in type(gl).__mro__ if k.__module__.startswith("mujoco.")
                    and k.__module__.split(".")[1] in ("osmesa", "egl", "glfw")), "") if gl else ""
    if backend == "mujoco.osmesa":
        from OpenGL import GL, osmesa

        osmesa.OSMesaMakeCurrent(None, None, GL.GL_FLOAT, 0, 0)
    elif backend == "mujoco.egl":
        from mujoco import egl

        if egl.EGL_DISPLAY is not None:
            egl.EGL.eglMakeCurrent(egl.EGL_DISPLAY, egl.EGL.EGL_NO_SURFACE, egl.EGL.EGL_NO_SURFACE,
                                   egl.EGL.EGL_NO_CONTEXT)
    elif backend == "mujoco.glfw":
        import glfw

        glfw.make_context_current(None)


def face_centre_m(model: mujoco.MjModel, data: mujoco.MjData, geom_id: int, toward_y: float = 1.0) -> np.ndarray:
    """Centre of what the camera sees of a marker posed in ``data``: a disc's camera-facing
    face (+y, or -y for a camera at -y), a sphere's centre.

    Parameters
    ----------
    model : mujoco.MjModel
        The model.
    data : mujoco.MjData
        Its data, posed.
    geom_id : int
        The marker's geom.
    toward_y : float
        +1: the camera at +y (the default side view); -1: at -y.

    Returns
    -------
    ndarray
        (3,) world position [m].
    """
    centre = data.geom_xpos[geom_id].copy()
    if model.geom_type[geom_id] == mujoco.mjtGeom.mjGEOM_CYLINDER:
        axis = data.geom_xmat[geom_id].reshape(3, 3)[:, 2]
        centre += toward_y * np.sign(axis[1]) * axis * float(model.geom_size[geom_id][1])  # the camera's face
    return centre


def seen_fraction(model: mujoco.MjModel, data: mujoco.MjData, cam: PinholeCamera, centre_m: np.ndarray,
                  geom_id: int) -> float:
    """Share of the marker (a disc or a sphere) ``geom_id`` (as the camera sees it) that no other geom hides.

    Rays go from the camera centre to points spread over what the camera sees of the
    marker (``_DISC_SAMPLES``): a disc's face, or a sphere's disc across the line of
    sight; a ray that meets the marker first sees it.

    Parameters
    ----------
    model : mujoco.MjModel
        The model.
    data : mujoco.MjData
        Its data, posed.
    cam : PinholeCamera
        The camera.
    centre_m : ndarray
        (3,) the marker's seen centre (:func:`face_centre_m`) [m].
    geom_id : int
        The marker's geom.

    Returns
    -------
    float
        Share of the sample rays that meet the marker first, 0..1.
    """
    radius = float(model.geom_size[geom_id][0])
    if model.geom_type[geom_id] == mujoco.mjtGeom.mjGEOM_CYLINDER:
        axes = data.geom_xmat[geom_id].reshape(3, 3)[:, :2].T   # the face's own two axes
    else:
        sight = centre_m - cam.position_m
        sight /= np.linalg.norm(sight)
        across = np.cross(sight, cam.rotation[1])
        across /= np.linalg.norm(across)
        axes = np.vstack([across, np.cross(sight, across)])
    seen, hit = 0, np.array([-1], dtype=np.int32)
    for target in centre_m + radius * _DISC_SAMPLES @ axes:
        ray = target - cam.position_m
        mujoco.mj_ray(model, data, cam.position_m, ray / np.linalg.norm(ray), None, 1, -1, hit)
        seen += int(hit[0]) == geom_id
    return seen / len(_DISC_SAMPLES)


# -- one clip: frames, truth rows, sidecars ------------------------------------------
@dataclass
class RenderedClip:
    """A rendered video and its sidecars.

    Attributes
    ----------
    video_path : Path
        The MP4.
    truth_path : Path
        ``<stem>.truth.csv``: every marker's true pixel and world position per frame.
    frames : int
        Frames written.
    fps : int
        Frame rate [1/s].
    width, height : int
        Frame size [px].
    camera_path : Path or None
        ``<stem>.camera.json``: the camera's intrinsics and pose.
    camera : str
        ``track`` (follows the chassis) or ``fixed``.
    """

    video_path: Path
    truth_path: Path
    frames: int
    fps: int
    width: int
    height: int
    camera_path: Path | None = None
    camera: str = "track"


def sidecar_paths(path: Path) -> tuple[Path, Path]:
    """A clip's two sidecars: ``<stem>.truth.csv`` and ``<stem>.camera.json``.

    Parameters
    ----------
    path : Path
        The clip (or still) path.

    Returns
    -------
    truth, camera : Path
        The two sidecar paths beside it.
    """
    return path.with_name(path.stem + ".truth.csv"), camera_json_beside(path)


def check_video_path(path: str | os.PathLike) -> Path:
    """Refuse names OpenCV cannot write as MP4 and never overwrite an earlier render.

    Parameters
    ----------
    path : str or os.PathLike
        The video path asked for.

    Returns
    -------
    Path
        The same path, checked.

    Raises
    ------
    SimError
        Not ``.mp4``, the video or a sidecar exists already, or its folder is a file.
    """
    path = Path(path)
    if path.suffix.lower() != ".mp4":
        raise SimError(f"video path {path} does not end in .mp4", "name the video <something>.mp4")
    for p in (path, *sidecar_paths(path)):
        if p.exists() or p.is_symlink():   # (a link pointing nowhere yet is there too)
            link = f" (a link to {os.readlink(p)})" if p.is_symlink() else ""
            raise SimError(f"{p} exists already{link}; not overwriting it",
                           "choose another video name, or move it away")
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

    ``add_frame(qpos, t_s)`` poses and renders the model (:class:`PoseRenderer`), projects
    the markers (the videos' ``marker_<name>`` discs, or ``marker_geoms``: name -> geom, e.g. a
    still's stickers; discs facing a camera at ``toward_y`` * y) and appends the frame;
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
    marker_geoms: dict[str, str] | None = None   # marker -> its geom (None: the videos' marker_<name>)
    toward_y: float = 1.0     # the camera's side: +1 at +y, -1 at -y
    quality: RenderQuality | None = None   # None: the model's own (VIDEO_QUALITY: a video's)
    rows: list[_TruthRow] = field(default_factory=list)
    cameras: list[PinholeCamera] = field(default_factory=list)

    def __post_init__(self) -> None:
        m = self.model
        geoms = self.marker_geoms or {n: f"marker_{n}" for n in MARKERS}
        self.marker_ids = {n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, g) for n, g in geoms.items()}
        self.markers = tuple(geoms)
        self.chassis_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "chassis")
        self.poser = PoseRenderer(m, self.width, self.height, self.shadows, self.quality)
        self.model, self.data = self.poser.model, self.poser.data
        fd, self.tmp_path = temp_beside(self.path, suffix=".mp4")
        os.close(fd)
        with opencv_path(self.tmp_path) as name:
            self.writer = cv2.VideoWriter(name, cv2.VideoWriter_fourcc(*"mp4v"), float(self.fps),
                                          (self.width, self.height))
        if not self.writer.isOpened():
            self.abort()
            raise SimError(f"OpenCV cannot write an MP4 at {self.path}",
                           "check the folder is writable and OpenCV has its video backend")

    @property
    def frames(self) -> int:
        """Frames added so far."""
        return len(self.rows)

    def add_frame(self, qpos: np.ndarray, t_s: float) -> None:
        """Pose and render the model, write the frame and record where its markers are.

        Parameters
        ----------
        qpos : ndarray
            The model's joint positions for this frame.
        t_s : float
            The frame's time [s].
        """
        d = self.poser.pose(qpos)
        view = self.view.at_x(float(d.xpos[self.chassis_id][0])) if self.camera == "track" else self.view
        rgb, cam = self.poser.render(view)
        self.writer.write(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        world = {n: self._marker_face_m(g) for n, g in self.marker_ids.items()}
        px = {n: tuple(float(v) for v in cam.project(world[n])[0]) for n in self.markers}
        seen = {n: self._seen_fraction(cam, world[n], self.marker_ids[n]) if self._in_image(px[n]) else 0.0
                for n in self.markers}
        self.rows.append(_TruthRow(len(self.rows), float(t_s), px, seen, world))
        self.cameras.append(cam)

    def _marker_face_m(self, geom_id: int) -> np.ndarray:
        return face_centre_m(self.model, self.data, geom_id, self.toward_y)

    def _in_image(self, px: tuple[float, float]) -> bool:
        return -0.5 <= px[0] <= self.width - 0.5 and -0.5 <= px[1] <= self.height - 0.5

    def _seen_fraction(self, cam: PinholeCamera, centre_m: np.ndarray, geom_id: int) -> float:
        return seen_fraction(self.model, self.data, cam, centre_m, geom_id)

    def truth_csv(self) -> str:
        """The truth sidecar's text: per frame, each marker's pixel, visibility, seen fraction and
        world x, z.

        Returns
        -------
        str
            CSV with a ``#`` comment line, pixels [px] and positions [m].
        """
        lines = [(f"# simulated ground truth: MuJoCo render of robot {self.robot_name!r}, camera {self.camera}; "
                  "pixels in the OpenCV convention (origin at the centre of the top-left pixel, x right, y down); "
                  "world x along the floor, z up, metres"),
                 ",".join(["frame", "t_s"] + [f"{n}_{c}" for n in self.markers
                                              for c in ("px", "py", "visible", "seen_frac", "x_m", "z_m")])]
        for r in self.rows:
            cells = [str(r.frame), f"{r.t_s:.6f}"]
            for n in self.markers:
                cells += [f"{r.px[n][0]:.4f}", f"{r.px[n][1]:.4f}", str(int(r.seen_frac[n] >= VISIBLE_FRAC)),
                          f"{r.seen_frac[n]:.3f}",
                          f"{r.world_m[n][0]:.6f}", f"{r.world_m[n][2]:.6f}"]
            lines.append(",".join(cells))
        return "\n".join(lines) + "\n"

    def camera_file(self) -> CameraFile:
        """The camera this clip was rendered with, as its owner (:mod:`locust.io.camera_json`) writes it.

        Returns
        -------
        CameraFile
            Intrinsics, rotation, one position (fixed) or one per frame (track) [m], and the
            markers' planes.
        """
        first = self.cameras[0]
        K = np.array([[first.fx_px, 0.0, first.cx_px], [0.0, first.fy_px, first.cy_px], [0.0, 0.0, 1.0]])
        fixed = self.camera == "fixed"
        return CameraFile(
            camera=self.camera, width_px=self.width, height_px=self.height, K=K, rotation=first.rotation,
            positions_m=(first.position_m[None, :] if fixed else np.array([c.position_m for c in self.cameras])),
            marker_planes={n: MarkerPlane(**p) for n, p in self.marker_planes().items()},
            fps=self.fps, frames=self.frames,
            frame_t_s=None if fixed else np.array([r.t_s for r in self.rows]),
            view={"lookat_m": list(self.view.lookat_m), "distance_m": self.view.distance_m,
                  "azimuth_deg": self.view.azimuth_deg, "elevation_deg": self.view.elevation_deg})

    def marker_planes(self) -> dict:
        """The plane y = const each marker's visible centre moves in, and how far it strays from it.

        Returns
        -------
        dict of str to dict
            Per marker, ``plane_y_m`` (the mean y) and ``max_off_plane_m`` [m].
        """
        out = {}
        for n in self.markers:
            y = np.array([r.world_m[n][1] for r in self.rows])
            out[n] = {"plane_y_m": float(np.mean(y)), "max_off_plane_m": float(np.max(np.abs(y - np.mean(y))))}
        return out

    def finish(self) -> RenderedClip:
        """Write the sidecars and move the video into place; on any failure leave nothing behind.

        Returns
        -------
        RenderedClip
            The video and its sidecars.

        Raises
        ------
        SimError
            No frames to write.
        WriteError
            The encoded video does not read back whole.
        """
        try:
            self.writer.release()
            self.poser.close()
            if not self.rows:
                raise SimError(f"no frames to write to {self.path}", "simulate for at least one frame period")
            check_encoded(self.tmp_path, self.frames, self.path)
            truth_path, camera_path = sidecar_paths(self.path)
            atomic_write_text(truth_path, self.truth_csv())
            write_camera_json(camera_path, self.camera_file())
            os.replace(self.tmp_path, self.path)
        except BaseException:
            self.abort()
            raise
        return RenderedClip(video_path=self.path, truth_path=truth_path, frames=self.frames, fps=self.fps,
                         width=self.width, height=self.height, camera_path=camera_path, camera=self.camera)

    def abort(self) -> None:
        """Release the writer and renderer and delete the temporary video."""
        if getattr(self, "writer", None) is not None:
            self.writer.release()
        if getattr(self, "poser", None) is not None:
            self.poser.close()
        try:
            os.unlink(self.tmp_path)
        except (FileNotFoundError, AttributeError):
            pass


def frame_times_s(duration_s: float, fps: int) -> np.ndarray:
    """One frame every 1/fps from t = 0: ``round(duration * fps)`` frames.

    Parameters
    ----------
    duration_s : float
        The span to film [s].
    fps : int
        Frame rate [1/s].

    Returns
    -------
    ndarray
        The frames' times [s].
    """
    return np.arange(round(duration_s * fps)) / fps


def validate_size(fps: int, width: int, height: int) -> None:
    """Refuse a frame rate or frame size the video writer should not be given.

    Parameters
    ----------
    fps : int
        Frame rate, a whole number in 1..1000 [1/s].
    width, height : int
        Frame size, even whole numbers in 16..4096 [px].

    Raises
    ------
    SimError
        Any of them out of range.
    """
    if not (isinstance(fps, int) and 1 <= fps <= 1000):
        raise SimError(f"video fps = {fps!r} is not a whole number of frames per second in 1..1000",
                       "use e.g. fps=30")
    for name, v in (("width", width), ("height", height)):
        if not (isinstance(v, int) and 16 <= v <= 4096) or v % 2:
            raise SimError(f"video {name} = {v!r} px is not an even whole number in 16..4096",
                           "use e.g. 1280x720 or 320x240")


def render_video(robot: Robot, path: str | os.PathLike, cycles: int | None = None, camera: str = "track",
                 fps: int = 30, width: int = 1280, height: int = 720,
                 trajectory: Trajectory | None = None, quality: RenderQuality | None = VIDEO_QUALITY) -> RenderedClip:
    """Simulate settle + ``cycles`` hops and render them to ``path`` (MP4), with truth sidecars.

    Frames sample the same rollout ``locust sim`` audits, at t = k / fps from the start of
    the simulation (the settle phase included); the frame count is duration x fps.

    ``trajectory``: a rollout of ``robot`` already made with its states kept (e.g.
    ``run(robot, keep_states=True).trajectory``) is rendered as it is, not simulated again;
    ``cycles`` is then the trajectory's own.

    Parameters
    ----------
    robot : Robot
        The robot to simulate.
    path : str or os.PathLike
        The MP4 to write; it and its sidecars must not exist.
    cycles : int, optional
        Cycles to simulate; default the robot's schedule's.
    camera : str
        ``track`` (follows the chassis) or ``fixed``.
    fps : int
        Frame rate [1/s].
    width, height : int
        Frame size [px].
    trajectory : Trajectory, optional
        A rollout of ``robot`` with its states kept, rendered instead of a new one.
    quality : RenderQuality or None
        The frames' multisampling and shadow map (None: the model's own, 4 samples and 2048 px).

    Returns
    -------
    RenderedClip
        The video and its sidecars.

    Raises
    ------
    SimError
        An unknown camera, a bad size or path, a trajectory without states, a simulation that
        fails its audit, or a video that cannot be written.
    """
    if camera not in CAMERAS:
        raise SimError(f"camera {camera!r} is not known", f"choose one of {', '.join(CAMERAS)}")
    validate_size(fps, width, height)
    path = check_video_path(path)
    if trajectory is None:
        trajectory = roll_out(robot, cycles=cycles, keep_states=True)
    elif trajectory.states is None:
        raise SimError("the trajectory to render kept no states",
                       "simulate it with keep_states=True, or let render_video simulate")
    traj = trajectory
    verdict = audit(traj)
    if not verdict.valid:
        raise SimError(f"not rendering an invalid simulation: {'; '.join(verdict.reasons)}",
                       "run `locust sim` on the same robot and fix the reasons it lists")
    model, s = traj.built.model, traj.built.sensors
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
                       robot_name=robot.name, quality=quality)
    try:
        with progress(length=len(times), label="rendering") as bar:
            for t, row in zip(times, rows):
                rec.add_frame(qpos0 if row < 0 else traj.states[row, 1:1 + nq], float(t))
                bar.update(1)
    except BaseException:
        rec.abort()
        raise
    return rec.finish()


__all__ = ["MARKERS", "VIDEO_QUALITY", "VISIBLE_FRAC", "ClipRecorder", "PoseRenderer", "RenderQuality", "RenderedClip",
           "check_video_path",
           "face_centre_m",
           "frame_times_s", "render_video", "seen_fraction", "sidecar_paths", "validate_size"]
