"""A virtual fold test: one link of a fold clamped, the other free on its folded hinge, a coin
taped on the free link, settled under gravity (``locust calibrate fold``'s bench, simulated).

The rig is a MuJoCo model (``MjSpec``, as :mod:`.model` builds the robot): the clamped link
fixed to the world, the free link on a hinge of a hidden stiffness and rest angle (MuJoCo's
joint ``stiffness`` and ``springref``), the coin a flat cylinder of its mass lying on the free
link's upper face at its lever arm, the three stickers of
:data:`locust.markers.FOLD_STICKER_COLOURS` on the links' camera-facing face (``+y``), a
clamp post standing on the table under the clamped link's end. The equilibrium is MuJoCo's
own: the fold angle where the hinge's spring moment (``qfrc_passive``) balances the weight
(``qfrc_bias`` at rest), found by a root-find from the rest angle as the load comes on
(:func:`settle`). :mod:`.foldphotos` renders it.

Angles are in the plane the camera sees (the stickers' face, camera at ``+y`` as in
:mod:`.still`): x to the right of the photo (world ``-x``), y up (world ``z``), counter-clockwise
positive. A link's direction is its angle from the fold toward its far end; the fold's angle
is the free link's direction less the clamped link's, less 180 deg: 0 with the two links in
line (the laminate flat), as :func:`locust.sim.fourbar.fold_angles_deg` counts a fold. A body
whose own x axis points along ``psi`` in that plane is turned by ``psi + 180`` deg about world
``+y`` (MuJoCo turns x toward ``-z``, which the camera sees counter-clockwise), so the hinge's
joint angle is the fold's angle itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import mujoco
import numpy as np
from scipy.optimize import brentq

from ..errors import SimError
from ..markers import FOLD_STICKER_COLOURS, hex_to_rgb01
from ..params import GRAVITY_M_PER_S2
from .stickers import STICKER_RADIUS_M
from .still import CARDSTOCK_RGBA, STICKER_PROUD_M  # the stills' cardstock and stickers

FOLD_STICKERS = tuple(FOLD_STICKER_COLOURS)   # axis, tip, base
CLAMP_RGBA = (0.12, 0.12, 0.14, 1.0)
COIN_RGBA = (0.72, 0.45, 0.20, 1.0)    # copper
TABLE_RGBA = (0.55, 0.52, 0.48, 1.0)
CLAMP_GRIP_M = 0.010            # the clamp holds the clamped link's last centimetre
STEP_DEG = 0.25                 # the root-find's march from the start angle
FOLD_LIMIT_DEG = 179.0          # the free link folded flat onto the clamped one


@dataclass(frozen=True)
class FoldRig:
    """A fold test as built: the hidden hinge, the links, the coin, where each sticker sits.

    Attributes
    ----------
    stiffness_nm_per_rad : float
        The hinge's stiffness [N·m/rad] (hidden: what the test measures).
    rest_deg : float
        The fold's unloaded angle, weightless [deg] (hidden: what the test measures).
    clamped_deg : float
        The clamped link's direction from the fold [deg, photo plane, CCW from x right].
    clamped_length_m, free_length_m : float
        The links from the fold to their far ends [m].
    width_m, thickness_m : float
        The laminate strip's width (along the fold, toward the camera) and thickness [m].
    density_kg_per_m3 : float
        The free link's density [kg/m³] (its mass: density x length x width x thickness).
    coin_mass_kg, coin_radius_m, coin_thickness_m : float
        The coin.
    coin_arm_m : float
        From the fold to the coin's centre along the free link [m].
    axis_offset_m : (float, float)
        The axis sticker's centre from the fold line, along the clamped link (toward its far end)
        and across it (toward the link's right, seen from the fold) [m]: a sticker placed by eye.
    tip_across_m, base_across_m : float
        The tip and base stickers' centres off their links' centre lines [m].
    tip_inset_m : float
        The tip sticker's centre in from the free link's end [m].
    base_from_fold_m : float
        The base sticker's centre from the fold along the clamped link [m].
    fold_height_m : float
        The fold above the table [m].
    """

    stiffness_nm_per_rad: float
    rest_deg: float
    clamped_deg: float = 180.0
    clamped_length_m: float = 0.04
    free_length_m: float = 0.04
    width_m: float = 0.03
    thickness_m: float = 0.001
    density_kg_per_m3: float = 700.0
    coin_mass_kg: float = 0.0023
    coin_radius_m: float = 0.008125
    coin_thickness_m: float = 0.00167
    coin_arm_m: float = 0.03
    axis_offset_m: tuple[float, float] = (0.0, 0.0)
    tip_across_m: float = 0.0
    base_across_m: float = 0.0
    tip_inset_m: float = 0.005
    base_from_fold_m: float = 0.025
    fold_height_m: float = 0.10

    @property
    def free_mass_kg(self) -> float:
        """The free link's mass [kg] (the strip: density x length x width x thickness)."""
        return self.density_kg_per_m3 * self.free_length_m * self.width_m * self.thickness_m

    @property
    def face_y_m(self) -> float:
        """The world ``y`` of the links' camera-facing face, where the stickers and the board are [m]."""
        return self.width_m / 2


@dataclass(frozen=True)
class FoldPose:
    """The rig settled: its fold angle and where the links point (photo plane, deg)."""

    loaded: bool
    fold_deg: float             # the hinge's angle: 0 with the links in line
    free_deg: float             # the free link's direction from the fold
    moment_nm: float            # the hinge's spring moment there (the weight's, balanced) [N·m]


def _yrot(deg: float) -> list[float]:
    """A quaternion turning by ``deg`` about world +y."""
    half = math.radians(deg) / 2
    return [math.cos(half), 0.0, math.sin(half), 0.0]


def _facing_camera() -> list[float]:
    """A cylinder's axis (its z) turned onto +y: a disc facing the camera."""
    q = np.zeros(4)
    mujoco.mju_euler2Quat(q, np.radians([-90.0, 0.0, 0.0]), "xyz")
    return q.tolist()


def to_world(rig: FoldRig, xy_m) -> np.ndarray:
    """A point of the photo plane (fold at the origin, x right, y up) in the world [m].

    Parameters
    ----------
    rig : FoldRig
        The rig.
    xy_m : (float, float)
        The point in the photo plane, from the fold [m].

    Returns
    -------
    numpy.ndarray
        (3,) world position on the stickers' face [m].
    """
    return np.array([-float(xy_m[0]), rig.face_y_m, rig.fold_height_m + float(xy_m[1])])


def _sticker(body, name: str, x_m: float, z_m: float, face_y_m: float) -> None:
    body.add_geom(name=f"sticker_{name}", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                  pos=[x_m, face_y_m + STICKER_PROUD_M / 2, z_m], quat=_facing_camera(),
                  size=[STICKER_RADIUS_M, STICKER_PROUD_M / 2, 0], material=f"sticker_{name}",
                  contype=0, conaffinity=0, mass=0.0, group=1)


def rig_spec(rig: FoldRig, coin: bool) -> mujoco.MjSpec:
    """The rig as an ``MjSpec``: table, clamp, the clamped link with the axis and base stickers,
    the free link on its hinge with the tip sticker and (``coin``) the coin on its upper face.

    Parameters
    ----------
    rig : FoldRig
        The rig.
    coin : bool
        Whether the coin is taped on.

    Returns
    -------
    mujoco.MjSpec
    """
    spec = mujoco.MjSpec()
    spec.compiler.degree = False                 # angles in radians, as model.py gives them
    spec.option.gravity = [0.0, 0.0, -GRAVITY_M_PER_S2]
    world = spec.worldbody
    world.add_light(pos=[-0.3, 0.8, 0.9], dir=[0.3, -0.8, -0.9], castshadow=False)
    world.add_light(pos=[0.4, 0.6, 0.5], dir=[-0.4, -0.6, -0.5], castshadow=False)
    world.add_geom(name="table", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[2, 2, 0.1], rgba=list(TABLE_RGBA),
                   contype=0, conaffinity=0)
    for name, (colour, _) in FOLD_STICKER_COLOURS.items():
        spec.add_material(name=f"sticker_{name}", rgba=[*hex_to_rgb01(colour), 1.0], emission=1.0)
    half_w, half_t, face_y = rig.width_m / 2, rig.thickness_m / 2, rig.face_y_m
    clamped = world.add_body(name="clamped", pos=list(to_world(rig, (0.0, 0.0))), quat=_yrot(rig.clamped_deg + 180))
    clamped.add_geom(name="clamped_link", type=mujoco.mjtGeom.mjGEOM_BOX, pos=[rig.clamped_length_m / 2, 0, 0],
                     size=[rig.clamped_length_m / 2, half_w, half_t], rgba=list(CARDSTOCK_RGBA), contype=0,
                     conaffinity=0, mass=0.001)
    along, across = rig.axis_offset_m
    # a body's z is its link's right seen from the fold: the photo plane's direction psi - 90 deg
    _sticker(clamped, "axis", along, across, half_w)
    _sticker(clamped, "base", rig.base_from_fold_m, rig.base_across_m, half_w)
    free = clamped.add_body(name="free", pos=[0, 0, 0], quat=_yrot(180.0))
    free.add_joint(name="fold", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0],
                   stiffness=rig.stiffness_nm_per_rad, springref=math.radians(rig.rest_deg))
    free.add_geom(name="free_link", type=mujoco.mjtGeom.mjGEOM_BOX, pos=[rig.free_length_m / 2, 0, 0],
                  size=[rig.free_length_m / 2, half_w, half_t], rgba=list(CARDSTOCK_RGBA), contype=0,
                  conaffinity=0, density=rig.density_kg_per_m3)
    _sticker(free, "tip", rig.free_length_m - rig.tip_inset_m, rig.tip_across_m, half_w)
    if coin:
        # on the face that is up with the link as it rests: its z points down where the link points right
        side = -1.0 if math.cos(math.radians(rig.clamped_deg + 180 + rig.rest_deg)) >= 0 else 1.0
        free.add_geom(name="coin", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                      pos=[rig.coin_arm_m, 0, side * (half_t + rig.coin_thickness_m / 2)],
                      size=[rig.coin_radius_m, rig.coin_thickness_m / 2, 0], mass=rig.coin_mass_kg,
                      rgba=list(COIN_RGBA), contype=0, conaffinity=0)
    _add_clamp(world, rig, face_y)
    return spec


