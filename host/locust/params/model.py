"""Robot parameters: one typed model, read from and written to ``robot.toml``.

Every number the toolkit uses about the robot lives here, with its unit in its name and
its provenance beside it: ``default`` (a reasonable value nobody measured), ``seed`` (the
team's notebook, Part 2), ``photo:<file>``, ``cut_file:<file>``, ``datasheet:<part>``,
``data:<recording>`` or ``estimate:<what>`` (the robot as built), ``preset:<name>``,
``override`` (``--set`` on the command line) or ``fit:<recording>`` (identified by
``locust calibrate``, with an uncertainty and a date).

This module: the parameter types, their sections and the access by dotted name
(``Robot.get``, ``with_values``, ``parse_set_options``). Limits: :mod:`.limits`; presets and
the robot as built: :mod:`.presets`; leg sets: :mod:`.legsets`; the file: :mod:`locust.io.robot_toml`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields, replace
from typing import Any

from ..errors import ParamsError
from .legs import Folds, Side

# Standard gravity, m/s^2 (9.80665 by definition, 3rd CGPM 1901), to the three figures of MuJoCo's
# default option.gravity: the world's, not the robot's, but every model and fit uses this one.
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
    # the output shaft's spline: a horn (and the crank on it) sits on it in steps of
    # 360 / spline_teeth deg (SG90_SOURCE: an estimate until counted)
    spline_teeth: int = 21
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
    """The servos' supply (docs/servo.md, "Power"): a source that holds ``supply_voltage_v`` at
    the servo plug with the servos at rest (the board running on it too), sagging by
    ``source_resistance_ohm`` for every ampere the servos draw (USB cable, board, breadboard),
    and giving no more than ``current_limit_a`` in all (a USB port's power switch, a
    polyfuse), the board's own ``board_current_a`` included. A servo whose plug falls below
    ``brownout_v`` stops driving. The defaults: an ideal supply (the seed's model)."""

    supply_voltage_v: float = 5.0         # at the servo plug, servos at rest, the board drawing its own
    source_resistance_ohm: float = 0.0    # shared by both servos
    current_limit_a: float = math.inf     # the source's, the board's draw included (inf: none)
    brownout_v: float = 0.0               # a servo's electronics stop driving below this at its plug
    board_current_a: float = 0.0          # the ESP32 board's own draw from the same source


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
    # where the floor contacts change, the step taken again at this finer one for
    # refine_window_s (sim/refine.py): 0 steps uniformly at timestep_s, which it must divide
    refine_timestep_s: float = 0.0
    refine_window_s: float = 0.04
    # after a change of the servos' command the fine step runs this long: the push and the
    # return each set off ~90 ms of touchdowns and foot bounces (contacts that last 0.4-2 ms, a
    # coarse step over them leaving the count as it was; docs/performance.md)
    refine_command_window_s: float = 0.1
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

    @property
    def refined(self) -> bool:
        """Whether a run refines its step where the floor contacts change."""
        return 0.0 < self.refine_timestep_s < self.timestep_s

    def steps_scaled(self, factor: float) -> dict[str, float]:
        """The values that scale every step by ``factor`` (``--check-convergence``: 0.5):
        ``timestep_s`` and, where the run refines, ``refine_timestep_s`` (the window is a time).

        Parameters
        ----------
        factor : float

        Returns
        -------
        dict of str to float
            Dotted names -> values, for :meth:`Robot.with_values`.
        """
        values = {"solver.timestep_s": self.timestep_s * factor}
        if self.refined:
            values["solver.refine_timestep_s"] = self.refine_timestep_s * factor
        return values

    @property
    def finest_step_s(self) -> float:
        """The finest step a run takes [s]: the step of one that steps uniformly in real time
        (the virtual robot)."""
        return self.refine_timestep_s if self.refined else self.timestep_s


SECTIONS: dict[str, type] = {
    "geometry": Geometry,
    "compliance": Compliance,
    "folds": Folds,
    "servo": Servo,
    "left": Side,
    "right": Side,
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
    """A complete, named parameter set.

    ``leg_set`` is the filmed leg set whose links the robot carries (a key of
    :data:`locust.params.LEG_SETS`: ``small`` is the cut file's strip as it is, ``medium`` and
    ``large`` add 1 and 2 cm to every link); :func:`locust.params.leg_set` swaps it for
    another, taking its own added length off first. It is part of the robot, written to and
    read from ``robot.toml``: nothing derives it from the name.

    A value may be inherited (None in its section, absent from ``robot.toml``: a fold's
    stiffness is the film hinge's until it is given, a side's servo gain the servo section's):
    :meth:`get` gives the value in effect, :meth:`own` the robot's own (None: inherited).
    """

    name: str = "seed"
    leg_set: str = "small"
    geometry: Geometry = field(default_factory=Geometry)
    compliance: Compliance = field(default_factory=Compliance)
    folds: Folds = field(default_factory=Folds)
    servo: Servo = field(default_factory=Servo)
    left: Side = field(default_factory=Side)
    right: Side = field(default_factory=Side)
    contact: Contact = field(default_factory=Contact)
    power: Power = field(default_factory=Power)
    schedule: Schedule = field(default_factory=Schedule)
    solver: Solver = field(default_factory=Solver)
    provenance: dict[str, Provenance] = field(default_factory=dict, compare=False)

    # -- dotted access ---------------------------------------------------------------
    def get(self, key: str) -> Any:
        """A value by its dotted name: the one in effect, an inherited value taken from the key it
        inherits (:func:`inherited_from`, followed until a value is set).

        Parameters
        ----------
        key : str
            ``section.name``, e.g. ``geometry.leg_m`` (the unit is the name's suffix).

        Returns
        -------
        Any
            The value, in the unit its name says (never None).

        Raises
        ------
        locust.errors.ParamsError
            Not a parameter of the model.
        """
        value = self.own(key)
        while value is None:
            key = INHERITS[key]
            value = self.own(key)
        return value

    def own(self, key: str) -> Any:
        """A value by its dotted name as this robot holds it: None where it is inherited.

        Parameters
        ----------
        key : str
            ``section.name``.

        Returns
        -------
        Any
            The value, or None (inherited: see :meth:`get`).

        Raises
        ------
        locust.errors.ParamsError
            Not a parameter of the model.
        """
        section, name = split_key(key)
        return getattr(getattr(self, section), name)

    def inherits(self, key: str) -> str | None:
        """The key whose value ``key`` takes now, or None where the robot holds its own.

        Parameters
        ----------
        key : str
            A dotted name.

        Returns
        -------
        str or None
            The key it inherits from (``compliance.hinge_stiffness_nm_per_rad`` for an unset
            ``folds.knee_stiffness_nm_per_rad``).
        """
        return INHERITS[key] if self.own(key) is None else None

    def source_of(self, key: str) -> Provenance:
        """Where a value comes from (an empty :class:`Provenance` when not recorded).

        Parameters
        ----------
        key : str
            A dotted name.

        Returns
        -------
        Provenance

        Raises
        ------
        locust.errors.ParamsError
            Not a parameter of the model.
        """
        split_key(key)
        return self.provenance.get(key, Provenance())

    def with_values(self, values: dict[str, Any], source: str | Provenance = "override") -> Robot:
        """A copy with ``values`` replaced, each recorded with ``source``.

        Parameters
        ----------
        values : dict of str to Any
            Dotted name -> value, in the unit the name says (coerced to the field's type); for
            a key that may inherit, None or ``"inherit"`` makes it inherit again (its
            provenance dropped).
        source : str or Provenance
            Where the values come from.

        Returns
        -------
        Robot

        Raises
        ------
        locust.errors.ParamsError
            An unknown name or a value of the wrong type.
        """
        prov = source if isinstance(source, Provenance) else Provenance(source=source)
        sections = {name: getattr(self, name) for name in SECTIONS}
        provenance = dict(self.provenance)
        for key, raw in values.items():
            section, name = split_key(key)
            value = _coerce(key, raw)
            sections[section] = replace(sections[section], **{name: value})
            if value is None:
                provenance.pop(key, None)
            else:
                provenance[key] = prov
        return replace(self, provenance=provenance, **sections)

    def with_provenance(self, key: str, prov: Provenance) -> Robot:
        """A copy with ``key``'s provenance replaced (its value kept).

        Parameters
        ----------
        key : str
            A dotted name.
        prov : Provenance
            Its new source, uncertainty and note.

        Returns
        -------
        Robot

        Raises
        ------
        locust.errors.ParamsError
            Not a parameter of the model.
        """
        split_key(key)
        return replace(self, provenance={**self.provenance, key: prov})

    def renamed(self, name: str) -> Robot:
        """A copy named ``name``.

        Parameters
        ----------
        name : str

        Returns
        -------
        Robot
        """
        return replace(self, name=name)

    def link_lengths_m(self) -> tuple[float, float, float, float]:
        """The four-bar's ground, crank, coupler and leg lengths [m].

        Returns
        -------
        tuple of float
            [m].
        """
        g = self.geometry
        return (g.ground_m, g.crank_m, g.coupler_m, g.leg_m)

    def flat(self) -> dict[str, Any]:
        """Every value in effect by its dotted name (:meth:`get`: inherited ones resolved).

        Returns
        -------
        dict of str to Any
            Each value in the unit its name says.
        """
        return {key: self.get(key) for key in all_keys()}


# the sections a side's own values live in (the model's leg "L" at +y, "R" at -y)
SIDE_SECTIONS = {"L": "left", "R": "right"}
# what a side takes from the servo section: its field "servo_X" inherits "servo.X"
SIDE_SERVO_FIELDS = ("kp_nm_per_rad", "stall_torque_nm", "noload_speed_rad_per_s", "armature_kgm2", "kv_nms_per_rad")
# keys for which +inf is a meaningful value ("no limit")
UNBOUNDED_KEYS = frozenset({"servo.noload_speed_rad_per_s", "power.current_limit_a",
                            *(f"{side}.servo_noload_speed_rad_per_s" for side in SIDE_SECTIONS.values())})


def all_keys() -> list[str]:
    """Every parameter's dotted name, section by section in field order.

    Returns
    -------
    list of str
    """
    return [f"{s}.{f.name}" for s, cls in SECTIONS.items() for f in fields(cls)]


def split_key(key: str) -> tuple[str, str]:
    """A dotted name's section and field, checked.

    Parameters
    ----------
    key : str
        ``section.name``.

    Returns
    -------
    section, name : str

    Raises
    ------
    locust.errors.ParamsError
        Not a parameter of the model (the hint names close ones).
    """
    section, _, name = key.partition(".")
    cls = SECTIONS.get(section)
    if cls is None or name not in {f.name for f in fields(cls)}:
        close = [k for k in all_keys() if k.endswith("." + name) or k.startswith(section + ".")]
        hint = f"did you mean {', '.join(close[:4])}?" if close else "run `locust params` to list every key"
        raise ParamsError(f"unknown robot parameter {key!r}", hint)
    return section, name


def _field_type(key: str) -> str:
    section, name = split_key(key)
    ftype = {f.name: f.type for f in fields(SECTIONS[section])}[name]
    return ftype if isinstance(ftype, str) else ftype.__name__


def value_type(key: str) -> str:
    """The type of a dotted key's value: ``"float"``, ``"int"``, ``"bool"`` or ``"str"``
    (ParamsError for an unknown key); a key that may inherit has its value's type.

    Parameters
    ----------
    key : str
        A dotted name.

    Returns
    -------
    str
    """
    return _field_type(key).removesuffix(" | None")


def is_optional(key: str) -> bool:
    """Whether ``key`` may be unset, taking its value from another (:func:`inherited_from`).

    Parameters
    ----------
    key : str
        A dotted name.

    Returns
    -------
    bool
    """
    return _field_type(key).endswith(" | None")


def _parent(key: str) -> str:
    """The key an unset ``key`` takes its value from (see :data:`INHERITS`)."""
    section, name = key.split(".")
    if section == "folds":
        return "compliance.hinge_" + name.partition("_")[2]   # servo_stiffness_... -> hinge_stiffness_...
    if name.startswith("servo_") and name.removeprefix("servo_") in SIDE_SERVO_FIELDS:
        return "servo." + name.removeprefix("servo_")
    return "folds." + name


# an unset key -> the key it takes its value from: a fold's stiffness and damping the film
# hinge's (compliance), a side's fold values the folds section's, a side's servo values the
# servo section's; followed until a value is set (Robot.get)
INHERITS: dict[str, str] = {key: _parent(key) for key in all_keys() if is_optional(key)}


def inherited_from(key: str) -> str | None:
    """The key whose value an unset ``key`` takes, or None for a key that is always set.

    Parameters
    ----------
    key : str
        A dotted name.

    Returns
    -------
    str or None
        E.g. ``compliance.hinge_stiffness_nm_per_rad`` for ``folds.knee_stiffness_nm_per_rad``,
        ``folds.knee_stiffness_nm_per_rad`` for ``left.knee_stiffness_nm_per_rad``.

    Raises
    ------
    locust.errors.ParamsError
        Not a parameter of the model.
    """
    split_key(key)
    return INHERITS.get(key)


def real_keys() -> list[str]:
    """Every real-valued key (the ones a fit or a draw can move), in file order.

    Returns
    -------
    list of str
    """
    return [key for key in all_keys() if value_type(key) == "float"]


# what the robot is (a fit may identify these), against what it is told to do (schedule) and
# how it is simulated (solver)
PHYSICAL_SECTIONS = ("geometry", "compliance", "folds", "servo", "left", "right", "contact", "power")


def fittable_keys() -> list[str]:
    """The real-valued physical keys: the only ones a fit may move.

    Returns
    -------
    list of str
    """
    return [key for key in real_keys() if key.partition(".")[0] in PHYSICAL_SECTIONS]


def _as_bool(key: str, raw: Any) -> bool:
    if isinstance(raw, bool):
        return raw
    text = str(raw).strip().lower()
    if text in ("1", "true", "yes", "on"):
        return True
    if text in ("0", "false", "no", "off"):
        return False
    raise ValueError("not true/false")


def _as_float(key: str, raw: Any) -> float:
    value = float(raw)
    if key in UNBOUNDED_KEYS and value == math.inf:
        return value
    if not math.isfinite(value):
        raise ValueError("not finite")
    return value


def _as_int(key: str, raw: Any) -> int:
    value = float(raw)
    if not math.isfinite(value) or value != int(value):
        raise ValueError("not a whole number")
    return int(value)


# a field's type -> how a value given for it (a number, or the text of --set) becomes one
_CONVERT = {"bool": _as_bool, "float": _as_float, "int": _as_int}


# what --set (or a robot file) gives to make a key that may inherit do so again
INHERIT_TEXT = "inherit"


def _coerce(key: str, raw: Any) -> Any:
    ftype = value_type(key)
    if is_optional(key) and (raw is None or (isinstance(raw, str) and raw.strip().lower() == INHERIT_TEXT)):
        return None
    try:
        if isinstance(raw, bool) and ftype in ("float", "int"):
            raise ValueError("true/false is not a number")
        convert = _CONVERT.get(ftype)
        return str(raw) if convert is None else convert(key, raw)
    except OverflowError:
        raise ParamsError(f"bad value {shown_value(raw)} for {key}: too large for a number", f"{key} takes a {ftype}") \
            from None
    except (TypeError, ValueError) as exc:
        raise ParamsError(f"bad value {shown_value(raw)} for {key}: {exc}", f"{key} takes a {ftype}") from None


def parse_set_options(items: tuple[str, ...] | list[str]) -> dict[str, str]:
    """``["geometry.leg_m=0.07", ...]`` -> ``{"geometry.leg_m": "0.07"}``, keys checked.

    Parameters
    ----------
    items : sequence of str
        ``KEY=VALUE`` strings (the command line's ``--set``).

    Returns
    -------
    dict of str to str
        Dotted name -> the value's text (converted by :meth:`Robot.with_values`).

    Raises
    ------
    locust.errors.ParamsError
        An item without ``=``, or an unknown name.
    """
    out: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise ParamsError(f"--set {item!r} is not KEY=VALUE", "e.g. --set servo.kp_nm_per_rad=0.4")
        split_key(key.strip())
        out[key.strip()] = value.strip()
    return out



def shown_value(raw: Any) -> str:
    """``raw`` as an error shows it: a table or a list by its kind, anything else by a short repr.

    Parameters
    ----------
    raw : Any
        A value as read from a file.

    Returns
    -------
    str
        At most 40 characters.
    """
    if isinstance(raw, dict):
        return "a table"
    if isinstance(raw, list):
        return "a list"
    text = repr(raw)
    return text if len(text) <= 40 else text[:37] + "..."


def as_dict(robot: Robot) -> dict[str, Any]:
    """Plain nested dict of values (for JSON and hashing).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    dict
        ``name`` and, per section, its values by field name (units in the names).
    """
    return {"name": robot.name, **{s: dataclasses.asdict(getattr(robot, s)) for s in SECTIONS}}
