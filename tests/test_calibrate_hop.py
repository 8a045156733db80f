"""The hop fit and the prediction's spread, on SYNTHETIC traces of known truth.

The "filmed" runs here are the simulation itself at known values (friction, hinge
stiffness, servo speed unlike the presets), sampled like a 30 frames/s video on a camera
clock of its own, with 0.1 mm of seeded Gaussian noise: the fit must recover the values it
was made with. The system test on the virtual robot's own videos is in
test_calibrate_hop_virtual.py (slow).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from locust.calibrate import hop as H
from locust.errors import CalibrationError
from locust.params import Provenance, leg_set, preset
from locust.sim import samples as S

CAMERA_HZ = 30.0
NOISE_M = 1e-4
TRUTH = {"compliance.hinge_stiffness_nm_per_rad": 0.045, "servo.noload_speed_rad_per_s": 9.0}


def seed_leg(config: str):
    """A leg set of the seed robot (the notebook's plate mass and hinge stiffness): the fit's
    machinery is tested on the model the figures here were measured on, not on the as-built
    presets, whose hinges are 280 times softer than this truth."""
    return leg_set(preset("seed"), config)


def synthetic_run(config: str, truth: dict, cycles: int = 3, seed: int = 0) -> H.HopRun:
    """A run of ``config`` at ``truth``, "filmed" at 30 frames/s from 0.4 s before the first
    push, camera clock 1.234 s ahead, positions with NOISE_M of noise (SYNTHETIC). The values
    not in ``truth`` are the preset's exactly, so here they carry no uncertainty."""
    robot = seed_leg(config)
    for key in S.uncertain_values(robot):
        if key not in truth:
            robot = robot.with_provenance(key, Provenance(source="synthetic: exact"))
    period = robot.schedule.push_s + robot.schedule.wait_s
    phase_s = np.array([k * period + d for k in range(cycles) for d in (0.0, robot.schedule.push_s)])
    pushing = np.array([True, False] * cycles)
    clock_s = 1.234
    t_cam = np.arange(clock_s - 0.4, clock_s + cycles * period, 1 / CAMERA_HZ)
    blank = H.MarkerTrack(t_cam, np.zeros_like(t_cam), np.zeros_like(t_cam))
    template = H.HopRun(source=H.Path(f"synthetic-{config}"), config=config, robot=robot, phase_s=phase_s,
                        pushing=pushing, onset_s=clock_s, tracks={"nose": blank, "foot": blank})
    sim = H.simulate_markers(template, [robot.with_values(truth)])[0]
    rng = np.random.default_rng(seed)
    tracks = {}
    for m in ("nose", "foot"):
        t, x, y = sim[m]
        tracks[m] = H.MarkerTrack(t_cam, np.interp(t_cam - clock_s, t, x) + rng.normal(0, NOISE_M, t_cam.size),
                                  np.interp(t_cam - clock_s, t, y) + rng.normal(0, NOISE_M, t_cam.size))
    nose = tracks["nose"]
    onset, x0, y0 = H.onset_time(nose.t_s, nose.x_m, nose.y_m)
    tracks = {m: H.MarkerTrack(tr.t_s, tr.x_m - np.median(tr.x_m[tr.t_s < onset]),
                               tr.y_m - np.median(tr.y_m[tr.t_s < onset])) for m, tr in tracks.items()}
    return H.HopRun(source=template.source, config=config, robot=robot, phase_s=phase_s, pushing=pushing,
                    onset_s=onset, tracks=tracks)


@pytest.fixture(scope="module")
def small_fit():
    run = synthetic_run("small", TRUTH)      # three hops: a cluster-robust interval on two values needs three
    return run, H.fit_hops([run], list(TRUTH), max_iter=20, grid_stages=2)


def test_fit_recovers_the_values_the_traces_were_made_with(small_fit):
    _, fit = small_fit
    for key, truth in TRUTH.items():
        est = fit.estimates[key]
        assert est.value == pytest.approx(truth, rel=0.02), key
        assert fit.identifiable[key]
    # started from the seed's values, 25 % and 13 % away, from a two-stage grid
    assert fit.start["compliance.hinge_stiffness_nm_per_rad"] == pytest.approx(0.056375)


def test_fit_intervals_cover_the_truth_and_say_what_they_include(small_fit):
    _, fit = small_fit
    for key, truth in TRUTH.items():
        est = fit.estimates[key]
        assert est.ci95_low <= truth <= est.ci95_high, (key, est)
        # honest, yet narrow enough to feed a prediction's spread: within +-20 % (the fit's
        # 0.13 mm of residual over three hops, t(2), gives about +-8 %)
        assert (est.ci95_high - est.ci95_low) / 2 < 0.20 * truth, (key, est)
        assert est.std_numerical is not None and 0 <= est.std_numerical <= est.std
        assert est.std_fixed is None          # nothing held fixed carries an uncertainty here
    assert fit.interval.startswith("cluster-robust over 3 hops (CR1), t(2)")
    assert fit.summary()["interval"] == fit.interval


def test_fit_residual_is_the_noise_it_was_given(small_fit):
    _, fit = small_fit
    # the traces carry 0.1 mm of noise per coordinate: the fit leaves that, no more
    assert fit.rms_m == pytest.approx(NOISE_M, rel=0.3)
    assert fit.runs[0].rms_by_marker_m.keys() == {"nose", "foot"}
    summary = fit.summary()
    entry = summary["parameters"]["servo.noload_speed_rad_per_s"]
    assert set(entry) >= {"value", "std", "ci95", "identifiable"}
    assert entry["ci95"][0] < entry["value"] < entry["ci95"][1]
    assert summary["runs"][0]["rms_residual_m"] == pytest.approx(fit.runs[0].rms_m)


def test_measured_phase_times_drive_the_command():
    run = synthetic_run("small", TRUTH, cycles=1)
    late = H.HopRun(**{**run.__dict__, "phase_s": np.array([0.0, 0.4])})   # a push measured 100 ms long
    dt = run.robot.solver.timestep_s
    plan, plan_late = H.measured_plan(run, run.robot), H.measured_plan(late, run.robot)
    push = math.radians(run.robot.schedule.push_deg)
    assert np.sum(plan.ctrl_rad == push) * dt == pytest.approx(0.3, abs=dt)
    assert np.sum(plan_late.ctrl_rad == push) * dt == pytest.approx(0.4, abs=dt)
    assert np.all(plan.ctrl_rad[:plan.settle_steps] == 0)


def test_keys_that_cannot_be_fitted_are_refused():
    run = synthetic_run("small", TRUTH, cycles=1)
    with pytest.raises(CalibrationError, match="real-valued"):
        H.check_keys(["schedule.cycles"], [run])
    with pytest.raises(CalibrationError, match="unknown robot parameter"):
        H.check_keys(["contact.foot_frict"], [run])
    large = H.HopRun(**{**run.__dict__, "robot": seed_leg("large")})
    with pytest.raises(CalibrationError, match="leg sets differ"):
        H.check_keys(["geometry.leg_m"], [run, large])


def test_samples_spread_comes_from_the_uncertainties():
    robot = seed_leg("small")
    spread = S.sample(robot, 8, cycles=2)
    # the seed's servo values carry the SG90 fit's uncertainties
    assert "servo.noload_speed_rad_per_s" in spread.uncertain
    assert spread.n_valid == 8 and spread.distance_m_sd > 0 and spread.max_nose_height_m_sd > 0
    # the same robot with every uncertainty removed: all draws are the nominal run
    bare = robot
    for key in spread.uncertain:
        bare = bare.with_provenance(key, Provenance(source="test"))
    none = S.sample(bare, 3, cycles=2)
    # (the draws share each thread's MjData, so the constraint solver's warm start differs: the
    # same run to within a few 1e-18 m)
    assert none.uncertain == {} and none.distance_m_sd < 1e-12


def test_draws_follow_the_written_uncertainties():
    """Each uncertain value is drawn about its own with the written standard deviation (one
    sigma, not a variance or a 95 % half-width) and independently of the others: 4000 draws
    give the mean within 4 standard errors, the SD within 5 %, correlations below 0.06."""
    robot = (seed_leg("small")
             .with_provenance("contact.foot_friction", Provenance(source="test", uncertainty=0.05))
             .with_provenance("compliance.hinge_stiffness_nm_per_rad", Provenance(source="test", uncertainty=0.004)))
    keys = ["contact.foot_friction", "compliance.hinge_stiffness_nm_per_rad", "servo.noload_speed_rad_per_s"]
    sds = S.uncertain_values(robot)
    drawn = np.array([[r.get(k) for k in keys] for r in S.draw(robot, 4000, seed=11)])
    for i, key in enumerate(keys):
        sd = sds[key]
        assert sd > 0, key
        assert drawn[:, i].mean() == pytest.approx(robot.get(key), abs=4 * sd / math.sqrt(4000)), key
        assert drawn[:, i].std(ddof=1) == pytest.approx(sd, rel=0.05), key
    corr = np.corrcoef(drawn.T)
    assert np.abs(corr[np.triu_indices(3, 1)]).max() < 0.06


def test_sweep_ranks_designs_by_the_mean_over_draws():
    from locust.sweep.design import evaluate

    base = preset("seed")
    plain = evaluate(base, {"scale": 0.0}, 1)
    mean = evaluate(base, {"scale": 0.0}, 1, samples=4)
    spread = S.sample(base, 4, cycles=1)
    assert mean["distance_m"] == pytest.approx(spread.distance_m_mean, abs=1e-12)
    assert mean["max_nose_height_m"] == pytest.approx(spread.max_nose_height_m_mean, abs=1e-12)
    # the mean of the draws is not the nominal run's (the seed's servo values are uncertain)
    assert abs(mean["distance_m"] - plain["distance_m"]) > 1e-6


def test_draws_outside_the_limits_are_invalid_not_simulated():
    """A push drawn beyond the servo's 45 deg travel is refused as `locust sim` would refuse it."""
    robot = seed_leg("small").with_provenance("schedule.push_deg", Provenance(source="test", uncertainty=20.0))
    drawn = [r.get("schedule.push_deg") for r in S.draw(robot, 12, seed=3)]
    outside = [abs(v) > robot.get("servo.travel_deg") for v in drawn]
    assert 0 < sum(outside) < 12                               # the seed gives some of each
    trajs = S.simulate_draws(robot, 12, cycles=1, seed=3)
    assert [t is None for t in trajs] == outside
    spread = S.sample(robot, 12, cycles=1, seed=3)
    assert spread.n_valid == 12 - sum(outside)
    assert [math.isnan(d) for d in spread.distance_m] == outside
