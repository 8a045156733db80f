"""Robot parameters: one typed model, read from and written to ``robot.toml``.

Every number the toolkit uses about the robot lives here, with its unit in its name and
its provenance beside it: ``default`` (a reasonable value nobody measured), ``seed`` (the
team's notebook, Part 2), ``photo:<file>``, ``cut_file:<file>``, ``datasheet:<part>``,
``data:<recording>`` or ``estimate:<what>`` (the robot as built), ``preset:<name>``,
``override`` (``--set`` on the command line) or ``fit:<recording>`` (identified by
``locust calibrate``, with an uncertainty and a date).

Presets:

- ``seed``: the notebook's Part 2 robot, run the corrected way: settled on the floor before
  the schedule starts, servo commands at the servo's 50 Hz PWM rate, the SG90 servo model, a
  near-rigid loop closure, rounded link edges on the floor, links that collide with the floor
  but not with their own chassis (a flexure hinge does not collide with the plate it is folded
  from), a time step at which the hop has converged (docs/servo.md), audited.
- ``small`` / ``medium`` / ``large``: the seed team's robot as built (``AS_BUILT``: its
  photos, cut file and the SG90's datasheet, each value with its source) with the leg sets
  of Part 3, +0 / +1 / +2 cm on every link of the cut file's strip, each at the time step
  its hop needs (``LEG_SETS``, the one table that presets, reports and the hop fit build a
  leg set from).
- ``seed-notebook``: the notebook's Part 2 simulation exactly (dropped from 8 cm with the
  schedule already running, 60 Hz control frames of ``int(1/60/dt)`` steps, Euler at
  dt = 1e-4 s, 50 solver iterations, tolerance 1e-8), for reproducing its figures.
"""

from __future__ import annotations

import dataclasses
import math
import stat
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any, NamedTuple

from .errors import ParamsError
from .fileio import atomic_write_text, locked, storable
from .firmware import protocol
from .robot_toml import document_text

# Standard gravity, m/s^2: the world's, not the robot's, but every model and fit uses this one.
GRAVITY_M_PER_S2 = 9.81


@dataclass(frozen=True)
class Geometry:
    """Linkage and chassis geometry, each value a length, angle or mass a student can measure
    with a ruler, a protractor and a scale (docs/hardware.md, "Measure your robot").

    Chassis frame: x along the plate from its nose (-x) to its leg end (+x), z toward the side
    the servos and legs hang from (down when the robot stands: the notebook's chassis is
    turned over, euler 180/pitch/180).
    """

    ground_m: float = 0.04          # blue link: glued to the servo, servo axis to front pivot
    crank_m: float = 0.04           # yellow link: on the servo horn
    coupler_m: float = 0.02         # green link
    leg_m: float = 0.06             # red link: the leg, foot at its far end
    crank_start_deg: float = -90.0  # crank angle at the 0 deg command (0 = along the ground link)
    body_length_m: float = 0.12
    body_width_m: float = 0.12
    body_thickness_m: float = 0.001
    body_mass_kg: float = 0.05      # the plate (the notebook's 0.05: everything that hops)
    servo_axis_x_m: float = 0.02    # servo shaft axis along the plate, from the plate's centre
    leg_mount_y_m: float = 0.045    # lateral offset of each leg loop's middle (left +, right -)
    servo_axis_below_plate_m: float = 0.0  # servo shaft axis under the plate's mid-plane
    ground_angle_deg: float = 0.0   # ground link against the plate (+: its front pivot nearer the plate)
    servo_mass_kg: float = 0.0      # each servo body (the notebook's model: none)
    servo_length_m: float = 0.023   # servo body along the plate (x)
    servo_width_m: float = 0.012    # servo body across the plate (z)
    servo_height_m: float = 0.029   # servo body along its shaft (y)
    servo_body_x_m: float = 0.0055  # servo body's centre from its shaft axis, along x
    servo_body_y_m: float = 0.0145  # servo body's centre from the plate's centre line, along y
    link_width_m: float = 0.03
    link_thickness_m: float = 0.001
    link_density_kg_per_m3: float = 1000.0
    nose_x_m: float = -0.06         # nose marker in the chassis frame
    body_pitch_deg: float = -30.0   # initial chassis attitude (notebook: euler 180 -30 180)
    drop_height_m: float = 0.08     # initial chassis height


@dataclass(frozen=True)
class Compliance:
    """The folded linkage's flexure hinges (four a leg, the one at the servo axis in parallel
    with the servo). A film hinge's stiffness, not a cardstock beam's: the links between the
    hinges carry their loads along their length and are rigid in the model (docs/servo.md,
    "Hinges and links" has the beam test's numbers for bending and buckling)."""

    hinge_stiffness_nm_per_rad: float = 0.056375
    hinge_damping_nms_per_rad: float = 0.00056375


@dataclass(frozen=True)
class Servo:
    """Hobby servo (docs/servo.md): torque = clip(kp*(cmd-q) - kv*qdot, +-stall) - (stall/noload)*qdot,
    with the gearbox's reflected rotor inertia (armature) on the servo joint.

    Defaults: an SG90 identified from two real recordings fitted together by ``locust
    calibrate servo`` (the course's AA-battery swing and a gyro on an unloaded horn stepped
    10-130 deg) with the datasheet's stall torque; see SG90_SOURCE.
    """

    kp_nm_per_rad: float = 0.377           # proportional gain inside the torque clamp
    stall_torque_nm: float = 0.15          # datasheet: 1.5-1.8 kg*cm
    noload_speed_rad_per_s: float = 10.31  # inf: no speed limit (the notebook's model)
    armature_kgm2: float = 4.65e-4         # rotor inertia x gear ratio^2, at the output shaft
    kv_nms_per_rad: float = 0.0            # velocity feedback inside the clamp (notebook: 0.0069)
    travel_deg: float = 45.0         # mechanical travel either side of rest
    pulse_min_us: float = 500.0      # pulse at -range_deg/2
    pulse_max_us: float = 2500.0     # pulse at +range_deg/2
    range_deg: float = 180.0         # angle swept by pulse_min..pulse_max
    # the DC motor behind the figures above: they hold at reference_voltage_v at the servo's
    # terminals; the winding resistance sets how far the supply's resistance sags them
    reference_voltage_v: float = 5.0
    winding_resistance_ohm: float = 10.0


