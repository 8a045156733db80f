"""Ramp: mu = tan(mean critical angle) with a Student-t interval; slip onset from a track."""

from __future__ import annotations

import math

import numpy as np
import pytest

from binomial import coverage_floor
from locust.calibrate import ramp, synthetic
from locust.errors import CalibrationError


def test_mu_is_tan_of_mean_angle():
    truth = synthetic.RampTruth()
    angles = synthetic.ramp_angles(truth, np.random.default_rng(21))
    fit = ramp.fit_ramp(angles)
    mu = fit.estimates["contact.foot_friction"]
    assert mu.value == pytest.approx(math.tan(math.radians(np.mean(angles))), rel=0.01)
    assert mu.value == pytest.approx(truth.mu_static, rel=0.03)


RAMP_DRAWS = 400      # 0.3 s in all


def test_ramp_intervals_cover_over_seeds():
    """SYNTHETIC: 400 sets of ten trials (0.8 deg scatter, read to 0.5 deg): the 95 % interval
    covers the truth at least coverage_floor(400) = 365 times (an 80 % interval: never, 6e-10)."""
    truth = synthetic.RampTruth()
    covered = 0
    for seed in range(RAMP_DRAWS):
        mu = ramp.fit_ramp(synthetic.ramp_angles(truth, np.random.default_rng(seed))).estimates["contact.foot_friction"]
        covered += mu.ci95_low <= truth.mu_static <= mu.ci95_high
    assert covered >= coverage_floor(RAMP_DRAWS), covered


def test_interval_by_hand():
    """Three trials 40, 41, 42 deg: mean 41, s = 1, t(0.975, 2) = 4.303."""
    fit = ramp.fit_ramp(np.array([40.0, 41.0, 42.0]))
    half = 4.302653 * 1 / math.sqrt(3)
    mu = fit.estimates["contact.foot_friction"]
    assert mu.ci95_low == pytest.approx(math.tan(math.radians(41 - half)), rel=1e-6)
    assert mu.ci95_high == pytest.approx(math.tan(math.radians(41 + half)), rel=1e-6)
    assert mu.std == pytest.approx(math.radians(1 / math.sqrt(3)) / math.cos(math.radians(41)) ** 2)


def test_identical_readings_give_the_resolutions_interval_not_a_point():
    """Three trials read 30 deg on a protractor graduated in degrees: each is 30 +- 0.5 deg, a
    spread of 1/sqrt(12) = 0.2887 deg (a uniform rounding error), so the interval is
    tan(30 +- 4.303 * 0.2887 / sqrt(3)) = [0.5608, 0.5942], never [0.5774, 0.5774]."""
    fit = ramp.fit_ramp(np.array([30.0, 30.0, 30.0]))
    half = 4.302653 * (1 / math.sqrt(12)) / math.sqrt(3)
    mu = fit.estimates["contact.foot_friction"]
    assert mu.ci95_low == pytest.approx(math.tan(math.radians(30 - half)), rel=1e-6)
    assert mu.ci95_high == pytest.approx(math.tan(math.radians(30 + half)), rel=1e-6)
    assert mu.ci95_low == pytest.approx(0.5608, abs=1e-4)
    assert fit.std_angle_deg == pytest.approx(0.288675, rel=1e-5) and "reading resolution" in fit.notes[0]
    # a finer reading (0.1 deg) narrows it tenfold; spread above the floor is the trials' own
    fine = ramp.fit_ramp(np.array([30.0, 30.0, 30.0]), resolution_deg=0.1)
    assert fine.std_angle_deg == pytest.approx(0.0288675, rel=1e-5)
    assert ramp.fit_ramp(np.array([40.0, 41.0, 42.0])).notes == []
    with pytest.raises(CalibrationError, match="resolution"):
        ramp.fit_ramp(np.array([30.0, 30.0]), resolution_deg=0.0)


def test_critical_angle_from_tilt_track():
    truth = synthetic.RampTruth()
    for seed in (1, 2):
        t, markers, crit = synthetic.ramp_tilt_track(truth, np.random.default_rng(seed), fps=30.0, rate_deg_per_s=6.0)
        onset = ramp.critical_angle_from_track(t, markers["ramp_a"], markers["ramp_b"], markers["robot"])
        assert onset.critical_angle_deg == pytest.approx(crit, abs=0.6)


def test_bad_ramp_input():
    with pytest.raises(CalibrationError, match="need at least 2"):
        ramp.fit_ramp(np.array([59.0]))
    with pytest.raises(CalibrationError, match="not between 0 and 90"):
        ramp.fit_ramp(np.array([59.0, 95.0]))
