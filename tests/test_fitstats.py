"""Intervals of a least-squares fit (locust.calibrate.fitstats) on SYNTHETIC linear fits of
known truth: a 95% interval must cover the truth in about 95% of repeated experiments."""

from __future__ import annotations

import numpy as np
import pytest

from locust.calibrate import fitstats

CLUSTERS, PER_CLUSTER, TRIALS = 8, 40, 2000


def _coverage(method: str, seed: int = 1) -> float:
    """Line y = a + b t fitted to clusters of samples whose noise is shared within a
    cluster (a random offset and slope per cluster, plus white noise): the fraction of
    trials whose 95% interval of the slope covers the true slope (SYNTHETIC)."""
    rng = np.random.default_rng(seed)
    t = np.tile(np.linspace(-1.0, 1.0, PER_CLUSTER), CLUSTERS)
    labels = np.repeat(np.arange(CLUSTERS), PER_CLUSTER)
    jac = -np.column_stack([np.ones_like(t), t])       # residual = y - (a + b t)
    truth = np.array([0.3, 2.0])
    hits = 0
    for _ in range(TRIALS):
        shared = rng.normal(0, 0.1, (CLUSTERS, 2))
        y = truth[0] + truth[1] * t + shared[labels, 0] + shared[labels, 1] * t + rng.normal(0, 0.02, t.size)
        fit = np.linalg.lstsq(-jac, y, rcond=None)[0]
        r = y + jac @ fit
        cov = fitstats.cluster_covariance(jac, r, labels) if method == "cluster" else fitstats.covariance(jac, r)
        est = cov.parameter(fit, 1)
        hits += est.ci95_low <= truth[1] <= est.ci95_high
    return hits / TRIALS


def test_cluster_robust_intervals_cover_at_their_level():
    # binomial sd of a 95% coverage over 2000 trials is 0.5 %: 0.93..0.975 is 4 sd wide
    assert 0.93 <= _coverage("cluster") <= 0.975


def test_intervals_that_assume_independent_residuals_do_not():
    # the same fits with s^2 (J^T J)^-1: the shared errors make them far too narrow
    assert _coverage("independent") < 0.5


def test_too_few_clusters_determine_nothing():
    jac = np.column_stack([np.ones(6), np.arange(6.0)])
    cov = fitstats.cluster_covariance(jac, np.arange(6.0) % 2 - 0.5, np.array([0, 0, 0, 1, 1, 1]))
    assert np.all(np.isinf(cov.matrix))


def test_a_numerical_shift_adds_in_quadrature_with_welch_satterthwaite_dof():
    cov = fitstats.Covariance(np.diag([0.03**2, 1.0]), dof=5, shift=np.array([0.04, 0.0]))
    est = cov.parameter(np.array([2.0, 1.0]), 0)
    assert est.std == pytest.approx(0.05) and est.std_numerical == pytest.approx(0.04)
    # nu_eff = 5 (0.05 / 0.03)^4 = 38.6 -> t = 2.0225
    assert est.ci95_high - 2.0 == pytest.approx(0.05 * 2.0225, rel=1e-3)
    assert "std_numerical" in est.as_dict()
    # the shift as a linear change of the data: the Gauss-Newton step of a line fit
    jac = -np.column_stack([np.ones(5), np.arange(5.0)])
    assert fitstats.linear_shift(jac, np.full(5, 0.1)) == pytest.approx([0.1, 0.0])


def test_values_held_fixed_carry_their_uncertainty_into_the_fit():
    """A line y = a x + b z fitted for a with b held at its calibrated value (sd 0.2): the
    fitted a moves by -(x.z / x.x) per unit of b, so its std_fixed is |x.z / x.x| 0.2, exactly
    what refitting a at b +- 0.2 gives; it adds in quadrature with the fit's own."""
    rng = np.random.default_rng(5)
    x, z = rng.normal(size=40), rng.normal(size=40)
    a_true, b_held, sd_b = 1.5, 0.7, 0.2
    y = a_true * x + b_held * z + rng.normal(scale=0.05, size=40)

    def fit_a(b):
        return float(x @ (y - b * z) / (x @ x))

    a = fit_a(b_held)
    r = y - a * x - b_held * z
    jac, jac_b = -x[:, None], -z[:, None]             # d residual / d a, d residual / d b
    fixed = fitstats.fixed_covariance(jac, jac_b, np.array([sd_b]))
    moved = (fit_a(b_held + sd_b) - fit_a(b_held - sd_b)) / 2
    assert np.sqrt(fixed[0, 0]) == pytest.approx(abs(moved), rel=1e-12)
    assert np.sqrt(fixed[0, 0]) == pytest.approx(abs(x @ z / (x @ x)) * sd_b, rel=1e-12)
    clusters = np.arange(40) // 4
    plain = fitstats.cluster_covariance(jac, r, clusters).parameter(np.array([a]), 0)
    est = fitstats.cluster_covariance(jac, r, clusters, fixed=fixed).parameter(np.array([a]), 0)
    assert est.std_fixed == pytest.approx(np.sqrt(fixed[0, 0]), rel=1e-12)
    assert est.std == pytest.approx(np.hypot(plain.std, est.std_fixed), rel=1e-12)
    assert est.std_numerical is None and "std_fixed" in est.as_dict()
