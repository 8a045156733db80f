"""The live simulation against the batch rollout: same model, same commands, same hop."""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.errors import SimError
from locust.params import preset
from locust.sim.live import PREROLL_S, LiveSim
from locust.sim.run import run


def drive_schedule(sim: LiveSim, robot, cycles: int) -> None:
    """What the firmware does: push for push_s, rest for wait_s, one command per 50 Hz tick."""
    sch, hz = robot.schedule, robot.solver.control_hz
    cycle_s = sch.push_s + sch.wait_s
    for i in range(int(cycles * cycle_s * hz + 1e-9)):
        angle = sch.push_deg if (i / hz) % cycle_s < sch.push_s else 0.0
        sim.set_servo_angles_deg(angle, angle)
        sim.advance_to((i + 1) / hz)


@pytest.fixture(scope="module")
def seed():
    return preset("seed")


def test_live_two_cycles_match_the_rollout(seed):
    sim = LiveSim(seed)
    drive_schedule(sim, seed, cycles=2)
    live = sim.close()
    ref = run(seed, cycles=2)
    assert ref.valid and live["valid"], live["reasons"]
    assert live["reasons"] == []
    assert live["sim_time_s"] == pytest.approx(2 * 1.3, abs=1e-9)
    assert ref.distance_m > 0.005        # two hops (about 3.1 mm each for the seed robot on its SG90s)
    # the same model, the same steps, the same commands at the same steps: bit for bit
    assert live["distance_m"] == ref.distance_m
    assert live["max_nose_height_m"] == ref.max_nose_height_m
    # cut where each push starts, the live run's hops are the rollout's cycles, bit for bit
    assert live["hops"] == [vars(hop) for hop in ref.hops] and len(live["hops"]) == 2
    assert live["outcome"] == ref.outcome == "stays_low"     # the seed shuffles, its nose about 1 mm up
    assert sim.close() == live           # closing twice gives the same answer


