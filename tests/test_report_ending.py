"""How a filmed run ended, read off its marker (locust.report.ending): over onto its back when a
cycle ends with the marker at rest more than 30 mm above where it stood (as-built Small lies
with it 87.5 mm up; a robot back on its feet rests within about a millimetre), a rear and return
when every hop lifts it more than 30 mm; and the words the summary gives each case.

The hops here are SYNTHETIC MeasuredHop rows (numbers chosen about the thresholds); the rule on
real simulated films is tests/test_report_headline.py's.
"""

from __future__ import annotations

import math

from locust.report.ending import Ending, marker_ending, trials_words, words
from locust.trials.measure import MeasuredHop


def hops(*rows):
    return [MeasuredHop(k, d, a, r) for k, (d, a, r) in enumerate(rows, start=1)]


def test_a_marker_resting_high_has_gone_over_and_the_hops_after_are_on_its_back():
    e = marker_ending(hops((0.007, 0.075, 0.0008), (-0.121, 0.096, 0.0875), (0.0001, 0.0876, 0.0874)))
    assert (e.outcome, e.over_hop) == ("goes_over", 2)
    assert [e.state(k) for k in (1, 2, 3)] == ["on its feet", "goes over", "on its back"]
    assert [e.came_down(k) for k in (1, 2, 3)] == [True, False, False]
    assert e.travel_m == math.fsum((0.007, -0.121, 0.0001)) and e.rest_height_m == 0.0874
    assert words(e) == "goes over at hop 2, its marker at rest 87.4 mm up and 113.9 mm behind where it stood"


def test_the_thresholds_are_30_mm_of_rest_and_of_rise():
    assert marker_ending(hops((0.005, 0.08, 0.029))).outcome == "rears_and_returns"
    assert marker_ending(hops((0.005, 0.08, 0.031))).over_hop == 1
    assert marker_ending(hops((0.005, 0.08, 0.001), (0.004, 0.029, 0.0))).outcome == "stays_low"
    uncovered = marker_ending(hops((math.nan, math.nan, math.nan)))
    assert uncovered.outcome == "" and words(uncovered) == "not seen (the track covers no hop)"


def test_the_simulations_words_say_where_the_robot_rests():
    e = Ending("goes_over", 1, -0.1281, 0.0875, distance_m=-0.07246)
    assert words(e) == "goes over at hop 1, rests on its back 72.5 mm behind its start"
    assert words(Ending("rears_and_returns", None, 0.02, 0.0, 0.021)) == "rears and returns"


def test_trials_that_agree_are_one_sentence_and_others_are_counted():
    over = [Ending("goes_over", 1, -0.128, 0.0858), Ending("goes_over", 1, -0.126, 0.0862)]
    assert trials_words(over) == ("goes over at hop 1, its marker at rest 86.0 mm up and 127.0 mm behind where it "
                                  "stood (all 2 trials)")
    mixed = [over[0], Ending("rears_and_returns", None, 0.02, 0.0)]
    assert trials_words(mixed) == "goes over at hop 1 in 1 of 2 trials; rears and returns in 1 of 2 trials"
    assert trials_words([]) == "—"
