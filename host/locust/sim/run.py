"""One audited simulation: build, roll out, audit, summarise -> :class:`~.result.SimResult`.

``run(robot, keep_states=True)`` also keeps the rollout the result was computed from
(``SimResult.trajectory``, with every step's state), so a video or a marker's trace can be
taken from the same simulation instead of a second one.
"""

from __future__ import annotations

import numpy as np

from ..errors import GeometryError
from ..params import Robot, check_robot, side_values
from .audit import audit
from .fourbar import GOOD_TRANSMISSION_DEG, Assembly
from .hops import summarise
from .model import SIDES, build
from .outcome import classify
from .result import SimResult, invalid_result
from .rollout import roll_out
from .supply import limit_note

# a robot whose nose ends the run this far above its standing height did not come back down
# from a push (a robot that hops and lands again stands within a few millimetres of its start)
STAYED_UP_M = 0.01


def run(robot: Robot, cycles: int | None = None, timestep_s: float | None = None,
        keep_states: bool = False) -> SimResult:
    """Simulate and audit. An impossible linkage raises :class:`GeometryError`.

    With ``keep_states`` the result carries the :class:`~.rollout.Trajectory` it was computed
    from, every step's full physics state kept (``result.trajectory.states``); without it,
    ``result.trajectory`` is None. The figures are the same either way.

    Parameters
    ----------
    robot : Robot
        The robot.
    cycles : int, optional
        Cycles to simulate; default the robot's schedule's.
    timestep_s : float, optional
        Physics step instead of the robot's ``solver.timestep_s`` [s].
    keep_states : bool
        Keep the rollout with every step's state.

    Returns
    -------
    SimResult
        The audited figures; invalid, with reasons, when the run breaks its audit.

    Raises
    ------
    ParamsError
        A robot or cycle count outside the limits a simulation can run.
    GeometryError
        A linkage that cannot be built.
    """
    if timestep_s is not None:
        robot = robot.with_values({"solver.timestep_s": timestep_s})
    check_robot(robot, cycles)  # nothing unsimulatable reaches MuJoCo
    built = build(robot)
    traj = roll_out(robot, cycles=cycles, built=built, keep_states=keep_states)
    verdict = audit(traj)
    summary = summarise(traj) if verdict.valid else None
    nan = float("nan")
    notes = list(verdict.notes)
    lo, hi = GOOD_TRANSMISSION_DEG
    if summary and summary.end_nose_rise_m > STAYED_UP_M:
        notes.append(f"did not come back down: the nose ends {summary.end_nose_rise_m * 1000:.0f} mm above its "
                     "standing height (it went over onto its back), so a hop's nose rise after the one that "
                     "reared is its resting height, not a hop")
    asm = worst_transmission(built.assemblies)
    if not lo <= asm.transmission_deg <= hi:
        where = "" if len({a.transmission_deg for a in built.assemblies.values()}) == 1 else " on one leg"
        notes.append(f"poor transmission angle {asm.transmission_deg:.0f} deg at the start{where} "
                     f"(outside {lo:g}-{hi:g})")
    if (supply := limit_note(robot.servo, robot.power)) is not None:
        notes.append(supply)
    return SimResult(
        robot_name=robot.name, valid=verdict.valid, reasons=verdict.reasons,
        distance_m=summary.distance_m if summary else nan,
        max_nose_height_m=summary.max_nose_height_m if summary else nan,
        hops=summary.hops if summary else [],
        cycles=len(traj.plan.cycle_start_steps) - 1, timestep_s=traj.timestep_s,
        duration_s=traj.plan.duration_s, wall_s=traj.wall_s,
        loop_residual_max_m=verdict.loop_residual_max_m, energy_surplus_max_j=verdict.energy_surplus_max_j,
        servo_work_j=verdict.servo_work_j, servo_peak_speed_rad_per_s=peak_servo_speed(traj),
        servo_noload_speed_rad_per_s=min(side_values(robot, side).servo.noload_speed_rad_per_s for side in SIDES),
        grashof=asm.grashof,
        transmission_deg=asm.transmission_deg,
        notes=notes, trajectory=traj if keep_states else None,
        outcome=classify(summary.hops) if summary else None,
    )


def worst_transmission(assemblies: dict[str, Assembly]) -> Assembly:
    """Of the legs' assemblies, the one whose transmission angle is farthest from 90 deg.

    Parameters
    ----------
    assemblies : dict of str to Assembly
        Each leg's, as :attr:`.model.BuiltModel.assemblies`.

    Returns
    -------
    Assembly
    """
    return max(assemblies.values(), key=lambda a: abs(a.transmission_deg - 90.0))


def peak_servo_speed(traj) -> float:
    """Largest |crank speed| of either servo once the schedule has started.

    Parameters
    ----------
    traj : Trajectory
        The rollout.

    Returns
    -------
    float
        The peak speed [rad/s]; nan when no sample is finite.
    """
    vel = traj.sensordata[traj.plan.settle_steps:, traj.built.sensors.actuator_velocity]
    finite = vel[np.isfinite(vel)]
    return float(np.abs(finite).max()) if finite.size else float("nan")


CONVERGED_REL = 0.01     # a result is converged in the step when its dt/2 change is within 1 %
CONVERGED_MM = 0.1       # ... or within 0.1 mm (per hop for the distance)


def check_convergence(robot: Robot, result: SimResult, cycles: int | None = None) -> dict[str, float | bool]:
    """Rerun with every step halved (``Solver.steps_scaled``): change of distance (mm per hop and %) and of nose height
    (mm and %); ``converged`` when each is within 1 % or 0.1 mm (per hop).

    Parameters
    ----------
    robot : Robot
        The robot simulated.
    result : SimResult
        Its result at its own time step.
    cycles : int, optional
        Cycles, as for ``result``.

    Returns
    -------
    dict
        The half step [s], its validity, distance [m] and nose height [m], the changes (in mm
        per hop, mm, and relative) and ``converged``.
    """
    at = robot.with_values({"solver.timestep_s": result.timestep_s})
    half = run(at.with_values(at.solver.steps_scaled(0.5)), cycles=cycles)
    hops = max(len(result.hops), 1)

    def rel(a: float, b: float) -> float:
        return abs(a - b) / abs(b) if b else float("inf")

    dist_mm = abs(result.distance_m - half.distance_m) * 1000 / hops
    nose_mm = abs(result.max_nose_height_m - half.max_nose_height_m) * 1000
    dist_rel = rel(result.distance_m, half.distance_m)
    nose_rel = rel(result.max_nose_height_m, half.max_nose_height_m)
    converged = bool(half.valid and (dist_rel <= CONVERGED_REL or dist_mm <= CONVERGED_MM)
                     and (nose_rel <= CONVERGED_REL or nose_mm <= CONVERGED_MM))
    return {
        "half_timestep_s": half.timestep_s,
        "half_valid": half.valid,
        "half_distance_m": half.distance_m,
        "half_max_nose_height_m": half.max_nose_height_m,
        "distance_change_mm_per_hop": dist_mm,
        "distance_rel_change": dist_rel,
        "max_nose_height_change_mm": nose_mm,
        "max_nose_height_rel_change": nose_rel,
        "converged": converged,
    }


__all__ = ["SimResult", "run", "check_convergence", "invalid_result", "GeometryError"]
