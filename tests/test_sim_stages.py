"""``locust sim --samples`` and ``--sensitivity``: every run on the progress bar, and the
sensitivity's ends sharing the draws' batches (locust.sim.job)."""

import pytest

from locust.params import preset
from locust.sim.job import SimOptions, planned_runs, simulated
from locust.sim.samples import sample
from locust.sim.sensitivity import outcome_sensitivity


@pytest.mark.parametrize("sensitivity", [True, None])
def test_the_draws_and_the_ends_are_counted_run_for_run_and_give_what_each_gives_alone(sensitivity):
    """Medium, one cycle, 8 draws: its 22 uncertain values' 44 ends share the draws' batches
    (asked for) or follow them (the draws split: 7 go over, 1 rears and returns). Either way
    the bar counts the run, the 8 draws and the 44 ends, 53 in all, and the spread and the
    sensitivity are those of ``sample`` and ``outcome_sensitivity`` run alone, number for number."""
    robot = preset("medium")
    options = SimOptions(cycles=1, samples=8, sensitivity=sensitivity, keep_states=False)
    counted: list[int] = []
    result = simulated(robot, options, progress=counted.append)
    runs, label = planned_runs(robot, options)
    assert runs == 1 + 8 + 44 and sum(counted) == runs and counted[:2] == [0, 1]
    assert ("if the draws split" in label) == (sensitivity is None)
    alone = sample(robot, 8, cycles=1)
    assert result.spread.distance_m == alone.distance_m
    assert result.spread.max_nose_height_m == alone.max_nose_height_m
    assert result.spread.outcome == alone.outcome
    assert {k for k, v in result.spread.outcomes.items() if v.share} == {"goes_over", "rears_and_returns"}
    assert result.sensitivity == outcome_sensitivity(robot, cycles=1)
    assert [e.key for e in result.sensitivity.deciding] == ["geometry.crank_start_deg", "geometry.ground_angle_deg"]


def test_draws_that_agree_count_the_ends_done_without_running_them():
    """The seed's 8 draws all stay low: no sensitivity runs, and its 8 ends are counted done,
    so the bar ends full (17 of 17)."""
    robot = preset("seed")
    options = SimOptions(cycles=1, samples=8, keep_states=False)
    counted: list[int] = []
    result = simulated(robot, options, progress=counted.append)
    assert result.sensitivity is None
    assert result.spread.outcomes["stays_low"].share == 1.0
    assert planned_runs(robot, options)[0] == sum(counted) == 1 + 8 + 8
    assert counted[-1] == 8            # the ends, counted in one step after the draws
