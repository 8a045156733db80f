"""The leg's own sections of the robot file: each fold a spring of its own (``folds``), and what
one leg has of its own (``left``, ``right``); :mod:`.sides` resolves them, :mod:`.model` holds
them in the robot."""

from __future__ import annotations

from dataclasses import dataclass

# the four folds of each leg, in the order the loop runs: ground link -> crank at the servo
# axis (in parallel with the servo), crank -> coupler (knee), coupler -> leg (ankle), and the
# leg's end -> the ground link's front pivot (the loop-closing fold)
FOLDS = ("servo", "knee", "ankle", "loop")


@dataclass(frozen=True)
class Folds:
    """Each of a leg's four folds (:data:`FOLDS`) as a spring of its own: stiffness, damping
    and the angle at which it is unloaded (docs/servo.md, "Hinges and links").

    A stiffness or damping of None is the film hinge's (``compliance.hinge_stiffness_nm_per_rad``,
    ``compliance.hinge_damping_nms_per_rad``). ``F_rest_offset_deg`` is the fold's unloaded
    angle less its angle in the robot assembled at rest (0 deg command, crank at
    ``geometry.crank_start_deg``): 0, unloaded as assembled. Angles turn as the model's joints
    do (a + servo command turns the servo fold +).
    """

    servo_stiffness_nm_per_rad: float | None = None
    servo_damping_nms_per_rad: float | None = None
    servo_rest_offset_deg: float = 0.0
    knee_stiffness_nm_per_rad: float | None = None
    knee_damping_nms_per_rad: float | None = None
    knee_rest_offset_deg: float = 0.0
    ankle_stiffness_nm_per_rad: float | None = None
    ankle_damping_nms_per_rad: float | None = None
    ankle_rest_offset_deg: float = 0.0
    loop_stiffness_nm_per_rad: float | None = None
    loop_damping_nms_per_rad: float | None = None
    loop_rest_offset_deg: float = 0.0


@dataclass(frozen=True)
class Side:
    """What one leg (section ``left`` or ``right``) has of its own; None takes the value of the
    section named in the comment (:func:`inherited_from`).

    ``crank_tooth``: the spline teeth its crank sits off ``geometry.crank_start_deg`` (+: turned
    the way a + command turns it; one tooth is ``360 / servo.spline_teeth`` deg). ``trim_deg``:
    the firmware's trim, added to this servo's command, in the command's sense (the board's
    ``config.json`` holds it times the servo's direction, -1 for the mirrored right servo).
    """

    crank_tooth: int = 0
    trim_deg: float = 0.0
    # None: the folds section's
    servo_stiffness_nm_per_rad: float | None = None
    servo_damping_nms_per_rad: float | None = None
    servo_rest_offset_deg: float | None = None
    knee_stiffness_nm_per_rad: float | None = None
    knee_damping_nms_per_rad: float | None = None
    knee_rest_offset_deg: float | None = None
    ankle_stiffness_nm_per_rad: float | None = None
    ankle_damping_nms_per_rad: float | None = None
    ankle_rest_offset_deg: float | None = None
    loop_stiffness_nm_per_rad: float | None = None
    loop_damping_nms_per_rad: float | None = None
    loop_rest_offset_deg: float | None = None
    # None: the servo section's
    servo_kp_nm_per_rad: float | None = None
    servo_stall_torque_nm: float | None = None
    servo_noload_speed_rad_per_s: float | None = None
    servo_armature_kgm2: float | None = None
    servo_kv_nms_per_rad: float | None = None


__all__ = ["FOLDS", "Folds", "Side"]
