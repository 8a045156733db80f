"""The filmed leg sets (Small, Medium, Large: notebook Part 3), the one table presets, reports
and the hop fit build a leg set from.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..errors import ParamsError
from .model import Provenance, Robot


def with_added_length(robot: Robot, added_m: float, source: str = "sweep:scale",
                      note: str | None = None) -> Robot:
    """``robot`` with the same length added to all four links (the seed's ``scale`` variable).

    Parameters
    ----------
    robot : Robot
    added_m : float
        The length added to each link [m] (may be negative).
    source, note : str
        The provenance recorded for the four link lengths.

    Returns
    -------
    Robot
    """
    g = robot.geometry
    values = {
        "geometry.ground_m": round(g.ground_m + added_m, 9),
        "geometry.crank_m": round(g.crank_m + added_m, 9),
        "geometry.coupler_m": round(g.coupler_m + added_m, 9),
        "geometry.leg_m": round(g.leg_m + added_m, 9),
    }
    note = note or f"{added_m * 1000:+g} mm on every link"
    return robot.with_values(values, Provenance(source=source, note=note))


@dataclass(frozen=True)
class LegSet:
    """A physical leg set: what it adds to the seed design and the step its hop needs."""

    added_m: float          # length added to every link (notebook Part 3)
    timestep_s: float       # the step at which its hop has converged (rk4; docs/servo.md)
    step_note: str          # why that step


# The one table of leg sets: presets, reports and the hop fit all build a leg set from it
LEG_SETS = {
    # rk4 at 1 ms keeps every leg set within 0.1 mm per hop of dt/2, on the seed design and on the
    # robot as built alike (docs/servo.md, "Time step"): seed design 0.066 / 0.056 / 0.070 mm,
    # as built 0.006 / 0.006 / 0.027 mm (nose 0.14 mm of 13.6 cm) for Small / Medium / Large
    "small": LegSet(0.0, 1e-3, "within 0.07 mm per hop of dt/2"),
    "medium": LegSet(0.01, 1e-3, "within 0.06 mm per hop of dt/2"),
    "large": LegSet(0.02, 1e-3, "within 0.07 mm per hop of dt/2"),
}


def leg_set(robot: Robot, name: str, source: str | None = None) -> Robot:
    """``robot`` with the leg set ``name`` (small/medium/large) in place of its own: every link
    changed by ``name``'s added length less that of the leg set it carries (``robot.leg_set``),
    so a leg set is never added on top of another; its converged time step where ``robot``'s
    is coarser (a finer one is kept).

    Parameters
    ----------
    robot : Robot
        The robot the leg set is put on (its name is kept).
    name : str
        ``small``, ``medium`` or ``large``.
    source : str, optional
        The provenance of the values changed (default ``preset:<name>``).

    Returns
    -------
    Robot
        With ``leg_set == name``.

    Raises
    ------
    locust.errors.ParamsError
        An unknown leg set.
    """
    spec, own = leg_set_spec(name), leg_set_spec(robot.leg_set)
    source = source or f"preset:{name}"
    out = robot
    if spec.added_m != own.added_m:
        note = (f"notebook Part 3 leg set {name}: {spec.added_m * 1000:+g} mm on every link of the strip "
                f"(in place of {robot.leg_set}'s {own.added_m * 1000:+g} mm)")
        out = with_added_length(robot, spec.added_m - own.added_m, source=source, note=note)
    if spec.timestep_s < out.solver.timestep_s:
        out = out.with_values({"solver.timestep_s": spec.timestep_s},
                              Provenance(source=source,
                                         note=f"converged step of this leg set, {spec.step_note} (docs/servo.md)"))
    return dataclasses.replace(out, leg_set=name)


def leg_set_spec(name: str) -> LegSet:
    """The leg set ``name`` of :data:`LEG_SETS`.

    Parameters
    ----------
    name : str
        ``small``, ``medium`` or ``large``.

    Returns
    -------
    LegSet

    Raises
    ------
    locust.errors.ParamsError
        An unknown leg set.
    """
    try:
        return LEG_SETS[name]
    except KeyError:
        raise ParamsError(f"unknown leg set {name!r}", f"choose one of {', '.join(LEG_SETS)}") from None