def _add_clamp(world, rig: FoldRig, face_y_m: float) -> None:
    """A post from the table to the clamped link's last :data:`CLAMP_GRIP_M`, behind the stickers' face."""
    c, s = math.cos(math.radians(rig.clamped_deg)), math.sin(math.radians(rig.clamped_deg))
    grip = (rig.clamped_length_m - CLAMP_GRIP_M / 2) * np.array([c, s])
    top = to_world(rig, grip)
    half_h = (top[2] + 0.008) / 2
    world.add_geom(name="clamp", type=mujoco.mjtGeom.mjGEOM_BOX,
                   pos=[top[0], -0.002, half_h], size=[CLAMP_GRIP_M / 2 + 0.003, face_y_m - 0.001, half_h],
                   rgba=list(CLAMP_RGBA), contype=0, conaffinity=0)


def compiled(rig: FoldRig, coin: bool) -> mujoco.MjModel:
    """The rig's compiled model (:func:`rig_spec`).

    Parameters
    ----------
    rig : FoldRig
    coin : bool
        Whether the coin is taped on.

    Returns
    -------
    mujoco.MjModel
    """
    return rig_spec(rig, coin).compile()


def _net_moment(model: mujoco.MjModel, data: mujoco.MjData, fold_deg: float) -> float:
    """The hinge's spring moment less the weight's (at rest), N·m: zero in equilibrium."""
    data.qpos[0] = math.radians(fold_deg)
    data.qvel[0] = 0.0
    mujoco.mj_forward(model, data)
    return float(data.qfrc_passive[0] - data.qfrc_bias[0])


