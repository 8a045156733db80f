"""``locust sim --push-clip`` and ``locust measure stroke`` against the simulation's own truth.

The clips are synthetic: MuJoCo renders of a robot whose servo is hidden from the
measurement (drawn about the SG90's values), each re-encoded with added pixel noise
(:func:`as_phone_clip`) before it is measured, so that only the picture carries over, never
the truth beside it. The truth is the same rule (:func:`locust.measure.swing.read_swing`) on
the crank's true angle at every physics step of the run the clip shows.
"""

from __future__ import annotations

import json
import math

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.errors import MeasureError
from locust.measure.crankclip import crank_angle_deg, read_crank_clip
from locust.measure.stroke import measure_stroke, model_push
from locust.measure.swing import read_swing, swing_intervals
from locust.params import preset
from locust.sim.push import LEAD_S, simulate_push
from locust.sim.pushclip import render_push_clips

NOISE_LEVELS = 2.0          # sd of the added pixel noise, in grey levels of 255
SIZE = (480, 360)           # the fast tests' frames
STROKE_TOL_DEG = 0.5        # the stroke's error, at most (its intervals are about 0.4 deg wide)


def as_phone_clip(path, out, seed: int):
    """A 'phone clip' of a rendered one: each frame with Gaussian noise of NOISE_LEVELS,
    encoded again (mp4v) at the same rate."""
    cap = cv2.VideoCapture(str(path))
    fps = cap.get(cv2.CAP_PROP_FPS)
    rng = np.random.default_rng(seed)
    writer = None
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        if writer is None:
            writer = cv2.VideoWriter(str(out), cv2.VideoWriter_fourcc(*"mp4v"), fps, (frame.shape[1], frame.shape[0]))
        noisy = frame.astype(float) + rng.normal(0.0, NOISE_LEVELS, frame.shape)
        writer.write(np.clip(np.rint(noisy), 0, 255).astype(np.uint8))
    writer.release()
    cap.release()
    return out


def hidden(seed: int):
    """A robot with its servo (and its crank's start) drawn, on a leg set of its own."""
    rng = np.random.default_rng(seed)
    leg = ("small", "medium", "large")[seed % 3]
    return preset(leg).with_values({
        "servo.stall_torque_nm": float(rng.uniform(0.05, 0.18)),
        "servo.noload_speed_rad_per_s": float(rng.uniform(5.0, 12.0)),
        "servo.armature_kgm2": float(rng.uniform(2e-4, 8e-4)),
        "servo.kp_nm_per_rad": float(rng.uniform(0.15, 0.6)),
        "geometry.crank_start_deg": float(rng.uniform(-108.0, -92.0))}, "hidden")


def truth_of(clip) -> dict:
    """The rule on the crank's true angle at every step of the run the clip shows."""
    return read_swing(clip.run.t_s, clip.run.crank_deg).figures()


def run_cli(*args: str):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    """One hidden robot's floor and held clips (SYNTHETIC), as rendered and as a phone gives them."""
    folder = tmp_path_factory.mktemp("push")
    robot = hidden(3)
    made = render_push_clips(robot, folder / "floor_render.mp4", folder / "held_render.mp4", width=SIZE[0],
                             height=SIZE[1])
    return {c.kind: {"render": c, "truth": truth_of(c),
                     "clip": as_phone_clip(c.clip.video_path, folder / f"{c.kind}.mp4", seed=k)}
            for k, c in enumerate(made)} | {"robot": robot, "folder": folder}


