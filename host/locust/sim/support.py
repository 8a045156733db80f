"""What the robot stands on: the floor's support points and where the centre of mass is over them.

A robot that goes over onto its back does it one way in this model (the audit of the presets,
docs/servo.md "Why a robot goes over"): the push swings the crank tips under the plate and past
the centre of mass, the nose leaves the floor, and the robot stands on the tips alone with its
centre of mass behind them; gravity then turns it over backwards about them. This module reads
that from a kept rollout: at each step, the points where the floor pushes on the robot (each
with the part it touches and its normal force) and how far the centre of mass is behind the
rearmost of them, along the robot's forward direction (from its tail to its nose, in the floor's
plane, taken from the robot standing).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from .model import BuiltModel

# a contact pushing with less than this is a touch, not a support [N] (the robot weighs 0.3 N)
MIN_SUPPORT_N = 1e-4
# where along a link a support counts as its tip or its root (fraction of its length)
TIP_FRACTION = 0.75
ROOT_FRACTION = 0.25
LINKS = ("crank", "coupler", "leg")
SIDE_WORDS = {"L": "left", "R": "right"}
# a support at a link's end is at the fold there: the knee joins crank and coupler, the foot (the
# ankle fold, the linkage's lowest point standing) coupler and leg, the leg's end closes the loop
# on the ground link's front pivot
AT_END = {("crank", "root"): "servo axis", ("crank", "tip"): "knee", ("coupler", "root"): "knee",
          ("coupler", "tip"): "foot", ("leg", "root"): "foot", ("leg", "tip"): "leg end"}


@dataclass(frozen=True)
class SupportPoint:
    """One point where the floor pushes on the robot.

    Attributes
    ----------
    part : str
        The part in words: a fold (``left foot``, ``right knee``, ``left servo axis``, ``left leg
        end``), a link between its folds (``right crank``), ``nose`` or ``plate``.
    forward_m : float
        Its position along the robot's forward direction (world, from the origin) [m].
    force_n : float
        The floor's normal force there [N].
    """

    part: str
    forward_m: float
    force_n: float


@dataclass(frozen=True)
class Stance:
    """The robot's support at one instant.

    Attributes
    ----------
    support : tuple of SupportPoint
        Every point the floor pushes on, rearmost first (empty: in the air).
    com_forward_m : float
        The centre of mass along the forward direction [m].
    com_behind_m : float
        How far the centre of mass is behind the rearmost support point [m]: positive, gravity
        turns the robot over backwards about it; negative, the centre of mass is over or in
        front of its supports by that much; nan in the air.
    """

    support: tuple[SupportPoint, ...]
    com_forward_m: float
    com_behind_m: float

    @property
    def parts(self) -> tuple[str, ...]:
        """The parts it stands on, each named once, rearmost first."""
        seen: list[str] = []
        for p in self.support:
            if p.part not in seen:
                seen.append(p.part)
        return tuple(seen)


def forward_direction(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """The robot's forward direction along world x: +1 when its nose is toward +x, else -1, from
    the pose in ``data`` (after ``mj_kinematics``): the nose site against the plate's centre.

    Parameters
    ----------
    model : mujoco.MjModel
    data : mujoco.MjData

    Returns
    -------
    float
        +1.0 or -1.0.
    """
    nose = data.site("nose").xpos
    centre = data.body("chassis").xpos
    return 1.0 if nose[0] >= centre[0] else -1.0


def _part(model: mujoco.MjModel, data: mujoco.MjData, geom: int, point: np.ndarray, built: BuiltModel) -> str:
    body = model.geom_bodyid[geom]
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or ""
    local = data.xmat[body].reshape(3, 3).T @ (point - data.xpos[body])
    if name == "chassis":
        half = model.geom_size[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "plate")][0]
        return "nose" if local[0] < -0.5 * half else "plate"
    side, _, link = name.partition("_")
    if link not in LINKS:
        return name
    length = built.link_lengths_m[1 + LINKS.index(link)]
    frac = local[0] / length
    where = "tip" if frac >= TIP_FRACTION else "root" if frac <= ROOT_FRACTION else ""
    return f"{SIDE_WORDS.get(side, side)} {AT_END.get((link, where), link)}"


def stance(built: BuiltModel, data: mujoco.MjData, forward: float) -> Stance:
    """The support in ``data`` (after ``mj_forward``): every floor contact pushing with at least
    :data:`MIN_SUPPORT_N`, and the centre of mass against the rearmost.

    Parameters
    ----------
    built : BuiltModel
        The model.
    data : mujoco.MjData
        Its data after ``mj_forward``.
    forward : float
        +1 or -1: the robot's forward direction along world x (:func:`forward_direction`).

    Returns
    -------
    Stance
    """
    model = built.model
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    wrench = np.zeros(6)
    points = []
    for i in range(data.ncon):
        con = data.contact[i]
        if floor not in (con.geom1, con.geom2) or con.efc_address < 0:
            continue
        mujoco.mj_contactForce(model, data, i, wrench)
        if wrench[0] < MIN_SUPPORT_N:
            continue
        geom = con.geom2 if con.geom1 == floor else con.geom1
        point = np.array(con.pos)
        points.append(SupportPoint(part=_part(model, data, geom, point, built), forward_m=forward * float(point[0]),
                                   force_n=float(wrench[0])))
    com = forward * float(data.subtree_com[model.body("chassis").id][0])
    points.sort(key=lambda p: p.forward_m)
    behind = points[0].forward_m - com if points else float("nan")
    return Stance(support=tuple(points), com_forward_m=com, com_behind_m=behind)


def stances(built: BuiltModel, states: np.ndarray, control: np.ndarray, rows: range,
             forward: float | None = None) -> list[Stance]:
    """The support at each of ``rows`` of a kept rollout's states.

    Parameters
    ----------
    built : BuiltModel
        The model the states are of.
    states : ndarray
        ``(nstep, nstate)`` full-physics states (``Trajectory.states``: row i after step i).
    control : ndarray
        ``(nstep, nu)`` the servo commands of the rollout [rad]: the floor's forces depend on
        the servos' torques, so row i is read with step i's command.
    rows : range
        The rows to read.
    forward : float, optional
        The forward direction (+1/-1); default from the first row's pose.

    Returns
    -------
    list of Stance
        One per row.
    """
    model = built.model
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    out = []
    for r in rows:
        mujoco.mj_setState(model, data, states[r], spec)
        data.ctrl[:] = control[r]
        mujoco.mj_forward(model, data)
        if forward is None:
            forward = forward_direction(model, data)
        out.append(stance(built, data, forward))
    return out


__all__ = ["MIN_SUPPORT_N", "Stance", "SupportPoint", "forward_direction", "stance", "stances"]
