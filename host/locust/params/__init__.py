"""Robot parameters: one typed model with each value's unit and source.

- :mod:`.model`: the parameter types (geometry, compliance, folds, servo, left and right,
  contact, power, schedule, solver), provenance, and access by dotted name; :mod:`.legs`: the
  leg's own sections (each fold's spring, what one leg has of its own).
- :mod:`.sides`: each leg's values resolved (its own, else the folds', the film hinge's or the
  servo's).
- :mod:`.limits`: each parameter's limits with their reasons; the checks before a simulation.
- :mod:`.presets`: the built-in robots (seed, the robot as built, seed-notebook), every value
  with its source.
- :mod:`.legsets`: the filmed leg sets, the one table presets, reports and the hop fit use.

``robot.toml`` is read and written by :mod:`locust.io.robot_toml`.
"""

from .legs import FOLDS, Folds, Side
from .legsets import LEG_SETS, LegSet, leg_set, leg_set_spec, with_added_length
from .limits import LIMITS, MAX_SIM_STEPS, Limit, check_robot, outside_limits, problems
from .model import (
    GRAVITY_M_PER_S2,
    INHERITS,
    PHYSICAL_SECTIONS,
    SECTIONS,
    UNBOUNDED_KEYS,
    Compliance,
    Contact,
    Geometry,
    Power,
    Provenance,
    Robot,
    Schedule,
    Servo,
    Solver,
    all_keys,
    as_dict,
    fittable_keys,
    inherited_from,
    is_optional,
    parse_set_options,
    real_keys,
    value_type,
)
from .presets import AS_BUILT, DEFAULT_PRESET, PRESETS, SG90_SOURCE, preset
from .sides import FoldValues, SideValues, is_symmetric, side_values, tooth_deg

__all__ = ["GRAVITY_M_PER_S2", "Geometry", "Compliance", "Folds", "FOLDS", "Servo", "Side", "Contact", "Power",
           "Schedule", "Solver", "INHERITS", "inherited_from", "is_optional", "FoldValues", "SideValues",
           "side_values", "is_symmetric", "tooth_deg",
           "SECTIONS", "Provenance", "Robot", "UNBOUNDED_KEYS", "all_keys", "value_type", "real_keys",
           "PHYSICAL_SECTIONS", "fittable_keys", "parse_set_options", "as_dict", "Limit", "LIMITS",
           "MAX_SIM_STEPS", "outside_limits", "problems", "check_robot", "with_added_length", "LegSet",
           "LEG_SETS", "leg_set", "leg_set_spec", "SG90_SOURCE", "AS_BUILT", "DEFAULT_PRESET", "PRESETS",
           "preset"]