def test_the_model_reads_its_crank_from_the_points_as_a_clip_does():
    """The four points' angle in the side view is the servo joint's (plus the crank's start),
    both sides, floor and held."""
    robot = preset("medium").with_values({"geometry.ground_angle_deg": 7.0})
    for kind in ("floor", "held"):
        for side in ("L", "R"):
            run = simulate_push(robot, kind, side)
            t, angle = model_push(robot, kind, side)
            assert np.max(np.abs(angle - run.crank_deg)) < 1e-9, (kind, side)
    # and a crank that does not move reads as the plate's own pitch does not matter
    px = {"nose": np.array([0.0, 10.0]), "tail": np.array([100.0, 110.0]), "axis": np.array([50.0, 60.0]),
          "crank": np.array([50.0, 60.0])}
    py = {"nose": np.array([0.0, -10.0]), "tail": np.array([0.0, -10.0]), "axis": np.array([0.0, -10.0]),
          "crank": np.array([40.0, 30.0])}
    assert crank_angle_deg(px, py, "L", 0.0) == pytest.approx([-90.0, -90.0])
    assert crank_angle_deg(px, py, "R", 5.0) == pytest.approx([85.0, 85.0])


def test_the_swing_of_a_known_curve():
    """A smooth swing of known stroke and speed (a raised cosine to 25 deg over 80 ms, back at
    400 ms), sampled at 240 frames/s: each figure to its sampling's precision."""
    t = np.arange(-0.2, 0.7, 1 / 240)
    rise = np.clip(t / 0.08, 0.0, 1.0)
    fall = np.clip((t - 0.4) / 0.08, 0.0, 1.0)
    angle = -100.0 - 25.0 * (0.5 - 0.5 * np.cos(np.pi * rise)) + 25.0 * (0.5 - 0.5 * np.cos(np.pi * fall))
    sw = read_swing(t, angle)
    assert sw.direction == -1
    assert sw.rest_deg == pytest.approx(-100.0, abs=1e-9)
    # a flat top: the quadratic through the frames within 0.5 deg of it takes in its shoulders
    assert sw.stroke_deg == pytest.approx(25.0, abs=0.01)
    assert sw.peak_speed_deg_per_s == pytest.approx(25.0 * math.pi / 2 / 0.08, rel=0.003)   # 490.9 deg/s
    t10, t90 = (0.08 / math.pi * math.acos(1 - 2 * q) for q in (0.1, 0.9))
    assert sw.mean_speed_deg_per_s == pytest.approx(0.8 * 25.0 / (t90 - t10), rel=0.003)


def test_the_swings_intervals_cover_over_many_noise_draws():
    """Independent noise of 0.1 deg a frame on the model's held swing: each figure's interval
    holds the noiseless value in at least 36 of 40 draws."""
    run = simulate_push(preset("small"), "held")
    truth = read_swing(run.t_s, run.crank_deg).figures()
    t = np.arange(run.t_s[0], run.t_s[-1], 1 / 240)
    clean = np.interp(t, run.t_s, run.crank_deg)
    covered = dict.fromkeys(truth, 0)
    for seed in range(40):
        noisy = clean + np.random.default_rng(seed).normal(0.0, 0.1, len(t))
        _, est = swing_intervals(t, noisy, 0.1, draws=100, seed=seed)
        for k, e in est.items():
            covered[k] += e.ci95[0] <= truth[k] <= e.ci95[1]
    assert min(covered.values()) >= 36, covered


def test_the_stroke_of_a_hidden_servo_is_measured_within_its_interval(clips):
    """The fast test: one hidden robot, its two phone clips, each figure beside the truth."""
    result = measure_stroke(preset("small"), [clips["floor"]["clip"], clips["held"]["clip"]], draws=100)
    for r in result.readings:
        truth = clips[r.kind]["truth"]
        est = r.estimates["stroke_deg"]
        assert est.value == pytest.approx(truth["stroke_deg"], abs=STROKE_TOL_DEG), r.kind
        assert est.ci95[0] <= truth["stroke_deg"] <= est.ci95[1], (r.kind, est, truth["stroke_deg"])
        assert est.ci95[1] - est.ci95[0] < 1.0
        for key in ("peak_speed_deg_per_s", "mean_speed_deg_per_s"):
            assert r.estimates[key].value == pytest.approx(truth[key], rel=0.05), (r.kind, key)
        # the model compared with is the file's (the preset's), not the hidden robot
        small = read_swing(*model_push(preset("small"), r.kind, "L"))
        assert r.model.stroke_deg == pytest.approx(small.stroke_deg, abs=1e-9)


