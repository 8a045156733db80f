"""The servos' supply from a multimeter at the servo plug (``locust measure supply``,
docs/hardware.md "The supply with a multimeter").

Two readings of the plug's voltage: at rest (the board running, the servos still), ``Vr``, and
with both horns held stalled by hand while they push, ``Vs``; and, with a meter in series with
the servos' shared lead, their stalled current ``I``. Stalled at full duty each servo draws its
plug's voltage over its winding (``R``, ``servo.winding_resistance_ohm``), so the sag
``Vr - Vs`` is the source's doing (:mod:`locust.sim.supply`), read one of two ways:

- its resistance (``--source resistance``): ``Rs = R*(Vr - Vs)/(2*Vs)``, or ``(Vr - Vs)/I`` with
  the current (then the winding's uncertainty drops out); the current limit is then at least
  what the servos drew;
- its current limit (``--source limit``: a polyfuse, a port's power switch holding the
  current): ``I_lim = 2*Vs/R + I_board``, or ``I + I_board``; the resistance is then at most
  the first reading's.

A reading of the two voltages cannot tell one from the other; the robot file's own value of
the other is checked against the reading (a file whose limit would have held the servos below
what they drew, or whose resistance alone would sag the plug below the reading, is refused).

The intervals: a meter's ``±(P % + N digits)`` (:mod:`.meter`): its percentage a gain error
common to the readings of one range (it cancels in ``Vr - Vs`` over ``Vs``, counts in full
in ``Vs`` alone and in the sag over a current), its digits independent per reading; the
winding's and the board's draw's uncertainties from the robot file; each term propagated to
first order, added in quadrature, 95 % = ±1.96 sd (a value the file gives no sd counts as
exact, and is said to). The voltage at rest is written too, as
``power.supply_voltage_v``; every value written has source ``data:measure supply``.
"""

from __future__ import annotations

import datetime as _dt
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import MeasureError
from ..params import Provenance, Robot
from ..sim.supply import SERVOS_ON_SUPPLY, PlugReadings, plug_readings
from .meter import MeterSpec
from .nose_load import GaussianValue

SOURCE = "data:measure supply"
SOLVES = ("resistance", "limit")
REST_KEY = "power.supply_voltage_v"
KEYS = {"resistance": "power.source_resistance_ohm", "limit": "power.current_limit_a"}
WINDING_KEY = "servo.winding_resistance_ohm"
BOARD_KEY = "power.board_current_a"


@dataclass(frozen=True)
class SupplyReadings:
    """What the meter read at the servo plug.

    Attributes
    ----------
    rest_v : float
        Both servos at rest [V].
    stall_v : float
        Both horns held stalled [V].
    stall_a : float or None
        Both servos' current, stalled, through a meter in their shared lead [A] (None: not read).
    """

    rest_v: float
    stall_v: float
    stall_a: float | None = None


@dataclass(frozen=True)
class SupplyResult:
    """The supply as measured, and the robot with it in place.

    Attributes
    ----------
    readings : SupplyReadings
    volts, amps : MeterSpec, MeterSpec or None
        The meter's range for the voltages and the current.
    solve : str
        ``resistance`` or ``limit``: what the sag was read as.
    key : str
        The robot key of the value solved for.
    rest : GaussianValue
        ``power.supply_voltage_v`` [V].
    value : GaussianValue
        The value solved for, in its key's unit (ohm or A).
    sd_terms : dict of str to float
        ``value``'s sd, term by term, in its unit.
    bound : float
        What the reading says of the other value: the resistance at most [ohm] (solving the
        limit), or the limit at least [A] (solving the resistance).
    winding_ohm : float or None
        With the current read: the stalled servos' winding, ``2*Vs/I`` [ohm].
    notes : list of str
    predicted : PlugReadings
        What the robot written reads on the same meter, perfect.
    robot : Robot
        The robot with the values in place.
    """

    readings: SupplyReadings
    volts: MeterSpec
    amps: MeterSpec | None
    solve: str
    key: str
    rest: GaussianValue
    value: GaussianValue
    sd_terms: dict[str, float]
    bound: float
    winding_ohm: float | None
    notes: list[str]
    predicted: PlugReadings
    robot: Robot = field(repr=False, compare=False)

    def to_json(self) -> dict:
        """The result as ``locust measure supply --json`` prints it (SI units, as the names say).

        Returns
        -------
        dict
        """

        def est(e: GaussianValue) -> dict:
            return {"value": e.value, "sd": e.sd, "ci95": list(e.ci95)}

        def spec(m: MeterSpec | None) -> dict | None:
            return None if m is None else {"percent": m.percent, "digits": m.digits, "resolution": m.resolution}

        r = self.readings
        bound = "resistance_at_most_ohm" if self.solve == "limit" else "current_limit_at_least_a"
        return {"rest_v": r.rest_v, "stall_v": r.stall_v, "stall_a": r.stall_a, "volts_meter": spec(self.volts),
                "amps_meter": spec(self.amps), "solve": self.solve, REST_KEY: est(self.rest), self.key: est(self.value),
                "sd_terms": self.sd_terms, bound: self.bound, "winding_ohm": self.winding_ohm, "notes": self.notes,
                "predicted_stall_v": self.predicted.stall_v, "predicted_stall_a": self.predicted.stall_a}