@dataclass(frozen=True)
class Contact:
    """The floor's contacts, one explicit pair per robot part: each friction acts exactly as
    given (docs/servo.md, "Contact and loop")."""

    foot_friction: float = 1.7       # the leg's links on the floor (ramp: mu = tan(theta))
    nose_friction: float = 1.6       # the plate (its nose edge) on the floor
    torsional_friction: float = 0.006
    rolling_friction: float = 0.00005
    # contact softness as a drop test sees it: the impact's time constant (MuJoCo's solref
    # timeconst) and the coefficient of restitution (0: no bounce), on every floor pair
    timeconst_s: float = 0.02
    restitution: float = 0.0
    self_collision: bool = False     # links collide with the chassis and each other (notebook: yes)
    # a link's edge on the floor is a rounded line (a capsule of the laminate's thickness);
    # False: sharp box corners, the notebook's model (docs/servo.md, "Contact and loop")
    rounded_edges: bool = True


@dataclass(frozen=True)
class Power:
    """The servos' supply: both servos draw through one source resistance (USB cable, board,
    breadboard), so the voltage at the servos sags under their current (docs/servo.md,
    "Power")."""

    supply_voltage_v: float = 5.0
    source_resistance_ohm: float = 0.0


@dataclass(frozen=True)
class Schedule:
    """Open-loop bang-bang hop schedule."""

    push_deg: float = -30.0
    push_s: float = 0.3
    wait_s: float = 1.0
    cycles: int = 6


@dataclass(frozen=True)
class Solver:
    """How the simulation is run (not a property of the robot, but of the result)."""

    # rk4 at 1 ms: the seed design within 0.1 mm per hop of dt/2 with the SG90 of both servo
    # recordings (0.066 mm at 1 ms, 0.29 mm at 2 ms; docs/servo.md, "Time step")
    timestep_s: float = 1e-3
    integrator: str = "rk4"          # euler | implicitfast | implicit | rk4
    iterations: int = 10
    tolerance: float = 1e-6
    control_hz: float = 50.0         # rate at which servo commands change (PWM period)
    settle_s: float = 0.5            # time on the floor, servos at rest, before the schedule
    # the loop-closing connect: impedance 1 = rigid. Near-rigid by default (the folded linkage
    # does not stretch: anchors stay within about 10 um under load), so its time constant only
    # sets how fast a drift is corrected and need not be near the step (docs/servo.md)
    loop_timeconst_s: float = 0.01   # (notebook: 0.02)
    loop_dmin: float = 0.9999        # impedance at zero violation (notebook: 0.9)
    loop_dmax: float = 0.9999        # impedance at full violation (notebook: 0.95)


SECTIONS: dict[str, type] = {
    "geometry": Geometry,
    "compliance": Compliance,
    "servo": Servo,
    "contact": Contact,
    "power": Power,
    "schedule": Schedule,
    "solver": Solver,
}


@dataclass(frozen=True)
class Provenance:
    """Where a value came from."""

    source: str = "default"
    uncertainty: float | None = None  # one standard deviation, in the value's own unit
    date: str | None = None
    note: str | None = None


@dataclass(frozen=True)
class Robot:
    """A complete, named parameter set."""

    name: str = "seed"
    geometry: Geometry = field(default_factory=Geometry)
    compliance: Compliance = field(default_factory=Compliance)
    servo: Servo = field(default_factory=Servo)
    contact: Contact = field(default_factory=Contact)
    power: Power = field(default_factory=Power)
    schedule: Schedule = field(default_factory=Schedule)
    solver: Solver = field(default_factory=Solver)
    provenance: dict[str, Provenance] = field(default_factory=dict, compare=False)

    # -- dotted access ---------------------------------------------------------------
    def get(self, key: str) -> Any:
        section, name = _split_key(key)
        return getattr(getattr(self, section), name)

    def source_of(self, key: str) -> Provenance:
        _split_key(key)
        return self.provenance.get(key, Provenance())

    def with_values(self, values: dict[str, Any], source: str | Provenance = "override") -> Robot:
        """A copy with ``values`` (dotted keys) replaced, each recorded with ``source``."""
        prov = source if isinstance(source, Provenance) else Provenance(source=source)
        sections = {name: getattr(self, name) for name in SECTIONS}
        provenance = dict(self.provenance)
        for key, raw in values.items():
            section, name = _split_key(key)
            sections[section] = replace(sections[section], **{name: _coerce(key, raw)})
            provenance[key] = prov
        return replace(self, provenance=provenance, **sections)

    def with_provenance(self, key: str, prov: Provenance) -> Robot:
        _split_key(key)
        return replace(self, provenance={**self.provenance, key: prov})

    def renamed(self, name: str) -> Robot:
        return replace(self, name=name)

    def link_lengths_m(self) -> tuple[float, float, float, float]:
        g = self.geometry
        return (g.ground_m, g.crank_m, g.coupler_m, g.leg_m)

    def flat(self) -> dict[str, Any]:
        """Every value by its dotted name."""
        return {key: self.get(key) for key in all_keys()}


