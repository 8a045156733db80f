"""Still photos of the robot from its left side: ``locust sim --still`` and ``--still-push``.

Two poses, each simulated and audited:

- **rest**: the robot dropped and settled on the floor with both servos at the 0 deg
  command (the state at the end of ``solver.settle_s``, where every hop starts);
- **push**: the robot held in the hand, its plate clear of the table (a weld to the world at
  :data:`HELD_ABOVE_M` above where it rests), both servos commanded to ``schedule.push_deg``
  and held there for :data:`HOLD_S` (as ``locust pose -30 -30`` holds a real one): the legs
  hang free, so the crank's turn is the servo's own under the legs' weight alone.

Each is rendered through one fixed camera square to the legs' plane (MuJoCo's free camera,
:mod:`.camera`), the robot in its cardstock grey, with the ArUco board of ``locust track
board`` standing on the floor in the plane of the left leg's outer face beside it, and the
six coloured stickers of :mod:`.stickers`. Beside ``<stem>.png`` go ``<stem>.camera.json``
(the pinhole camera, through :mod:`locust.io.camera_json`, each sticker's plane) and
``<stem>.truth.csv`` (each sticker's true pixel, OpenCV convention, the share of it seen
and its world position; the servo's angle and the crank's in a comment), simulated ground
truth for testing ``locust measure stance``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import mujoco
import numpy as np

from ..arucoboard import BOARD_MARGIN_MM, DEFAULT_BOARD, BoardSpec, parse_board
from ..errors import SimError
from ..fileio import atomic_write_bytes, atomic_write_text, check_distinct
from ..io.camera_json import CameraFile, MarkerPlane, write_camera_json
from ..markers import STICKER_COLOURS, hex_to_rgb01
from ..params import Robot, side_values
from .audit import audit
from .camera import PinholeCamera, frame_views, side_azimuth_deg
from .clip import PoseRenderer, face_centre_m, seen_fraction, sidecar_paths, validate_size
from .model import SIDES, build_spec, compile_spec
from .rollout import simulate_built
from .schedule import ControlPlan, steps_per_tick
from .stickers import STICKER_RADIUS_M, STICKERS, on_bodies

HOLD_S = 1.0                    # push still: time the push command is held before the picture
HELD_ABOVE_M = 0.05             # push still: the plate held this far above where it rests
STICKER_PROUD_M = 0.0002        # a sticker's thickness on its face
CARDSTOCK_RGBA = (0.3, 0.3, 0.3, 1.0)   # the robot as built: grey cardstock and grey servos
BOARD_PX_PER_MM = 4.0           # the board's texture resolution
BOARD_GAP_M = 0.03              # between the robot's reach and the board
IMAGE_FORMATS = (".png", ".jpg", ".jpeg")


@dataclass(frozen=True)
class StillPose:
    """One pose of a still: the joint positions and what the servo did."""

    kind: str                   # "rest" or "push"
    qpos: np.ndarray
    command_deg: float          # the servos' command
    servo_deg: float            # the side's servo joint's angle (its turn from the crank's start angle)
    crank_deg: float            # the side's crank from its ground link: its start (tooth included) + servo_deg


@dataclass(frozen=True)
class StillInfo:
    """A written still and its truth."""

    path: Path
    truth_path: Path
    camera_path: Path
    pose: StillPose
    points_px: dict[str, tuple[float, float]]    # each sticker's true centre, OpenCV pixels
    seen_frac: dict[str, float]
    plate_pitch_deg: float      # the plate's leg end above its nose end, from the stickers' world positions


def _plan(robot: Robot, command_rad: float, hold_s: float) -> ControlPlan:
    """Settle at the 0 deg command, then ``command_rad`` held for ``hold_s``."""
    dt, hz = robot.solver.timestep_s, robot.solver.control_hz
    settle = int(round(robot.solver.settle_s / dt))
    hold = int(round(hold_s / dt))
    ctrl = np.concatenate([np.zeros(settle), np.full(hold, command_rad)])
    return ControlPlan(ctrl_rad=ctrl, timestep_s=dt, steps_per_tick=steps_per_tick(hz, dt), settle_steps=settle,
                       cycle_start_steps=np.array([settle, settle + hold]))


def _audited_final(built, plan: ControlPlan, what: str) -> np.ndarray:
    traj = simulate_built(built, plan, keep_states=True)
    verdict = audit(traj)
    if not verdict.valid:
        raise SimError(f"not rendering the {what} still of an invalid simulation: {'; '.join(verdict.reasons)}",
                       "run `locust sim` on the same robot and fix the reasons it lists")
    return traj.states[-1, 1:1 + built.model.nq].copy()


def _servo_deg(model: mujoco.MjModel, qpos: np.ndarray, side: str) -> float:
    return math.degrees(float(qpos[model.jnt_qposadr[model.joint(f"{side}_servo").id]]))


def rest_pose(robot: Robot, side: str = "L") -> StillPose:
    """The robot settled on the floor at the 0 deg command (``solver.settle_s``), audited.

    Parameters
    ----------
    robot : Robot
        The robot.
    side : str
        The leg whose servo and crank the pose reports: ``L`` or ``R``.

    Returns
    -------
    StillPose
        The pose, its servo and crank angles [deg].

    Raises
    ------
    SimError
        The settling run fails its audit.
    """
    spec, asm = build_spec(robot)
    built = compile_spec(spec, asm, robot)
    qpos = _audited_final(built, _plan(robot, 0.0, 0.0), "rest")
    servo = _servo_deg(built.model, qpos, side)
    return StillPose("rest", qpos, 0.0, servo, side_values(robot, side).crank_start_deg + servo)


def held_model(robot: Robot, rest: StillPose):
    """The robot held by its plate :data:`HELD_ABOVE_M` above its rest pose: the model with the
    hand (a weld of the plate to the world where it was built), and the robot it was built from.

    Parameters
    ----------
    robot : Robot
        The robot.
    rest : StillPose
        Its rest pose (:func:`rest_pose`).

    Returns
    -------
    built : BuiltModel
        The held model.
    held : Robot
        ``robot`` raised to the hand: its drop height and pitch those of the rest pose.
    """
    chassis_z = float(rest.qpos[2])
    quat = rest.qpos[3:7]
    # the rest attitude as the chassis' euler (180, pitch, 180): a turn about y only
    turn_deg = math.degrees(2.0 * math.atan2(float(quat[2]), float(quat[0]))) + 180.0
    pitch_deg = -(turn_deg - 360.0 * round(turn_deg / 360.0))
    held = robot.with_values({"geometry.drop_height_m": chassis_z + HELD_ABOVE_M,
                              "geometry.body_pitch_deg": pitch_deg}, "still:held")
    spec, asm = build_spec(held)
    # the hand: the plate welded to the world where it was built (data as MJCF fills it; a zero
    # quaternion takes the relative pose from the reference configuration)
    spec.add_equality(name="hand", type=mujoco.mjtEq.mjEQ_WELD, objtype=mujoco.mjtObj.mjOBJ_BODY,
                      name1="chassis", name2="", data=[0.0, 0.0, 0.0, 0.0, 1.0, 0.0] + [0.0] * 4 + [1.0, 0.0])
    return compile_spec(spec, asm, held), held


def push_pose(robot: Robot, rest: StillPose, side: str = "L") -> StillPose:
    """The robot held by its plate :data:`HELD_ABOVE_M` above its rest pose, the push command
    held for :data:`HOLD_S`, audited.

    Parameters
    ----------
    robot : Robot
        The robot.
    rest : StillPose
        Its rest pose (:func:`rest_pose`).
    side : str
        The leg whose servo and crank the pose reports: ``L`` or ``R``.

    Returns
    -------
    StillPose
        The held pose at the push command, its servo and crank angles [deg].

    Raises
    ------
    SimError
        The holding run fails its audit.
    """
    built, held = held_model(robot, rest)
    command = robot.schedule.push_deg
    qpos = _audited_final(built, _plan(held, math.radians(command), HOLD_S), "push")
    servo = _servo_deg(built.model, qpos, side)
    return StillPose("push", qpos, command, servo, side_values(robot, side).crank_start_deg + servo)


# -- the scene: stickers and the board ---------------------------------------------------
def sticker_model(robot: Robot, board: BoardSpec | None, board_x_m: float | None,
                 side: str = "L") -> tuple[mujoco.MjModel, float]:
    """The robot's model in cardstock grey with its stickers on the side ``side`` (and the board
    standing at ``board_x_m``, its edge nearest the robot there; None: no board); and the plane
    ``y`` of that leg's outer face, where the board stands."""
    g = robot.geometry
    out = outward_y(side)
    spec, asm = build_spec(robot)
    for geom in spec.geoms:
        if geom.name.startswith("marker_"):          # the videos' dots: no second dot of a sticker's colour
            geom.rgba = [0.0, 0.0, 0.0, 0.0]
            geom.material = ""
        elif geom.name != "floor":
            geom.rgba = list(CARDSTOCK_RGBA)
            geom.material = ""
    for site in spec.sites:                          # the nose site's red sphere is no sticker
        site.rgba = [0.0, 0.0, 0.0, 0.0]
    face_y = out * (g.leg_mount_y_m + g.link_width_m / 2)
    for name, (body, x) in on_bodies(g, side).items():
        spec.add_material(name=f"sticker_{name}", rgba=[*hex_to_rgb01(STICKER_COLOURS[name][0]), 1.0], emission=1.0)
        y = out * ((g.body_width_m if body == "chassis" else g.link_width_m) / 2 + STICKER_PROUD_M / 2)
        spec.body(body).add_geom(name=f"sticker_{name}", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                                 pos=[x, y, 0.0], quat=_facing(out),
                                 size=[STICKER_RADIUS_M, STICKER_PROUD_M / 2, 0], material=f"sticker_{name}",
                                 contype=0, conaffinity=0, mass=0.0, group=1)
    if board_x_m is not None and board is not None:
        _add_board(spec, board, board_x_m, face_y)
    spec.visual.global_.offwidth = 4096
    spec.visual.global_.offheight = 4096
    return compile_spec(spec, asm, robot).model, face_y


