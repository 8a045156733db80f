"""A hop fit's candidate models without compiling each: the fitted values set in the numbers
of one compiled model.

A fit simulates hundreds of candidates that differ from the run's robot only in the fitted
values. Where a value reaches the compiled model only through some of its numbers, each an
exact function ``a + b*g(value)`` of it with ``g`` the value or its reciprocal (a friction
copied into the floor's contact pairs, a hinge stiffness into its joints, a servo's damping
that is its stall torque over its no-load speed), a candidate is a copy of the run's
compiled model with those numbers set: ``MjModel`` fields changed instead of the spec
compiled again (about 40 ms a candidate). Which numbers, and the function, are found by
compiling the robot at three values of each fitted key and comparing every floating-point
array of the model; a key whose numbers change in any other way (a length or an angle: the
compiler derives masses, inertias and the standing pose from it), or that shares a number
with another fitted key, is compiled for every candidate as before. So is a candidate whose
supply limits its servos (:func:`locust.sim.supply.supply_limits`): its stepped model takes the
servo and the supply from the robot, not from the compiled numbers.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..params import Robot
from ..sim.model import BuiltModel, build
from ..sim.supply import supply_limits

PROBES = (1.1, 1.3)              # the factors of the start value the map is found (and checked) at
MATCH_RTOL = 1e-12               # how exactly the third compiled value must follow the map
TRANSFORMS: dict[str, Callable[[float], float]] = {"value": lambda v: v, "reciprocal": lambda v: 1.0 / v}


@dataclass(frozen=True)
class FieldEntries:
    """Entries ``index`` of the model's array ``field``: ``offset + slope * g(value)``."""

    field: str
    index: np.ndarray
    offset: np.ndarray
    slope: np.ndarray


@dataclass(frozen=True)
class KeyMap:
    """How one key's value reaches the compiled model (``transform``: the name of ``g``)."""

    key: str
    transform: str
    entries: tuple[FieldEntries, ...]


def _float_arrays(model) -> dict[str, np.ndarray]:
    out = {}
    for name in dir(model):
        if name.startswith("_"):
            continue
        try:
            value = getattr(model, name)
        except Exception:  # a property MuJoCo cannot give for this model
            continue
        if isinstance(value, np.ndarray) and value.dtype.kind == "f":
            out[name] = value.copy()
    return out


def key_map(robot: Robot, key: str, base_arrays: dict[str, np.ndarray]) -> KeyMap | None:
    """The numbers of ``robot``'s compiled model that ``key`` sets and how, or None where they
    are not an exact ``a + b*g(value)`` of it (see the module docstring)."""
    v0 = robot.get(key)
    values = [v0 * f for f in PROBES]
    compiled = [_float_arrays(build(robot.with_values({key: v}, "fit: model map")).model) for v in values]
    changed = {}
    for name, a0 in base_arrays.items():
        arrays = [c.get(name) for c in compiled]
        if any(a is None or a.shape != a0.shape for a in arrays):
            return None
        moved = np.flatnonzero((arrays[0] != a0).ravel())
        if moved.size:
            changed[name] = moved
        if np.any((arrays[1] != a0).ravel()[np.setdiff1d(np.arange(a0.size), moved)]):
            return None
    if not changed:
        return None
    for transform, g in TRANSFORMS.items():
        entries = []
        for name, idx in changed.items():
            y0 = base_arrays[name].ravel()[idx]
            y1 = compiled[0][name].ravel()[idx]
            y2 = compiled[1][name].ravel()[idx]
            slope = (y1 - y0) / (g(values[0]) - g(v0))
            offset = y0 - slope * g(v0)
            if not np.allclose(offset + slope * g(values[1]), y2, rtol=MATCH_RTOL, atol=0.0):
                break
            entries.append(FieldEntries(name, idx, offset, slope))
        else:
            return KeyMap(key, transform, tuple(entries))
    return None


class CandidateModels:
    """Compiled models of ``robot`` at other values of ``keys``: set in a copy of one compiled
    model where every changed key maps (:func:`key_map`), compiled otherwise."""

    def __init__(self, robot: Robot, keys: tuple[str, ...]):
        self.robot = robot
        self.base = build(robot)
        arrays = _float_arrays(self.base.model)
        maps = {key: key_map(robot, key, arrays) for key in keys}
        # a number two keys set is not the sum of their maps: such keys are compiled
        owners: dict[tuple[str, int], str] = {}
        for key, m in maps.items():
            for e in m.entries if m else ():
                for i in e.index.tolist():
                    other = owners.setdefault((e.field, i), key)
                    if other != key:
                        maps[key] = maps[other] = None
        self.maps = {k: m for k, m in maps.items() if m is not None}
        self.compiled = 0          # candidates that needed the compiler

    def built(self, values: dict[str, float]) -> BuiltModel:
        """The model with ``values`` (key -> value) in place of the robot's (compiled where
        its supply limits the servos: the stepped model takes its numbers from the robot)."""
        changed = {k: v for k, v in values.items() if v != self.robot.get(k)}
        candidate = self.robot.with_values(values, "fit") if changed else self.robot
        if (any(k not in self.maps for k in changed) or self.base.supply is not None
                or supply_limits(candidate.servo, candidate.power)):
            self.compiled += 1
            return build(candidate)
        model = copy.copy(self.base.model)
        for key, value in changed.items():
            m = self.maps[key]
            g = TRANSFORMS[m.transform](value)
            for e in m.entries:
                getattr(model, e.field).reshape(-1)[e.index] = e.offset + e.slope * g
        return replace(self.base, model=model)
