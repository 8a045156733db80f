"""The limits of every robot parameter, each with its reason, and the checks a robot must pass
before it is simulated (``problems``, ``check_robot``).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from ..errors import ParamsError
from ..firmware import config as fw_config
from ..firmware import protocol
from .legs import FOLDS
from .model import SIDE_SECTIONS, SIDE_SERVO_FIELDS, Robot

# -- limits -------------------------------------------------------------------------
# The robots this toolkit is for: a desk hopper of a few grams to a kilogram, links of
# millimetres to tens of centimetres, hobby servos. Each key's (lowest, highest, lowest
# allowed?, highest allowed?, reason): a value outside is refused with its limit and reason
# before anything is built, so nothing unsimulatable reaches MuJoCo and nothing absurd is
# simulated as valid. The schedule's limits are the firmware's own (firmware/protocol.py,
# the ``hop`` command).
_OPEN, _SHUT = False, True
_HOP = protocol.COMMANDS["hop"]   # argument -> (kind, lowest, highest, default)


class Limit(NamedTuple):
    """One parameter's admissible range, in the parameter's unit, and why.

    Attributes
    ----------
    low, high : float
        The bounds.
    low_ok, high_ok : bool
        Whether each bound itself is admissible (closed) or not (open).
    reason : str
        What the range stands for (e.g. "a link of a desk hopper"), shown when it is broken.
    """

    low: float
    high: float
    low_ok: bool
    high_ok: bool
    reason: str


_LINK = "a link of a desk hopper: millimetres to tens of centimetres"
_BODY = "a desk hopper's plate: a centimetre to half a metre"
_SHEET = "a sheet or laminate: 0.1 mm to 1 cm thick"
_PLACE = "a position on a desk hopper's plate: within half a metre of its centre"
_SERVO_SIZE = "a hobby servo's body: 5 mm to 10 cm"
_ANGLE = "an angle: within a turn either way"
_FRICTION = "a friction coefficient: 0 (ice) to 5 (far above rubber on a rough floor, mu 1-2)"
_SCHEDULE = "the firmware's own limit on the hop command (firmware/protocol.py)"
_IMPEDANCE = "a constraint impedance: strictly between 0 and 1 (MuJoCo)"
_TRIM = fw_config.LIMITS["trim_deg"]   # (lowest, highest, integer?): the board's own limit
_HINGE_K = Limit(0.0, 10.0, _SHUT, _SHUT, "a flexure hinge of film or card: 0 to 10 N*m/rad (the seed's cardstock beam "
                                          "0.056, the film hinge 1.5e-4)")
_HINGE_B = Limit(0.0, 1.0, _SHUT, _SHUT, "a flexure hinge's damping: 0 to 1 N*m*s/rad (the seed's 5.6e-4)")
_REST = Limit(-180.0, 180.0, _SHUT, _SHUT, "a fold's unloaded angle: within half a turn of its angle as assembled")
_FOLD_LIMITS = {f"{fold}_{kind}": limit for fold in FOLDS for kind, limit in (
    ("stiffness_nm_per_rad", _HINGE_K), ("damping_nms_per_rad", _HINGE_B), ("rest_offset_deg", _REST))}
LIMITS: dict[str, Limit] = {
    **{f"geometry.{n}": Limit(0.001, 0.5, _SHUT, _SHUT, _LINK) for n in ("ground_m", "crank_m", "coupler_m", "leg_m")},
    **{f"geometry.{n}": Limit(0.01, 0.5, _SHUT, _SHUT, _BODY) for n in ("body_length_m", "body_width_m")},
    **{f"geometry.{n}": Limit(0.0001, 0.01, _SHUT, _SHUT, _SHEET) for n in ("body_thickness_m", "link_thickness_m")},
    "geometry.link_width_m": Limit(0.001, 0.2, _SHUT, _SHUT, "a link's width: a millimetre to 20 cm"),
    **{f"geometry.{n}": Limit(0.005, 0.1, _SHUT, _SHUT, _SERVO_SIZE) for n in (
        "servo_length_m", "servo_width_m", "servo_height_m")},
    **{f"geometry.{n}": Limit(-0.5, 0.5, _SHUT, _SHUT, _PLACE) for n in (
        "servo_axis_x_m", "leg_mount_y_m", "servo_axis_below_plate_m", "servo_body_x_m", "servo_body_y_m",
        "nose_x_m")},
    "geometry.body_mass_kg": Limit(0.001, 1.0, _SHUT, _SHUT, "a desk hopper's plate: a gram to a kilogram"),
    "geometry.servo_mass_kg": Limit(0.0, 0.2, _SHUT, _SHUT, "a hobby servo: none (massless) to 200 g"),
    "geometry.link_density_kg_per_m3": Limit(50.0, 3000.0, _SHUT, _SHUT,
                                             "a laminate: foam (50 kg/m^3) to aluminium (2700 kg/m^3)"),
    "geometry.drop_height_m": Limit(0.0, 0.3, _SHUT, _SHUT,
                                    "a hop starts on a desk: dropped from at most 30 cm, on the floor "
                                    "before the schedule starts"),
    "geometry.ground_angle_deg": Limit(-180.0, 180.0, _SHUT, _SHUT, _ANGLE),
    "geometry.crank_start_deg": Limit(-360.0, 360.0, _SHUT, _SHUT, _ANGLE),
    "geometry.body_pitch_deg": Limit(-180.0, 180.0, _SHUT, _SHUT, _ANGLE),
    "compliance.hinge_stiffness_nm_per_rad": _HINGE_K,
    "compliance.hinge_damping_nms_per_rad": _HINGE_B,
    **{f"folds.{name}": limit for name, limit in _FOLD_LIMITS.items()},
    "servo.kp_nm_per_rad": Limit(0.0, 100.0, _OPEN, _SHUT,
                                 "a hobby servo's gain: above 0 to 100 N*m/rad (an SG90 0.38)"),
    "servo.stall_torque_nm": Limit(0.0, 5.0, _OPEN, _SHUT,
                                   "a hobby servo's stall torque: above 0 to 5 N*m (50 kg*cm; an SG90 0.15)"),
    "servo.noload_speed_rad_per_s": Limit(0.5, math.inf, _SHUT, _SHUT,
                                          "a hobby servo's no-load speed: at least 0.5 rad/s (an SG90 10.3); "
                                          "inf: no speed limit"),
    "servo.armature_kgm2": Limit(0.0, 0.01, _SHUT, _SHUT,
                                 "a hobby servo's reflected rotor inertia: 0 to 0.01 kg*m^2 (an SG90 4.7e-4)"),
    "servo.kv_nms_per_rad": Limit(0.0, 10.0, _SHUT, _SHUT, "a hobby servo's velocity feedback: 0 to 10 N*m*s/rad"),
    "servo.travel_deg": Limit(0.0, 90.0, _OPEN, _SHUT, "a hobby servo turns at most 90 deg either side of rest"),
    "servo.pulse_min_us": Limit(100.0, 5000.0, _SHUT, _SHUT, "a hobby servo's pulse: 0.1 to 5 ms"),
    "servo.pulse_max_us": Limit(100.0, 5000.0, _SHUT, _SHUT, "a hobby servo's pulse: 0.1 to 5 ms"),
    "servo.range_deg": Limit(0.0, 360.0, _OPEN, _SHUT, "a hobby servo sweeps at most one turn over its pulses"),
    "servo.spline_teeth": Limit(8, 48, _SHUT, _SHUT, "a hobby servo's output spline: 8 to 48 teeth (micro servos "
                                                     "15 to 25: Hitec A1 15, SG90 about 21, Futaba 3F 25)"),
    "servo.reference_voltage_v": Limit(1.0, 24.0, _SHUT, _SHUT, "a hobby servo runs on 1 to 24 V (an SG90 4.8-6 V)"),
    "servo.winding_resistance_ohm": Limit(0.1, 1000.0, _SHUT, _SHUT,
                                          "a hobby servo's motor winding: 0.1 to 1000 ohm (an SG90 about 10)"),
    **{f"{side}.{name}": limit for side in SIDE_SECTIONS.values() for name, limit in (
        ("crank_tooth", Limit(-48, 48, _SHUT, _SHUT, "a crank sits less than a turn off its place: fewer teeth either "
                                                    "way than its servo's spline has (servo.spline_teeth)")),
        ("trim_deg", Limit(_TRIM[0], _TRIM[1], _SHUT, _SHUT, "the firmware's own limit on a servo's trim "
                                                            "(firmware/config.py)")),
        *_FOLD_LIMITS.items())},
    "contact.foot_friction": Limit(0.0, 5.0, _SHUT, _SHUT, _FRICTION),
    "contact.nose_friction": Limit(0.0, 5.0, _SHUT, _SHUT, _FRICTION),
    "contact.torsional_friction": Limit(0.0, 0.1, _SHUT, _SHUT, "a contact patch's torsional friction: 0 to 0.1 m"),
    "contact.rolling_friction": Limit(0.0, 0.01, _SHUT, _SHUT, "a contact patch's rolling friction: 0 to 0.01 m"),
    "contact.timeconst_s": Limit(0.0, 1.0, _OPEN, _SHUT, "an impact's time constant: above 0 to 1 s"),
    "contact.restitution": Limit(0.0, 1.0, _SHUT, _OPEN, "a bounce keeps less than all of its speed (0 to below 1)"),
    "power.supply_voltage_v": Limit(1.0, 24.0, _SHUT, _SHUT, "a hobby servo's supply: 1 to 24 V (USB 5 V)"),
    "power.source_resistance_ohm": Limit(0.0, 100.0, _SHUT, _SHUT,
                                         "cables, board and battery: 0 to 100 ohm (USB about 0.5)"),
    "power.current_limit_a": Limit(0.0, math.inf, _OPEN, _SHUT,
                                   "a source's current limit: above 0 A (a USB 2.0 port's switch 0.7 to 1.3 A); "
                                   "inf: none"),
    "power.brownout_v": Limit(0.0, 24.0, _SHUT, _SHUT,
                              "the voltage below which a servo stops driving: 0 (never) to 24 V (an SG90 about 3.5)"),
    "power.board_current_a": Limit(0.0, 5.0, _SHUT, _SHUT,
                                   "a board's own draw: 0 to 5 A (an ESP32 dev board about 0.05)"),
    "schedule.push_deg": Limit(_HOP["push_deg"][1], _HOP["push_deg"][2], _SHUT, _SHUT, _SCHEDULE),
    "schedule.push_s": Limit(_HOP["push_ms"][1] / 1000.0, _HOP["push_ms"][2] / 1000.0, _SHUT, _SHUT, _SCHEDULE),
    "schedule.wait_s": Limit(_HOP["wait_ms"][1] / 1000.0, _HOP["wait_ms"][2] / 1000.0, _SHUT, _SHUT, _SCHEDULE),
    "schedule.cycles": Limit(_HOP["cycles"][1], _HOP["cycles"][2], _SHUT, _SHUT, _SCHEDULE),
    "solver.timestep_s": Limit(0.0, 0.01, _OPEN, _SHUT, "a step of at most 10 ms resolves a hop (docs/servo.md)"),
    "solver.refine_timestep_s": Limit(0.0, 0.01, _SHUT, _SHUT, "the step where contacts change: 0 (off) to 10 ms, "
                                      "a whole fraction of solver.timestep_s"),
    "solver.refine_window_s": Limit(0.0, 1.0, _OPEN, _SHUT, "how long the fine step runs after a contact change: "
                                    "above 0 to 1 s"),
    "solver.refine_command_window_s": Limit(0.0, 1.0, _SHUT, _SHUT, "how long the fine step runs after a command "
                                            "change: 0 to 1 s"),
    "solver.iterations": Limit(1, 10000, _SHUT, _SHUT, "MuJoCo's solver iterations: 1 to 10000"),
    "solver.tolerance": Limit(0.0, 1.0, _SHUT, _OPEN, "MuJoCo's solver tolerance: 0 to below 1"),
    "solver.control_hz": Limit(0.0, 10000.0, _OPEN, _SHUT, "a servo command rate: above 0 to 10 kHz (PWM 50 Hz)"),
    "solver.settle_s": Limit(0.0, 60.0, _SHUT, _SHUT, "time on the floor before the schedule: 0 to 60 s"),
    "solver.loop_timeconst_s": Limit(0.0, 1.0, _OPEN, _SHUT, "the loop closure's time constant: above 0 to 1 s"),
    "solver.loop_dmin": Limit(0.0, 1.0, _OPEN, _OPEN, _IMPEDANCE),
    "solver.loop_dmax": Limit(0.0, 1.0, _OPEN, _OPEN, _IMPEDANCE),
}
# a side's servo values have the servo section's limits
LIMITS.update({f"{side}.servo_{name}": LIMITS[f"servo.{name}"] for side in SIDE_SECTIONS.values()
               for name in SIDE_SERVO_FIELDS})
# the most physics steps one simulation may take: its record is kept in memory, about
# 1.5 kB a step (half a million steps is 1300 s of the seed at 2.5 ms)
MAX_SIM_STEPS = 2_000_000


def outside_limits(key: str, value: float) -> str | None:
    """Why ``value`` is outside ``key``'s limits (with the limit and its reason), or None.

    Parameters
    ----------
    key : str
        A dotted name.
    value : float
        Its value, in the unit its name says.

    Returns
    -------
    str or None
    """
    low, high, low_ok, high_ok, reason = LIMITS[key]
    if (value > low or (low_ok and value == low)) and (value < high or (high_ok and value == high)):
        return None
    lo = f"{'>=' if low_ok else '>'} {low:g}"
    hi = f"{'<=' if high_ok else '<'} {high:g}"
    if high == math.inf:
        return f"{key} = {value:g} must be {lo} ({reason})"
    return f"{key} = {value:g} must be {lo} and {hi} ({reason})"


def problems(robot: Robot, cycles: int | None = None) -> list[str]:
    """Every reason ``robot`` cannot be simulated or run as given (empty: it can).

    Parameters
    ----------
    robot : Robot
    cycles : int, optional
        Hop cycles to be simulated (default the schedule's): their physics steps are held to
        the simulation's limit.

    Returns
    -------
    list of str
    """
    # a value inherited is checked where it is set (once, not again for every key taking it)
    out = [p for key in LIMITS if (v := robot.own(key)) is not None and (p := outside_limits(key, v))]
    s, sol, sch = robot.servo, robot.solver, robot.schedule
    if abs(sch.push_deg) > s.travel_deg and not outside_limits("schedule.push_deg", sch.push_deg):
        out.append(f"schedule.push_deg = {sch.push_deg:g} is beyond the servo travel of "
                   f"+-{s.travel_deg:g} deg (servo.travel_deg)")
    out += _side_problems(robot)
    if s.pulse_min_us >= s.pulse_max_us:
        out.append(f"servo.pulse_min_us = {s.pulse_min_us:g} must be below servo.pulse_max_us = {s.pulse_max_us:g}")
    out += _supply_problems(robot)
    if sol.timestep_s > 0 and sol.control_hz * sol.timestep_s > 1.0 + 1e-9:
        out.append(f"solver.control_hz = {sol.control_hz:g} is faster than one command per physics step "
                   f"(1/solver.timestep_s = {1.0 / sol.timestep_s:g} Hz)")
    if sol.refined and abs((k := sol.timestep_s / sol.refine_timestep_s) - round(k)) > 1e-6 * k:
        out.append(f"solver.refine_timestep_s = {sol.refine_timestep_s:g} does not divide solver.timestep_s = "
                   f"{sol.timestep_s:g} into whole steps (choose {sol.timestep_s:g} s over 2, 4, 8, ...)")
    if not out:
        n = sch.cycles if cycles is None else cycles
        steps = (sol.settle_s + n * (sch.push_s + sch.wait_s)) / sol.timestep_s
        if steps > MAX_SIM_STEPS:
            out.append(f"{n} cycles of {sch.push_s + sch.wait_s:g} s at a {sol.timestep_s:g} s step are "
                       f"{steps:.3g} physics steps, over the limit of {MAX_SIM_STEPS:g}")
    return out


def _side_problems(robot: Robot) -> list[str]:
    """Each side's crank within a turn of its place, and its trim and travel within the pulse
    range's angle (the firmware's own check, firmware/config.py)."""
    out, s = [], robot.servo
    for section in SIDE_SECTIONS.values():
        side = getattr(robot, section)
        if abs(side.crank_tooth) >= s.spline_teeth and not outside_limits(f"{section}.crank_tooth", side.crank_tooth):
            out.append(f"{section}.crank_tooth = {side.crank_tooth} is a turn or more of the {s.spline_teeth}-tooth "
                       "spline (servo.spline_teeth): the crank sits fewer teeth than that off its place")
        if abs(side.trim_deg) + s.travel_deg > s.range_deg / 2 and not outside_limits(f"{section}.trim_deg",
                                                                                   side.trim_deg):
            out.append(f"{section}.trim_deg = {side.trim_deg:g} with servo.travel_deg = {s.travel_deg:g} exceeds half "
                       f"the pulse range's angle (servo.range_deg / 2 = {s.range_deg / 2:g}), as the firmware refuses")
    return out


def _supply_problems(robot: Robot) -> list[str]:
    """A supply that cannot drive the servos at all: the board alone takes the source's whole
    current limit, or the servos brown out at rest."""
    p = robot.power
    out = []
    if p.board_current_a >= p.current_limit_a:
        out.append(f"power.board_current_a = {p.board_current_a:g} A is the whole of the source's "
                   f"power.current_limit_a = {p.current_limit_a:g} A: nothing is left for the servos")
    if p.brownout_v >= p.supply_voltage_v:
        out.append(f"power.brownout_v = {p.brownout_v:g} V is at or above power.supply_voltage_v = "
                   f"{p.supply_voltage_v:g} V: the servos would never drive")
    return out


def check_robot(robot: Robot, cycles: int | None = None) -> Robot:
    """``robot`` if it can be simulated and run; else :class:`ParamsError` naming every problem.

    Parameters
    ----------
    robot : Robot
    cycles : int, optional
        Hop cycles to be simulated (default the schedule's).

    Returns
    -------
    Robot
        ``robot`` itself.

    Raises
    ------
    locust.errors.ParamsError
        Every problem :func:`problems` finds, in one message.
    """
    found = problems(robot, cycles)
    if found:
        raise ParamsError("; ".join(found),
                          "change the value(s) with --set KEY=VALUE or in the robot.toml; values are in the "
                          "units their names end in (m, kg, s, deg: 5 cm is 0.05) (`locust params` lists every "
                          "value)")
    return robot