def test_left_and_right_are_independent(seed):
    sim = LiveSim(seed)
    sim.set_servo_angles_deg(-30.0, 0.0)
    sim.advance_to(0.3)
    m, d = sim.model, sim.data
    q = {side: math.degrees(d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{side}_servo")]])
         for side in ("L", "R")}
    # the pushed horn swung towards -30 deg, held short by the legs' load (kp 0.26 N*m/rad)
    assert q["L"] < -10.0
    assert abs(q["R"]) < 3.0             # the resting one held near 0
    assert sim.close()["sim_time_s"] == pytest.approx(0.3)


def test_live_video_frames_and_truth(seed, tmp_path):
    path = tmp_path / "live.mp4"
    sim = LiveSim(seed, video_path=str(path), fps=30, width=160, height=120, camera="track")
    drive_schedule(sim, seed, cycles=1)
    out = sim.close()
    frames = round((PREROLL_S + 1.3) * 30)   # the clip opens on the robot standing
    assert out["frames"] == frames and out["video_path"] == str(path)
    truth = pd.read_csv(tmp_path / "live.truth.csv", comment="#")
    assert len(truth) == frames
    assert truth.t_s.iloc[-1] == pytest.approx((frames - 1) / 30)
    # the nose marker's true track covers the hop the summary reports
    assert truth.nose_x_m.iloc[-1] - truth.nose_x_m.iloc[0] == pytest.approx(out["distance_m"], abs=0.01)


def test_live_fixed_video_tracks_into_metres(tmp_path):
    """The virtual robot's default video: a fixed camera framed on the planned run (2 cycles
    here), camera.json beside it, and `locust track` turns it into world metres."""
    robot = preset("seed").with_values({"schedule.cycles": 2})
    path = tmp_path / "live.mp4"
    sim = LiveSim(robot, video_path=str(path))          # 640x360, fixed camera
    drive_schedule(sim, robot, cycles=2)
    out = sim.close()
    assert out["valid"] and out["frames"] == round((PREROLL_S + 2.6) * 30)
    truth = pd.read_csv(tmp_path / "live.truth.csv", comment="#")
    camera = json.loads((tmp_path / "live.camera.json").read_text())
    assert camera["camera"] == "fixed" and (camera["width_px"], camera["height_px"]) == (640, 360)
    for name in ("nose", "foot"):   # the whole run stays in the picture, clear of the edges
        assert truth[f"{name}_px"].between(10, 630).all() and truth[f"{name}_py"].between(10, 350).all()
        assert (truth[f"{name}_seen_frac"] >= 0.9).mean() >= 0.95
    res = CliRunner().invoke(cli, ["track", str(path), "--overlay", "none", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    tracks = pd.read_csv(tmp_path / "live.tracks.csv")
    for name in ("nose", "foot"):
        assert tracks[f"{name}_ok"].all()
        px_err = np.hypot(tracks[f"{name}_px"] - truth[f"{name}_px"], tracks[f"{name}_py"] - truth[f"{name}_py"])
        m_err = np.hypot(tracks[f"{name}_x_m"] - truth[f"{name}_x_m"], tracks[f"{name}_y_m"] - truth[f"{name}_z_m"])
        assert float(np.sqrt(np.mean(px_err ** 2))) <= 0.5          # measured 0.11 / 0.10 px
        assert float(np.sqrt(np.mean(m_err ** 2))) <= 1e-3          # measured 0.17 / 0.15 mm
    # the tracked hop is the one the live summary reports (nose marker start -> end)
    assert tracks.nose_x_m.iloc[-1] - tracks.nose_x_m.iloc[0] == pytest.approx(out["distance_m"], abs=0.01)


def test_bad_commands_raise_and_nothing_is_written(seed, tmp_path):
    sim = LiveSim(seed)
    for bad in (float("nan"), float("inf"), "30"):
        with pytest.raises(SimError, match="servo command"):
            sim.set_servo_angles_deg(bad, 0.0)
    for bad in (-0.1, float("nan")):
        with pytest.raises(SimError, match="advance_to"):
            sim.advance_to(bad)
    sim.advance_to(0.1)
    sim.advance_to(0.05)                 # an earlier time does nothing
    assert sim.sim_time_s == pytest.approx(0.1)
    sim.close()
    with pytest.raises(SimError, match="closed"):
        sim.advance_to(0.2)
    existing = tmp_path / "taken.mp4"
    existing.write_bytes(b"keep")
    with pytest.raises(SimError, match="not overwriting"):
        LiveSim(seed, video_path=str(existing))
    assert existing.read_bytes() == b"keep" and len(list(tmp_path.iterdir())) == 1


def test_a_blown_up_live_run_is_reported_invalid(seed):
    """The stiffest servo and hinge within the limits, with no rotor, blow the simulation up at
    Euler's longest allowed step (MuJoCo flags a non-finite acceleration; the rollout's audit
    says so): the live audit agrees."""
    coarse = seed.with_values({"servo.kp_nm_per_rad": 100.0, "servo.armature_kgm2": 0.0,
                               "compliance.hinge_stiffness_nm_per_rad": 10.0, "solver.timestep_s": 0.01,
                               "solver.integrator": "euler"})
    ref = run(coarse, cycles=1)
    sim = LiveSim(coarse)
    drive_schedule(sim, coarse, cycles=1)
    live = sim.close()
    assert not ref.valid and not live["valid"]
    assert math.isnan(live["distance_m"])
    assert any("BADQACC" in r for r in live["reasons"])
    assert any("BADQACC" in r for r in ref.reasons)


def test_live_video_opens_on_the_robot_standing(tmp_path):
    """The first PREROLL_S of the clip come before time 0: the robot stands still in them."""
    robot = preset("seed")
    path = tmp_path / "live.mp4"
    sim = LiveSim(robot, video_path=str(path), width=320, height=240, cycles=1)
    drive_schedule(sim, robot, cycles=1)
    sim.close()
    truth = pd.read_csv(tmp_path / "live.truth.csv", comment="#")
    still = truth[truth.t_s < PREROLL_S - 1e-9]
    assert len(still) == round(PREROLL_S * 30)
    for name in ("nose", "foot"):   # settled: under 0.1 mm of motion while standing
        assert float(np.ptp(still[f"{name}_x_m"])) < 1e-4 and float(np.ptp(still[f"{name}_z_m"])) < 1e-4
    moved = np.hypot(truth.nose_x_m - truth.nose_x_m.iloc[0], truth.nose_z_m - truth.nose_z_m.iloc[0])
    assert truth.t_s[moved > 1e-3].iloc[0] >= PREROLL_S   # the first push comes after it