# keys for which +inf is a meaningful value ("no limit")
UNBOUNDED_KEYS = frozenset({"servo.noload_speed_rad_per_s"})


def all_keys() -> list[str]:
    return [f"{s}.{f.name}" for s, cls in SECTIONS.items() for f in fields(cls)]


def _split_key(key: str) -> tuple[str, str]:
    section, _, name = key.partition(".")
    cls = SECTIONS.get(section)
    if cls is None or name not in {f.name for f in fields(cls)}:
        close = [k for k in all_keys() if k.endswith("." + name) or k.startswith(section + ".")]
        hint = f"did you mean {', '.join(close[:4])}?" if close else "run `locust params` to list every key"
        raise ParamsError(f"unknown robot parameter {key!r}", hint)
    return section, name


def value_type(key: str) -> str:
    """The type of a dotted key's value: ``"float"``, ``"int"``, ``"bool"`` or ``"str"``
    (ParamsError for an unknown key)."""
    section, name = _split_key(key)
    ftype = {f.name: f.type for f in fields(SECTIONS[section])}[name]
    return ftype if isinstance(ftype, str) else ftype.__name__


def real_keys() -> list[str]:
    """Every real-valued key (the ones a fit or a draw can move), in file order."""
    return [key for key in all_keys() if value_type(key) == "float"]


# what the robot is (a fit may identify these), against what it is told to do (schedule) and
# how it is simulated (solver)
PHYSICAL_SECTIONS = ("geometry", "compliance", "servo", "contact", "power")


def fittable_keys() -> list[str]:
    """The real-valued physical keys: the only ones a fit may move."""
    return [key for key in real_keys() if key.partition(".")[0] in PHYSICAL_SECTIONS]


def _coerce(key: str, raw: Any) -> Any:
    ftype = value_type(key)
    try:
        if ftype == "bool":
            if isinstance(raw, bool):
                return raw
            text = str(raw).strip().lower()
            if text in ("1", "true", "yes", "on"):
                return True
            if text in ("0", "false", "no", "off"):
                return False
            raise ValueError("not true/false")
        if isinstance(raw, bool) and ftype in ("float", "int"):
            raise ValueError("true/false is not a number")
        if ftype == "float":
            value = float(raw)
            if key in UNBOUNDED_KEYS and value == math.inf:
                return value
            if not math.isfinite(value):
                raise ValueError("not finite")
            return value
        if ftype == "int":
            value = float(raw)
            if not math.isfinite(value) or value != int(value):
                raise ValueError("not a whole number")
            return int(value)
        return str(raw)
    except OverflowError:
        raise ParamsError(f"bad value {_shown(raw)} for {key}: too large for a number", f"{key} takes a {ftype}") \
            from None
    except (TypeError, ValueError) as exc:
        raise ParamsError(f"bad value {_shown(raw)} for {key}: {exc}", f"{key} takes a {ftype}") from None


def parse_set_options(items: tuple[str, ...] | list[str]) -> dict[str, str]:
    """``["geometry.leg_m=0.07", ...]`` -> ``{"geometry.leg_m": "0.07"}``, keys checked."""
    out: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise ParamsError(f"--set {item!r} is not KEY=VALUE", "e.g. --set servo.kp_nm_per_rad=0.4")
        _split_key(key.strip())
        out[key.strip()] = value.strip()
    return out


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
    "compliance.hinge_stiffness_nm_per_rad": Limit(0.0, 10.0, _SHUT, _SHUT,
                                                   "a flexure hinge of film or card: 0 to 10 N*m/rad "
                                                   "(the seed's cardstock beam 0.056)"),
    "compliance.hinge_damping_nms_per_rad": Limit(0.0, 1.0, _SHUT, _SHUT,
                                                  "a flexure hinge's damping: 0 to 1 N*m*s/rad (the seed's 5.6e-4)"),
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
    "servo.reference_voltage_v": Limit(1.0, 24.0, _SHUT, _SHUT, "a hobby servo runs on 1 to 24 V (an SG90 4.8-6 V)"),
    "servo.winding_resistance_ohm": Limit(0.1, 1000.0, _SHUT, _SHUT,
                                          "a hobby servo's motor winding: 0.1 to 1000 ohm (an SG90 about 10)"),
    "contact.foot_friction": Limit(0.0, 5.0, _SHUT, _SHUT, _FRICTION),
    "contact.nose_friction": Limit(0.0, 5.0, _SHUT, _SHUT, _FRICTION),
    "contact.torsional_friction": Limit(0.0, 0.1, _SHUT, _SHUT, "a contact patch's torsional friction: 0 to 0.1 m"),
    "contact.rolling_friction": Limit(0.0, 0.01, _SHUT, _SHUT, "a contact patch's rolling friction: 0 to 0.01 m"),
    "contact.timeconst_s": Limit(0.0, 1.0, _OPEN, _SHUT, "an impact's time constant: above 0 to 1 s"),
    "contact.restitution": Limit(0.0, 1.0, _SHUT, _OPEN, "a bounce keeps less than all of its speed (0 to below 1)"),
    "power.supply_voltage_v": Limit(1.0, 24.0, _SHUT, _SHUT, "a hobby servo's supply: 1 to 24 V (USB 5 V)"),
    "power.source_resistance_ohm": Limit(0.0, 100.0, _SHUT, _SHUT,
                                         "cables, board and battery: 0 to 100 ohm (USB about 0.5)"),
    "schedule.push_deg": Limit(_HOP["push_deg"][1], _HOP["push_deg"][2], _SHUT, _SHUT, _SCHEDULE),
    "schedule.push_s": Limit(_HOP["push_ms"][1] / 1000.0, _HOP["push_ms"][2] / 1000.0, _SHUT, _SHUT, _SCHEDULE),
    "schedule.wait_s": Limit(_HOP["wait_ms"][1] / 1000.0, _HOP["wait_ms"][2] / 1000.0, _SHUT, _SHUT, _SCHEDULE),
    "schedule.cycles": Limit(_HOP["cycles"][1], _HOP["cycles"][2], _SHUT, _SHUT, _SCHEDULE),
    "solver.timestep_s": Limit(0.0, 0.01, _OPEN, _SHUT, "a step of at most 10 ms resolves a hop (docs/servo.md)"),
    "solver.iterations": Limit(1, 10000, _SHUT, _SHUT, "MuJoCo's solver iterations: 1 to 10000"),
    "solver.tolerance": Limit(0.0, 1.0, _SHUT, _OPEN, "MuJoCo's solver tolerance: 0 to below 1"),
    "solver.control_hz": Limit(0.0, 10000.0, _OPEN, _SHUT, "a servo command rate: above 0 to 10 kHz (PWM 50 Hz)"),
    "solver.settle_s": Limit(0.0, 60.0, _SHUT, _SHUT, "time on the floor before the schedule: 0 to 60 s"),
    "solver.loop_timeconst_s": Limit(0.0, 1.0, _OPEN, _SHUT, "the loop closure's time constant: above 0 to 1 s"),
    "solver.loop_dmin": Limit(0.0, 1.0, _OPEN, _OPEN, _IMPEDANCE),
    "solver.loop_dmax": Limit(0.0, 1.0, _OPEN, _OPEN, _IMPEDANCE),
}
# the most physics steps one simulation may take: its record is kept in memory, about
# 1.5 kB a step (half a million steps is 1300 s of the seed at 2.5 ms)
MAX_SIM_STEPS = 2_000_000


