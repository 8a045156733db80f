"""Servo steps: no-load speed, armature and kp of the hobby-servo model, identified with the
MuJoCo rig model, mujoco.rollout and mujoco.minimize; on SYNTHETIC steps (known truth) and on
the real SG90 recording in ../shared/data/servo."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from locust.calibrate import servo as SV
from locust.calibrate import synthetic as S
from locust.calibrate.recordings import read_table
from locust.errors import CalibrationError
from locust.params import Servo

SG90 = Servo()   # the preset SG90


def recording(truth: S.ServoTruth, seed: int) -> SV.StepRecording:
    t, angle, command = S.servo_step(truth, np.random.default_rng(seed))
    return SV.StepRecording(t, angle, command, SV.ServoRig(truth.inertia_kgm2, truth.gravity_moment_nm),
                            source=f"synthetic seed {seed}")


def test_rig_model_is_the_hobby_servo():
    servo = Servo(kp_nm_per_rad=0.3, stall_torque_nm=0.15, noload_speed_rad_per_s=10.0, armature_kgm2=2e-4)
    model = SV.rig_model(SV.ServoRig(inertia_kgm2=4e-4, gravity_moment_nm=0.03), servo)
    assert model.actuator_gainprm[0, 0] == 0.3
    assert list(model.actuator_biasprm[0, :3]) == [0.0, -0.3, 0.0]
    assert list(model.actuator_forcerange[0]) == [-0.15, 0.15]
    assert model.dof_damping[0] == pytest.approx(0.015, rel=1e-12)     # stall / no-load speed
    assert model.dof_armature[0] == 2e-4
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert data.M[0] == pytest.approx(4e-4 + 2e-4, rel=1e-9)           # load + reflected rotor
    assert -data.qfrc_bias[0] == pytest.approx(-0.03, rel=1e-6)         # gravity moment at angle 0
    # the same servo put on a compiled model without recompiling
    copy = SV.with_servo(SV.rig_model(SV.ServoRig(4e-4, 0.03)), servo)
    for name in ("actuator_gainprm", "actuator_biasprm", "actuator_forcerange", "dof_damping", "dof_armature"):
        assert np.array_equal(getattr(copy, name), getattr(model, name)), name


def test_saturated_servo_slews_at_its_noload_speed():
    """Full drive on a light load: the horn's speed tends to stall/b = the no-load speed, with
    the time constant (J + armature)/b; no overshoot of the speed limit."""
    rig = SV.ServoRig(inertia_kgm2=1e-6, timestep_s=1e-4)
    t = np.arange(0, 0.4, 1e-3)
    command = np.where(t < 0.01, 0.0, 180.0)
    rec = SV.StepRecording(t, np.zeros_like(t), command, rig)
    angle = SV.simulate_deg(SV.rig_model(rig), [SG90], [SV.Timing()], rec, 0.0)[0]
    speed = np.radians(np.diff(angle) / np.diff(t))
    tau = (1e-6 + SG90.armature_kgm2) * SG90.noload_speed_rad_per_s / SG90.stall_torque_nm
    assert speed.max() <= SG90.noload_speed_rad_per_s * 1.001
    i = np.searchsorted(t, 0.01 + 5 * tau)    # five time constants into the slew
    assert speed[i] == pytest.approx(SG90.noload_speed_rad_per_s * (1 - math.exp(-5)), rel=0.01)


def test_simulated_angle_moves_smoothly_with_the_delay():
    """Moving the command edge by 0.1 ms moves the slewing horn's angle by 0.1 ms of its speed,
    although the physics step is 1 ms (a fit needs this derivative)."""
    truth = S.ServoTruth(edges=1)
    rec = recording(truth, 0)
    model = SV.rig_model(SV.ServoRig(truth.inertia_kgm2))
    a, b = SV.simulate_deg(model, [SG90, SG90], [SV.Timing(0.0100), SV.Timing(0.0101)], rec, 0.0)
    slewing = (a > 20) & (a < 100)
    speed_deg_per_s = math.degrees(SG90.noload_speed_rad_per_s)
    assert slewing.sum() >= 3
    assert np.median(a[slewing] - b[slewing]) == pytest.approx(1e-4 * speed_deg_per_s, rel=0.03)


def test_synthetic_step_other_load_and_frame_rate_is_recovered():
    """SYNTHETIC: the preset SG90 on a 6e-5 kg*m^2 load filmed at 120 frames/s (the bundled
    recording: 1.5e-5 at 60, the real one 3.3e-6 at 30), stall torque given."""
    truth = dataclasses.replace(S.ServoTruth(), inertia_kgm2=6e-5, fps=120.0, edges=4, target_deg=90.0,
                                delay_s=0.02, clock_ratio=0.998)
    fit = SV.fit_servo([recording(truth, 11)], stall_torque_nm=0.15)
    est = fit.estimates
    assert est["noload_speed_rad_per_s"].value == pytest.approx(SG90.noload_speed_rad_per_s, rel=0.05)
    assert est["armature_kgm2"].value == pytest.approx(SG90.armature_kgm2, rel=0.15)
    assert est["kp_nm_per_rad"].value == pytest.approx(SG90.kp_nm_per_rad, rel=0.30)
    assert all(fit.identifiable.values()), fit.notes
    assert fit.rms_residual_deg == pytest.approx(truth.noise_deg, rel=0.15)
    assert fit.timings[0].delay_s == pytest.approx(0.02, abs=0.002)
    assert fit.timings[0].clock_ratio == pytest.approx(0.998, abs=5e-4)
    assert fit.rms_half_step_deg == pytest.approx(fit.rms_residual_deg, rel=0.02)   # converged in dt


def test_two_loads_give_the_stall_torque():
    """SYNTHETIC: the same SG90 on two loads; no stall torque given, all four identified."""
    light = S.ServoTruth()
    heavy = dataclasses.replace(light, inertia_kgm2=1e-3, half_period_s=1.2)
    fit = SV.fit_servo([recording(light, 4), recording(heavy, 5)])
    assert all(fit.identifiable.values()), fit.notes
    for name in SV.PARAMS:
        true = getattr(SG90, name)
        est = fit.estimates[name]
        assert est.value == pytest.approx(true, rel=0.05), name
        assert abs(est.value - true) < 4 * est.std, name


def test_stalled_servo_gives_stall_torque_not_kp():
    """SYNTHETIC: a weight too heavy to lift: the horn stalls where M*cos(angle) = stall."""
    truth = S.STALL_SERVO
    fit = SV.fit_servo([recording(truth, 12)])
    assert fit.estimates["stall_torque_nm"].value == pytest.approx(0.15, rel=0.01)
    assert fit.identifiable["stall_torque_nm"] and not fit.identifiable["kp_nm_per_rad"]
    assert any("kp_nm_per_rad is not identifiable" in n for n in fit.notes)


def test_one_load_without_stall_torque_is_refused():
    with pytest.raises(CalibrationError, match="stall torque is needed"):
        SV.fit_servo([recording(S.ServoTruth(), 1)])


def test_real_sg90_recording_is_followed(shared_data):
    """REAL: an SG90 swinging an AA battery (3.3e-6 kg*m^2) 0 <-> 180 deg at 30 frames/s.
    Datasheet: no-load 0.1 s/60 deg = 10.5 rad/s; a reflected rotor inertia of a few 1e-4."""
    table = read_table(shared_data / "servo" / "sg90_aa_battery_step.csv")
    c = table.columns
    rec = SV.StepRecording(c["t_s"], c["angle_deg"], c["command_deg"], SV.ServoRig(3.3e-6), source="sg90")
    fit = SV.fit_servo([rec], stall_torque_nm=0.15)
    assert fit.rms_residual_deg <= 2.5
    assert 8.0 <= fit.estimates["noload_speed_rad_per_s"].value <= 13.0
    assert 5e-5 <= fit.estimates["armature_kgm2"].value <= 2e-3
    assert all(fit.identifiable.values()), fit.notes
    # the preset SG90 is this fit (params.SG90_SOURCE), to its stated uncertainty
    for name in ("noload_speed_rad_per_s", "armature_kgm2", "kp_nm_per_rad"):
        assert fit.estimates[name].value == pytest.approx(getattr(SG90, name), abs=2 * fit.estimates[name].std), name


def test_horn_angle_from_track():
    ang = np.radians([10.0, 100.0, 179.0, 181.0, 270.0])
    x, y = 0.1 + 0.05 * np.cos(ang), 0.2 + 0.05 * np.sin(ang)
    assert SV.horn_angle_deg(x, y, 0.1, 0.2) == pytest.approx([10, 100, 179, 181, 270])


def test_flat_servo_signal_is_refused():
    t = np.arange(100) / 240
    command = np.where(t < 0.05, 0.0, 90.0)
    rec = SV.StepRecording(t, np.random.default_rng(0).normal(0, 0.3, len(t)), command, SV.ServoRig(4e-4))
    with pytest.raises(CalibrationError, match="flat signal"):
        SV.fit_servo([rec], stall_torque_nm=0.15)
