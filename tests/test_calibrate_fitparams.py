"""The fit-parameter type (calibrate/fitparams.py): vector packing, bounds, log scaling,
held values and the delta-method covariance, against values computed by hand; and a
SYNTHETIC exponential decay fitted in log space over many seeds, its intervals covering."""

import math

import numpy as np
import pytest
from scipy import optimize

from locust.calibrate.fitparams import FitParameter, FitParameters
from locust.calibrate.fitstats import covariance
from locust.errors import CalibrationError


def example() -> FitParameters:
    return FitParameters([
        FitParameter("speed_rad_per_s", "rad/s", 10.0, 0.5, 200.0, scaling="log"),
        FitParameter("stall_torque_nm", "N*m", 0.15, held=True, std=0.02, source="datasheet"),
        FitParameter("delay_s", "s", 0.01, -0.25, 0.25, scale=0.01),
        FitParameter("clock_ratio", "1", 1.0, 0.95, 1.05, scale=1e-3, reference=1.0),
        FitParameter("gain", "units per rad/s", -8.0, -1e9, -1e-9, scaling="log", reference=-1.0),
        FitParameter("kp_nm_per_rad", "N*m/rad", 0.3, 0.03, 30.0, scaling="log", reference=0.3),
    ])


def test_vector_holds_the_free_values_in_order():
    fp = example()
    assert fp.free == ("speed_rad_per_s", "delay_s", "clock_ratio", "gain", "kp_nm_per_rad")
    assert fp.held == ("stall_torque_nm",)
    assert fp.size == 5 and len(fp) == 6 and fp.index("gain") == 3
    x = fp.as_vector()
    assert x == pytest.approx([math.log(10.0), 1.0, 0.0, math.log(8.0), 0.0], abs=1e-15)


def test_values_round_trip_through_the_vector():
    fp = example()
    values = {"speed_rad_per_s": 7.3, "delay_s": -0.031, "clock_ratio": 1.0042, "gain": -0.02, "kp_nm_per_rad": 2.5}
    back = fp.from_vector(fp.as_vector(values))
    assert list(back) == [p.name for p in fp]
    assert back["stall_torque_nm"] == 0.15
    for name, v in values.items():
        assert back[name] == pytest.approx(v, rel=1e-14), name
    x = np.array([0.4, -2.0, 3.0, 1.5, -0.7])
    # (the clock's offset of 1 costs about 1e-13 of its 1e-3 scale in the round trip)
    assert fp.as_vector(fp.from_vector(x)) == pytest.approx(x, rel=1e-14, abs=1e-12)
    assert fp.free_values(x) == pytest.approx([math.exp(0.4), -0.02, 1.003, -math.exp(1.5), 0.3 * math.exp(-0.7)],
                                              rel=1e-14)


def test_log_scaling_is_exp_of_the_variable():
    p = FitParameter("k", "N/m", 2.0, 1e-3, 1e3, scaling="log", reference=2.0)
    assert p.to_value(math.log(5.0)) == pytest.approx(10.0, rel=1e-15)
    assert p.to_x(0.2) == pytest.approx(math.log(0.1), rel=1e-15)
    assert p.derivative(math.log(5.0)) == pytest.approx(10.0, rel=1e-15)   # d(2 e^x)/dx = value
    h = 1e-6
    assert (p.to_value(0.3 + h) - p.to_value(0.3 - h)) / (2 * h) == pytest.approx(p.derivative(0.3), rel=1e-8)


def test_bounds_in_the_solvers_variable():
    lo, hi = example().bounds()
    assert lo == pytest.approx([math.log(0.5), -25.0, -50.0, math.log(1e-9), math.log(0.1)], rel=1e-12)
    assert hi == pytest.approx([math.log(200.0), 25.0, 50.0, math.log(1e9), math.log(100.0)], rel=1e-12)
    free = FitParameters([FitParameter("c", "m", 0.0, scale=1e-3), FitParameter("k", "N/m", 1.0, 0.0, scaling="log")])
    assert free.bounds()[0].tolist() == [-math.inf, -math.inf] and free.bounds()[1].tolist() == [math.inf, math.inf]
    x = np.array([math.log(0.5) + 5e-4, 0.0, 49.9999, 0.0, 0.0])
    assert example().near_bound(x) == (True, False, True, False, False)


