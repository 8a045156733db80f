"""The virtual fold test photographed: two SYNTHETIC side photos of :mod:`.foldrig`'s rig, the
fold unloaded and with the coin on, as ``locust calibrate fold`` reads real ones.

Each photo is a MuJoCo render through one camera square to the stickers' face (MuJoCo's free
camera framing the rig and the board, :func:`.camera.frame_views`, then turned by a little
yaw, pitch and roll as a hand-held phone is), with the ArUco board of ``locust track board``
standing on the table in the stickers' plane beside the clamp (turned in its plane by
``board_tilt_deg``: a board not quite upright), and sensor noise of ``noise_levels`` grey
levels added to every pixel. ``frames`` > 1 writes each state as a folder of that many photos,
each with its own noise (the frames of a clip of a still fold).

Every file says it is synthetic: the photos are named ``synthetic_...``, each PNG carries a
``Description`` text that says so, and ``<stem>.truth.json`` beside them holds the hidden
stiffness and rest angle, the settled angles and each sticker's true pixel (simulated ground
truth, read only by the tests and the demo).
"""

from __future__ import annotations

import io
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import mujoco
import numpy as np

from ..arucoboard import BOARD_MARGIN_MM, DEFAULT_BOARD, BoardSpec, parse_board
from ..errors import SimError
from ..fileio import atomic_write_bytes, atomic_write_text, json_text, make_folder
from .camera import CameraView, PinholeCamera, frame_views
from .clip import PoseRenderer, face_centre_m
from .foldrig import FOLD_STICKERS, FoldPose, FoldRig, rig_spec, settle, to_world

BOARD_PX_PER_MM = 4.0           # the board's texture resolution
BOARD_GAP_M = 0.02              # between the clamp and the board
SYNTHETIC = "SYNTHETIC"


@dataclass(frozen=True)
class FoldShot:
    """How the virtual fold test is photographed.

    Attributes
    ----------
    yaw_deg, pitch_deg, roll_deg : float
        The camera turned from square to the stickers' face: about the vertical, about the
        horizontal across the photo, about its own axis [deg].
    distance_scale : float
        The camera's distance over the one that frames rig and board.
    noise_levels : float
        Sensor noise added to every pixel, its standard deviation [grey levels of 255].
    board_tilt_deg : float
        The board turned in its plane from upright (CCW as the camera sees it) [deg].
    width_px, height_px : int
        The photo's size [px].
    frames : int
        Photos of each state (more than one: a folder of them, each its own noise).
    jpeg_quality : int or None
        Written as JPEG of this quality (its comment says it is synthetic); None: PNG.
    """

    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    roll_deg: float = 0.0
    distance_scale: float = 1.0
    noise_levels: float = 2.0
    board_tilt_deg: float = 0.0
    width_px: int = 1280
    height_px: int = 960
    frames: int = 1
    jpeg_quality: int | None = None


@dataclass(frozen=True)
class FoldPhotos:
    """The virtual fold test as written: its photos, their truth, and the rig behind them."""

    unloaded: Path              # a photo, or a folder of them (``frames`` > 1)
    loaded: Path
    truth: Path                 # ``<stem>.truth.json``
    rig: FoldRig
    unloaded_pose: FoldPose
    loaded_pose: FoldPose
    points_px: dict[str, dict[str, tuple[float, float]]]   # "unloaded"/"loaded" -> sticker -> true pixel


def _board_size_m(board: BoardSpec) -> tuple[float, float]:
    return (board.width_mm + 2 * BOARD_MARGIN_MM) / 1000.0, (board.height_mm + 2 * BOARD_MARGIN_MM) / 1000.0