def outside_limits(key: str, value: float) -> str | None:
    """Why ``value`` is outside ``key``'s limits (with the limit and its reason), or None."""
    low, high, low_ok, high_ok, reason = LIMITS[key]
    if (value > low or (low_ok and value == low)) and (value < high or (high_ok and value == high)):
        return None
    lo = f"{'>=' if low_ok else '>'} {low:g}"
    hi = f"{'<=' if high_ok else '<'} {high:g}"
    if high == math.inf:
        return f"{key} = {value:g} must be {lo} ({reason})"
    return f"{key} = {value:g} must be {lo} and {hi} ({reason})"


def problems(robot: Robot, cycles: int | None = None) -> list[str]:
    """Every reason ``robot`` cannot be simulated or run as given (empty: it can)."""
    out = [p for key in LIMITS if (p := outside_limits(key, robot.get(key)))]
    s, sol, sch = robot.servo, robot.solver, robot.schedule
    if abs(sch.push_deg) > s.travel_deg and not outside_limits("schedule.push_deg", sch.push_deg):
        out.append(f"schedule.push_deg = {sch.push_deg:g} is beyond the servo travel of "
                   f"+-{s.travel_deg:g} deg (servo.travel_deg)")
    if s.pulse_min_us >= s.pulse_max_us:
        out.append(f"servo.pulse_min_us = {s.pulse_min_us:g} must be below servo.pulse_max_us = {s.pulse_max_us:g}")
    if sol.timestep_s > 0 and sol.control_hz * sol.timestep_s > 1.0 + 1e-9:
        out.append(f"solver.control_hz = {sol.control_hz:g} is faster than one command per physics step "
                   f"(1/solver.timestep_s = {1.0 / sol.timestep_s:g} Hz)")
    if not out:
        n = sch.cycles if cycles is None else cycles
        steps = (sol.settle_s + n * (sch.push_s + sch.wait_s)) / sol.timestep_s
        if steps > MAX_SIM_STEPS:
            out.append(f"{n} cycles of {sch.push_s + sch.wait_s:g} s at a {sol.timestep_s:g} s step are "
                       f"{steps:.3g} physics steps, over the limit of {MAX_SIM_STEPS:g}")
    return out


def check_robot(robot: Robot, cycles: int | None = None) -> Robot:
    """``robot`` if it can be simulated and run; else :class:`ParamsError` naming every problem."""
    found = problems(robot, cycles)
    if found:
        raise ParamsError("; ".join(found),
                          "change the value(s) with --set KEY=VALUE or in the robot.toml; values are in the "
                          "units their names end in (m, kg, s, deg: 5 cm is 0.05) (`locust params` lists every "
                          "value)")
    return robot


# -- presets ------------------------------------------------------------------------
_SEED_SOURCE = Provenance(source="seed", note="notebook Part 2")
# The SG90 as identified by `locust calibrate servo sg90_aa_battery_step.csv
# sg90_unloaded_gyro_steps.txt --inertia-kgm2 3.3e-6 --inertia-kgm2 1e-6 --stall-torque-nm 0.15`
# (a real SG90 swinging an AA battery, filmed at 30 frames/s, the course's servo experiment;
# and a real SG90 with a gyro on its horn stepped 0 -> A -> 0, A = 10 ... 130 deg). kv held at
# 0: fitted, it is 0.002 +- 0.0015 and changes neither RMS. Uncertainties: the fit's 1 sigma
# (cluster-robust over the 33 steps); docs/servo.md has the figures.
_SG90_FIT = "fit:sg90_aa_battery_step.csv+sg90_unloaded_gyro_steps.txt"
_SG90_DATE = "2026-11-24"
SG90_SOURCE = {
    "servo.stall_torque_nm": Provenance(source="datasheet:SG90", uncertainty=0.015,
                                        note="1.5-1.8 kg*cm at 4.8-6 V; the fit's split of the ratios"),
    "servo.noload_speed_rad_per_s": Provenance(source=_SG90_FIT, uncertainty=0.11, date=_SG90_DATE,
                                               note="95% CI [10.08, 10.53]; datasheet: 0.1 s/60 deg = "
                                                    "10.5 rad/s at 4.8 V"),
    "servo.armature_kgm2": Provenance(source=_SG90_FIT, uncertainty=2.5e-5, date=_SG90_DATE,
                                      note="95% CI [4.14e-4, 5.15e-4]; reflected rotor inertia; scales with the "
                                           "stall torque 0.15 N*m"),
    "servo.kp_nm_per_rad": Provenance(source=_SG90_FIT, uncertainty=0.014, date=_SG90_DATE,
                                      note="95% CI [0.349, 0.405]; pinned by the gyro's small steps; scales with "
                                           "the stall torque 0.15 N*m"),
    "servo.kv_nms_per_rad": Provenance(source="model", note="a hobby servo has no velocity feedback; fitted to "
                                                            "both recordings 0.002 +- 0.0015, RMS unchanged"),
}