def check_readings(readings: SupplyReadings) -> None:
    """Refuse readings no supply gives.

    Parameters
    ----------
    readings : SupplyReadings

    Raises
    ------
    locust.errors.MeasureError
        A voltage or current that is not a positive number (negative: the leads reversed), or a
        stalled plug above the plug at rest.
    """
    for name, v in (("at rest", readings.rest_v), ("stalled", readings.stall_v)):
        if not (math.isfinite(v) and v > 0):
            raise MeasureError(f"the servo plug's voltage {name} must be a positive number of volts, not {v:g}",
                               "a negative reading is the meter's leads reversed: red on the plug's + (red) wire, "
                               "black on its - (brown); read the volts (V, DC) range")
    if readings.stall_a is not None and not (math.isfinite(readings.stall_a) and readings.stall_a > 0):
        raise MeasureError(f"the stalled current must be a positive number of amperes, not {readings.stall_a:g}",
                           "the meter in series with the servos' shared + lead, on its A (DC) range, red towards "
                           "the board")
    if readings.stall_v > readings.rest_v:
        raise MeasureError(f"the plug reads {readings.stall_v:g} V stalled, above its {readings.rest_v:g} V at rest: "
                           "a stall draws current, and the plug sags",
                           "hold both horns still while the servos push against your fingers (locust pose -30 -30), "
                           "and read both at the same place, the servo plug")


def _sd(robot: Robot, key: str) -> float:
    sd = robot.source_of(key).uncertainty
    return float(sd) if sd and math.isfinite(sd) else 0.0


def _solve(robot: Robot, r: SupplyReadings, volts: MeterSpec, amps: MeterSpec | None, solve: str):
    """The value solved for, its sd terms, and the reading's bound on the other."""
    w, board = robot.servo.winding_resistance_ohm, robot.power.board_current_a
    vr, vs, i = r.rest_v, r.stall_v, r.stall_a
    sag = vr - vs
    d = volts.digits_sd
    if solve == "resistance" and i is None:
        value = w * sag / (2 * vs)
        terms = {"rest reading": w / (2 * vs) * d, "stalled reading": w * vr / (2 * vs ** 2) * d,
                 WINDING_KEY: sag / (2 * vs) * _sd(robot, WINDING_KEY)}
        return value, terms, 2 * vs / w + board
    if solve == "resistance":
        value = sag / i
        terms = {"rest reading": d / i, "stalled reading": d / i, "the volts' gain": volts.gain_sd(value),
                 "current reading": sag / i ** 2 * amps.sd(i)}
        return value, terms, i + board
    if i is None:
        value = 2 * vs / w + board
        terms = {"stalled reading": 2 / w * volts.sd(vs), WINDING_KEY: 2 * vs / w ** 2 * _sd(robot, WINDING_KEY),
                 BOARD_KEY: _sd(robot, BOARD_KEY)}
        return value, terms, w * sag / (2 * vs)
    terms = {"current reading": amps.sd(i), BOARD_KEY: _sd(robot, BOARD_KEY)}
    return i + board, terms, sag / i


def _check_other(robot: Robot, solve: str, bound: float) -> None:
    """The robot file's own value of what was not solved for must agree with the reading."""
    p = robot.power
    if solve == "resistance" and p.current_limit_a < bound:
        raise MeasureError(f"the robot file's power.current_limit_a = {p.current_limit_a:g} A would have held the "
                           f"stalled servos below what this reading says they drew ({bound:.3g} A with the board's)",
                           "read the sag as the current limit (--source limit), or raise power.current_limit_a "
                           "(--set power.current_limit_a=...)")
    if solve == "limit" and p.source_resistance_ohm > bound:
        raise MeasureError(f"the robot file's power.source_resistance_ohm = {p.source_resistance_ohm:g} ohm alone "
                           f"would sag the stalled plug below this reading: the resistance is at most {bound:.3g} ohm",
                           "read the sag as the resistance (--source resistance), or set power.source_resistance_ohm "
                           f"to at most {bound:.3g} (--set)")


