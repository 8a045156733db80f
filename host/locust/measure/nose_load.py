"""Where the centre of mass sits along the plate, from the nose's weight on a kitchen scale.

The robot stands as it does before a hop (servos at the 0 deg command), its nose on a
kitchen scale's pan and its feet level with the pan (on a book as thick as the scale). The
model predicts the reading (:func:`locust.sim.statics.standing_load`); the measurement
moves one value until the model reads what the scale read.

The value moved is ``geometry.servo_axis_x_m``, the servo axis's place along the plate.
Why that one: the two servos are 18 g of the robot's 30 g, and their axis is where the
photos are least sure of the build (the top view scales it to 28 +- 3 mm from the plate's
middle); moving it moves the servos, the legs and the feet together, so it is the value
that sets where the weight sits over the feet, and with it whether a push carries the
centre of mass behind them (docs/servo.md). The plate's mass (``geometry.body_mass_kg``),
the one mass no datasheet gives, is what the whole robot's weight sets when it is weighed
too (the reading less the servos and links, combined with the file's own plate mass): first
the weight sets the plate's mass, then the nose sets the axis.

The interval: the scale's reading is the true load rounded to its resolution R (an error
uniform over R, sd R/sqrt(12)); every other value of the robot that carries an uncertainty
is moved by its own sd and its change of the nose load counted as an axis error (one at a
time, the larger of its two sides); these add in quadrature to the axis's sd from the scale.
Where the robot file already carries an sd on the axis (a photo, a stance measurement), the
two are combined by their variances, so a coarse scale never makes the robot file worse.
The 95 % interval is +- 1.96 sd.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from scipy.optimize import brentq

from ..errors import LocustError, MeasureError
from ..params import LIMITS, Provenance, Robot
from ..sim.samples import uncertain_values
from ..sim.statics import standing_load

AXIS_KEY = "geometry.servo_axis_x_m"
PLATE_KEY = "geometry.body_mass_kg"
Z95 = 1.959964
SEARCH_M = 0.015         # the axis is searched this far either side of the robot file's value (5 photo sd)
SLOPE_STEP_M = 0.001     # the slope of the load against the axis, by central differences


@dataclass(frozen=True)
class GaussianValue:
    """A measured value with a normal uncertainty, in the unit of the quantity it stands for.

    Attributes
    ----------
    value : float
        The estimate.
    sd : float
        One standard deviation.
    """

    value: float
    sd: float                   # one standard deviation

    @property
    def ci95(self) -> tuple[float, float]:
        """The normal 95% interval, value ± 1.96 sd."""
        return (self.value - Z95 * self.sd, self.value + Z95 * self.sd)


@dataclass(frozen=True)
class NoseLoadResult:
    """What the scale says, and the robot with the measured values in place."""

    nose_load_kg: float                  # the scale's reading under the nose
    resolution_kg: float
    total_mass_kg: float | None          # the whole robot's reading, when weighed
    axis_from_scale: GaussianValue            # geometry.servo_axis_x_m from the nose load alone
    axis_before: GaussianValue | None         # the robot file's own (sd None: no prior)
    axis: GaussianValue                       # the two combined: what is written
    plate_mass: GaussianValue | None          # geometry.body_mass_kg, when the whole robot is weighed
    slope_kg_per_m: float                # d(nose load)/d(axis) at the estimate
    axis_sd_terms_m: dict[str, float]    # the axis's sd from the scale alone, term by term
    predicted_nose_load_kg: float        # the model at the written values
    com_from_nose_m: float               # the centre of mass along the plate from the nose, there
    robot: Robot = field(repr=False, compare=False)

    def to_json(self) -> dict:
        """The result as ``locust measure nose-load --json`` prints it (SI units, as the names say).

        Returns
        -------
        dict
        """

        def est(e: GaussianValue | None) -> dict | None:
            return None if e is None else {"value": e.value, "sd": e.sd, "ci95": list(e.ci95)}

        return {"nose_load_kg": self.nose_load_kg, "resolution_kg": self.resolution_kg,
                "total_mass_kg": self.total_mass_kg, "key": AXIS_KEY, "axis_from_scale": est(self.axis_from_scale),
                "axis_before": est(self.axis_before), "axis": est(self.axis),
                "plate_mass": est(self.plate_mass), "slope_kg_per_m": self.slope_kg_per_m,
                "axis_sd_terms_m": self.axis_sd_terms_m, "predicted_nose_load_kg": self.predicted_nose_load_kg,
                "com_from_nose_m": self.com_from_nose_m}


def _nose(robot: Robot, axis_m: float) -> float:
    return standing_load(robot.with_values({AXIS_KEY: axis_m})).nose_load_kg


def _plate_from_weight(robot: Robot, total_kg: float, resolution_kg: float) -> GaussianValue:
    """The plate's mass that makes the model weigh ``total_kg``: the reading less every other
    part; its sd from the resolution and the other parts' own uncertainties."""
    from ..sim.model import build

    def mass(robot: Robot) -> float:
        from ..sim.gl import mujoco

        model = build(robot).model
        return float(model.body_subtreemass[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "chassis")])

    plate0 = robot.get(PLATE_KEY)
    others = mass(robot) - plate0
    value = total_kg - others
    if not value > LIMITS[PLATE_KEY].low:
        raise MeasureError(f"the whole robot weighed {total_kg * 1000:.1f} g, but its servos and links alone "
                           f"weigh {others * 1000:.1f} g in the robot file",
                           "check the reading (grams), or the servo and link masses in the robot file")
    var = (resolution_kg / math.sqrt(12)) ** 2
    for key, sd in uncertain_values(robot).items():
        if key == PLATE_KEY:
            continue
        centre = robot.get(key)
        moved = robot.with_values({key: centre + sd})
        try:
            var += (mass(moved) - plate0 - others) ** 2
        except LocustError:   # a value that cannot be built at +1 sd adds nothing to the mass
            continue
    return combine(GaussianValue(value, math.sqrt(var)), prior_of(robot, PLATE_KEY))