def test_measure_stroke_prints_writes_and_refuses(clips, tmp_path):
    floor, held = str(clips["floor"]["clip"]), str(clips["held"]["clip"])
    csv, plot = tmp_path / "angle.csv", tmp_path / "stroke.png"
    result = run_cli("measure", "stroke", floor, held, "--preset", "small", "--csv", str(csv), "--plot", str(plot),
                     "--json", "--draws", "50")
    assert result.exit_code == 0, result.output
    got = json.loads(result.stdout)
    assert set(got["clips"]) == {"floor", "held"}
    for kind, c in got["clips"].items():
        assert c["side"] == "left" and c["fps"] == 240
        stroke = c["measured"]["stroke_deg"]
        assert stroke["value"] == pytest.approx(clips[kind]["truth"]["stroke_deg"], abs=STROKE_TOL_DEG)
        assert c["difference"]["stroke_deg"] == pytest.approx(stroke["value"] - c["model"]["stroke_deg"], abs=1e-9)
    rows = csv.read_text().splitlines()
    assert rows[0] == "clip,frame,t_s,t_from_onset_s,crank_deg,crank_sd_deg,model_crank_deg"
    frames = clips["floor"]["render"].clip.frames
    assert len(rows) == 1 + 2 * frames
    assert plot.read_bytes()[:4] == b"\x89PNG"
    text = run_cli("measure", "stroke", floor, held, "--preset", "small", "--draws", "50").output
    assert "push on the floor" in text and "push held up" in text and "the floor's stroke less" in text
    again = run_cli("measure", "stroke", floor, "--preset", "small", "--csv", str(csv))
    assert again.exit_code == 2 and f"error: --csv {csv} exists" in again.output


def test_a_clip_of_the_other_side_is_refused(clips):
    result = run_cli("measure", "stroke", str(clips["held"]["clip"]), "--held-only", "--side", "right",
                     "--preset", "small")
    assert result.exit_code == 2
    assert "shows the robot's left side (its nose left of its tail), not its right" in result.output
    assert "hint: film the right side" in result.output


def _rewrite(path, out, keep=None, paint=None):
    """``path``'s frames ``keep`` (a slice), each with the pixels of colour ``paint`` (BGR) greyed."""
    cap = cv2.VideoCapture(str(path))
    frames = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(frame)
    cap.release()
    frames = frames[keep] if keep is not None else frames
    writer = cv2.VideoWriter(str(out), cv2.VideoWriter_fourcc(*"mp4v"), 240.0, (frames[0].shape[1], frames[0].shape[0]))
    for frame in frames:
        if paint is not None:
            near = np.linalg.norm(frame.astype(float) - paint, axis=2) < 160
            frame = frame.copy()
            frame[near] = 70
        writer.write(frame)
    writer.release()
    return out


def test_a_clip_without_the_crank_sticker_says_which_and_what_to_do(clips):
    bare = _rewrite(clips["held"]["clip"], clips["folder"] / "no_crank.mp4", paint=(0, 255, 0))
    with pytest.raises(MeasureError) as err:
        read_crank_clip(bare, 0.0)
    assert "no_crank.mp4: the crank sticker (#00ff00" in err.value.message
    assert "stick the dots" in err.value.hint and "locust track preview" in err.value.hint


def test_a_clip_too_short_is_refused_with_what_to_film(clips):
    run = clips["held"]["render"].run
    onset = int(round((read_swing(run.t_s, run.crank_deg).onset_s + LEAD_S) * 240))   # its frame in the clip
    late = _rewrite(clips["held"]["clip"], clips["folder"] / "late.mp4", keep=slice(onset - 3, None))
    with pytest.raises(MeasureError) as err:
        measure_stroke(preset("small"), [late], kinds=("held",), draws=20)
    assert "late.mp4: only" in err.value.message and "frames at rest before the crank moves" in err.value.message
    assert "film from a second before the push" in err.value.hint
    early = _rewrite(clips["held"]["clip"], clips["folder"] / "early.mp4", keep=slice(0, onset + 8))
    with pytest.raises(MeasureError) as err:
        measure_stroke(preset("small"), [early], kinds=("held",), draws=20)
    assert "early.mp4: it ends before the crank reaches the push's extreme" in err.value.message
    still = _rewrite(clips["held"]["clip"], clips["folder"] / "still.mp4", keep=slice(0, 40))
    with pytest.raises(MeasureError) as err:
        measure_stroke(preset("small"), [still], kinds=("held",), draws=20)
    assert "never turns more than" in err.value.message


