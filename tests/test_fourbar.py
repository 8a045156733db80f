"""Four-bar solver against hand-computed geometry and textbook Grashof cases."""

import math

import pytest

from locust.errors import GeometryError
from locust.sim.fourbar import assemble, grashof_class


def test_seed_linkage_matches_hand_computation():
    # ground 4, crank 4 at -90 deg, coupler 2, leg 6 (cm). P2 = (-2, -4); P4 = (2, 0);
    # d = |P4 - P2| = 4*sqrt(2); a = (2^2 - 6^2 + 32) / (2d) = 0 -> the knee is the point at
    # distance 2 from P2 perpendicular to P2->P4: P3 = P2 + 2*(1, -1)/sqrt(2).
    asm = assemble(0.04, 0.04, 0.02, 0.06, -90.0)
    s = math.sqrt(2)
    assert asm.p2_m == pytest.approx((-0.02, -0.04), abs=1e-12)
    assert asm.p3_m == pytest.approx((-0.02 + 0.02 / s, -0.04 - 0.02 / s), abs=1e-12)
    assert asm.coupler_deg == pytest.approx(-45.0, abs=1e-9)
    assert asm.coupler_rel_deg == pytest.approx(45.0, abs=1e-9)   # -45 - (-90)
    # leg from P3 to P4: direction (0.04 - 0.02/s, 0.04 + 0.02/s)
    expected_leg = math.degrees(math.atan2(0.04 + 0.02 / s, 0.04 - 0.02 / s))
    assert asm.leg_deg == pytest.approx(expected_leg, abs=1e-9)
    # transmission angle at the knee: law of cosines with d^2 = 32 cm^2 -> cos = (4 + 36 - 32)/24
    assert asm.transmission_deg == pytest.approx(math.degrees(math.acos(8 / 24)), abs=1e-9)
    assert asm.closure_error_m < 1e-15


def test_seed_sweep_units_bug_is_not_reproduced():
    # The seed's sweep used degrees(atan2(..)) - radians(-90) = -45 + 1.5708 = -43.43 deg for
    # the coupler; the correct relative angle is +45 deg.
    asm = assemble(0.04 + 0.01, 0.04 + 0.01, 0.02 + 0.01, 0.06 + 0.01, -90.0)
    assert abs(asm.coupler_rel_deg - (asm.coupler_deg - -90.0)) < 1e-9
    assert asm.coupler_rel_deg > 0


@pytest.mark.parametrize("links, kind", [
    ((0.04, 0.01, 0.05, 0.045), "crank-rocker"),    # shortest is the crank
    ((0.01, 0.04, 0.05, 0.045), "double-crank"),    # shortest is the ground
    ((0.04, 0.045, 0.01, 0.05), "double-rocker"),   # shortest is the coupler
    ((0.04, 0.04, 0.02, 0.06), "change-point"),     # 2 + 6 == 4 + 4
    ((0.05, 0.05, 0.03, 0.07), "change-point"),     # medium leg set: 3 + 7 == 5 + 5
    ((0.06, 0.05, 0.05, 0.07), "non-grashof"),      # 5 + 7 > 6 + 5
])
def test_grashof_cases(links, kind):
    assert grashof_class(*links) == kind


def test_coupler_too_long_is_refused_with_numbers():
    with pytest.raises(GeometryError) as err:
        assemble(0.04, 0.04, 0.2, 0.06, -90.0)
    assert "geometry.coupler_m" in err.value.message and "0.2" in err.value.message


def test_cannot_reach_names_the_gap():
    # crank tip to front pivot 5.66 cm, coupler + leg = 4 cm: short by 1.66 cm
    with pytest.raises(GeometryError) as err:
        assemble(0.04, 0.04, 0.01, 0.03, -90.0)
    assert "short by 1.66 cm" in err.value.message


def test_overshoot_names_the_gap():
    # |coupler - leg| = 7 cm > 5.66 cm, overshooting by 1.34 cm
    with pytest.raises(GeometryError) as err:
        assemble(0.04, 0.04, 0.02, 0.09, -90.0)
    assert "|coupler - leg| is 7.00 cm" in err.value.message and "by 1.34 cm" in err.value.message
