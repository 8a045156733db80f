"""The servos' supply as a circuit: the source's resistance and current limit, the board's own
draw, and the servos' brown-out (docs/servo.md, "Power").

The source holds ``power.supply_voltage_v`` at the servo plug with the servos at rest (the
board already drawing its ``board_current_a`` from it), falls by ``source_resistance_ohm`` for
each ampere the servos draw, and gives no more than ``current_limit_a`` in all: the servos
share what the board leaves of it. Each servo is a DC motor behind its controller's duty
``u`` in [-1, 1] (the controller's torque over its stall torque, :mod:`.servo`); at the output
shaft, on a rail of ``V`` volts::

    I = (u*V - K*w) / R          the motor's current at speed w
    torque = k_t * I             k_t = stall torque / stall current, at the reference voltage
    drawn from the rail = u * I  (the H-bridge's average input current)

with ``K`` = reference voltage / no-load speed and ``R`` the winding. Below ``brownout_v`` at
its plug a servo's electronics stop: it gives no drive.

The model uses it two ways. Statically, both servos stalled at full duty (:func:`stall_point`):
the torque cap and the sag folded into the MuJoCo model (:func:`locust.sim.servo.at_supply`,
:func:`servo_torque_cap_nm`), what a multimeter reads on the supply (:func:`plug_readings`),
and whether the supply limits at all (:func:`supply_limits`). Where it does, step by step
(:func:`rail_voltage_v`): :mod:`.supply_rollout` solves the rail before each physics step from
both servos' duties and speeds and drives each servo as its motor on that rail.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..params import Power, Robot, Servo

SERVOS_ON_SUPPLY = 2   # both legs' servos share the supply (and its resistance and limit)


def torque_constant_nm_per_a(servo: Servo) -> float:
    """``k_t``: the servo's stall torque over its stall current at its reference voltage.

    Parameters
    ----------
    servo : Servo
        Its stall torque [N·m], reference voltage [V] and winding resistance [ohm].

    Returns
    -------
    float
        Output torque per ampere of motor current [N·m/A].
    """
    return servo.stall_torque_nm * servo.winding_resistance_ohm / servo.reference_voltage_v


def backemf_v_s_per_rad(servo: Servo) -> float:
    """``K``: the motor's back-EMF per rad/s of the output shaft (0: no speed limit).

    Parameters
    ----------
    servo : Servo
        Its reference voltage [V] and no-load speed there [rad/s].

    Returns
    -------
    float
        [V·s/rad].
    """
    if math.isinf(servo.noload_speed_rad_per_s):
        return 0.0
    return servo.reference_voltage_v / servo.noload_speed_rad_per_s


def servos_current_a(power: Power) -> float:
    """What the source's current limit leaves both servos together, the board's draw taken off.

    Parameters
    ----------
    power : Power

    Returns
    -------
    float
        [A]; inf for a source without a limit.
    """
    return power.current_limit_a - power.board_current_a


def servo_torque_cap_nm(servo: Servo, power: Power) -> float:
    """Each servo's torque at the source's current limit, both drawing alike: ``k_t * I / 2``.

    Parameters
    ----------
    servo : Servo
        As identified (its ``k_t``).
    power : Power
        The source's limit and the board's draw [A].

    Returns
    -------
    float
        [N·m]; inf for a source without a limit.
    """
    return torque_constant_nm_per_a(servo) * servos_current_a(power) / SERVOS_ON_SUPPLY


@dataclass(frozen=True)
class StallPoint:
    """The servos held stalled at full duty, as the supply lets them draw.

    Attributes
    ----------
    current_a : float
        Each stalled servo's current [A].
    plug_v : float
        The servo plug's voltage [V].
    torque_nm : float
        Each stalled servo's torque at the output shaft, were it driving [N·m].
    current_limited : bool
        The source's current limit sets the current (else its resistance).
    browned_out : bool
        The plug is below ``power.brownout_v``: the servos give no drive at stall.
    """

    current_a: float
    plug_v: float
    torque_nm: float
    current_limited: bool
    browned_out: bool


def stall_point(servo: Servo, power: Power, stalled: int = SERVOS_ON_SUPPLY) -> StallPoint:
    """``stalled`` servos held still at full duty (the others at rest): each draws its plug's
    voltage over its winding, the source's resistance sagging the plug, its limit capping the sum.

    Parameters
    ----------
    servo : Servo
        As identified, at its reference voltage.
    power : Power
        The supply.
    stalled : int
        Servos held stalled (1 or 2).

    Returns
    -------
    StallPoint
    """
    r = servo.winding_resistance_ohm
    thevenin = power.supply_voltage_v / (r + stalled * power.source_resistance_ohm)
    cap = servos_current_a(power) / stalled
    current = min(thevenin, cap)
    plug = r * current
    return StallPoint(current_a=current, plug_v=plug, torque_nm=torque_constant_nm_per_a(servo) * current,
                      current_limited=cap < thevenin, browned_out=plug < power.brownout_v)


def supply_limits(servo: Servo, power: Power) -> bool:
    """Whether the supply limits the servos beyond its resistance's sag: its current limit
    caps their stall current, or their stall brings the plug below their brown-out voltage.
    Where it does not, the static model (:func:`locust.sim.servo.at_supply`) is exact at full
    duty; where it does, the model is stepped (:mod:`.supply_rollout`).

    Parameters
    ----------
    servo : Servo
        As identified.
    power : Power

    Returns
    -------
    bool
    """
    s = stall_point(servo, power)
    return s.current_limited or s.browned_out


def limit_note(servo: Servo, power: Power) -> str | None:
    """What a supply that limits the servos does to them at stall, in words (None: it does not).

    Parameters
    ----------
    servo : Servo
        As identified.
    power : Power

    Returns
    -------
    str or None
    """
    s = stall_point(servo, power)
    if not (s.current_limited or s.browned_out):
        return None
    if s.browned_out:
        return (f"the supply browns the servos out: stalled, their plug falls to {s.plug_v:.2f} V, under their "
                f"{power.brownout_v:g} V (power.brownout_v), so they give no drive at stall (docs/servo.md, Power)")
    return (f"the supply's current limit ({power.current_limit_a:g} A) holds each stalled servo to "
            f"{s.current_a:.3f} A, {s.torque_nm:.4f} N*m, its plug at {s.plug_v:.2f} V (docs/servo.md, Power)")


def rail_voltage_v(servos: Sequence[Servo], power: Power, duties: Sequence[float],
                   speeds_rad_per_s: Sequence[float]) -> float:
    """The rail with each servo at its duty and speed, the motors' currents settled
    (quasi-static): through the source's resistance, ``V = V0 - Rs * sum(u_i * I_i)``; where
    that would draw more than the current limit leaves the servos, the voltage at which they
    draw just that, ``sum(u_i * I_i) = I_max``.

    Parameters
    ----------
    servos : sequence of Servo
        Each servo as identified (its winding and back-EMF constant), one per duty.
    power : Power
        The supply.
    duties : sequence of float
        Each servo's duty, -1 to 1 (0: at rest, or off).
    speeds_rad_per_s : sequence of float
        Each servo's output shaft speed [rad/s].

    Returns
    -------
    float
        The servo plug's voltage [V], at least 0.
    """
    # sum(u_i * I_i) = a*V - b, with I_i = (u_i*V - K_i*w_i) / R_i
    a = sum(u * u / s.winding_resistance_ohm for s, u in zip(servos, duties))
    b = sum(u * backemf_v_s_per_rad(s) * w / s.winding_resistance_ohm
            for s, u, w in zip(servos, duties, speeds_rad_per_s))
    rs = power.source_resistance_ohm
    volts = (power.supply_voltage_v + rs * b) / (1.0 + rs * a)
    limit = servos_current_a(power)
    if a > 0.0 and a * volts - b > limit:
        volts = (limit + b) / a
    return max(volts, 0.0)


@dataclass(frozen=True)
class ServoSupply:
    """The servos and the supply of a model whose supply limits them (:func:`supply_limits`),
    for the model to be stepped (:mod:`.supply_rollout`).

    Attributes
    ----------
    servos : tuple of Servo
        Each servo as identified, at its reference voltage, in the order of the model's servo
        actuators (L, R).
    power : Power
        The supply.
    """

    servos: tuple[Servo, ...]
    power: Power


@dataclass(frozen=True)
class PlugReadings:
    """What a multimeter reads on the supply (a perfect one: :mod:`locust.measure.meter` adds a
    real meter's error).

    Attributes
    ----------
    rest_v : float
        At the servo plug, both servos at rest [V].
    stall_v : float
        At the servo plug, both horns held stalled [V].
    stall_a : float
        Both servos' current, stalled, through a meter in their shared lead [A].
    browned_out : bool
        The stalled plug is below the servos' brown-out voltage: they would not hold the stall.
    """

    rest_v: float
    stall_v: float
    stall_a: float
    browned_out: bool


def plug_readings(robot: Robot) -> PlugReadings:
    """What a multimeter reads on ``robot``'s supply at rest and with both horns held stalled.

    Parameters
    ----------
    robot : Robot
        Its ``servo`` (as identified) and ``power``.

    Returns
    -------
    PlugReadings
    """
    s = stall_point(robot.servo, robot.power)
    return PlugReadings(rest_v=robot.power.supply_voltage_v, stall_v=s.plug_v,
                        stall_a=SERVOS_ON_SUPPLY * s.current_a, browned_out=s.browned_out)


__all__ = ["SERVOS_ON_SUPPLY", "PlugReadings", "ServoSupply", "StallPoint", "backemf_v_s_per_rad", "limit_note",
           "plug_readings", "rail_voltage_v", "servo_torque_cap_nm", "servos_current_a", "stall_point", "supply_limits",
           "torque_constant_nm_per_a"]