def _seed() -> Robot:
    measured = [
        "geometry.ground_m", "geometry.crank_m", "geometry.coupler_m", "geometry.leg_m",
        "geometry.crank_start_deg", "geometry.body_length_m", "geometry.body_width_m",
        "geometry.body_thickness_m", "geometry.body_mass_kg", "geometry.servo_axis_x_m",
        "geometry.leg_mount_y_m", "geometry.link_width_m", "geometry.link_thickness_m",
        "geometry.nose_x_m", "geometry.body_pitch_deg", "geometry.drop_height_m",
        "compliance.hinge_stiffness_nm_per_rad", "compliance.hinge_damping_nms_per_rad",
        "servo.stall_torque_nm", "servo.travel_deg", "contact.foot_friction", "contact.nose_friction",
        "contact.torsional_friction", "contact.rolling_friction", "schedule.push_deg",
        "schedule.push_s", "schedule.wait_s", "schedule.cycles",
    ]
    provenance = {k: _SEED_SOURCE for k in measured}
    provenance["contact.nose_friction"] = Provenance(
        source="seed", note="notebook Part 2: its floor's 1.6, which MuJoCo's mixing gave the plate's contact")
    provenance.update(SG90_SOURCE)
    return Robot(name="seed", provenance=provenance)


# -- the robot as built ----------------------------------------------------------------
# The seed team's robot (../shared/data/robot/: the top view, the folded loop, the flat strip,
# the cut files), each value a length, angle or mass with where it was read; docs/hardware.md,
# "Measure your robot", says how to measure yours. What the photos do not show is a datasheet
# figure or the notebook's, named as such.
_TOP = "photo:assembled_top_view.png"
# the top view's scale, read from the SG90s lying in it (the breadboard's 55 mm, 200 px, is
# farther from the camera and foreshortened): 32 mm over the tabs = 91 px, the 22.8 mm body
# = 71 px
_TOP_SCALE = "scale 3.0 +- 0.3 px/mm from the SG90s in the photo (32 mm over the tabs = 91 px)"
_SG90 = "datasheet:SG90"
_CUT = "cut_file:zz.dxf"
_HINGE = "fit:Damping_test.trk"
AS_BUILT: dict[str, tuple[Any, Provenance]] = {
    "geometry.ground_m": (0.04, Provenance(_CUT, note="hinge slots at 4, 8, 10, 16 cm of the 18 x 3 cm strip: "
                                                      "links 4, 4, 2, 6 cm, the last 2 cm glued over the first")),
    "geometry.crank_m": (0.04, Provenance(_CUT, note="strip 4-8 cm, on the servo horn")),
    "geometry.coupler_m": (0.02, Provenance(_CUT, note="strip 8-10 cm")),
    "geometry.leg_m": (0.06, Provenance(_CUT, note="strip 10-16 cm")),
    "geometry.link_width_m": (0.03, Provenance(_CUT, note="the strip is 3 cm wide")),
    # no photo shows the robot from the side: the crank's angle at rest and the ground link's
    # angle to the plate are estimates (locust measure stance measures them from two stills)
    "geometry.crank_start_deg": (-100.0, Provenance("estimate", uncertainty=10.0,
        note="the loose loop (folded_leg_loop.png) rests at 100 deg between ground link and crank, but on the "
             "servo the horn sits on its spline in steps of about 18 deg, which no photo shows: measure it")),
    "geometry.ground_angle_deg": (0.0, Provenance("estimate", uncertainty=15.0,
        note="the ground link taken along the servo's side, parallel to the plate; the top view looks down on "
             "the plate and cannot show this side-plane angle: measure it")),
    "geometry.body_length_m": (0.12, Provenance(_TOP, uncertainty=0.01,
        note=f"{_TOP_SCALE}: the plate's near edge 370 px = 123 mm, its far edge 328 px = 109 mm")),
    "geometry.body_width_m": (0.12, Provenance(_TOP, uncertainty=0.01,
        note=f"{_TOP_SCALE}: the plate's edge across the legs 353 px = 118 mm")),
    "geometry.nose_x_m": (-0.06, Provenance(_TOP, uncertainty=0.005, note="the plate's edge away from the legs")),
    "geometry.body_mass_kg": (0.004, Provenance("datasheet:cardstock", uncertainty=0.001,
        note="the plate alone: 12 x 12 cm of black cardstock at about 270 g/m^2; weigh yours")),
    "geometry.link_density_kg_per_m3": (700.0, Provenance("datasheet:cardstock", uncertainty=150.0,
        note="two 270 g/m^2 cardstock layers, 0.05 mm PET film, two adhesive layers: about 0.7 kg/m^2 "
             "over the 1 mm laminate (a Small strip 3.8 g); weigh a strip")),
    "geometry.servo_axis_x_m": (0.028, Provenance(_TOP, uncertainty=0.003,
        note=f"{_TOP_SCALE}: the visible horn's centre 96 px (32 +- 3 mm) in from the plate's leg-end edge, "
             "6 cm from the plate's middle (the loops reach past the edge)")),
    "geometry.leg_mount_y_m": (0.045, Provenance(_TOP, uncertainty=0.005,
        note="servos back to back on the centre line: 29 mm of servo, then half the 3 cm loop; the loops' "
             "tops are 40 and 55 mm from the servos' joint in the photo (perspective)")),
    "geometry.servo_axis_below_plate_m": (0.0065, Provenance(_SG90, uncertainty=0.002,
        note="the servo on its side under the plate, the shaft at mid-width of its 12 mm")),
    "geometry.servo_mass_kg": (0.009, Provenance(_SG90, uncertainty=0.0005)),
    "geometry.servo_length_m": (0.023, Provenance(_SG90)),
    "geometry.servo_width_m": (0.012, Provenance(_SG90)),
    "geometry.servo_height_m": (0.029, Provenance(_SG90)),
    "geometry.servo_body_x_m": (0.0055, Provenance(_SG90, uncertainty=0.001,
        note="the shaft 6 mm from one end of the 23 mm body; the body toward the plate's leg end (photo)")),
    "geometry.servo_body_y_m": (0.0145, Provenance(_SG90, uncertainty=0.002,
        note="half the servo's 29 mm: the top view shows them back to back on the centre line")),
    # locust calibrate hinge on the course's damping test (calibration/protocols/hinge.md): a
    # folded film hinge, not the cardstock beam (the seed's 0.056 was the beam's); viscous model,
    # link 8.5e-7 kg*m^2 about the hinge; the team's own fit gave 1.60e-4 and 2.14e-6
    "compliance.hinge_stiffness_nm_per_rad": (1.46e-4, Provenance(_HINGE, uncertainty=2.5e-7, date="2026-11-24",
        note="95% CI [1.456e-4, 1.466e-4], the fit's own; the hinge stiffens as it rings down (period "
             "0.50 -> 0.46 s), a model error larger than that interval (docs/calibrate.md)")),
    "compliance.hinge_damping_nms_per_rad": (1.59e-6, Provenance(_HINGE, uncertainty=1.8e-8, date="2026-11-24",
        note="95% CI [1.553e-6, 1.623e-6]")),
    "servo.reference_voltage_v": (5.0, Provenance("data:servo/sg90_aa_battery_step.csv",
        note="the recording's 5 V supply: the identified stall torque, speed and gain hold there")),
    "servo.winding_resistance_ohm": (10.0, Provenance(_SG90, uncertainty=1.5,
        note="stall current about 0.6 A at 6 V")),
    "power.supply_voltage_v": (5.0, Provenance("datasheet:USB", uncertainty=0.25,
        note="USB's 5 V +- 5 %: the top view shows the servos on the USB-powered ESP32's 5 V, through the "
             "breadboard")),
    "power.source_resistance_ohm": (0.5, Provenance("estimate:USB", uncertainty=0.3,
        note="USB cable (about 0.2 ohm a conductor) and breadboard contacts; measure the servo plug's "
             "voltage with both servos held stalled")),
}