def prior_of(robot: Robot, key: str) -> GaussianValue | None:
    """The robot file's own value and sd for ``key`` (None when it carries no sd).

    Parameters
    ----------
    robot : Robot
    key : str
        A dotted name.

    Returns
    -------
    GaussianValue or None
        In the unit the name says.
    """
    sd = robot.source_of(key).uncertainty
    return GaussianValue(robot.get(key), sd) if sd and math.isfinite(sd) and sd > 0 else None


def combine(new: GaussianValue, prior: GaussianValue | None) -> GaussianValue:
    """Two independent estimates of one value, weighted by their variances.

    Parameters
    ----------
    new : GaussianValue
        The new estimate.
    prior : GaussianValue or None
        The earlier one, in the same unit; None: ``new`` alone.

    Returns
    -------
    GaussianValue
        The inverse-variance weighted mean and its sd.
    """
    if prior is None:
        return new
    w_new, w_prior = 1 / new.sd ** 2, 1 / prior.sd ** 2
    return GaussianValue((new.value * w_new + prior.value * w_prior) / (w_new + w_prior),
                         math.sqrt(1 / (w_new + w_prior)))


def measure_nose_load(robot: Robot, nose_load_kg: float, resolution_kg: float = 0.001,
                      total_mass_kg: float | None = None, note: str = "kitchen_scale") -> NoseLoadResult:
    """Place the servo axis along the plate (and, weighed, the plate's mass) from a scale.

    Parameters
    ----------
    robot : Robot
        The robot as it is known (a preset, or a robot file, e.g. with the stance measured).
    nose_load_kg : float
        The scale's reading under the nose, feet level with its pan (kg; 4.2 g is 0.0042).
    resolution_kg : float, default 0.001
        The scale's resolution (its last digit: 1 g for most kitchen scales).
    total_mass_kg : float, optional
        The whole robot on the same scale; sets the plate's mass first.
    note : str
        Names the measurement in the written provenance (``measured:<note>``).

    Returns
    -------
    NoseLoadResult
        The axis from the scale alone, combined with the robot file's own, its 95 % interval,
        the terms of its sd, and ``robot`` with the values in place (source ``measured:...``).

    Raises
    ------
    locust.errors.MeasureError
        No place of the axis within 15 mm of the robot file's makes the model read the scale's
        value, or the whole robot weighs less than its servos and links.
    """
    for name, v in (("nose load", nose_load_kg), ("resolution", resolution_kg)):
        if not (math.isfinite(v) and v > 0):
            raise MeasureError(f"the {name} must be a positive number of grams, not {v * 1000:g}",
                               "read the scale with the nose on it; its resolution is its last digit")
    plate = None
    if total_mass_kg is not None:
        plate = _plate_from_weight(robot, total_mass_kg, resolution_kg)
        robot = robot.with_values({PLATE_KEY: plate.value}, Provenance(
            f"measured:{note}", uncertainty=plate.sd,
            note=f"the whole robot weighed {total_mass_kg * 1000:g} g (resolution {resolution_kg * 1000:g} g) "
                 "less the servos and links of the robot file, combined with the file's plate"))
    axis0 = robot.get(AXIS_KEY)   # the robot file's, before the scale
    lim = LIMITS[AXIS_KEY]
    lo, hi = max(axis0 - SEARCH_M, lim.low), min(axis0 + SEARCH_M, lim.high)
    load_lo, load_hi = _nose(robot, lo) - nose_load_kg, _nose(robot, hi) - nose_load_kg
    if load_lo * load_hi > 0:
        a, b = sorted((load_lo + nose_load_kg, load_hi + nose_load_kg))
        raise MeasureError(f"a nose load of {nose_load_kg * 1000:g} g: the model reads {a * 1000:.1f} to "
                           f"{b * 1000:.1f} g with the servo axis anywhere from {lo * 1000:.0f} to {hi * 1000:.0f} mm "
                           "from the plate's middle",
                           "check that the feet stand level with the scale's pan and the servos are at rest (0 deg); "
                           "measure the stance first (locust measure stance) if its angles differ from the file's")
    value = brentq(lambda a: _nose(robot, a) - nose_load_kg, lo, hi, xtol=1e-6)
    slope = (_nose(robot, value + SLOPE_STEP_M) - _nose(robot, value - SLOPE_STEP_M)) / (2 * SLOPE_STEP_M)
    base = _nose(robot, value)
    at = robot.with_values({AXIS_KEY: value})
    terms = {"scale resolution": resolution_kg / math.sqrt(12) / abs(slope)}
    for key, sd in uncertain_values(at).items():
        if key == AXIS_KEY:
            continue
        centre = at.get(key)
        changes = []
        for sign in (-1.0, 1.0):
            try:
                changes.append(abs(standing_load(at.with_values({key: centre + sign * sd})).nose_load_kg - base))
            except LocustError:   # a side that cannot stand (or be built) is left out of that key's term
                continue
        if changes and max(changes) > 0:
            terms[key] = max(changes) / abs(slope)
    alone = GaussianValue(value, math.sqrt(sum(t * t for t in terms.values())))
    before = prior_of(robot, AXIS_KEY)
    combined = combine(alone, before)
    said = (f"nose {nose_load_kg * 1000:g} g on a scale of {resolution_kg * 1000:g} g: "
            f"{alone.value * 1000:.1f} +- {alone.sd * 1000:.1f} mm alone")
    if before is not None:
        said += f", combined with the file's {before.value * 1000:.1f} +- {before.sd * 1000:.1f} mm"
    out = robot.with_values({AXIS_KEY: combined.value}, Provenance(f"measured:{note}", uncertainty=combined.sd,
                                                                    note=said))
    final = standing_load(out)
    return NoseLoadResult(nose_load_kg=nose_load_kg, resolution_kg=resolution_kg, total_mass_kg=total_mass_kg,
                          axis_from_scale=alone, axis_before=before, axis=combined, plate_mass=plate,
                          slope_kg_per_m=slope, axis_sd_terms_m=terms, predicted_nose_load_kg=final.nose_load_kg,
                          com_from_nose_m=final.com_from_nose_m, robot=out)


__all__ = ["AXIS_KEY", "PLATE_KEY", "GaussianValue", "NoseLoadResult", "measure_nose_load"]