# -- ten hidden robots (slow) ------------------------------------------------------------
@pytest.mark.slow
def test_ten_hidden_servos_their_stroke_within_its_interval(tmp_path):
    """Ten robots, each with its servo drawn (stall 0.05-0.18 N m, no-load 5-12 rad/s,
    armature 2-8e-4 kg m2, kp 0.15-0.6 N m/rad, crank start -108 to -92 deg) on a leg set of
    its own, filmed from its left at 640x480 and 240 frames/s on the floor and held up, and
    measured against the preset of its leg set: the stroke's interval holds the truth in at
    least 8 of 10 of each kind, every stroke within 0.5 deg."""
    rows = []
    for seed in range(10):
        robot = hidden(100 + seed)
        made = render_push_clips(robot, tmp_path / f"f{seed}.mp4", tmp_path / f"h{seed}.mp4")
        phone = [as_phone_clip(c.clip.video_path, tmp_path / f"{c.kind}{seed}.mp4", seed=seed) for c in made]
        result = measure_stroke(preset(robot.leg_set), phone, seed=seed)
        for c, r in zip(made, result.readings):
            est, truth = r.estimates["stroke_deg"], truth_of(c)["stroke_deg"]
            rows.append((seed, c.kind, truth, est, r.model.stroke_deg))
    print(f"\n{'seed':>4s} {'clip':5s} {'truth':>7s} {'measured':>8s} {'95 %':>17s} {'width':>6s} {'model':>7s}")
    for seed, kind, truth, est, model in rows:
        print(f"{seed:4d} {kind:5s} {truth:7.2f} {est.value:8.2f} [{est.ci95[0]:7.2f},{est.ci95[1]:7.2f}] "
              f"{est.ci95[1] - est.ci95[0]:6.2f} {model:7.2f}")
    for kind in ("floor", "held"):
        mine = [(truth, est) for _, k, truth, est, _ in rows if k == kind]
        covered = sum(e.ci95[0] <= t <= e.ci95[1] for t, e in mine)
        print(f"{kind}: covered {covered} of 10; widths {np.median([e.ci95[1] - e.ci95[0] for _, e in mine]):.2f} deg "
              f"(median); largest error {max(abs(e.value - t) for t, e in mine):.3f} deg")
        assert covered >= 8, kind
        assert max(abs(e.value - t) for t, e in mine) <= STROKE_TOL_DEG, kind


def test_a_clip_from_the_right_of_a_robot_with_a_tooth_off_there(tmp_path):
    """The right leg filmed from the robot's right (the camera at -y), its crank a tooth on:
    the clip's side found, its stroke as the truth's, and the model read on that side."""
    robot = preset("small").with_values({"right.crank_tooth": 1})
    clip, = render_push_clips(robot, held_path=tmp_path / "right.mp4", side="R", width=SIZE[0], height=SIZE[1])
    phone = as_phone_clip(clip.clip.video_path, tmp_path / "right_phone.mp4", seed=7)
    result = measure_stroke(robot, [phone], kinds=("held",), side="R", draws=50)
    r, = result.readings
    truth = truth_of(clip)
    assert r.series.side == "R"
    assert r.estimates["rest_deg"].value == pytest.approx(truth["rest_deg"], abs=STROKE_TOL_DEG)
    assert r.estimates["stroke_deg"].value == pytest.approx(truth["stroke_deg"], abs=STROKE_TOL_DEG)
    assert r.model.rest_deg == pytest.approx(truth["rest_deg"], abs=1e-6)   # the file is the truth here
    assert r.model.rest_deg > -90.0        # a tooth (17.1 deg) on from the left's -100