def _built() -> Robot:
    """The seed team's robot as built: the seed's values where nothing better was measured,
    every value the photos, cut files and datasheets give replaced (AS_BUILT)."""
    robot = _seed()
    for key, (value, prov) in AS_BUILT.items():
        robot = robot.with_values({key: value}, prov)
    return robot


def with_added_length(base: Robot, added_m: float, source: str = "sweep:scale",
                      note: str | None = None) -> Robot:
    """``base`` with the same length added to all four links (the seed's ``scale`` variable)."""
    g = base.geometry
    values = {
        "geometry.ground_m": round(g.ground_m + added_m, 9),
        "geometry.crank_m": round(g.crank_m + added_m, 9),
        "geometry.coupler_m": round(g.coupler_m + added_m, 9),
        "geometry.leg_m": round(g.leg_m + added_m, 9),
    }
    note = note or f"+{added_m * 100:g} cm on every link"
    return base.with_values(values, Provenance(source=source, note=note))


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


def leg_set(base: Robot, name: str, source: str | None = None) -> Robot:
    """The physical leg set ``name`` (small/medium/large) built on ``base``'s parameters: its
    links, and its converged time step where ``base``'s is coarser (a finer one is kept);
    ``source``: the provenance of what it changes (``preset:<name>``)."""
    try:
        spec = LEG_SETS[name]
    except KeyError:
        raise ParamsError(f"unknown leg set {name!r}", f"choose one of {', '.join(LEG_SETS)}") from None
    source = source or f"preset:{name}"
    note = f"notebook Part 3 leg set: +{spec.added_m * 100:g} cm on every link"
    robot = with_added_length(base, spec.added_m, source=source, note=note).renamed(name)
    if spec.timestep_s < base.solver.timestep_s:
        robot = robot.with_values({"solver.timestep_s": spec.timestep_s},
                                  Provenance(source=source,
                                             note=f"converged step of this leg set, {spec.step_note} (docs/servo.md)"))
    return robot


