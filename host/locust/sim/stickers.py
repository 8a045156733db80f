"""Where the stickers of a still photo sit: on which body, and in the plate's own frame.

Six coloured dots (:data:`locust.markers.STICKER_COLOURS`) mark the points a student marks on
a side photo of the robot: the plate's two ends, the servo horn's axis, the crank's tip, and
the leg near the coupler-leg joint and further up. Each sits a fixed distance along its link, so
one function gives where the render draws it (:func:`on_bodies`) and another where the stance
puts it in the plate's frame (:func:`plate_points`), the model ``locust measure stance`` fits.

Plate frame (the chassis frame of :mod:`.model`, seen in the legs' plane): x along the plate
from its nose end (-x) to its leg end, z toward the side the legs hang from. The left leg's
four-bar hangs from the servo axis at ``(servo_axis_x_m, servo_axis_below_plate_m)``, its
ground link at ``ground_angle_deg`` to the plate, assembled by :func:`.fourbar.assemble` at the
crank angle it is posed at (``crank_start_deg`` plus the servo's turn), mirrored as
:mod:`.model` mirrors it.
"""

from __future__ import annotations

import math

import numpy as np

from ..markers import STICKER_COLOURS
from ..params import Geometry
from .fourbar import assemble

STICKERS = tuple(STICKER_COLOURS)   # nose, tail, axis, crank, knee, foot
STICKER_RADIUS_M = 0.003            # a 6 mm dot
PLATE_INSET_M = 0.010               # the plate's dots, in from each end
CRANK_INSET_M = 0.008               # the crank's tip dot, in from the crank-coupler joint (near the floor at rest)
KNEE_UP_M = 0.008                   # the knee dot, up the leg from the coupler-leg joint (the coupler may lie
                                    # on the floor, the joint touches it)
FOOT_UP_M = 0.025                   # the leg's dot, up from the coupler-leg joint (the videos' foot dot)


def on_bodies(g: Geometry, side: str = "L") -> dict[str, tuple[str, float]]:
    """Sticker -> (the model's body it is on, distance along that body's x axis), metres.

    The plate's dots are on the chassis (its x axis runs along the plate); the link dots on
    the side's leg's links, whose bodies start at their first joint and run along the link.

    Parameters
    ----------
    g : Geometry
        The robot's geometry.
    side : str
        The leg the link dots are on: ``L`` (the default camera's, at +y) or ``R`` (at -y).

    Returns
    -------
    dict of str to (str, float)
        Per sticker, its body and distance along it [m].
    """
    return {"nose": ("chassis", g.nose_x_m + PLATE_INSET_M),
            "tail": ("chassis", g.body_length_m / 2 - PLATE_INSET_M),
            "axis": (f"{side}_crank", 0.0),
            "crank": (f"{side}_crank", g.crank_m - CRANK_INSET_M),
            "knee": (f"{side}_leg", KNEE_UP_M),
            "foot": (f"{side}_leg", FOOT_UP_M)}


def plate_points(g: Geometry, crank_deg: float, ground_angle_deg: float, servo_axis_x_m: float) -> np.ndarray:
    """The stickers' positions (len(STICKERS), 2) in the plate frame, ``(x, z)`` metres.

    ``crank_deg``: the crank's angle from the ground link as posed (at rest, the 0 deg command:
    ``crank_start_deg`` plus the servo's deflection under load). The link lengths, the plate
    and the axis' depth under the plate are ``g``'s. Raises :class:`~locust.errors.GeometryError`
    where the loop cannot close.

    Parameters
    ----------
    g : Geometry
        The robot's geometry.
    crank_deg : float
        The crank's angle from the ground link [deg].
    ground_angle_deg : float
        The ground link's angle to the plate [deg].
    servo_axis_x_m : float
        The servo axis' position along the plate [m].

    Returns
    -------
    ndarray
        (len(STICKERS), 2) positions [m].
    """
    asm = assemble(g.ground_m, g.crank_m, g.coupler_m, g.leg_m, crank_deg)
    p1, p2, p3, p4 = (np.asarray(p) for p in (asm.p1_m, asm.p2_m, asm.p3_m, asm.p4_m))
    tip = p2 + CRANK_INSET_M * (p1 - p2) / g.crank_m
    knee = p3 + KNEE_UP_M * (p4 - p3) / g.leg_m
    foot = p3 + FOOT_UP_M * (p4 - p3) / g.leg_m
    linkage = np.array([p1, tip, knee, foot]) - p1          # from the servo axis, four-bar frame
    mount = np.column_stack([linkage[:, 0], -linkage[:, 1]])   # the model's mirror (sim/model.py)
    c, s = math.cos(math.radians(ground_angle_deg)), math.sin(math.radians(ground_angle_deg))
    on_plate = np.column_stack([servo_axis_x_m + mount[:, 0] * c + mount[:, 1] * s,
                                g.servo_axis_below_plate_m - mount[:, 0] * s + mount[:, 1] * c])
    ends = np.array([[g.nose_x_m + PLATE_INSET_M, 0.0], [g.body_length_m / 2 - PLATE_INSET_M, 0.0]])
    return np.vstack([ends, on_plate])


def to_view(points_m: np.ndarray, x0_m: float, y0_m: float, pitch_deg: float, mirrored: bool = False) -> np.ndarray:
    """Plate-frame points (N, 2) placed in a side view's plane frame (x right, y up), metres.

    Seen from the robot's left (the model's camera side, :mod:`.camera`) a level plate's x
    runs to the right of the view, its legs' side (z) down; the plate is then turned by
    ``pitch_deg`` (counter-clockwise in the view: its leg end up) and shifted by
    ``(x0_m, y0_m)``. ``mirrored``: seen from the robot's right, x runs to the left.

    Parameters
    ----------
    points_m : ndarray
        (N, 2) plate-frame points [m].
    x0_m, y0_m : float
        Where the plate's origin goes in the view [m].
    pitch_deg : float
        The plate's pitch in the view [deg].
    mirrored : bool
        Seen from the robot's right.

    Returns
    -------
    ndarray
        (N, 2) view-plane points [m].
    """
    p = np.asarray(points_m, float)
    u = np.column_stack([-p[:, 0] if mirrored else p[:, 0], -p[:, 1]])
    c, s = math.cos(math.radians(pitch_deg)), math.sin(math.radians(pitch_deg))
    return np.column_stack([x0_m + u[:, 0] * c - u[:, 1] * s, y0_m + u[:, 0] * s + u[:, 1] * c])


__all__ = ["CRANK_INSET_M", "FOOT_UP_M", "KNEE_UP_M", "PLATE_INSET_M", "STICKERS", "STICKER_RADIUS_M", "on_bodies",
           "plate_points", "to_view"]
