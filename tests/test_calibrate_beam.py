"""Beam drop: fitted frequency, damping ratio and stiffness against the synthetic truth."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from locust.calibrate import beam as B
from locust.calibrate import synthetic as S
from locust.errors import CalibrationError


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_beam_fit_recovers_truth(seed):
    truth = S.BeamTruth()
    t, x, y = S.beam_tip_track(truth, np.random.default_rng(seed))
    fit = B.fit_beam(t, B.principal_displacement(x, y), truth.mass_kg, length_m=truth.length_m)
    assert fit.natural_frequency_hz.value == pytest.approx(truth.natural_frequency_hz, rel=0.01)
    assert fit.damping_ratio.value == pytest.approx(truth.damping_ratio, rel=0.05)
    assert fit.stiffness_n_per_m.value == pytest.approx(truth.stiffness_n_per_m, rel=0.02)
    # the model's hinge: k*L^2, b*L^2 (seed stiffness 0.056375 N*m/rad)
    assert fit.hinge_stiffness_nm_per_rad.value == pytest.approx(0.056375, rel=0.02)
    assert fit.hinge_damping_nms_per_rad.value == pytest.approx(truth.hinge_damping_nms_per_rad, rel=0.06)
    # the 95% interval is honest: truth inside a 3-sigma band, and the residual is the noise
    assert abs(fit.natural_frequency_hz.value - truth.natural_frequency_hz) < 3 * fit.natural_frequency_hz.std
    assert fit.rms_residual_m == pytest.approx(truth.noise_m, rel=0.2)


def test_heavily_damped_seed_beam():
    """The seed's damping (stiffness/100 s) on this beam is zeta ~ 0.24: still fitted within 5%."""
    truth = dataclasses.replace(S.BeamTruth(), damping_ratio=0.2374)
    t, x, y = S.beam_tip_track(truth, np.random.default_rng(7))
    fit = B.fit_beam(t, B.principal_displacement(x, y), truth.mass_kg, length_m=truth.length_m)
    assert fit.damping_ratio.value == pytest.approx(0.2374, rel=0.05)
    assert fit.natural_frequency_hz.value == pytest.approx(truth.natural_frequency_hz, rel=0.02)


def test_beam_mass_adds_rayleigh_share():
    truth = S.BeamTruth()
    t, x, y = S.beam_tip_track(truth, np.random.default_rng(4))
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
    truth = S.BeamTruth()
    t, x, y = S.beam_tip_track(truth, np.random.default_rng(0))
    with pytest.raises(CalibrationError, match="samples in the fit window"):
        B.fit_beam(t, B.principal_displacement(x, y), 0.01, start_s=0.2, end_s=0.25)