def _seed_notebook() -> Robot:
    prov = Provenance(source="seed", note="notebook Part 2 simulation loop, reproduced exactly")
    return _seed().with_values(
        {   # the notebook's servo: a stiff position actuator, no speed limit, no rotor inertia
            "servo.kp_nm_per_rad": 20.0, "servo.kv_nms_per_rad": 0.0069, "servo.stall_torque_nm": 0.15,
            "servo.noload_speed_rad_per_s": math.inf, "servo.armature_kgm2": 0.0,
            "solver.timestep_s": 1e-4, "solver.integrator": "euler", "solver.iterations": 50,
            "solver.tolerance": 1e-8, "solver.control_hz": 60.0, "solver.settle_s": 0.0,
            "contact.self_collision": True, "contact.rounded_edges": False,
            "solver.loop_timeconst_s": 0.02, "solver.loop_dmin": 0.9, "solver.loop_dmax": 0.95,
        },
        prov,
    ).renamed("seed-notebook")


PRESETS = {
    "seed": _seed,
    # the filmed leg sets of the robot as built (AS_BUILT), each at its converged step
    "small": lambda: leg_set(_built(), "small"),
    "medium": lambda: leg_set(_built(), "medium"),
    "large": lambda: leg_set(_built(), "large"),
    "seed-notebook": _seed_notebook,
}


def preset(name: str) -> Robot:
    try:
        return PRESETS[name]()
    except KeyError:
        raise ParamsError(f"unknown preset {name!r}", f"choose one of {', '.join(PRESETS)}") from None


# -- TOML ---------------------------------------------------------------------------
def _uncertainty(path: Path, key: str, raw: Any) -> float | None:
    """One standard deviation, a finite number >= 0 in the value's unit, or absent."""
    if raw is None:
        return None
    if isinstance(raw, bool) or not isinstance(raw, (int, float)) or not math.isfinite(raw) or raw < 0:
        raise ParamsError(f"{path}: {key} has uncertainty = {raw!r}, not a number >= 0",
                          "write one standard deviation in the value's own unit, "
                          "e.g. uncertainty = 0.01, or leave it out")
    return float(raw)


# A robot.toml is a few kB (every value with its source and note: under 20 kB).
MAX_ROBOT_FILE_BYTES = 1_000_000


def _check_robot_file(path: Path) -> None:
    """:class:`ParamsError` unless ``path`` is a regular file of at most
    :data:`MAX_ROBOT_FILE_BYTES`: a pipe or a device is refused before it is opened (reading
    one blocks or never ends)."""
    info = path.stat()
    if not stat.S_ISREG(info.st_mode):
        raise ParamsError(f"{path}: not a regular file (a pipe, device or folder)",
                          "give the path of a robot.toml file")
    if info.st_size > MAX_ROBOT_FILE_BYTES:
        raise ParamsError(f"{path}: {info.st_size:,} bytes, over the {MAX_ROBOT_FILE_BYTES:,} a robot.toml can be",
                          "give a robot.toml (a few kB, as `locust params --write` makes)")


def _shown(raw: Any) -> str:
    """``raw`` as an error shows it: a table or a list by its kind, anything else by a short repr."""
    if isinstance(raw, dict):
        return "a table"
    if isinstance(raw, list):
        return "a list"
    text = repr(raw)
    return text if len(text) <= 40 else text[:37] + "..."


def load_robot(path: str | Path) -> Robot:
    """Read a robot.toml. Missing values fall back to the seed preset's."""
    path = Path(path)
    try:
        _check_robot_file(path)
        doc = tomllib.loads(path.read_bytes().decode("utf-8"))
    except RecursionError:
        raise ParamsError(f"{path}: not a robot.toml: its tables or lists are nested too deep to read",
                          "a robot.toml has sections of key = value (or {value = ..., source = ...}) and no "
                          "deeper nesting; regenerate it with `locust params --write`") from None
    except FileNotFoundError:
        raise ParamsError(f"{path}: no such file", "give the path of a robot.toml, or use --preset") from None
    except UnicodeDecodeError as exc:
        raise ParamsError(f"{path}: not a robot.toml: byte {exc.start} is not UTF-8 text",
                          "give a robot.toml (UTF-8 text, as `locust params --write` makes), not another "
                          "kind of file") from None
    except OSError as exc:
        raise ParamsError(f"{path}: cannot read it ({exc.strerror})",
                          "give the path of a readable robot.toml file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParamsError(f"{path}: not valid TOML ({exc})",
                          "fix the file, or regenerate it with `locust params --write`") from None
    base, name = doc.get("base", "seed"), doc.get("name", path.stem)
    if not isinstance(base, str) or base not in PRESETS:
        raise ParamsError(f"{path}: base = {_shown(base)} is not a preset", f"choose one of {', '.join(PRESETS)}")
    if not isinstance(name, str):
        raise ParamsError(f"{path}: name = {_shown(name)} is not a string", 'write it in quotes: name = "mine"')
    robot = preset(base).renamed(name)
    for section, table in doc.items():
        if section in ("name", "base"):
            continue
        if section not in SECTIONS:
            raise ParamsError(f"{path}: unknown section [{section}]", f"sections are {', '.join(SECTIONS)}")
        if not isinstance(table, dict):
            raise ParamsError(f"{path}: {section} = {_shown(table)}, where a section [{section}] of values belongs",
                              f"write its values under a line [{section}]")
        for name, entry in table.items():
            key = f"{section}.{name}"
            try:
                _split_key(key)
            except ParamsError as exc:
                raise ParamsError(f"{path}: {exc.message}", exc.hint) from None
            if isinstance(entry, dict):
                if "value" not in entry:
                    raise ParamsError(f"{path}: {key} has no 'value'", "write it as {value = ..., source = \"...\"}")
                for field in ("source", "date", "note"):
                    if isinstance(entry.get(field), (dict, list)):
                        raise ParamsError(f"{path}: {key} has {field} = {_shown(entry[field])}, not a string",
                                          f'write it in quotes: {field} = "..."')
                prov = Provenance(
                    source=str(entry.get("source", "default")),
                    uncertainty=_uncertainty(path, key, entry.get("uncertainty")),
                    date=None if entry.get("date") is None else str(entry["date"]),
                    note=None if entry.get("note") is None else str(entry["note"]),
                )
                value = entry["value"]
            else:
                prov, value = Provenance(source=f"file:{path.name}"), entry
            if isinstance(value, (dict, list)):
                raise ParamsError(f"{path}: {key} = {_shown(value)}, where a number belongs",
                                  f"write one value: {key.split('.')[1]} = 0.05, or "
                                  '{value = 0.05, source = "..."}')
            try:
                robot = robot.with_values({key: value}, prov)
            except ParamsError as exc:
                raise ParamsError(f"{path}: {exc.message}", exc.hint) from None
    return robot


