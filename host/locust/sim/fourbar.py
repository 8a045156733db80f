"""Planar four-bar linkage: assembly at a crank angle, Grashof class, transmission angle.

Frame (the leg's own plane, as in the notebook): the ground link lies on the x axis from the
rear pivot ``P1 = (-ground/2, 0)`` (the servo axis, where the crank turns) to the front pivot
``P4 = (ground/2, 0)``. The crank runs ``P1 -> P2`` at ``crank_deg`` from +x, the coupler
``P2 -> P3``, the leg ``P3 -> P4`` closes the loop. Of the two assemblies, the one with the
knee ``P3`` on the clockwise side of ``P2 -> P4`` is taken (the notebook's choice).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import GeometryError
from ..params import FOLDS, Robot, side_values

# Transmission angles outside this band transmit force poorly; reported, not refused.
GOOD_TRANSMISSION_DEG = (40.0, 140.0)


@dataclass(frozen=True)
class Assembly:
    """The linkage assembled at one crank angle (positions in metres, angles in degrees)."""

    p1_m: tuple[float, float]           # rear pivot (servo)
    p2_m: tuple[float, float]           # crank tip
    p3_m: tuple[float, float]           # knee (coupler-leg hinge)
    p4_m: tuple[float, float]           # front pivot
    crank_deg: float                    # crank direction, from +x
    coupler_deg: float                  # coupler direction, from +x
    leg_deg: float                      # leg direction (P3 -> P4), from +x
    coupler_rel_deg: float              # coupler relative to crank (joint angle at P2)
    leg_rel_deg: float                  # leg relative to coupler (joint angle at P3)
    transmission_deg: float             # angle between coupler and leg at the knee, 0..180
    grashof: str                        # see grashof_class()
    closure_error_m: float              # |P3 - P4| - leg, should be ~1e-17


def grashof_class(ground_m: float, crank_m: float, coupler_m: float, leg_m: float) -> str:
    """Grashof type of a four-bar with the given link lengths.

    ``"crank-rocker"``, ``"double-crank"``, ``"double-rocker"`` (Grashof: s + l < p + q, so at
    least one link turns fully), ``"change-point"`` (s + l == p + q: it can fold flat) or
    ``"non-grashof"`` (triple rocker: no link turns fully).

    Parameters
    ----------
    ground_m, crank_m, coupler_m, leg_m : float
        The four link lengths [m].

    Returns
    -------
    str
        The class's name.
    """
    links = [ground_m, crank_m, coupler_m, leg_m]
    shortest_m, longest_m = min(links), max(links)
    p_plus_q = sum(links) - shortest_m - longest_m
    tol = 1e-12 * max(links)
    if shortest_m + longest_m > p_plus_q + tol:
        return "non-grashof"
    if abs(shortest_m + longest_m - p_plus_q) <= tol:
        return "change-point"
    shortest = links.index(shortest_m)
    return {0: "double-crank", 1: "crank-rocker", 2: "double-rocker", 3: "crank-rocker"}[shortest]


def check_lengths(ground_m: float, crank_m: float, coupler_m: float, leg_m: float) -> None:
    """Refuse link lengths no four-bar can be built from.

    Parameters
    ----------
    ground_m, crank_m, coupler_m, leg_m : float
        The four link lengths [m].

    Raises
    ------
    GeometryError
        A length that is not a positive number, or a longest link not shorter than the other
        three together.
    """
    names = {"geometry.ground_m": ground_m, "geometry.crank_m": crank_m,
             "geometry.coupler_m": coupler_m, "geometry.leg_m": leg_m}
    for key, value in names.items():
        if not (math.isfinite(value) and value > 0):
            raise GeometryError(f"{key} = {value!r}: a link length must be a positive number of metres")
    longest_key = max(names, key=names.get)
    if names[longest_key] >= sum(names.values()) - names[longest_key]:
        others = sum(names.values()) - names[longest_key]
        raise GeometryError(
            f"the linkage cannot close at any crank angle: {longest_key} = {names[longest_key]:.4g} m "
            f"is not shorter than the other three together ({others:.4g} m)",
            "make the longest link shorter than the sum of the other three",
        )


def assemble(ground_m: float, crank_m: float, coupler_m: float, leg_m: float,
             crank_deg: float) -> Assembly:
    """Assemble the loop at ``crank_deg``; :class:`GeometryError` names the violated condition.

    Parameters
    ----------
    ground_m, crank_m, coupler_m, leg_m : float
        The four link lengths [m].
    crank_deg : float
        The crank's angle from the ground link [deg].

    Returns
    -------
    Assembly
        The joint positions [m], link angles [deg], transmission angle [deg] and Grashof class.

    Raises
    ------
    GeometryError
        Bad lengths, or a loop that cannot close at this crank angle.
    """
    check_lengths(ground_m, crank_m, coupler_m, leg_m)
    th = math.radians(crank_deg)
    p1 = (-ground_m / 2, 0.0)
    p4 = (ground_m / 2, 0.0)
    p2 = (p1[0] + crank_m * math.cos(th), p1[1] + crank_m * math.sin(th))
    dx, dz = p4[0] - p2[0], p4[1] - p2[1]
    d = math.hypot(dx, dz)
    if d < 1e-9:
        raise GeometryError(
            f"crank tip coincides with the front pivot at crank {crank_deg:g} deg "
            f"(crank {crank_m:.4g} m, ground {ground_m:.4g} m): the loop is singular",
            "change geometry.crank_start_deg or the link lengths",
        )
    if d > coupler_m + leg_m:
        raise GeometryError(
            f"the four-bar cannot close at crank {crank_deg:g} deg: crank tip to front pivot is "
            f"{d * 100:.2f} cm but coupler + leg reach only {(coupler_m + leg_m) * 100:.2f} cm "
            f"(short by {(d - coupler_m - leg_m) * 100:.2f} cm)",
            "lengthen geometry.coupler_m or geometry.leg_m, or change geometry.crank_start_deg",
        )
    if d < abs(coupler_m - leg_m):
        raise GeometryError(
            f"the four-bar cannot close at crank {crank_deg:g} deg: crank tip to front pivot is "
            f"{d * 100:.2f} cm but |coupler - leg| is {abs(coupler_m - leg_m) * 100:.2f} cm "
            f"(the longer of the two overshoots by {(abs(coupler_m - leg_m) - d) * 100:.2f} cm)",
            "make geometry.coupler_m and geometry.leg_m closer in length, or change the crank angle",
        )
    a = (coupler_m**2 - leg_m**2 + d**2) / (2 * d)
    h = math.sqrt(max(coupler_m**2 - a**2, 0.0))
    p3 = (p2[0] + a * dx / d + h * dz / d, p2[1] + a * dz / d - h * dx / d)
    coupler_deg = math.degrees(math.atan2(p3[1] - p2[1], p3[0] - p2[0]))
    leg_deg = math.degrees(math.atan2(p4[1] - p3[1], p4[0] - p3[0]))
    transmission = math.degrees(math.acos(max(-1.0, min(1.0, (coupler_m**2 + leg_m**2 - d**2)
                                                             / (2 * coupler_m * leg_m)))))
    closure = math.hypot(p4[0] - p3[0], p4[1] - p3[1]) - leg_m
    return Assembly(
        p1_m=p1, p2_m=p2, p3_m=p3, p4_m=p4,
        crank_deg=crank_deg, coupler_deg=coupler_deg, leg_deg=leg_deg,
        coupler_rel_deg=_wrap(coupler_deg - crank_deg), leg_rel_deg=_wrap(leg_deg - coupler_deg),
        transmission_deg=transmission,
        grashof=grashof_class(ground_m, crank_m, coupler_m, leg_m),
        closure_error_m=abs(closure),
    )


def side_assembly(robot: Robot, side: str) -> Assembly:
    """One leg assembled at rest: at its crank's start angle, its tooth included
    (:func:`locust.params.side_values`).

    Parameters
    ----------
    robot : Robot
    side : str
        ``"L"`` or ``"R"``.

    Returns
    -------
    Assembly

    Raises
    ------
    GeometryError
        The loop cannot close at that crank angle.
    """
    g = robot.geometry
    return assemble(g.ground_m, g.crank_m, g.coupler_m, g.leg_m, side_values(robot, side).crank_start_deg)


def fold_angles_deg(robot: Robot, side: str) -> dict[str, float]:
    """Each fold's angle in the robot assembled at rest (0 deg command), 0 where its two links
    lie in line as on the flat strip (ground, crank, coupler, leg, glued back over the ground).

    The loop runs P4 -> P1 along the ground link, then crank, coupler and leg back to P4; a
    fold's angle is the turn from the link before it to the link after it, in the frame's
    counter-clockwise sense (the sense the model's joints turn in), within half a turn. The
    four add up to a whole turn (360 deg: the knee on the clockwise side turns the loop counter-clockwise).

    Parameters
    ----------
    robot : Robot
    side : str
        ``"L"`` or ``"R"``.

    Returns
    -------
    dict of str to float
        Each fold of :data:`locust.params.FOLDS` -> its angle [deg].

    Raises
    ------
    GeometryError
        The loop cannot close at that side's crank angle.
    """
    asm = side_assembly(robot, side)
    angles = (_wrap(asm.crank_deg - 180.0), asm.coupler_rel_deg, asm.leg_rel_deg, _wrap(180.0 - asm.leg_deg))
    return dict(zip(FOLDS, angles))


def _wrap(deg: float) -> float:
    return (deg + 180.0) % 360.0 - 180.0
