"""A hop fit's candidates set in one compiled model (calibrate/hopmodels.py) against the model
compiled at the same values: every floating-point number the same."""

from __future__ import annotations

import numpy as np
import pytest

from locust.calibrate import hopmodels as HM
from locust.params import leg_set, preset
from locust.sim.model import build

KEYS = ("contact.foot_friction", "compliance.hinge_stiffness_nm_per_rad", "servo.noload_speed_rad_per_s")


@pytest.fixture(scope="module")
def candidates():
    robot = leg_set(preset("seed"), "small")
    return robot, HM.CandidateModels(robot, KEYS + ("geometry.crank_m",))


def test_physical_values_map_onto_model_numbers(candidates):
    _, cm = candidates
    fields = {k: (m.transform, sorted(e.field for e in m.entries)) for k, m in cm.maps.items()}
    assert fields == {"contact.foot_friction": ("value", ["geom_friction", "pair_friction"]),
                      # the film hinge's: the servo, knee and ankle folds' joints and the loop fold's tendon
                      "compliance.hinge_stiffness_nm_per_rad": ("value", ["jnt_stiffness", "tendon_stiffness"]),
                      # the servo's back-EMF damping: stall torque over no-load speed
                      "servo.noload_speed_rad_per_s": ("reciprocal", ["dof_damping"])}
    assert "geometry.crank_m" not in cm.maps       # a length moves masses and poses: compiled


@pytest.mark.parametrize("factors", [(1.37, 0.61, 1.12), (0.8, 2.5, 0.7)])
def test_candidate_equals_the_compiled_model(candidates, factors):
    robot, cm = candidates
    values = {k: robot.get(k) * f for k, f in zip(KEYS, factors)}
    made = cm.built(values).model
    compiled = build(robot.with_values(values, "test")).model
    assert cm.compiled == 0
    for name, a in HM._float_arrays(compiled).items():
        np.testing.assert_allclose(getattr(made, name), a, rtol=1e-12, atol=0, err_msg=name)
    # the base model is left as it was
    np.testing.assert_array_equal(cm.base.model.jnt_stiffness, build(robot).model.jnt_stiffness)


def test_a_key_without_a_map_is_compiled(candidates):
    robot, cm = candidates
    before = cm.compiled
    made = cm.built({"geometry.crank_m": robot.get("geometry.crank_m") * 1.05}).model
    assert cm.compiled == before + 1
    assert not np.array_equal(made.body_pos, cm.base.model.body_pos)