def outward_y(side: str) -> float:
    """+1 for the left side (at +y, the default camera's), -1 for the right.

    Parameters
    ----------
    side : str
        ``L`` or ``R``.

    Returns
    -------
    float
        The sign of y on that side.

    Raises
    ------
    SimError
        Not a side.
    """
    if side not in SIDES:
        raise SimError(f"side {side!r} is not known", f"choose one of {', '.join(SIDES)}")
    return 1.0 if side == "L" else -1.0


def _facing(out: float) -> list[float]:
    """A cylinder's axis along ``out`` * y (its face toward a camera on that side)."""
    q = np.zeros(4)
    mujoco.mju_euler2Quat(q, np.radians([-90.0 * out, 0.0, 0.0]), "xyz")
    return q.tolist()


def _board_size_m(board: BoardSpec) -> tuple[float, float]:
    """The printed sheet's size (the board and its white margin), metres."""
    return (board.width_mm + 2 * BOARD_MARGIN_MM) / 1000.0, (board.height_mm + 2 * BOARD_MARGIN_MM) / 1000.0


def _add_board(spec: mujoco.MjSpec, board: BoardSpec, right_x_m: float, face_y_m: float) -> None:
    """The printed board on a thin card standing on the floor, its face in the plane
    ``y = face_y_m`` (toward the camera on that side), its edge nearest the robot at
    ``x = right_x_m`` (it stands at -x)."""
    image = board.image(BOARD_PX_PER_MM)
    h, w = image.shape
    tex = spec.add_texture(name="board", type=mujoco.mjtTexture.mjTEXTURE_2D, width=w, height=h, nchannel=3)
    # the box maps the texture's columns along world +x, which a camera at +y sees run to the
    # left: the image goes in mirrored there, to be read the right way round
    out = 1.0 if face_y_m > 0 else -1.0
    tex.data = np.repeat((image[:, ::-1] if out > 0 else image)[:, :, None], 3, axis=2).tobytes()
    mat = spec.add_material(name="board", emission=0.6)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "board"
    width_m, height_m = _board_size_m(board)
    half_t = 0.0005
    spec.worldbody.add_geom(name="board", type=mujoco.mjtGeom.mjGEOM_BOX,
                            pos=[right_x_m - width_m / 2, face_y_m - out * half_t, height_m / 2],
                            size=[width_m / 2, half_t, height_m / 2], material="board", contype=0, conaffinity=0)