def _add_board(spec: mujoco.MjSpec, board: BoardSpec, centre_x_m: float, face_y_m: float, tilt_deg: float) -> None:
    """The printed board on a thin card standing on the table, its face in the plane
    ``y = face_y_m``, centred at world ``x = centre_x_m``, turned in its plane by ``tilt_deg``
    about its bottom edge's middle (CCW as the camera sees it)."""
    image = board.image(BOARD_PX_PER_MM)
    h, w = image.shape
    tex = spec.add_texture(name="board", type=mujoco.mjtTexture.mjTEXTURE_2D, width=w, height=h, nchannel=3)
    # the box maps the texture's columns along world +x, which the camera (at +y) sees run to
    # the left: the image goes in mirrored, to be read the right way round (as sim/still.py does)
    tex.data = np.repeat(image[:, ::-1, None], 3, axis=2).tobytes()
    mat = spec.add_material(name="board", emission=0.6)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "board"
    width_m, height_m = _board_size_m(board)
    half_t = 0.0005
    # CCW in the photo (x right = world -x, y up = z) is a turn about world +y by the same angle
    half = math.radians(tilt_deg) / 2
    card = spec.worldbody.add_body(name="board", pos=[centre_x_m, face_y_m - half_t, 0.0],
                                   quat=[math.cos(half), 0.0, math.sin(half), 0.0])
    card.add_geom(name="board", type=mujoco.mjtGeom.mjGEOM_BOX, pos=[0.0, 0.0, height_m / 2],
                  size=[width_m / 2, half_t, height_m / 2], material="board", contype=0, conaffinity=0)


def _reach_m(rig: FoldRig, poses: list[FoldPose]) -> np.ndarray:
    """Points of the rig in the photo (world): the fold, the links' ends, the coin, the clamp's foot."""
    pts = [(0.0, 0.0)]
    c = math.radians(rig.clamped_deg)
    pts.append((rig.clamped_length_m * math.cos(c), rig.clamped_length_m * math.sin(c)))
    pts.append((rig.clamped_length_m * math.cos(c), -rig.fold_height_m))
    for pose in poses:
        f = math.radians(pose.free_deg)
        reach = rig.free_length_m + rig.coin_radius_m
        pts.append((reach * math.cos(f), reach * math.sin(f)))
    return np.array([to_world(rig, p) for p in pts])


def _scene(rig: FoldRig, coin: bool, board: BoardSpec, board_x_m: float, tilt_deg: float) -> mujoco.MjModel:
    spec = rig_spec(rig, coin)
    _add_board(spec, board, board_x_m, rig.face_y_m, tilt_deg)
    return spec.compile()


def _camera(renderer: PoseRenderer, view: CameraView, shot: FoldShot) -> PinholeCamera:
    """The framing view turned by the shot's yaw, pitch and distance, then rolled about its axis."""
    turned = CameraView(view.lookat_m, view.distance_m * shot.distance_scale, view.azimuth_deg + shot.yaw_deg,
                        view.elevation_deg + shot.pitch_deg)
    _, cam = renderer.render(turned)
    r = math.radians(shot.roll_deg)
    roll = np.array([[math.cos(r), -math.sin(r), 0.0], [math.sin(r), math.cos(r), 0.0], [0.0, 0.0, 1.0]])
    return PinholeCamera(cam.width_px, cam.height_px, cam.fx_px, cam.fy_px, cam.cx_px, cam.cy_px,
                         roll @ cam.rotation, cam.position_m)


def _encoded(rgb: np.ndarray, description: str, jpeg_quality: int | None) -> bytes:
    """The photo as PNG (its ``Description`` text) or JPEG (its comment), saying it is synthetic."""
    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    buf = io.BytesIO()
    if jpeg_quality is not None:
        Image.fromarray(rgb).save(buf, format="JPEG", quality=jpeg_quality, comment=description.encode())
        return buf.getvalue()
    info = PngInfo()
    info.add_text("Description", description)
    info.add_text("Software", "locust.sim.foldphotos")
    Image.fromarray(rgb).save(buf, format="PNG", pnginfo=info, compress_level=1)   # noise compresses poorly
    return buf.getvalue()


def _noisy(rgb: np.ndarray, rng: np.random.Generator, levels: float) -> np.ndarray:
    out = rgb.astype(float) + rng.normal(0.0, levels, rgb.shape) if levels > 0 else rgb.astype(float)
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)


def _write_state(path: Path, rgb: np.ndarray, shot: FoldShot, rng: np.random.Generator, what: str) -> Path:
    """One state's photo (or folder of ``shot.frames`` photos), each with its own noise."""
    description = (f"{SYNTHETIC}: MuJoCo render of a virtual fold test, the fold {what} "
                   f"(locust.sim.foldphotos); its truth in the .truth.json beside it")
    suffix = ".png" if shot.jpeg_quality is None else ".jpg"
    if shot.frames <= 1:
        path = path.with_suffix(suffix)
        atomic_write_bytes(path, _encoded(_noisy(rgb, rng, shot.noise_levels), description, shot.jpeg_quality))
        return path
    folder = make_folder(path.with_suffix(""))
    for k in range(shot.frames):
        atomic_write_bytes(folder / f"frame_{k:03d}{suffix}",
                           _encoded(_noisy(rgb, rng, shot.noise_levels), description, shot.jpeg_quality))
    return folder


