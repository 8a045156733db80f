"""Each leg's values as its model is built: the robot's sections resolved for one side.

A side (``"L"``, the left leg at +y; ``"R"``, the right at -y) takes each value from its own
section (``left``, ``right``) where it is set, else from the ``folds`` section, else from the
film hinge's (``compliance``) or the servo's section (:data:`locust.params.model.INHERITS`).
:func:`side_values` gives every one of them as a number; :func:`is_symmetric` says whether the
two legs are alike.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..errors import ParamsError
from .legs import FOLDS
from .model import SIDE_SECTIONS, SIDE_SERVO_FIELDS, Robot, Servo

__all__ = ["FOLDS", "FoldValues", "SideValues", "side_values", "is_symmetric", "tooth_deg", "SIDES"]

SIDES = tuple(SIDE_SECTIONS)   # ("L", "R")


@dataclass(frozen=True)
class FoldValues:
    """One fold's spring as the model builds it.

    Attributes
    ----------
    stiffness_nm_per_rad : float
        Its torque per radian of deflection from its rest angle [N·m/rad].
    damping_nms_per_rad : float
        Its torque per radian per second [N·m·s/rad].
    rest_offset_deg : float
        Its unloaded angle less its angle in the robot assembled at rest [deg].
    """

    stiffness_nm_per_rad: float
    damping_nms_per_rad: float
    rest_offset_deg: float


@dataclass(frozen=True)
class SideValues:
    """One leg's values, every one resolved to a number.

    Attributes
    ----------
    side : str
        ``"L"`` or ``"R"``.
    crank_tooth : int
        Spline teeth its crank sits off ``geometry.crank_start_deg``.
    crank_start_deg : float
        Its crank's angle from the ground link at the 0 deg command, the tooth included [deg].
    trim_deg : float
        The trim added to its servo's command [deg].
    servo : Servo
        Its servo (the servo section with the side's own values in place), not yet on the supply.
    folds : dict of str to FoldValues
        Each fold of :data:`FOLDS` -> its spring.
    """

    side: str
    crank_tooth: int
    crank_start_deg: float
    trim_deg: float
    servo: Servo
    folds: dict[str, FoldValues]


def tooth_deg(robot: Robot) -> float:
    """One tooth of the servo's spline [deg]: ``360 / servo.spline_teeth``.

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    float
    """
    return 360.0 / robot.servo.spline_teeth


def side_values(robot: Robot, side: str) -> SideValues:
    """Every value of one leg, resolved.

    Parameters
    ----------
    robot : Robot
    side : str
        ``"L"`` (section ``left``) or ``"R"`` (section ``right``).

    Returns
    -------
    SideValues

    Raises
    ------
    locust.errors.ParamsError
        ``side`` is neither.
    """
    section = SIDE_SECTIONS.get(side)
    if section is None:
        raise ParamsError(f"unknown side {side!r}", "a side is 'L' (the left leg, section left) or 'R' (right)")
    own = getattr(robot, section)
    servo = replace(robot.servo, **{name: robot.get(f"{section}.servo_{name}") for name in SIDE_SERVO_FIELDS})
    folds = {fold: FoldValues(robot.get(f"{section}.{fold}_stiffness_nm_per_rad"),
                              robot.get(f"{section}.{fold}_damping_nms_per_rad"),
                              robot.get(f"{section}.{fold}_rest_offset_deg")) for fold in FOLDS}
    return SideValues(side=side, crank_tooth=own.crank_tooth,
                      crank_start_deg=robot.geometry.crank_start_deg + own.crank_tooth * tooth_deg(robot),
                      trim_deg=own.trim_deg, servo=servo, folds=folds)


def is_symmetric(robot: Robot) -> bool:
    """Whether both legs are built alike (every resolved value of :func:`side_values` the same).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    bool
    """
    left, right = (side_values(robot, side) for side in SIDES)
    return replace(left, side="R") == right