def _sticker_world(model: mujoco.MjModel, data: mujoco.MjData, out: float = 1.0) -> dict[str, np.ndarray]:
    return {n: face_centre_m(model, data, model.geom(f"sticker_{n}").id, out) for n in STICKERS}


def _reach_m(model: mujoco.MjModel, poses: list[StillPose]) -> np.ndarray:
    """Points the robot occupies in the poses (body origins, stickers, the plate's ends)."""
    data = mujoco.MjData(model)
    pts = []
    for p in poses:
        data.qpos[:] = p.qpos
        mujoco.mj_kinematics(model, data)
        pts.append(data.xpos[1:].copy())
        pts.append(np.array(list(_sticker_world(model, data).values())))
        for geom in ("plate", *(f"{s}_servo_body" for s in SIDES)):
            g = model.geom(geom).id
            half = model.geom_size[g][0]
            axis = data.geom_xmat[g].reshape(3, 3)[:, 0]
            pts.append(data.geom_xpos[g] + np.outer([-1.0, 1.0], half * axis))
    return np.vstack(pts)


# -- writing ---------------------------------------------------------------------------
def check_still_path(path: str | os.PathLike) -> Path:
    """An image name OpenCV writes (PNG or JPEG) that neither it nor its sidecars exist.

    Parameters
    ----------
    path : str or os.PathLike
        The still path asked for.

    Returns
    -------
    Path
        The same path, checked.

    Raises
    ------
    SimError
        Not ``.png``/``.jpg``, the still or a sidecar exists, or its folder is a file.
    """
    path = Path(path)
    if path.suffix.lower() not in IMAGE_FORMATS:
        raise SimError(f"still path {path} does not end in .png or .jpg", "name the still <something>.png")
    for p in (path, *sidecar_paths(path)):
        if p.exists():
            raise SimError(f"{p} exists already; not overwriting it", "choose another still name, or move it away")
    if path.parent.exists() and not path.parent.is_dir():
        raise SimError(f"{path.parent} is not a folder", "choose a still path inside a folder")
    return path


