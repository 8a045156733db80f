"""The robot standing still: how its weight shares between nose and feet.

The model is dropped and settled at the 0 deg command exactly as ``locust sim`` settles it
before the first push (``solver.settle_s``), and MuJoCo's contact forces are read: the
normal force on the plate (which touches the floor only at its nose when the robot stands
nose down) is what a kitchen scale under the nose reads, the rest is carried by the feet.
The scale's pan is taken level with the feet (stand the feet on a book as thick as the
scale).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..errors import SimError
from ..params import Robot, check_robot
from .model import build
from .schedule import control_plan
from .supply_rollout import supply_stepper

AT_REST_REL = 0.01   # the floor's normal forces must carry the weight to 1 %: the robot is still
# a robot whose schedule starts as it is dropped (seed-notebook: settle_s 0) still stands on the
# floor before anyone runs it: it is settled this long at least
MIN_SETTLE_S = 0.5


@dataclass(frozen=True)
class StandingLoad:
    """The settled robot's weight, and the share the nose carries (in kg, as a scale reads)."""

    nose_load_kg: float          # normal force under the nose / g
    total_mass_kg: float         # the whole robot (plate, servos, links)
    com_from_nose_m: float       # centre of mass along the plate, from the nose toward the tail
    plate_pitch_deg: float       # the plate's angle to the floor standing (nose down negative)


def _floor_normals(model: mujoco.MjModel, data: mujoco.MjData, plate: int, floor: int) -> tuple[float, float]:
    """Vertical force of the floor on the plate, and on the whole robot (N)."""
    on_plate = total = 0.0
    wrench = np.zeros(6)
    for i in range(data.ncon):
        con = data.contact[i]
        if floor not in (con.geom1, con.geom2):
            continue
        mujoco.mj_contactForce(model, data, i, wrench)
        # the contact frame's rows are its normal and two tangents, in world coordinates
        fz = abs(float(wrench[:3] @ con.frame.reshape(3, 3)[:, 2]))
        total += fz
        if plate in (con.geom1, con.geom2):
            on_plate += fz
    return on_plate, total


def standing_load(robot: Robot) -> StandingLoad:
    """Settle ``robot`` at the 0 deg command (for its ``solver.settle_s``, at least
    :data:`MIN_SETTLE_S`) and read the load under its nose.

    Parameters
    ----------
    robot : Robot
        Any robot ``locust sim`` accepts.

    Returns
    -------
    StandingLoad
        ``nose_load_kg`` (what a kitchen scale under the nose reads, feet level with the pan),
        ``total_mass_kg``, ``com_from_nose_m`` and ``plate_pitch_deg``.

    Raises
    ------
    locust.errors.SimError
        The robot is not at rest after ``solver.settle_s`` (its floor forces do not carry
        its weight to 1 %).
    """
    check_robot(robot, 1)
    if robot.solver.settle_s < MIN_SETTLE_S:
        robot = robot.with_values({"solver.settle_s": MIN_SETTLE_S}, "statics")
    built = build(robot)
    plan = control_plan(robot.schedule, robot.solver, 1)
    stepper = supply_stepper(built, plan.steps_per_tick)   # a supply that limits the servos (docs/servo.md)
    model = built.model if stepper is None else stepper.model
    data = mujoco.MjData(model)
    for k in range(plan.settle_steps):
        data.ctrl[list(built.servo_actuators)] = plan.ctrl_rad[k]
        if stepper is not None:
            stepper.before_step(data, k)
        mujoco.mj_step(model, data)
    mujoco.mj_forward(model, data)
    geom = mujoco.mjtObj.mjOBJ_GEOM
    plate, floor = mujoco.mj_name2id(model, geom, "plate"), mujoco.mj_name2id(model, geom, "floor")
    chassis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "chassis")
    g = -float(model.opt.gravity[2])
    mass = float(model.body_subtreemass[chassis])
    nose, total = _floor_normals(model, data, plate, floor)
    if abs(total - mass * g) > AT_REST_REL * mass * g:
        raise SimError(f"{robot.name} is not at rest after settling {robot.solver.settle_s:g} s: the floor carries "
                       f"{total / g * 1000:.2f} g of its {mass * 1000:.2f} g",
                       "give it longer to settle (--set solver.settle_s=1.0)")
    rot = data.xmat[chassis].reshape(3, 3)
    com_local = rot.T @ (data.subtree_com[chassis] - data.xpos[chassis])
    nose_local_x = robot.geometry.nose_x_m
    # the tail lies on the other side of the plate's centre from the nose
    com_from_nose = float((com_local[0] - nose_local_x) * np.sign(-nose_local_x or 1.0))
    nose_w = data.site("nose").xpos - data.xpos[chassis]
    pitch = float(np.degrees(np.arctan2(nose_w[2], abs(float(np.hypot(nose_w[0], nose_w[1]))))))
    return StandingLoad(nose_load_kg=nose / g, total_mass_kg=mass, com_from_nose_m=com_from_nose,
                        plate_pitch_deg=pitch)


__all__ = ["StandingLoad", "standing_load"]
