"""Servo step: kp, kv, torque limit identified with the MuJoCo rig model and mujoco.minimize."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from locust.calibrate import servo as SV
from locust.calibrate import synthetic as S
from locust.errors import CalibrationError


def test_rig_model_is_the_position_actuator():
    rig = SV.ServoRig(inertia_kgm2=4e-4, gravity_moment_nm=0.03)
    model = SV.rig_model(rig, SV.ServoGains(0.6, 0.04, 0.15))
    assert model.actuator_gainprm[0, 0] == 0.6
    assert list(model.actuator_biasprm[0, :3]) == [0.0, -0.6, -0.04]
    assert list(model.actuator_forcerange[0]) == [-0.15, 0.15]
    # inertia about the axis and gravity moment at angle 0 are the rig's
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert data.M[0] == pytest.approx(4e-4, rel=1e-9)
    assert -data.qfrc_bias[0] == pytest.approx(-0.03, rel=1e-6)
    data.qpos[0] = math.radians(60)
    mujoco.mj_forward(model, data)
    assert -data.qfrc_bias[0] == pytest.approx(-0.03 * 0.5, rel=1e-6)


def test_servo_with_visible_linear_range_is_identified():
    truth = S.ServoTruth()
    t, angle, command = S.servo_step(truth, np.random.default_rng(11))
    fit = SV.fit_servo(t, angle, command, truth.rig)
    assert fit.kp_nm_per_rad.value == pytest.approx(truth.kp_nm_per_rad, rel=0.10)
    assert fit.kv_nms_per_rad.value == pytest.approx(truth.kv_nms_per_rad, rel=0.10)
    assert fit.torque_limit_nm.value == pytest.approx(truth.torque_limit_nm, rel=0.05)
    assert all(fit.identifiable.values()), fit.notes
    assert fit.rms_residual_deg == pytest.approx(truth.noise_deg, rel=0.25)
    for name, true in zip(SV.PARAMS, truth.gains.as_array()):
        est = getattr(fit, name)
        assert est.ci95_low < true < est.ci95_high or abs(est.value - true) < 3 * est.std


def test_stalled_servo_kp_not_identifiable():
    """Seed gains lifting too heavy a weight: torque-limited throughout; kp, kv unidentifiable."""
    truth = S.STALL_SERVO
    t, angle, command = S.servo_step(truth, np.random.default_rng(12))
    fit = SV.fit_servo(t, angle, command, truth.rig)
    assert fit.identifiable == {"kp_nm_per_rad": False, "kv_nms_per_rad": False, "torque_limit_nm": True}
    assert fit.torque_limit_nm.value == pytest.approx(0.15, rel=0.05)
    assert any("stalled" in n and "not identifiable" in n for n in fit.notes)


def test_horn_angle_from_track():
    ang = np.radians([10.0, 100.0, 179.0, 181.0, 270.0])
    x, y = 0.1 + 0.05 * np.cos(ang), 0.2 + 0.05 * np.sin(ang)
    assert SV.horn_angle_deg(x, y, 0.1, 0.2) == pytest.approx([10, 100, 179, 181, 270])


def test_flat_servo_signal_is_refused():
    t = np.arange(100) / 240
    command = np.where(t < 0.05, 0.0, 90.0)
    with pytest.raises(CalibrationError, match="flat signal"):
        SV.fit_servo(t, np.random.default_rng(0).normal(0, 0.3, len(t)), command, SV.ServoRig(4e-4))