def _truth_csv(robot: Robot, pose: StillPose, world: dict[str, np.ndarray], px: dict, seen: dict,
               pitch_deg: float, side: str) -> str:
    what = ("settled on the floor at the 0 deg command" if pose.kind == "rest" else
            f"held clear of the floor at the {pose.command_deg:g} deg command")
    name = {"L": "left", "R": "right"}[side]
    lines = [f"# simulated ground truth: MuJoCo still of robot {robot.name!r}, {what}, seen from its {name}",
             f"# servo_deg = {pose.servo_deg:.4f} (the {name} servo joint); crank_deg = {pose.crank_deg:.4f} "
             f"(the crank from its ground link); plate_pitch_deg = {pitch_deg:.4f} (leg end above nose end)",
             "# pixels in the OpenCV convention (origin at the centre of the top-left pixel, x right, y down); "
             f"world x along the floor, y toward the {name} side, z up, metres",
             "point,px,py,seen_frac,x_m,y_m,z_m"]
    for n in STICKERS:
        x, y, z = world[n]
        lines.append(f"{n},{px[n][0]:.4f},{px[n][1]:.4f},{seen[n]:.3f},{x:.6f},{y:.6f},{z:.6f}")
    return "\n".join(lines) + "\n"


def _camera_file(cam: PinholeCamera, world_y: dict[str, float], view) -> CameraFile:
    K = np.array([[cam.fx_px, 0.0, cam.cx_px], [0.0, cam.fy_px, cam.cy_px], [0.0, 0.0, 1.0]])
    return CameraFile(camera="fixed", width_px=cam.width_px, height_px=cam.height_px, K=K, rotation=cam.rotation,
                      positions_m=cam.position_m[None, :],
                      marker_planes={n: MarkerPlane(y, 0.0) for n, y in world_y.items()}, frames=1,
                      view={"lookat_m": list(view.lookat_m), "distance_m": view.distance_m,
                            "azimuth_deg": view.azimuth_deg, "elevation_deg": view.elevation_deg})