def test_covariance_goes_back_to_the_values_by_the_delta_method():
    """Two values: a = 2 e^x0 (log, reference 2) and b = 0.5 x1 (linear, scale 0.5), at
    x = (0.3, 4): d = (2 e^0.3, 0.5). By hand: var a = 4 e^0.6 * 0.04 = 0.291539...,
    cov ab = 2 e^0.3 * 0.5 * 0.01 = 0.0134986, var b = 0.25 * 0.09 = 0.0225."""
    fp = FitParameters([FitParameter("a", "N", 2.0, 1e-3, 1e3, scaling="log", reference=2.0),
                        FitParameter("b", "m", 0.0, scale=0.5)])
    cov_x = np.array([[0.04, 0.01], [0.01, 0.09]])
    x = np.array([0.3, 4.0])
    cov = fp.to_values_covariance(cov_x, x)
    assert cov[0, 0] == pytest.approx(0.29153901, rel=1e-7)
    assert cov[0, 1] == cov[1, 0] == pytest.approx(0.013498588, rel=1e-7)
    assert cov[1, 1] == pytest.approx(0.0225, rel=1e-14)
    # the same from a numerical Jacobian of the values in x
    h = 1e-6
    jac = np.column_stack([(fp.free_values(x + h * e) - fp.free_values(x - h * e)) / (2 * h) for e in np.eye(2)])
    assert cov == pytest.approx(jac @ cov_x @ jac.T, rel=1e-8)
    # and the gradient handed to fitstats gives the same standard deviation
    grad = fp.gradient(x, "a")
    assert math.sqrt(grad @ cov_x @ grad) == pytest.approx(math.sqrt(cov[0, 0]), rel=1e-14)
    assert fp.gradient(x, "b", factor=100.0) == pytest.approx([0.0, 50.0])


def test_held_values_keep_their_uncertainty_and_source():
    fp = example()
    assert fp.held_std() == {"stall_torque_nm": 0.02}
    assert fp["stall_torque_nm"].source == "datasheet"
    assert fp.units()["kp_nm_per_rad"] == "N*m/rad"
    more = fp.extended(FitParameter("tau_c_nm", "N*m", 1e-4, 0.0, scale=1e-4))
    assert more.free[-1] == "tau_c_nm" and more.size == 6 and fp.size == 5


@pytest.mark.parametrize("kwargs, match", [
    (dict(scaling="cubic"), "scaling"),
    (dict(scale=0.0), "scale must be positive"),
    (dict(lower=2.0, upper=1.0), "lower bound"),
    (dict(scaling="log", lower=-1.0, upper=1.0), "sign of its reference"),
    (dict(scaling="log", reference=0.0), "nonzero"),
    (dict(held=True, std=-1.0), "std must be 0 or more"),
])
def test_bad_parameters_are_refused(kwargs, match):
    with pytest.raises(CalibrationError, match=match):
        FitParameter("v", "m", 1.0, **kwargs)


def test_a_name_twice_and_a_short_vector_are_refused():
    with pytest.raises(CalibrationError, match="named twice: a"):
        FitParameters([FitParameter("a", "m", 1.0), FitParameter("a", "m", 2.0)])
    with pytest.raises(CalibrationError, match="a vector of 2 for 5"):
        example().from_vector(np.zeros(2))


def test_log_space_intervals_cover_over_seeds():
    """SYNTHETIC: y = A exp(-t/tau) + noise (A = 2 m, tau = 0.4 s, sigma = 0.05 m, 40 samples),
    fitted with A and tau log-scaled; the Jacobian taken back to the values
    (to_values_jacobian) gives fitstats' interval of tau: over 400 seeds it covers the truth
    in 92-98 % of them (95 % nominal; 400 draws: sd 1.1 %)."""
    fp = FitParameters([FitParameter("amplitude_m", "m", 1.0, 1e-3, 1e3, scaling="log"),
                        FitParameter("tau_s", "s", 1.0, 1e-3, 1e3, scaling="log")])
    t = np.linspace(0.0, 2.0, 40)
    truth = {"amplitude_m": 2.0, "tau_s": 0.4}
    covered = 0
    for seed in range(400):
        y = truth["amplitude_m"] * np.exp(-t / truth["tau_s"]) + np.random.default_rng(seed).normal(0, 0.05, t.size)

        def residual(x, y=y):
            v = fp.from_vector(x)
            return v["amplitude_m"] * np.exp(-t / v["tau_s"]) - y

        res = optimize.least_squares(residual, fp.as_vector(), bounds=fp.bounds(), xtol=1e-12, ftol=1e-12)
        cov = covariance(fp.to_values_jacobian(res.jac, res.x), res.fun)
        est = cov.parameter(fp.free_values(res.x), fp.index("tau_s"))
        covered += est.ci95_low <= truth["tau_s"] <= est.ci95_high
    assert 0.92 <= covered / 400 <= 0.98, covered