def measure_supply(robot: Robot, readings: SupplyReadings, volts: MeterSpec, amps: MeterSpec | None = None,
                   solve: str = "resistance") -> SupplyResult:
    """The supply's voltage at rest and its resistance or current limit, from a meter's readings.

    Parameters
    ----------
    robot : Robot
        The robot as it is known: its servos' winding (and its sd), the board's draw, the other
        supply value.
    readings : SupplyReadings
        The plug's volts at rest and stalled, and maybe the stalled current.
    volts : MeterSpec
        The meter's range for the volts.
    amps : MeterSpec, optional
        Its range for the current (needed with ``readings.stall_a``).
    solve : str
        ``resistance`` or ``limit``: what the sag is read as.

    Returns
    -------
    SupplyResult
        The values, their 95 % intervals and sd terms, and ``robot`` with them in place
        (source ``data:measure supply``).

    Raises
    ------
    locust.errors.MeasureError
        Bad readings (:func:`check_readings`), an unknown ``solve``, a current without its
        meter, or a robot file whose other supply value disagrees with the reading.
    """
    if solve not in SOLVES:
        raise MeasureError(f"--source {solve!r} is not known", f"choose one of {', '.join(SOLVES)}")
    check_readings(readings)
    if readings.stall_a is not None and amps is None:
        raise MeasureError("a current was read without its meter's range", "give the ammeter's accuracy and last digit")
    value, terms, bound = _solve(robot, readings, volts, amps, solve)
    _check_other(robot, solve, bound)
    terms = {k: float(v) for k, v in terms.items() if v > 0}
    estimate = GaussianValue(float(value), math.sqrt(sum(t * t for t in terms.values())))
    rest = GaussianValue(readings.rest_v, volts.sd(readings.rest_v))
    key = KEYS[solve]
    date = _dt.date.today().isoformat()
    said = (f"{readings.rest_v:g} V at rest, {readings.stall_v:g} V stalled"
            + ("" if readings.stall_a is None else f", {readings.stall_a:g} A") + f", a meter of {volts.describe()} V")
    out = robot.with_values({REST_KEY: rest.value}, Provenance(SOURCE, uncertainty=rest.sd, date=date, note=said))
    out = out.with_values({key: estimate.value}, Provenance(SOURCE, uncertainty=estimate.sd, date=date,
                                                            note=f"{said}; read as the source's {solve}"))
    notes = []
    if solve == "limit" and _sd(robot, BOARD_KEY) == 0.0:
        notes.append(f"{BOARD_KEY} ({robot.power.board_current_a:g} A) carries no uncertainty in the robot file: "
                     "counted as exact (a USB meter between the port and the board reads it)")
    if readings.stall_v < robot.power.brownout_v:
        notes.append(f"the stalled plug, {readings.stall_v:g} V, is below the robot file's brown-out voltage "
                     f"({robot.power.brownout_v:g} V): if the servos held the stall without twitching, their "
                     "brown-out is lower (power.brownout_v)")
    winding = None if readings.stall_a is None else SERVOS_ON_SUPPLY * readings.stall_v / readings.stall_a
    return SupplyResult(readings=readings, volts=volts, amps=amps, solve=solve, key=key, rest=rest, value=estimate,
                        sd_terms=terms, bound=float(bound), winding_ohm=winding, notes=notes,
                        predicted=plug_readings(out), robot=out)


def virtual_readings(robot: Robot, volts: MeterSpec, amps: MeterSpec | None = None, seed: int = 0) -> SupplyReadings:
    """What a meter of ``volts`` (and ``amps``) reads on ``robot``'s supply, at rest and stalled.

    The circuit's values (:func:`locust.sim.supply.plug_readings`) through the meter's error,
    one gain error for both voltages (one range), the digits drawn per reading. (On a supply
    that browns the servos out at stall, ``plug_readings(robot).browned_out``, no real meter
    reads a steady stall: the servos reset as they stall.)

    Parameters
    ----------
    robot : Robot
        The robot whose supply is read (its values the truth).
    volts : MeterSpec
    amps : MeterSpec, optional
        With it, the stalled current is read too.
    seed : int
        Seed of NumPy's default generator.

    Returns
    -------
    SupplyReadings
    """
    rng = np.random.default_rng(seed)
    truth = plug_readings(robot)
    gain = rng.uniform(-1.0, 1.0) * volts.percent / 100.0
    rest, stall = (volts.reading(v, rng, gain) for v in (truth.rest_v, truth.stall_v))
    current = None if amps is None else amps.reading(truth.stall_a, rng)
    return SupplyReadings(rest_v=rest, stall_v=stall, stall_a=current)


__all__ = ["SOLVES", "SOURCE", "SupplyReadings", "SupplyResult", "check_readings", "measure_supply",
           "virtual_readings"]