def _write_still(path: Path, rgb: np.ndarray) -> None:
    ok, buf = cv2.imencode(path.suffix.lower(), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    if not ok:
        raise SimError(f"OpenCV cannot encode {path.name}", "name the still <something>.png")
    atomic_write_bytes(path, buf.tobytes())


def render_stills(robot: Robot, rest_path: str | os.PathLike | None = None,
                  push_path: str | os.PathLike | None = None, board: str | BoardSpec = DEFAULT_BOARD,
                  width: int = 1280, height: int = 960, side: str = "L") -> list[StillInfo]:
    """Render the rest still to ``rest_path`` and the push still to ``push_path`` (either may
    be None), through one fixed camera, each with its truth and camera sidecars.

    ``side``: the robot seen from its left (``L``, the camera at +y, the stickers on the left
    leg and the board in its plane) or from its right (``R``: all of it at -y).

    Parameters
    ----------
    robot : Robot
        The robot.
    rest_path, push_path : str or os.PathLike, optional
        Where to write the rest and push stills.
    board : str or BoardSpec
        The ArUco board lying behind the robot.
    width, height : int
        Image size [px].
    side : str
        ``L`` or ``R``: the side seen.

    Returns
    -------
    list of StillInfo
        Each written still, rest first.

    Raises
    ------
    SimError
        No path given, a bad size or path, or a pose that fails its audit.
    """
    spec = parse_board(board) if isinstance(board, str) else board
    validate_size(1, width, height)
    paths = {"rest": None if rest_path is None else check_still_path(rest_path),
             "push": None if push_path is None else check_still_path(push_path)}
    if paths["rest"] is None and paths["push"] is None:
        raise SimError("no still to render", "give --still REST.png and/or --still-push PUSH.png")
    options = {"--still": paths["rest"], "--still-push": paths["push"]}
    check_distinct({f"{option}{what}": p for option, path in options.items() if path is not None
                    for what, p in zip(("", " truth", " camera"), (path, *sidecar_paths(path)))})
    out_y = outward_y(side)
    rest = rest_pose(robot, side)
    poses = {"rest": rest, "push": push_pose(robot, rest, side)}
    model, face_y = sticker_model(robot, spec, None, side)
    reach = _reach_m(model, list(poses.values()))
    board_right = float(reach[:, 0].min()) - BOARD_GAP_M
    model, face_y = sticker_model(robot, spec, board_right, side)
    bw, bh = _board_size_m(spec)
    corners = np.array([[board_right - bw, face_y, 0.0], [board_right, face_y, bh]])
    points = np.vstack([reach, corners])
    fixed, _ = frame_views(points, points[:, 0], robot.geometry.body_length_m, face_y,
                           float(model.vis.global_.fovy), width / height, azimuth_deg=side_azimuth_deg(side))
    renderer = PoseRenderer(model, width, height)
    out = []
    try:
        for kind, pose in poses.items():
            path = paths[kind]
            if path is None:
                continue
            data = renderer.pose(pose.qpos)
            rgb, cam = renderer.render(fixed)
            world = _sticker_world(model, data, out_y)
            px = {n: tuple(float(v) for v in cam.project(world[n])[0]) for n in STICKERS}
            seen = {n: seen_fraction(model, data, cam, world[n], model.geom(f"sticker_{n}").id) for n in STICKERS}
            d = world["tail"] - world["nose"]
            pitch = math.degrees(math.atan2(d[2], abs(d[0])))
            truth_path, camera_path = sidecar_paths(path)
            _write_still(path, rgb)
            atomic_write_text(truth_path, _truth_csv(robot, pose, world, px, seen, pitch, side))
            write_camera_json(camera_path, _camera_file(cam, {n: float(world[n][1]) for n in STICKERS}, fixed))
            out.append(StillInfo(path, truth_path, camera_path, pose, px, seen, pitch))
    finally:
        renderer.close()
    return out


__all__ = ["HELD_ABOVE_M", "HOLD_S", "StillInfo", "StillPose", "check_still_path", "held_model", "outward_y",
           "push_pose", "render_stills", "rest_pose", "sticker_model"]
