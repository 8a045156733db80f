"""The regime of a run (locust.sim.outcome): the rules on their thresholds, and simulated runs
whose regime is known (docs/servo.md): the presets go over, settings inside the as-built
uncertainties rear and return, others stay low."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from locust import params as P
from locust.sim import outcome as O
from locust.sim.run import run


def hop(nose_cm: float, turn_deg: float = 0.0):
    return SimpleNamespace(nose_apex_m=nose_cm / 100, end_turn_deg=turn_deg)


@pytest.mark.parametrize("hops, expected", [
    ([hop(7), hop(7), hop(7)], O.REARS_AND_RETURNS),
    ([hop(3.01)] * 4, O.REARS_AND_RETURNS),
    ([hop(3.0)] * 4, O.STAYS_LOW),                       # not above 3 cm
    ([hop(7), hop(2.9), hop(7)], O.STAYS_LOW),           # one low hop: not every hop rears
    ([hop(0.7)] * 6, O.STAYS_LOW),
    ([], O.STAYS_LOW),
    ([hop(7), hop(10.8, 45.1), hop(10.8, 93.5)], O.GOES_OVER),
    ([hop(7, 45.0)] * 2, O.REARS_AND_RETURNS),           # 45 deg itself is not over
    ([hop(1.0, 200.0)], O.GOES_OVER),                    # turned right over, nose low again
])
def test_rules_on_their_thresholds(hops, expected):
    assert O.classify(hops) == expected


# (preset, values, outcome, nose rise range per hop in cm); each near-threshold setting is
# inside the as-built uncertainties (crank angle -100 +- 10 deg, ground angle 0 +- 15 deg)
KNOWN = [
    ("small", {}, O.GOES_OVER, (10.0, 11.5)),
    ("medium", {}, O.GOES_OVER, (11.5, 12.5)),
    ("large", {}, O.GOES_OVER, (12.8, 13.8)),
    ("large", {"geometry.crank_start_deg": -94.0}, O.REARS_AND_RETURNS, (6.0, 8.1)),
    ("medium", {"geometry.ground_angle_deg": 15.0}, O.REARS_AND_RETURNS, (6.0, 7.8)),
    ("small", {"geometry.crank_start_deg": -80.0}, O.STAYS_LOW, (0.5, 0.9)),
    ("large", {"geometry.crank_start_deg": -85.0}, O.STAYS_LOW, (1.2, 1.6)),
]


@pytest.mark.parametrize("preset, values, expected, nose_cm", KNOWN)
def test_simulated_runs_of_known_regime(preset, values, expected, nose_cm):
    r = run(P.preset(preset).with_values(values), cycles=6)
    assert r.valid, r.reasons
    assert O.classify(r.hops) == expected
    lo, hi = nose_cm
    assert all(lo / 100 < h.nose_apex_m < hi / 100 for h in r.hops[-5:]), [h.nose_apex_m for h in r.hops]
    turns = [h.end_turn_deg for h in r.hops]
    if expected == O.GOES_OVER:
        # on its back after the first push, turned 90-112 deg from standing, and it stays
        assert all(90.0 < t < 112.0 for t in turns), turns
    else:
        # each cycle ends standing as it started, within a degree
        assert all(abs(t) < 1.0 for t in turns), turns