def to_toml(robot: Robot, template: str | None = None) -> str:
    """``robot`` as robot.toml text (:func:`locust.robot_toml.document_text`); ``template``: the
    text of the file it replaces, whose comments and layout are kept."""
    sections = {
        section: {f.name: (robot.get(f"{section}.{f.name}"),
                           dataclasses.asdict(robot.source_of(f"{section}.{f.name}")))
                  for f in fields(SECTIONS[section])}
        for section in SECTIONS
    }
    return document_text(robot.name, sections, template)


def _same(a: Any, b: Any) -> bool:
    """``a`` (read back) is ``b`` as the file stores it."""
    if isinstance(b, str):
        b = storable(b)
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))


def _read_back(robot: Robot, path: Path, tmp: Path) -> None:
    """Refuse (:class:`ParamsError`) a written robot.toml that does not read back to ``robot``."""
    try:
        back = load_robot(tmp)
    except ParamsError as exc:
        raise ParamsError(f"{path}: the robot file written does not read back ({exc.message}); "
                          "the old file is kept", "report this as a bug in locust, with the command run") from None
    differ = [key for key, value in robot.flat().items()
              if not _same(back.get(key), value)
              or dataclasses.astuple(back.source_of(key)) != dataclasses.astuple(_stored(robot.source_of(key)))]
    if back.name != storable(robot.name):
        differ.insert(0, "name")
    if differ:
        raise ParamsError(f"{path}: the robot file written reads back different ({', '.join(differ[:5])}); "
                          "the old file is kept", "report this as a bug in locust, with the command run")


def _stored(prov: Provenance) -> Provenance:
    """``prov`` as the file holds it (text UTF-8 can store)."""
    return Provenance(*(storable(v) if isinstance(v, str) else v for v in dataclasses.astuple(prov)))


def file_text(path: Path) -> str | None:
    """The robot.toml at ``path`` as text, to keep its layout; None when there is none or it is
    not TOML (then it is not replaced anyway: load_robot refused it first)."""
    try:
        text = path.read_bytes().decode("utf-8")
        tomllib.loads(text)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return None
    return text


def save_robot(robot: Robot, path: str | Path, *, template: str | None = None, exclusive: bool = False) -> Path:
    """Write ``robot`` to the robot.toml ``path``, atomically, and read it back first.

    Parameters
    ----------
    robot : Robot
        What to write: every value with its provenance.
    path : str or Path
        The file; one there already is replaced (but see ``exclusive``).
    template : str, optional
        TOML text whose comments and layout the new file keeps (the file being replaced, or the
        one the robot was read from).
    exclusive : bool
        Only create ``path``: :class:`~locust.errors.WriteError` if it exists, even when another
        process made it a moment ago.

    Returns
    -------
    Path
        The file written. It reads back (``load_robot``) to ``robot``'s values and provenance,
        or it is not written and the old file is kept (:class:`ParamsError`).
    """
    path = Path(path)
    text = to_toml(robot, template)
    return atomic_write_text(path, text, check=lambda tmp: _read_back(robot, path, tmp), exclusive=exclusive)


def update_robot(path: str | Path, change: Callable[[Robot], Robot], *, start: Callable[[], Robot] | None = None,
                 wait_s: float = 60.0) -> Path:
    """Read the robot.toml ``path``, change it and write it back, as one step for every process.

    Under an exclusive lock on ``path`` (:func:`locust.fileio.locked`), so two commands updating
    one file (``calibrate ... --write`` of two experiments) each see the other's values: no
    update is lost. The file's comments and layout are kept (:func:`save_robot`).

    Parameters
    ----------
    path : str or Path
        The robot.toml to update.
    change : callable
        ``Robot -> Robot``, the update; it may raise to leave the file as it is.
    start : callable, optional
        The robot when ``path`` does not exist yet (default: the seed preset).
    wait_s : float
        How long to wait for another process's update, seconds.

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
    with locked(path, wait_s) as target:
        if target.exists():
            robot, template = load_robot(target), file_text(target)
        else:
            robot, template = (start or (lambda: preset("seed")))(), None
        return save_robot(change(robot), path, template=template)


def resolve_robot(preset_name: str | None = None, config: str | Path | None = None,
                  sets: tuple[str, ...] | list[str] = ()) -> Robot:
    """The robot a command runs on: ``--config`` file, else ``--preset``, then ``--set``."""
    robot = load_robot(config) if config else preset(preset_name or "seed")
    overrides = parse_set_options(sets)
    return check_robot(robot.with_values(overrides, "override") if overrides else robot)


def as_dict(robot: Robot) -> dict[str, Any]:
    """Plain nested dict of values (for JSON and hashing)."""
    return {"name": robot.name, **{s: dataclasses.asdict(getattr(robot, s)) for s in SECTIONS}}
