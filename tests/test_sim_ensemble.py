"""``--check-convergence`` with ``--samples``: the draws' shares and percentiles at dt/2
against their intervals (locust.sim.ensemble)."""

import math

import numpy as np
import pytest

from locust.params import preset
from locust.sim.ensemble import bootstrap_interval, compare, wilson_interval
from locust.sim.figures import RunFigures
from locust.sim.job import SimOptions, planned_runs, run_simulation
from locust.sim.samples import sample, spread_of


def test_wilson_interval_is_the_published_one():
    """Wilson's score interval, 95 %: 0 of 10 is 0-0.2775, 5 of 10 is 0.2366-0.7634 (Newcombe
    1998, Table I, method 3)."""
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    assert all(math.isnan(v) for v in wilson_interval(0, 0))


def test_the_intervals_cover_the_truth_95_times_in_100():
    """Over 2000 SYNTHETIC sets of 32 draws the share's interval holds the true share 0.3 in
    95.2 % of them, and over 400 sets of 32 normal values the median's bootstrap interval holds
    the true median in 95.5 % (bounds: a few of the binomial sd of a coverage, 0.5 and 1.1 %)."""
    rng = np.random.default_rng(11)
    hits = [lo <= 0.3 <= hi for lo, hi in (wilson_interval(int(k), 32) for k in rng.binomial(32, 0.3, 2000))]
    assert 0.93 <= np.mean(hits) <= 0.98
    medians = [bootstrap_interval(rng.normal(5.0, 2.0, 32), 0.5, draws=500, seed=k) for k in range(400)]
    assert 0.90 <= np.mean([lo <= 5.0 <= hi for lo, hi in medians]) <= 0.99


def _spread(outcomes, distances):
    figures = [RunFigures(outcome=o, nose_rise_m=0.05, distance_m=d,
                          max_nose_height_m=0.1 if o == "goes_over" else 0.05) for o, d in zip(outcomes, distances)]
    return spread_of(preset("medium"), len(figures), 0, figures)


def test_one_draw_that_flips_is_named_and_the_ensemble_is_still_converged():
    """SYNTHETIC draws: 24 of 32 go over at dt; at dt/2 one draw on the threshold rears and
    returns instead. Its share moves 75 -> 72 %, inside its interval (58-87 %): converged, the
    flip named. Eight draws flipping (75 -> 50 %) is outside it: not converged."""
    at = ["goes_over"] * 24 + ["rears_and_returns"] * 8
    dist = list(np.linspace(-0.12, 0.02, 32))
    one = list(at)
    one[3] = "rears_and_returns"
    ec = compare(_spread(at, dist), _spread(one, dist), 5e-4)
    assert [(f.draw, f.outcome, f.half_outcome) for f in ec.flips] == [(3, "goes_over", "rears_and_returns")]
    over = next(s for s in ec.shares if s.outcome == "goes_over")
    assert (over.share, over.half_share) == (0.75, 23 / 32) and over.low == pytest.approx(0.5789, abs=1e-4)
    assert ec.converged
    many = ["rears_and_returns" if i < 8 else o for i, o in enumerate(at)]
    assert not compare(_spread(at, dist), _spread(many, dist), 5e-4).converged


def test_the_draws_at_half_the_step_are_the_same_draws_run_again():
    """Small, one cycle, 8 draws: the dt/2 draws are ``sample`` of the robot with its steps halved,
    number for number, and the bar counts them (1 + 8 draws + 44 ends + 1 + 8)."""
    robot = preset("small")
    options = SimOptions(cycles=1, samples=8, check_convergence=True, keep_states=False)
    counted: list[int] = []
    result = run_simulation(robot, options, progress=counted.append)
    ec = result.ensemble_convergence
    alone = sample(robot.with_values({"solver.timestep_s": 5e-4}), 8, cycles=1)
    assert ec.half.distance_m == alone.distance_m and ec.half.outcome == alone.outcome
    assert ec.half_timestep_s == 5e-4 and ec.n == 8
    assert sum(counted) == planned_runs(robot, options)[0] == 1 + 8 + 44 + 1 + 8
    assert "ensemble_convergence" in result.to_json()