def settle(rig: FoldRig, coin: bool, start_deg: float | None = None) -> FoldPose:
    """The fold angle the rig comes to rest at: from ``start_deg`` (default the rest angle, as the
    link's weight comes on; the loaded rig from its unloaded pose, as the coin does), the first
    angle the net moment's direction reaches where it changes sign, refined by a root-find.

    Parameters
    ----------
    rig : FoldRig
        The rig.
    coin : bool
        With the coin on.
    start_deg : float, optional
        Where the link starts [deg, fold angle].

    Returns
    -------
    FoldPose

    Raises
    ------
    SimError
        The link folds flat onto the clamped link before it balances (a coin too heavy for the hinge).
    """
    if start_deg is None:
        start_deg = rig.rest_deg if not coin else settle(rig, False).fold_deg
    model = compiled(rig, coin)
    data = mujoco.MjData(model)
    here = _net_moment(model, data, start_deg)
    step = STEP_DEG if here > 0 else -STEP_DEG
    a = start_deg
    while True:
        b = a + step
        if abs(b) > FOLD_LIMIT_DEG:
            raise SimError(f"the fold test's free link folds flat (past {FOLD_LIMIT_DEG:g} deg) before it balances",
                           "a lighter coin, a shorter lever arm or a stiffer hinge")
        if (_net_moment(model, data, b) > 0) != (here > 0):
            break
        a = b
    fold = brentq(lambda d: _net_moment(model, data, d), a, b, xtol=1e-10) if here != 0 else start_deg
    moment = -rig.stiffness_nm_per_rad * math.radians(fold - rig.rest_deg)
    return FoldPose(coin, float(fold), float(rig.clamped_deg + 180.0 + fold), moment)


def with_placement(rig: FoldRig, rng: np.random.Generator, sd_m: float) -> FoldRig:
    """``rig`` with its stickers placed by eye: each centre off where it belongs by a normal draw
    of ``sd_m`` [m] in each direction that moves it in the photo (the tip along its link does not).

    Parameters
    ----------
    rig : FoldRig
    rng : numpy.random.Generator
    sd_m : float
        The placement's standard deviation [m].

    Returns
    -------
    FoldRig
    """
    d = rng.normal(0.0, sd_m, 4)
    return replace(rig, axis_offset_m=(float(d[0]), float(d[1])), tip_across_m=float(d[2]),
                   base_across_m=float(d[3]))


__all__ = ["FOLD_STICKERS", "FoldPose", "FoldRig", "compiled", "rig_spec", "settle", "to_world", "with_placement"]
