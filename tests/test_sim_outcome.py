"""The regime of a run (locust.sim.outcome): the rules on their thresholds, and simulated runs
whose regime is known (docs/servo.md): the presets go over, settings inside the as-built
uncertainties rear and return, others stay low."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from locust import params
from locust.io import robot_toml
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
    ("small", {}, O.GOES_OVER, (11.0, 12.0)),
    ("medium", {}, O.GOES_OVER, (12.2, 13.2)),
    ("large", {}, O.GOES_OVER, (13.4, 14.4)),
    ("medium", {"geometry.crank_start_deg": -90.0}, O.GOES_OVER, (-0.5, 0.5)),    # right over, plate flat
    ("small", {"geometry.crank_start_deg": -89.0}, O.REARS_AND_RETURNS, (6.5, 7.5)),
    ("medium", {"geometry.ground_angle_deg": 18.0}, O.REARS_AND_RETURNS, (7.5, 11.0)),
    ("large", {"geometry.crank_start_deg": -90.0}, O.REARS_AND_RETURNS, (9.0, 12.0)),
    ("small", {"geometry.crank_start_deg": -88.0}, O.STAYS_LOW, (2.0, 2.8)),
    ("small", {"geometry.crank_start_deg": -80.0}, O.STAYS_LOW, (0.1, 0.5)),
]


@pytest.mark.parametrize("preset, values, expected, nose_cm", KNOWN)
def test_simulated_runs_of_known_regime(preset, values, expected, nose_cm):
    r = run(params.preset(preset).with_values(values), cycles=6)
    assert r.valid, r.reasons
    assert O.classify(r.hops) == expected
    lo, hi = nose_cm
    assert all(lo / 100 < h.nose_apex_m < hi / 100 for h in r.hops[-5:]), [h.nose_apex_m for h in r.hops]
    turns = [h.end_turn_deg for h in r.hops]
    if expected == O.GOES_OVER:
        # on its back after the first push (turned 91-107 deg from standing, or right over
        # onto the plate's top, 212 deg), and it stays
        assert all(90.0 < t < 110.0 for t in turns) or all(200.0 < t < 220.0 for t in turns), turns
    else:
        # each cycle ends standing as it started, within a degree
        assert all(abs(t) < 1.0 for t in turns), turns


def test_outcome_shares_are_each_outcomes_own_figures():
    kinds = [O.GOES_OVER, O.STAYS_LOW, None, O.GOES_OVER, O.GOES_OVER]
    dist = [-0.10, 0.008, float("nan"), -0.12, -0.08]
    nose = [0.12, 0.009, float("nan"), 0.13, 0.11]
    out = O.outcome_shares(kinds, dist, nose)
    assert list(out) == list(O.OUTCOMES)
    assert [out[k].share for k in O.OUTCOMES] == [0.75, 0.0, 0.25]       # of the 4 valid draws
    over = out[O.GOES_OVER]
    assert over.n == 3 and over.distance_m.mean == pytest.approx(-0.10, abs=1e-15)
    assert over.distance_m.sd == pytest.approx(0.02, rel=1e-12)          # sd of -0.10, -0.12, -0.08
    assert over.max_nose_height_m.sd == pytest.approx(0.01, rel=1e-12)
    low = out[O.STAYS_LOW]
    assert low.distance_m.mean == 0.008 and math.isnan(low.distance_m.sd)   # one draw: no sd
    assert math.isnan(out[O.REARS_AND_RETURNS].distance_m.mean)


def only_uncertain(robot, uncertain: dict[str, float]):
    """``robot`` with every uncertainty removed but those given (key -> sd)."""
    from locust.sim.samples import uncertain_values

    bare = robot.with_values({k: robot.get(k) for k in uncertain_values(robot)}, params.Provenance("test"))
    for key, sd in uncertain.items():
        bare = bare.with_values({key: bare.get(key)}, params.Provenance("estimate", uncertainty=sd))
    return bare


def test_sensitivity_names_the_value_that_decides_the_regime():
    """Medium as preset goes over; its crank angle at -80 deg (+2 sd) stays low and at -120
    goes over; the servo mass at -/+2 sd (8 and 10 g) does not change it."""
    from locust.sim.sensitivity import outcome_sensitivity

    robot = only_uncertain(params.preset("medium"),
                           {"geometry.crank_start_deg": 10.0, "geometry.servo_mass_kg": 0.0005})
    sens = outcome_sensitivity(robot, cycles=2)
    assert sens.nominal == O.GOES_OVER
    crank, mass = sens.effects
    assert (crank.key, crank.low_value, crank.high_value) == ("geometry.crank_start_deg", -120.0, -80.0)
    assert (crank.low_outcome, crank.high_outcome) == (O.GOES_OVER, O.STAYS_LOW)
    assert mass.low_value == pytest.approx(0.008) and mass.high_value == pytest.approx(0.010)
    assert (mass.low_outcome, mass.high_outcome) == (O.GOES_OVER, O.GOES_OVER)
    assert [e.key for e in sens.deciding] == ["geometry.crank_start_deg"]
    assert sens.to_json()["deciding"] == ["geometry.crank_start_deg"]


def test_sim_json_and_samples_give_the_outcome_and_its_shares(tmp_path):
    """``locust sim --samples 6 --json`` on Medium with only its crank angle uncertain
    (-100 +- 10 deg): each draw's outcome, shares summing to 1 that count the draws, each
    outcome's mean its own draws' mean; the split names the crank angle as deciding it."""
    import json

    from click.testing import CliRunner

    from locust.commands import cli

    robot = only_uncertain(params.preset("medium"), {"geometry.crank_start_deg": 10.0})
    robot_toml.save_robot(robot, tmp_path / "r.toml")
    res = CliRunner().invoke(cli, ["sim", "--config", str(tmp_path / "r.toml"), "--cycles", "2", "--samples", "6",
                                   "--seed", "3", "--json"])
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out["outcome"] == O.GOES_OVER
    assert out["nose_load_kg"] == pytest.approx(0.00420, abs=5e-5)
    assert out["total_mass_kg"] == pytest.approx(0.03113, abs=5e-5)
    draws = out["samples"]
    shares = out["outcomes"]
    assert sum(s["share"] for s in shares.values()) == pytest.approx(1.0, abs=1e-12)
    for name, s in shares.items():
        mine = [d for d, k in zip(draws["distance_m"], draws["outcome"]) if k == name]
        assert s["n"] == len(mine) and s["share"] == pytest.approx(len(mine) / draws["n_valid"])
        if mine:
            assert s["distance_m"]["mean"] == pytest.approx(sum(mine) / len(mine), rel=1e-12)
    assert 0 < shares[O.GOES_OVER]["share"] < 1, draws["outcome"]       # seed 3 splits them
    assert out["sensitivity"]["deciding"] == ["geometry.crank_start_deg"]


def test_the_report_shows_each_outcomes_share_of_the_draws():
    """The report's spread (``locust report --samples``) classifies its draws as ``locust sim
    --samples`` does: Medium with only its crank angle uncertain, seed 3, splits the same way,
    and the HTML table gives each outcome's count of the draws."""
    from locust.report.page import outcome_table
    from locust.report.spread import spread
    from locust.sim.samples import sample

    robot = only_uncertain(params.preset("medium"), {"geometry.crank_start_deg": 10.0})
    sp = spread(robot, 2, "nose", 6, seed=3)
    ref = sample(robot, 6, cycles=2, seed=3)
    assert {k: v.n for k, v in sp.outcomes.items()} == {k: v.n for k, v in ref.outcomes.items()}
    assert sum(o.share for o in sp.outcomes.values()) == pytest.approx(1.0, abs=1e-12)
    over = sp.outcomes[O.GOES_OVER]
    assert over.distance_m.mean == pytest.approx(ref.outcomes[O.GOES_OVER].distance_m.mean, rel=1e-12)
    html = outcome_table({"medium": sp}, {"medium": "Medium"})
    assert f"{over.n} of {sp.n_valid}" in html and "goes over" in html


def test_the_api_shows_the_outcome_shares_as_the_command_does():
    """``locust.simulate(robot, samples=6, seed=3)`` on the same robot as the command above:
    the same split, shown in its table, and ``sensitivity=False`` leaves it out."""
    import locust

    robot = only_uncertain(params.preset("medium"), {"geometry.crank_start_deg": 10.0})
    r = locust.simulate(robot, cycles=2, samples=6, seed=3, keep_states=False, sensitivity=False)
    assert r.outcome == O.GOES_OVER and r.sensitivity is None
    over = r.spread.outcomes[O.GOES_OVER]
    assert 0 < over.n < r.spread.n_valid
    assert f"goes over           {over.n} of {r.spread.n_valid} (" in repr(r)
    assert r.to_json()["outcomes"][O.GOES_OVER]["n"] == over.n