def render_fold_test(rig: FoldRig, folder: str | Path, shot: FoldShot = FoldShot(), board: str | BoardSpec =
                     DEFAULT_BOARD, seed: int = 0, stem: str = "synthetic_fold") -> FoldPhotos:
    """Settle the rig unloaded and with its coin, photograph both, and write the photos and their truth.

    Parameters
    ----------
    rig : FoldRig
        The fold test as built (its hidden stiffness and rest angle).
    folder : path-like
        Where the photos go (made if missing): ``<stem>_unloaded.png``, ``<stem>_loaded.png``
        (``.jpg`` with ``shot.jpeg_quality``; folders of ``frame_NNN.png`` with ``shot.frames`` > 1)
        and ``<stem>.truth.json``.
    shot : FoldShot
        How it is photographed.
    board : str or BoardSpec
        The ArUco board standing beside the rig.
    seed : int
        The pixel noise's seed.
    stem : str
        The files' common name; it must say the photos are synthetic.

    Returns
    -------
    FoldPhotos

    Raises
    ------
    SimError
        A stem that does not say ``synthetic``, or a coin too heavy for the hinge.
    """
    if "synthetic" not in stem.lower():
        raise SimError(f"stem {stem!r}: synthetic photos must say so in their name", "e.g. stem='synthetic_fold'")
    spec = parse_board(board) if isinstance(board, str) else board
    folder = make_folder(folder)
    poses = {"unloaded": settle(rig, False)}
    poses["loaded"] = settle(rig, True, poses["unloaded"].fold_deg)
    reach = _reach_m(rig, list(poses.values()))
    bw, bh = _board_size_m(spec)
    # the board to the clamp's side (world +x is the photo's left), clear of the rig
    board_x = float(reach[:, 0].max()) + BOARD_GAP_M + bw / 2
    corners = np.array([[board_x - bw / 2, rig.face_y_m, 0.0], [board_x + bw / 2, rig.face_y_m, bh]])
    points = np.vstack([reach, corners])
    # one model (the coin in it) and one renderer for both photos: the unloaded one with the
    # coin not drawn (its alpha 0); a photo's pose is the settled angle of its own model
    model = _scene(rig, True, spec, board_x, shot.board_tilt_deg)
    coin_alpha = float(model.geom_rgba[model.geom("coin").id, 3])
    view, _ = frame_views(points, points[:, 0], 0.1, rig.face_y_m, float(model.vis.global_.fovy),
                          shot.width_px / shot.height_px)
    rng = np.random.default_rng(seed)
    paths, pixels = {}, {}
    renderer = PoseRenderer(model, shot.width_px, shot.height_px, shadows=False)
    try:
        cam = _camera(renderer, view, shot)
        for kind, pose in poses.items():
            model.geom_rgba[model.geom("coin").id, 3] = coin_alpha if kind == "loaded" else 0.0
            data = renderer.pose(np.array([math.radians(pose.fold_deg)]))
            rgb, cam = renderer.render(cam)
            pixels[kind] = {n: tuple(float(v) for v in cam.project(face_centre_m(model, data,
                                                                                 model.geom(f"sticker_{n}").id))[0])
                            for n in FOLD_STICKERS}
            paths[kind] = _write_state(folder / f"{stem}_{kind}.png", rgb, shot, rng, kind)
    finally:
        renderer.close()
    truth = folder / f"{stem}.truth.json"
    atomic_write_text(truth, json_text({
        "what": f"{SYNTHETIC} ground truth of a virtual fold test (locust.sim.foldphotos)",
        "stiffness_nm_per_rad": rig.stiffness_nm_per_rad, "rest_deg": rig.rest_deg,
        "free_mass_kg": rig.free_mass_kg, "rig": asdict(rig), "shot": asdict(shot), "board": spec.text(),
        "poses": {k: asdict(p) for k, p in poses.items()}, "points_px": pixels,
        "photos": {k: p.name for k, p in paths.items()}}))
    return FoldPhotos(paths["unloaded"], paths["loaded"], truth, rig, poses["unloaded"], poses["loaded"], pixels)


__all__ = ["FoldPhotos", "FoldShot", "render_fold_test"]
