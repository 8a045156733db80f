"""Beam drop: fitted frequency, damping ratio and stiffness against the synthetic truth."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy import signal

from locust.calibrate import beam as B
from locust.calibrate import synthetic
from locust.errors import CalibrationError


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_beam_fit_recovers_truth(seed):
    truth = synthetic.BeamTruth()
    t, x, y = synthetic.beam_tip_track(truth, np.random.default_rng(seed))
    fit = B.fit_beam(t, B.principal_displacement(x, y), truth.mass_kg, length_m=truth.length_m)
    assert fit.natural_frequency_hz.value == pytest.approx(truth.natural_frequency_hz, rel=0.01)
    assert fit.damping_ratio.value == pytest.approx(truth.damping_ratio, rel=0.05)
    assert fit.stiffness_n_per_m.value == pytest.approx(truth.stiffness_n_per_m, rel=0.02)
    # the model's hinge: k*L^2, b*L^2 (seed stiffness 0.056375 N*m/rad)
    k, b = fit.estimates["compliance.hinge_stiffness_nm_per_rad"], fit.estimates["compliance.hinge_damping_nms_per_rad"]
    assert k.value == pytest.approx(0.056375, rel=0.02)
    assert b.value == pytest.approx(truth.hinge_damping_nms_per_rad, rel=0.06)
    # the 95% interval is honest: truth inside a 3-sigma band, and the residual is the noise
    assert abs(fit.natural_frequency_hz.value - truth.natural_frequency_hz) < 3 * fit.natural_frequency_hz.std
    assert fit.rms_residual_m == pytest.approx(truth.noise_m, rel=0.2)


def test_heavily_damped_seed_beam():
    """The seed's damping (stiffness/100 s) on this beam is zeta ~ 0.24: still fitted within 5%."""
    truth = dataclasses.replace(synthetic.BeamTruth(), damping_ratio=0.2374)
    t, x, y = synthetic.beam_tip_track(truth, np.random.default_rng(7))
    fit = B.fit_beam(t, B.principal_displacement(x, y), truth.mass_kg, length_m=truth.length_m)
    assert fit.damping_ratio.value == pytest.approx(0.2374, rel=0.05)
    assert fit.natural_frequency_hz.value == pytest.approx(truth.natural_frequency_hz, rel=0.02)


def test_beam_mass_adds_rayleigh_share():
    truth = synthetic.BeamTruth()
    t, x, y = synthetic.beam_tip_track(truth, np.random.default_rng(4))
    d = B.principal_displacement(x, y)
    plain = B.fit_beam(t, d, 0.010)
    with_beam = B.fit_beam(t, d, 0.010, beam_mass_kg=0.0014)
    assert with_beam.effective_mass_kg == pytest.approx(0.010 + 0.0014 * 33 / 140)
    assert with_beam.stiffness_n_per_m.value / plain.stiffness_n_per_m.value == pytest.approx(
        with_beam.effective_mass_kg / 0.010, rel=1e-9)


def test_flat_beam_signal_is_refused():
    rng = np.random.default_rng(0)
    t = np.arange(300) / 240
    with pytest.raises(CalibrationError, match="flat signal"):
        B.fit_beam(t, 0.1 + rng.normal(0, 3e-4, len(t)), 0.01)
    with pytest.raises(CalibrationError, match="flat signal"):
        B.fit_beam(t, np.full(len(t), 0.1), 0.01)


def test_too_few_beam_samples_are_refused():
    truth = synthetic.BeamTruth()
    t, x, y = synthetic.beam_tip_track(truth, np.random.default_rng(0))
    with pytest.raises(CalibrationError, match="samples in the fit window"):
        B.fit_beam(t, B.principal_displacement(x, y), 0.01, start_s=0.2, end_s=0.25)


# Interval coverage over many ring-downs: damping ratios from a lightly damped strip to a
# heavily damped one with a single visible cycle, the frame rates of phones (30-240 frames/s)
# and tracking noise of half a pixel to a pixel (0.3 and 0.6 mm), all SYNTHETIC. At 30
# frames/s the tip mass is 40 g (3.8 Hz, 8 frames a cycle; 10 g rings at 7.6 Hz, 4 frames).
COVERAGE_SEEDS = 50
COVERAGE_FPS = (30.0, 60.0, 120.0, 240.0)
COVERAGE_MASS_KG = {30.0: 0.04}
COVERAGE_NOISE_M = (0.0003, 0.0006)


