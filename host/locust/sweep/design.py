"""One design of a sweep: which values it varies, the robot they make, and its checked result.

``NAME`` is any numeric robot parameter by its dotted name, or ``scale``: the same length (m)
added to all four links, the seed notebook's sweep variable. A design is checked before it is
simulated (the four-bar assembles at the start angle and stays closed over the whole crank
range the schedule commands) and audited after (:mod:`locust.sim.audit`); a design that fails
either is a row with ``valid`` false and the reason, never a result.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..errors import GeometryError, LocustError, SweepError
from ..params import Provenance, Robot, all_keys, outside_limits, problems, with_added_length
from ..sim.fourbar import assemble
from ..sim.outcome import GOES_OVER, OUTCOMES
from ..tables import for_person, person_unit, sig, split_unit

SCALE = "scale"
CRANK_CHECK_STEP_DEG = 1.0


def shown_unit(name: str) -> tuple[float, str]:
    """The unit a person reads the design variable ``name`` in, and the factor to it from the
    parameter's own: ``scale`` and a ``*_m`` length in mm, a ``*_kg`` mass in g, anything else in
    its own unit, as its name says (the value stays in metres, kilograms, ... in CSV and JSON).

    Parameters
    ----------
    name : str
        ``scale`` or a dotted parameter name.

    Returns
    -------
    tuple
        (factor from the parameter's unit to the shown one, the shown unit; "" for none).
    """
    if name == SCALE:
        return person_unit("m")
    _, factor, unit = for_person(name)
    return factor, unit


def axis_scale(name: str) -> tuple[float, str]:
    """How to draw the sweep axis ``name``: in the unit :func:`shown_unit` gives, which its label
    names (``geometry.leg (mm)``, never a key in metres beside a value in mm).

    Parameters
    ----------
    name : str
        ``scale`` or a dotted parameter name.

    Returns
    -------
    tuple
        (factor from the parameter's unit to the drawn one, axis label).
    """
    factor, unit = shown_unit(name)
    if name == SCALE:
        return factor, f"added length on every link ({unit})"
    stem = split_unit(name)[0]
    return factor, f"{stem} ({unit})" if unit else name


def design_text(name: str, value: float) -> str:
    """One design variable as a person reads it: ``scale 30.50 mm``, ``geometry.crank_start -100.0 deg``.

    Parameters
    ----------
    name : str
        ``scale`` or a dotted parameter name.
    value : float
        In the parameter's unit (``scale``: m).

    Returns
    -------
    str
        The name less its unit suffix, the value to 4 significant figures, the unit.
    """
    factor, unit = shown_unit(name)
    stem = name if name == SCALE else split_unit(name)[0]
    return f"{stem} {sig(value * factor)} {unit}".rstrip()


@dataclass(frozen=True)
class Axis:
    """``NAME=START:STOP:N``: N values from START to STOP inclusive (``numpy.linspace``).

    Attributes
    ----------
    name : str
        ``scale`` or a dotted parameter name.
    start, stop : float
        The first and last value, in the parameter's unit (``scale``: m).
    n : int
        The number of values.
    """

    name: str
    start: float
    stop: float
    n: int

    def values(self) -> list[float]:
        """The axis's values.

        Returns
        -------
        list of float
            ``n`` values from ``start`` to ``stop``, in the parameter's unit.
        """
        return [float(v) for v in np.linspace(self.start, self.stop, self.n)]

    def to_dict(self) -> dict[str, Any]:
        """The axis as sweep.json stores it.

        Returns
        -------
        dict
            ``name``, ``start``, ``stop`` and ``n``.
        """
        return {"name": self.name, "start": self.start, "stop": self.stop, "n": self.n}


@dataclass(frozen=True)
class Bound:
    """``NAME=LOW:HIGH`` (a range, in steps of ``step`` when given) or ``NAME=A,B,C`` (the
    values ``choices``, a categorical) for the optimiser.

    Attributes
    ----------
    name : str
        ``scale`` or a dotted parameter name.
    low, high : float
        The range, in the parameter's unit (``scale``: m); for choices, the lowest and highest.
    step : float or None
        The step, in the parameter's unit.
    choices : tuple of float or None
        The values of a categorical.
    """

    name: str
    low: float
    high: float
    step: float | None = None
    choices: tuple[float, ...] | None = None

    def to_dict(self) -> dict[str, Any]:
        """The bound as the optimiser's settings store it.

        Returns
        -------
        dict
            ``name``, ``low``, ``high``, and ``step`` or ``choices`` when set.
        """
        out: dict[str, Any] = {"name": self.name, "low": self.low, "high": self.high}
        if self.step is not None:
            out["step"] = self.step
        if self.choices is not None:
            out["choices"] = list(self.choices)
        return out


def check_name(name: str, robot: Robot) -> None:
    """Refuse a ``--vary`` name that is not ``scale`` or a numeric robot parameter (or is
    ``schedule.cycles``, which is ``--cycles``).

    Parameters
    ----------
    name : str
        The name given.
    robot : Robot
        The robot the sweep starts from.

    Raises
    ------
    SweepError
        No such parameter (with the nearest names), not a number, or ``schedule.cycles``.
    """
    if name == SCALE:
        return
    if name not in all_keys():
        close = [k for k in all_keys() if name.split(".")[-1] in k][:4]
        hint = f"did you mean {', '.join(close)}?" if close else "use `scale` or a dotted name from `locust params`"
        raise SweepError(f"--vary {name!r}: no such robot parameter", hint)
    value = robot.get(name)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SweepError(f"--vary {name!r}: the parameter is not a number ({value!r})",
                         "vary a numeric parameter, e.g. geometry.leg_m or schedule.push_deg")
    if name == "schedule.cycles":   # one rule: every design of a run hops as often
        raise SweepError("--vary schedule.cycles: the hops per design are --cycles, the same for every design",
                         "give --cycles N instead (one run per number of hops, each with its own --out)")


def is_integer(robot: Robot, name: str) -> bool:
    """Whether the parameter ``name`` holds whole numbers (schedule.cycles, solver.iterations).

    Parameters
    ----------
    robot : Robot
        The robot the sweep starts from.
    name : str
        ``scale`` or a dotted parameter name.

    Returns
    -------
    bool
        True for an integer parameter (``scale`` never is).
    """
    if name == SCALE:
        return False
    value = robot.get(name)
    return isinstance(value, int) and not isinstance(value, bool)


def check_range(item: str, name: str, low: float, high: float, robot: Robot) -> None:
    """Both ends of a --vary range within the limits of what it changes (``scale``: the four
    links), checked before any design runs: a range outside is a unit slip (centimetres typed
    for metres), not a sweep of invalid designs.

    Parameters
    ----------
    item : str
        The ``--vary`` text, for the message.
    name : str
        ``scale`` or a dotted parameter name.
    low, high : float
        The ends, in the parameter's unit (``scale``: m added to each link).
    robot : Robot
        The robot the sweep starts from.

    Raises
    ------
    SweepError
        An end outside the parameter's limits.
    """
    for end in (low, high):
        if name == SCALE:
            g = robot.geometry
            changed = {f"geometry.{k}": getattr(g, k) + end for k in ("ground_m", "crank_m", "coupler_m", "leg_m")}
        else:
            changed = {name: end}
        found = [p for key, value in changed.items() if (p := outside_limits(key, value))]
        if found:
            more = f" (and {len(found) - 1} more)" if len(found) > 1 else ""
            raise SweepError(f"--vary {item!r}: at {end:g}, {found[0]}{more}",
                             "values are in the units their names end in (m, kg, s, deg; scale in m): "
                             "5 cm is 0.05, e.g. --vary scale=0:0.05:30")


def _numbers(text: str, parts: int, what: str, item: str) -> list[float]:
    fields = text.split(":")
    if len(fields) != parts:
        raise SweepError(f"--vary {item!r} is not {what}", "e.g. --vary scale=0:0.05:30" if parts == 3
                         else "e.g. --vary geometry.leg_m=0.05:0.09")
    try:
        out = [float(f) for f in fields]
    except ValueError:
        raise SweepError(f"--vary {item!r}: {text!r} holds something that is not a number",
                         f"write {what}") from None
    if not all(math.isfinite(v) for v in out):
        raise SweepError(f"--vary {item!r}: values must be finite", f"write {what}")
    return out


def _split(item: str) -> tuple[str, str]:
    name, sep, rest = item.partition("=")
    if not sep or not name.strip() or not rest.strip():
        raise SweepError(f"--vary {item!r} is not NAME=RANGE", "e.g. --vary scale=0:0.05:30")
    return name.strip(), rest.strip()


def parse_axis(item: str, robot: Robot) -> Axis:
    """Read ``NAME=START:STOP:N`` for a sweep.

    Parameters
    ----------
    item : str
        The ``--vary`` text.
    robot : Robot
        The robot the sweep starts from.

    Returns
    -------
    Axis
        The checked axis.

    Raises
    ------
    SweepError
        Not ``NAME=START:STOP:N``, an unknown or non-numeric name, N not a whole number >= 1,
        ends outside the limits, or fractions for a whole-number parameter.
    """
    name, rest = _split(item)
    check_name(name, robot)
    start, stop, n = _numbers(rest, 3, "START:STOP:N", item)
    if n != int(n) or n < 1:
        raise SweepError(f"--vary {item!r}: N = {n:g} must be a whole number of designs >= 1",
                         "e.g. --vary scale=0:0.05:30")
    if int(n) == 1 and start != stop:
        raise SweepError(f"--vary {item!r}: one design cannot span {start:g}..{stop:g}", "use N >= 2")
    check_range(item, name, start, stop, robot)
    axis = Axis(name, start, stop, int(n))
    if is_integer(robot, name):
        fractions = [v for v in axis.values() if v != round(v)]
        if fractions:
            raise SweepError(f"--vary {item!r}: {name} is a whole number, and this range gives "
                             f"{', '.join(f'{v:g}' for v in fractions[:3])}",
                             "choose START, STOP and N so that every step is whole, e.g. "
                             f"--vary {name}={math.ceil(start)}:{math.ceil(start) + int(n) - 1}:{int(n)}")
    return axis


def parse_bound(item: str, robot: Robot, step: float | None = None) -> Bound:
    """Read ``NAME=LOW:HIGH`` (with ``step``: LOW, LOW + step, ... up to HIGH) or ``NAME=A,B,C``.

    Parameters
    ----------
    item : str
        The ``--vary`` text.
    robot : Robot
        The robot the optimisation starts from.
    step : float, optional
        The step of the range, in the parameter's unit; HIGH is lowered to the last step.

    Returns
    -------
    Bound
        The checked bound.

    Raises
    ------
    SweepError
        Not in either form, an unknown or non-numeric name, LOW not below HIGH, a value given
        twice, values outside the limits, or a step not in (0, HIGH - LOW].
    """
    name, rest = _split(item)
    check_name(name, robot)
    if "," in rest:
        choices = _numbers(rest.replace(",", ":"), rest.count(",") + 1, "A,B,C", item)
        if len(set(choices)) != len(choices):
            raise SweepError(f"--vary {item!r}: a value is given twice", "give each value once")
        for v in choices:
            check_range(item, name, v, v, robot)
        return Bound(name, min(choices), max(choices), choices=tuple(choices))
    low, high = _numbers(rest, 2, "LOW:HIGH", item)
    if not low < high:
        raise SweepError(f"--vary {item!r}: LOW {low:g} must be below HIGH {high:g}",
                         "e.g. --vary geometry.leg_m=0.05:0.09")
    check_range(item, name, low, high, robot)
    if step is not None:
        if not (math.isfinite(step) and 0 < step <= high - low):
            raise SweepError(f"--step {name}={step:g}: a step must be above 0 and at most HIGH - LOW "
                             f"({high - low:g})", "e.g. --step geometry.crank_start_deg=18 (a horn's spline step)")
        # Optuna's stepped range ends on the last step at or below HIGH
        high = low + math.floor((high - low) / step + 1e-9) * step
    return Bound(name, low, high, step=step)


LINKS = tuple(f"geometry.{k}" for k in ("ground_m", "crank_m", "coupler_m", "leg_m"))


def design_robot(robot: Robot, values: dict[str, float]) -> Robot:
    """``robot`` with the design's values; ``scale`` first, named parameters over it.

    A value the design sets keeps the uncertainty of the value it replaces: a link cut to a new
    length, or a horn set on another spline step, is built no more exactly than the one it
    replaces was known, and draws of the uncertain values (``--samples``, ``--robust``) meet
    every design with the same deviates.

    Parameters
    ----------
    robot : Robot
        The robot the sweep starts from.
    values : dict of str to float
        Parameter name (or ``scale``) to value, in the parameter's unit.

    Returns
    -------
    Robot
        The design's robot.
    """
    design = robot
    if SCALE in values:
        design = with_added_length(design, values[SCALE])
    named = {k: v for k, v in values.items() if k != SCALE}
    if named:
        design = design.with_values(named, Provenance(source="sweep"))
    changed = (LINKS if SCALE in values else ()) + tuple(named)
    for key in changed:
        sd = robot.source_of(key).uncertainty
        if sd is not None and design.source_of(key).uncertainty is None:
            design = design.with_provenance(key, replace(design.source_of(key), uncertainty=sd))
    return design


def precheck(robot: Robot) -> str | None:
    """Why the design cannot be built or driven, or None.

    The loop must assemble at the start angle and stay closed over every crank angle the
    schedule commands (start .. start + push): a linkage that locks part way would have the
    servo stall against its own loop.

    Parameters
    ----------
    robot : Robot
        The design's robot.

    Returns
    -------
    str or None
        The reason, or None when it can be built and driven.
    """
    g, sch = robot.geometry, robot.schedule
    try:
        assemble(g.ground_m, g.crank_m, g.coupler_m, g.leg_m, g.crank_start_deg)
    except GeometryError as exc:
        return str(exc)
    if abs(sch.push_deg) > robot.servo.travel_deg:
        return f"push {sch.push_deg:g} deg is beyond the servo travel of +-{robot.servo.travel_deg:g} deg"
    n = max(2, int(math.ceil(abs(sch.push_deg) / CRANK_CHECK_STEP_DEG)) + 1)
    for q in np.linspace(0.0, sch.push_deg, n)[1:]:
        try:
            assemble(g.ground_m, g.crank_m, g.coupler_m, g.leg_m, g.crank_start_deg + float(q))
        except GeometryError as exc:
            return f"the linkage locks before the push angle: {exc}"
    return None


def invalid_row(reason: str, grashof: str = "", transmission_deg: float = math.nan) -> dict[str, Any]:
    """The result fields of a design that is not a result.

    Parameters
    ----------
    reason : str
        Why.
    grashof : str, optional
        The linkage's Grashof class, when known.
    transmission_deg : float, optional
        Its worst transmission angle [deg], when known.

    Returns
    -------
    dict
        ``valid`` false, the reason, and NaN figures.
    """
    nan = math.nan
    return {"valid": False, "reason": reason, "outcome": "", "flip_share": nan, "distance_m": nan,
            "max_nose_height_m": nan, "nose_apex_max_m": nan, "com_apex_max_m": nan, "hops": 0, "grashof": grashof,
            "transmission_deg": transmission_deg}


def evaluate(robot: Robot, values: dict[str, float], cycles: int, samples: int = 0) -> dict[str, Any]:
    """Check, simulate and audit one design -> the result fields of its row.

    A pure function of its arguments: whichever process or machine runs it, the row is the same.
    ``outcome`` is the run's class (:func:`locust.sim.outcome.classify`) and ``flip_share`` 1
    when it goes over, else 0. With ``samples``, ``distance_m`` and ``max_nose_height_m`` are
    the means over that many draws of the robot file's uncertain values (:func:`sampled`), so
    designs are ranked by what they do on average over what is not known about the robot;
    ``outcome`` is the draws' most common class and ``flip_share`` the share that goes over.

    Parameters
    ----------
    robot : Robot
        The robot the sweep starts from.
    values : dict of str to float
        The design's values, in each parameter's unit.
    cycles : int
        Hop cycles simulated.
    samples : int, default 0
        Draws of the uncertain values per design (0: the nominal run alone).

    Returns
    -------
    dict
        ``valid``, ``reason``, ``outcome``, ``flip_share``, ``distance_m``,
        ``max_nose_height_m``, ``nose_apex_max_m``, ``com_apex_max_m``, ``hops``, ``grashof``
        and ``transmission_deg``.
    """
    from ..sim.run import run

    try:
        design = design_robot(robot, values)
    except LocustError as exc:
        return invalid_row(str(exc))
    reason = "; ".join(problems(design, cycles)) or precheck(design)
    if reason:
        return invalid_row(reason)
    try:
        result = run(design, cycles=cycles)
    except LocustError as exc:
        return invalid_row(str(exc))
    if not result.valid:
        return invalid_row("; ".join(result.reasons), result.grashof, result.transmission_deg)
    hops = result.hops
    outcome = result.outcome
    distance_m, nose_m, flip = result.distance_m, result.max_nose_height_m, float(outcome == GOES_OVER)
    if samples:
        spread = sampled(design, samples, cycles)
        if spread is None:
            return invalid_row(f"fewer than two of {samples} draws of the uncertain values are valid",
                               result.grashof, result.transmission_deg)
        outcome, flip, distance_m, nose_m = spread
    return {
        "valid": True, "reason": "", "outcome": outcome, "flip_share": flip, "distance_m": distance_m,
        "max_nose_height_m": nose_m,
        "nose_apex_max_m": max(h.nose_apex_m for h in hops),
        "com_apex_max_m": max(h.com_apex_m for h in hops),
        "hops": sum(1 for h in hops if h.flight_s > 0),
        "grashof": result.grashof, "transmission_deg": result.transmission_deg,
    }


def sampled(robot: Robot, samples: int, cycles: int) -> tuple[str, float, float, float] | None:
    """Over ``samples`` draws of the uncertain values (:func:`locust.sim.samples.sample`, seed 0:
    the same deviates for every design): the most common outcome, the share that goes over, and
    the means of distance and highest nose point over the valid draws.

    Parameters
    ----------
    robot : Robot
        The design's robot.
    samples : int
        Number of draws.
    cycles : int
        Hop cycles simulated.

    Returns
    -------
    tuple or None
        (outcome, flip_share, distance_m [m], max_nose_height_m [m]); None when fewer than two
        draws are valid.
    """
    from ..sim.samples import sample

    spread = sample(robot, samples, cycles=cycles)
    kinds = [k for k in spread.outcome if k is not None]
    if spread.n_valid < 2 or not kinds:
        return None
    return (max(OUTCOMES, key=kinds.count), kinds.count(GOES_OVER) / len(kinds), spread.distance_m_mean,
            spread.max_nose_height_m_mean)
