"""One push of the hop schedule, simulated on the floor or with the robot held up.

``locust measure stroke`` compares the crank's swing in a filmed push with the model's for
the same push; the virtual clips of :mod:`.pushclip` are renders of these runs. Two runs:

- **floor**: the robot settled on the floor (``solver.settle_s`` at the 0 deg command), then
  one cycle of its schedule: ``schedule.push_deg`` for ``schedule.push_s``, then 0 deg for
  ``schedule.wait_s`` (the hop as :func:`.rollout.roll_out` runs it);
- **held**: the same command, the plate held in the hand :data:`.still.HELD_ABOVE_M` above
  where it rests (a weld to the world, as the push still holds it): the legs swing free, so
  the crank's swing is the servo's own under the legs' inertia alone.

Each keeps, from :data:`LEAD_S` before the push command to the end of the cycle, every step's
joint positions, the side's crank angle from its ground link (the servo joint's angle plus the
crank's start angle: the truth) and the world positions of the four points the stroke is read
from (:data:`POINTS`: the plate's two dots and the crank's two, :mod:`.stickers`), so that the
model's crank angle can be read from the points exactly as a clip's is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..errors import SimError
from ..params import Robot, check_robot, side_values
from .audit import audit
from .model import SIDES, build
from .rollout import simulate_built
from .schedule import control_plan
from .stickers import CRANK_INSET_M, PLATE_INSET_M

LEAD_S = 0.2                               # kept before the push command
POINTS = ("nose", "tail", "axis", "crank")  # the dots the stroke is read from
KINDS = ("floor", "held")


@dataclass(frozen=True)
class PushRun:
    """One simulated push: each kept step's time, command, crank angle and points.

    Attributes
    ----------
    kind : str
        ``floor`` or ``held``.
    side : str
        The leg read: ``L`` (at +y) or ``R`` (at -y).
    t_s : ndarray
        ``(n,)`` each kept state's time from the push command's first step [s].
    command_deg : ndarray
        ``(n,)`` the servo command in force [deg].
    crank_deg : ndarray
        ``(n,)`` the side's crank from its ground link (the four-bar frame of :mod:`.fourbar`) [deg].
    points_m : dict of str to ndarray
        Per point of :data:`POINTS`, its world position ``(n, 3)`` [m], on the side's face.
    qpos : ndarray
        ``(n, nq)`` the joint positions (for rendering).
    timestep_s : float
        The physics step [s].
    push_deg : float
        The push command [deg].
    push_s : float
        How long it is held [s].
    """

    kind: str
    side: str
    t_s: np.ndarray
    command_deg: np.ndarray
    crank_deg: np.ndarray
    points_m: dict[str, np.ndarray]
    qpos: np.ndarray
    timestep_s: float
    push_deg: float
    push_s: float


def _check(kind: str, side: str) -> None:
    if kind not in KINDS:
        raise SimError(f"push {kind!r} is not known", f"choose one of {', '.join(KINDS)}")
    if side not in SIDES:
        raise SimError(f"side {side!r} is not known", f"choose one of {', '.join(SIDES)}")


def _built(robot: Robot, kind: str):
    """The model the push runs on, and the robot it was built from (held: raised to the hand)."""
    if kind == "floor":
        return build(robot), robot
    from .still import held_model, rest_pose

    return held_model(robot, rest_pose(robot))


def point_offsets_m(robot: Robot, side: str) -> dict[str, tuple[str, np.ndarray]]:
    """Each point of :data:`POINTS`: the model's body it is on and its place in that body's
    frame, on the side's outer face (the face a camera on that side sees) [m].

    Parameters
    ----------
    robot : Robot
        The robot.
    side : str
        ``L`` or ``R``.

    Returns
    -------
    dict of str to (str, ndarray)
        Per point, its body and its ``(3,)`` position in the body's frame [m].
    """
    g = robot.geometry
    out = 1.0 if side == "L" else -1.0
    plate_y, link_y = out * g.body_width_m / 2, out * g.link_width_m / 2
    return {"nose": ("chassis", np.array([g.nose_x_m + PLATE_INSET_M, plate_y, 0.0])),
            "tail": ("chassis", np.array([g.body_length_m / 2 - PLATE_INSET_M, plate_y, 0.0])),
            "axis": (f"{side}_crank", np.array([0.0, link_y, 0.0])),
            "crank": (f"{side}_crank", np.array([g.crank_m - CRANK_INSET_M, link_y, 0.0]))}


def simulate_push(robot: Robot, kind: str = "floor", side: str = "L", timestep_s: float | None = None) -> PushRun:
    """Simulate one push of ``robot``'s schedule on the floor or held up, audited.

    Parameters
    ----------
    robot : Robot
        The robot; its schedule's push angle and time are the push.
    kind : str
        ``floor`` or ``held``.
    side : str
        The leg whose crank is read: ``L`` or ``R``.
    timestep_s : float, optional
        The physics step instead of the solver's [s] (a clip's frames fall on steps).

    Returns
    -------
    PushRun
        Every kept step.

    Raises
    ------
    SimError
        An unknown kind or side, or a run that fails its audit.
    ParamsError
        The robot is outside the parameter limits.
    """
    _check(kind, side)
    if timestep_s is not None:
        robot = robot.with_values({"solver.timestep_s": timestep_s}, "push:frame-step")
    check_robot(robot, 1)
    built, run_robot = _built(robot, kind)
    plan = control_plan(run_robot.schedule, run_robot.solver, cycles=1)
    traj = simulate_built(built, plan, keep_states=True)
    verdict = audit(traj)
    if not verdict.valid:
        raise SimError(f"the {kind} push is an invalid simulation: {'; '.join(verdict.reasons)}",
                       "run `locust sim` on the same robot and fix the reasons it lists")
    model, dt = built.model, plan.timestep_s
    first = max(0, plan.settle_steps - int(round(LEAD_S / dt)) - 1)
    rows = np.arange(first, plan.nstep)
    t = (rows + 1 - plan.settle_steps) * dt                # state row i: after step i + 1
    qpos = traj.states[rows, 1:1 + model.nq]
    servo = np.degrees(qpos[:, model.jnt_qposadr[model.joint(f"{side}_servo").id]])
    command = np.degrees(plan.ctrl_rad[np.minimum(rows + 1, plan.nstep - 1)])
    return PushRun(kind, side, t, command, side_values(robot, side).crank_start_deg + servo,
                   _points(model, robot, side, qpos), qpos, dt, robot.schedule.push_deg, robot.schedule.push_s)


def _points(model: mujoco.MjModel, robot: Robot, side: str, qpos: np.ndarray) -> dict[str, np.ndarray]:
    data = mujoco.MjData(model)
    offsets = point_offsets_m(robot, side)
    bodies = {n: model.body(b).id for n, (b, _) in offsets.items()}
    out = {n: np.empty((len(qpos), 3)) for n in offsets}
    for i, q in enumerate(qpos):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        for n, (_, p) in offsets.items():
            b = bodies[n]
            out[n][i] = data.xpos[b] + data.xmat[b].reshape(3, 3) @ p
    return out


def frame_step_s(robot: Robot, fps: float) -> float:
    """The largest physics step not above the robot's that divides a frame period, so that
    every frame of a clip at ``fps`` falls on a step [s].

    Parameters
    ----------
    robot : Robot
        The robot (its ``solver.timestep_s``).
    fps : float
        Frames per second.

    Returns
    -------
    float
        [s].
    """
    period = 1.0 / fps
    return period / math.ceil(period / robot.solver.timestep_s - 1e-9)


__all__ = ["KINDS", "LEAD_S", "POINTS", "PushRun", "frame_step_s", "point_offsets_m", "simulate_push"]