def _coverage_runs(zeta: float) -> list[tuple[synthetic.BeamTruth, B.BeamFit]]:
    """(truth, fit) of ``COVERAGE_SEEDS`` ring-downs at damping ratio ``zeta``."""
    runs = []
    for seed in range(COVERAGE_SEEDS):
        fps = COVERAGE_FPS[seed % len(COVERAGE_FPS)]
        noise = COVERAGE_NOISE_M[seed // len(COVERAGE_FPS) % len(COVERAGE_NOISE_M)]
        truth = dataclasses.replace(synthetic.BeamTruth(), damping_ratio=zeta, fps=fps, noise_m=noise,
                                    mass_kg=COVERAGE_MASS_KG.get(fps, synthetic.BeamTruth.mass_kg))
        t, x, y = synthetic.beam_tip_track(truth, np.random.default_rng(9000 + seed))
        runs.append((truth, B.fit_beam(t, B.principal_displacement(x, y), truth.mass_kg)))
    return runs


@pytest.mark.parametrize("zeta", [0.02, 0.03, 0.10, 0.24, 0.40])
def test_beam_intervals_cover_truth_over_seeds(zeta):
    runs = _coverage_runs(zeta)
    covered = {"natural_frequency_hz": 0, "damping_ratio": 0}
    for truth, fit in runs:
        fn_true = truth.natural_frequency_hz
        for name, true in (("natural_frequency_hz", fn_true), ("damping_ratio", zeta)):
            est = getattr(fit, name)
            inside = est.ci95_low <= true <= est.ci95_high
            covered[name] += inside
            # never a confident wrong answer: a miss is within 4 of its own standard errors
            # (the spectral start's fits were 60-250 % off, tens of standard errors)
            assert inside or abs(est.value - true) < 4 * est.std, (name, truth, est)
        est = fit.natural_frequency_hz
        # a 3 % error is never excluded where the frequency is pinned to 1 % (a 3-sigma miss)
        if est.std < 0.01 * fn_true and abs(est.value / fn_true - 1) > 0.03:
            assert est.ci95_low <= fn_true <= est.ci95_high, (truth, est)
    # 95 % intervals: fn's held the truth in 93.5 %, zeta's in 92 % of 200 such ring-downs at
    # zeta 0.10 (the spectral start's: 24 % at 0.24); 50 draws of a 92 % coverage fall to 42
    # about one time in 40, hence zeta's looser floor
    assert covered["natural_frequency_hz"] >= 0.88 * len(runs), covered
    assert covered["damping_ratio"] >= 0.84 * len(runs), covered


def test_beam_intervals_hold_with_correlated_tracking_noise():
    """A tracker whose error wanders from frame to frame (AR(1), lag-1 correlation 0.8, 0.3 mm):
    the residuals' autocorrelation widens the intervals (s^2 (J^T J)^-1 alone covered the
    truth in 32 of these 50 ring-downs); SYNTHETIC."""
    truth = dataclasses.replace(synthetic.BeamTruth(), damping_ratio=0.1, noise_m=0.0)
    rho, covered, fitted_rho = 0.8, 0, []
    for seed in range(50):
        rng = np.random.default_rng(300 + seed)
        t, x, y = synthetic.beam_tip_track(truth, rng)
        noise = signal.lfilter([1.0], [1.0, -rho], rng.normal(0, 3e-4 * np.sqrt(1 - rho**2), len(t) + 200))[200:]
        fit = B.fit_beam(t, B.principal_displacement(x, y) + noise, truth.mass_kg)
        est = fit.natural_frequency_hz
        covered += est.ci95_low <= truth.natural_frequency_hz <= est.ci95_high
        fitted_rho.append(fit.residual_autocorrelation)
    assert np.median(fitted_rho) == pytest.approx(rho, abs=0.05)
    assert covered >= 44


def test_creeping_tip_is_refused():
    """A mass lowered by hand: the tip creeps 5.3 mm to its new rest over ~3 s, no ringing
    (the shape of the real deflection test in ../shared/data/hinge); SYNTHETIC. Refused,
    not fitted as a 0.5 Hz 'oscillation' at the damping bound."""
    rng = np.random.default_rng(11)
    t = np.arange(200) / 60.0
    y = 0.0053 * (1 - np.exp(-np.clip(t - 0.5, 0, None) / 0.8)) + rng.normal(0, 1e-4, len(t))
    with pytest.raises(CalibrationError, match="no ring-down") as err:
        B.fit_beam(t, y, 0.095, length_m=0.048)
    assert "add --static to read its static deflection" in err.value.hint


# Ring-downs with a release transient at the drop (a finger leaving the mass, a higher mode
# of the strip): extra tip displacement of 30-100 % of the swing, of either sign, gone within
# 3-10 ms, a decaying offset or a ringing at the strip's second-mode ratio (6.27 x fn); the
# drop lands anywhere between two frames; 30-240 frames/s; all SYNTHETIC.
def _transient_truth(zeta: float, seed: int) -> tuple[synthetic.BeamTruth, np.random.Generator]:
    rng = np.random.default_rng(5000 + seed)
    fps = COVERAGE_FPS[seed % len(COVERAGE_FPS)]
    base = dataclasses.replace(synthetic.BeamTruth(), damping_ratio=zeta, fps=fps,
                               mass_kg=COVERAGE_MASS_KG.get(fps, synthetic.BeamTruth.mass_kg),
                               noise_m=COVERAGE_NOISE_M[seed // len(COVERAGE_FPS) % len(COVERAGE_NOISE_M)])
    wn = 2 * np.pi * base.natural_frequency_hz
    swing = np.hypot(base.mass_kg * 9.81 / base.stiffness_n_per_m, np.sqrt(2 * 9.81 * base.drop_height_m) / wn)
    return dataclasses.replace(base, drop_at_s=0.1 + rng.uniform(0, 1) / fps,
                               transient_m=rng.choice([-1, 1]) * rng.uniform(0.3, 1.0) * swing,
                               transient_s=rng.uniform(0.003, 0.010),
                               transient_hz=rng.choice([0.0, 6.27 * base.natural_frequency_hz])), rng


@pytest.mark.parametrize("sign", [1, -1])
def test_release_transient_is_skipped(sign):
    """A transient of 8 mm dying out in 6 ms at a drop on a frame of a 240 frames/s ring-down
    (zeta 0.24): the window starts after it and the fit holds the truth; a window pinned at
    the drop (--start-s) keeps it, and its interval widens for it (zeta 0.28 [0.20, 0.36] for
    a push along the motion); SYNTHETIC."""
    truth = dataclasses.replace(synthetic.BeamTruth(), damping_ratio=0.24, transient_m=sign * 0.008, transient_s=0.006)
    for seed in range(3):
        t, x, y = synthetic.beam_tip_track(truth, np.random.default_rng(seed))
        d = B.principal_displacement(x, y)
        fit = B.fit_beam(t, d, truth.mass_kg)
        assert fit.fit_start_s > truth.drop_at_s + 0.008        # two frames after the drop at least
        est = fit.damping_ratio
        assert est.value == pytest.approx(0.24, rel=0.04) and est.ci95_low <= 0.24 <= est.ci95_high, est
        pinned = B.fit_beam(t, d, truth.mass_kg, start_s=truth.drop_at_s)
        assert pinned.fit_start_s == truth.drop_at_s
        assert abs(pinned.damping_ratio.value - 0.24) > 0.01        # the transient biases it ...
        assert pinned.damping_ratio.ci95_low <= 0.24 <= pinned.damping_ratio.ci95_high     # ... and widens it


@pytest.mark.slow
@pytest.mark.parametrize("zeta", [0.03, 0.10, 0.24])
def test_release_transient_intervals_cover_over_seeds(zeta):
    """95 % intervals over 90 transient ring-downs at each damping ratio (measured: zeta's
    held the truth in 86, 86 and 83 of 90 at 0.03, 0.10, 0.24; before the transient was
    skipped and the window's start assessed, 86, 84 and 77; the frequency's: 89, 87, 89 and
    before 85, 75, 73); SYNTHETIC. test_release_transient_is_skipped is its fast companion."""
    covered = {"natural_frequency_hz": 0, "damping_ratio": 0}
    for seed in range(90):
        truth, rng = _transient_truth(zeta, seed)
        t, x, y = synthetic.beam_tip_track(truth, rng)
        fit = B.fit_beam(t, B.principal_displacement(x, y), truth.mass_kg)
        for name, true in (("natural_frequency_hz", truth.natural_frequency_hz), ("damping_ratio", zeta)):
            est = getattr(fit, name)
            covered[name] += est.ci95_low <= true <= est.ci95_high
    assert min(covered.values()) >= 0.88 * 90, covered
