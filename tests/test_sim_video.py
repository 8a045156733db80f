"""The rendered hop video against its own truth sidecars.

The truth pixels are projected through the camera MuJoCo rendered with; here they are
checked against what is actually in the MP4: the centroid of each marker's colour blob.
"""

from __future__ import annotations

import json

import cv2
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.errors import SimError
from locust.markers import MARKER_COLOURS
from locust.params import preset
from locust.sim.clip import VIDEO_QUALITY, VISIBLE_FRAC, render_video
from locust.sim.rollout import roll_out
from locust.sim.run import run

W, H, FPS = 320, 240, 30
FULLY_SEEN = 0.8         # frames where a marker is at least this much in view (not on the floor)
VISIBLE = VISIBLE_FRAC     # the truth's own "visible" threshold


def _frames(path) -> np.ndarray:
    cap = cv2.VideoCapture(str(path))
    out = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        out.append(frame)
    cap.release()
    return np.array(out)


def _hue_opencv(hex_colour: str) -> int:
    bgr = np.uint8([[[int(hex_colour[5:7], 16), int(hex_colour[3:5], 16), int(hex_colour[1:3], 16)]]])
    return int(cv2.cvtColor(bgr, cv2.COLOR_BGR2HSV)[0, 0, 0])


def blob_centroid(frame_bgr: np.ndarray, hex_colour: str) -> tuple[float, float] | None:
    """Centroid of the largest blob of a saturated, bright pixel of the marker's hue."""
    hsv = cv2.cvtColor(frame_bgr, cv2.COLOR_BGR2HSV)
    dh = np.abs(((hsv[..., 0].astype(int) - _hue_opencv(hex_colour) + 90) % 180) - 90)
    mask = ((dh < 12) & (hsv[..., 1] > 100) & (hsv[..., 2] > 120)).astype(np.uint8)
    n, _, stats, centres = cv2.connectedComponentsWithStats(mask)
    if n < 2:
        return None
    k = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    return float(centres[k][0]), float(centres[k][1])


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    folder = tmp_path_factory.mktemp("video")
    # the notebook's servo hops about 10 cm, which puts the camera framing to work
    robot = preset("seed-notebook").with_values({"solver.settle_s": 0.5})
    infos = {cam: render_video(robot, folder / f"hop-{cam}.mp4", cycles=1, camera=cam, fps=FPS, width=W, height=H)
             for cam in ("track", "fixed")}
    return robot, infos


def test_frame_count_is_duration_times_fps(clips):
    robot, infos = clips
    duration_s = robot.solver.settle_s + robot.schedule.push_s + robot.schedule.wait_s   # 1 cycle
    expected = round(duration_s * FPS)
    assert expected == 54
    for info in infos.values():
        assert info.frames == expected
        assert len(_frames(info.video_path)) == expected
        truth = pd.read_csv(info.truth_path, comment="#")
        assert len(truth) == expected
        assert truth.t_s.iloc[-1] == pytest.approx((expected - 1) / FPS, abs=1e-6)


def _blob_errors(infos, min_seen_frac: float) -> tuple[np.ndarray, int]:
    """Blob centroid - true pixel centre, for every marker seen at least ``min_seen_frac``."""
    errors, misses = [], 0
    for info in infos.values():
        frames = _frames(info.video_path)
        truth = pd.read_csv(info.truth_path, comment="#")
        for name, (hex_colour, _) in MARKER_COLOURS.items():
            for i in np.flatnonzero(truth[f"{name}_seen_frac"] >= min_seen_frac):
                c = blob_centroid(frames[i], hex_colour)
                if c is None:
                    misses += 1
                    continue
                errors.append((c[0] - truth[f"{name}_px"][i], c[1] - truth[f"{name}_py"][i]))
    return np.array(errors).reshape(-1, 2), misses


def _rms(err: np.ndarray) -> float:
    return float(np.sqrt((err ** 2).sum(axis=1).mean()))


def test_truth_pixels_match_marker_blobs(clips):
    """Projection check: true pixel centre vs colour-blob centroid in the decoded MP4.

    Fully seen markers (in flight) test the projection itself, to a fraction of a pixel (a
    half-pixel slip in the pixel convention would fail it); markers flagged visible include
    those half sunk in the floor when the robot stands, whose blob is only their top half.
    """
    _, infos = clips
    err, misses = _blob_errors(infos, FULLY_SEEN)
    assert misses == 0
    assert len(err) >= 10, "too few frames with a fully seen marker to judge the projection"
    assert _rms(err) <= 0.5, f"fully seen: truth vs blob RMS {_rms(err):.2f} px over {len(err)} markers"
    err, misses = _blob_errors(infos, VISIBLE)
    assert misses == 0 and len(err) >= 40
    assert _rms(err) <= 1.5, f"visible: truth vs blob RMS {_rms(err):.2f} px over {len(err)} markers"


def test_truth_world_positions_are_the_audited_run(clips):
    """Frame k shows the rollout's state at t = k / fps: each marker is rigidly fixed to the
    nose / foot point the hop analytics use, at the offset the model puts it."""
    from locust.sim.model import MARKER_FOOT_UP, MARKER_NOSE_BACK, MARKER_NOSE_UP, MARKER_RADIUS_M
    from locust.sim.rollout import roll_out

    robot, infos = clips
    traj = roll_out(robot, cycles=1)
    s = traj.built.sensors
    truth = pd.read_csv(infos["fixed"].truth_path, comment="#")
    # mj_step evaluates sensors before it integrates: sensor row k is the pose at t = k dt
    rows = np.rint(truth.t_s.to_numpy() / traj.timestep_s).astype(int)
    expected_m = {"nose": MARKER_RADIUS_M * np.hypot(MARKER_NOSE_BACK, MARKER_NOSE_UP),
                  "foot": MARKER_RADIUS_M * MARKER_FOOT_UP}
    for name, cols in (("nose", s.nose_pos), ("foot", s.foot_pos)):
        point = traj.sensordata[rows][:, cols]
        gap = np.hypot(truth[f"{name}_x_m"] - point[:, 0], truth[f"{name}_z_m"] - point[:, 2])
        np.testing.assert_allclose(gap, expected_m[name], atol=3e-6)   # 6-decimal CSV, rigid offset


def test_markers_clear_of_the_floor_and_found_by_default(clips):
    """The dots sit clear of the floor and other parts: fully seen in nearly every frame, and
    `locust track` with no --marker finds both in every frame (it found 10 of 54 when the
    dots were half sunk in the floor)."""
    _, infos = clips
    for info in infos.values():
        truth = pd.read_csv(info.truth_path, comment="#")
        for name in MARKER_COLOURS:
            assert (truth[f"{name}_seen_frac"] >= 0.9).mean() >= 0.95, (info.camera, name)
        res = CliRunner().invoke(cli, ["track", str(info.video_path), "--overlay", "none", "--out",
                                       str(info.video_path.parent)])
        assert res.exit_code == 0, res.output
        tracks = pd.read_csv(info.video_path.with_name(info.video_path.stem + ".tracks.csv"))
        for name in MARKER_COLOURS:
            assert tracks[f"{name}_ok"].all(), (info.camera, name)


@pytest.mark.parametrize("camera", ["fixed", "track"])
def test_track_gives_world_metres_through_camera_json(clips, camera, tmp_path):
    """`locust track` finds hop.camera.json beside the video and maps pixels through each
    marker's plane: world positions within 1 mm RMS of the truth, pixels within 0.5 px."""
    _, infos = clips
    info = infos[camera]
    out = tmp_path / "t.csv"
    res = CliRunner().invoke(cli, ["track", str(info.video_path), "--out", str(out), "--overlay", "none"])
    assert res.exit_code == 0, res.output
    truth = pd.read_csv(info.truth_path, comment="#")
    tracks = pd.read_csv(out)
    sidecar = json.loads(out.with_suffix(".json").read_text())
    assert sidecar["calibration"]["source"] == "camera.json"
    assert sidecar["calibration"]["camera"] == camera
    for name in MARKER_COLOURS:
        seen = truth[f"{name}_seen_frac"].to_numpy() >= 0.9
        ok = tracks[f"{name}_ok"].to_numpy().astype(bool)
        assert ok[seen].mean() >= 0.95
        use = seen & ok
        px_err = np.hypot(tracks[f"{name}_px"] - truth[f"{name}_px"], tracks[f"{name}_py"] - truth[f"{name}_py"])[use]
        m_err = np.hypot(tracks[f"{name}_x_m"] - truth[f"{name}_x_m"],
                         tracks[f"{name}_y_m"] - truth[f"{name}_z_m"])[use]
        px_rms, m_rms = float(np.sqrt(np.mean(px_err ** 2))), float(np.sqrt(np.mean(m_err ** 2)))
        assert px_rms <= 0.5, f"{camera} {name}: pixel RMS {px_rms:.3f}"
        assert m_rms <= 1e-3, f"{camera} {name}: world RMS {m_rms * 1000:.3f} mm"


def test_fixed_camera_has_static_background(clips):
    """The floor in front of the robot does not change in the fixed clip; it slides in the tracking one."""
    _, infos = clips
    changed = {}
    for cam, info in infos.items():
        grey = np.array([cv2.cvtColor(f, cv2.COLOR_BGR2GRAY) for f in _frames(info.video_path)]).astype(int)
        floor = grey[:, int(0.8 * H):]      # floor between the camera and the robot
        span = floor.max(axis=0) - floor.min(axis=0)
        changed[cam] = float((span > 8).mean())
        if cam == "fixed":
            assert int(span.max()) <= 6   # codec noise only
    assert changed["fixed"] == 0.0
    assert changed["track"] > 0.5           # the same measure sees a moving camera


def test_fixed_camera_metres_per_pixel(clips):
    """m/px at the nose's plane turns the true pixel track into the true metric track."""
    _, infos = clips
    cam = json.loads(infos["fixed"].camera_path.read_text())
    assert cam["camera"] == "fixed" and cam["width_px"] == W and cam["height_px"] == H
    m_per_px = cam["m_per_px"]["nose_plane"]["m_per_px"]
    truth = pd.read_csv(infos["fixed"].truth_path, comment="#")
    dx_m = truth.nose_x_m.iloc[-1] - truth.nose_x_m.iloc[0]
    dpx = truth.nose_px.iloc[-1] - truth.nose_px.iloc[0]
    assert abs(dx_m) > 0.05                                     # the robot hopped
    assert -dpx * m_per_px == pytest.approx(dx_m, rel=0.02)     # +x runs right to left in this view


def test_renders_an_audited_run_without_simulating_again(clips, tmp_path):
    robot, infos = clips
    traj = run(robot, cycles=1, keep_states=True).trajectory
    info = render_video(robot, tmp_path / "again.mp4", camera="fixed", fps=FPS, width=W, height=H, trajectory=traj)
    assert info.truth_path.read_text() == infos["fixed"].truth_path.read_text()
    assert info.camera_path.read_text() == infos["fixed"].camera_path.read_text()
    with pytest.raises(SimError, match="kept no states"):
        render_video(robot, tmp_path / "stateless.mp4", trajectory=roll_out(robot, cycles=1))


def test_a_video_renders_at_its_own_quality_and_leaves_the_model_its_own(clips, tmp_path):
    """A video's frames are rendered without multisampling and with a 1024 px shadow map (2.3-3x
    faster: bench/video_speed.py) on a copy of the model: the stills and photos rendered from
    the same model after it keep its 4 samples and 2048 px shadows. Its markers' blobs are
    where the truth says (test_truth_pixels_match_marker_blobs) as at the model's quality."""
    robot, _ = clips
    traj = run(robot, cycles=1, keep_states=True).trajectory
    quality = traj.built.model.vis.quality
    own = (quality.offsamples, quality.shadowsize)
    assert (VIDEO_QUALITY.msaa_samples, VIDEO_QUALITY.shadow_map_px) == (0, 1024) and own == (4, 2048)
    fast = render_video(robot, tmp_path / "fast.mp4", camera="fixed", fps=FPS, width=W, height=H, trajectory=traj)
    assert (quality.offsamples, quality.shadowsize) == own
    full = render_video(robot, tmp_path / "full.mp4", camera="fixed", fps=FPS, width=W, height=H, trajectory=traj,
                        quality=None)
    assert fast.truth_path.read_text() == full.truth_path.read_text()   # the truth is the scene's, not the image's
    a, b = cv2.VideoCapture(str(fast.video_path)), cv2.VideoCapture(str(full.video_path))
    differ = []
    for _ in range(fast.frames):
        (_, fa), (_, fb) = a.read(), b.read()
        differ.append(float(np.abs(fa.astype(float) - fb.astype(float)).mean()))
    # the same picture, its edges aliased and its shadows softer: under a grey level apart on average
    assert 0.0 < float(np.mean(differ)) < 2.0       # 0.70 measured; a black or another frame: tens


def test_refuses_to_overwrite_and_bad_names(tmp_path):
    robot = preset("seed")
    existing = tmp_path / "clip.mp4"
    existing.write_bytes(b"user's video")
    with pytest.raises(SimError, match="not overwriting"):
        render_video(robot, existing, cycles=1, width=W, height=H)
    assert existing.read_bytes() == b"user's video"
    with pytest.raises(SimError, match=r"\.mp4"):
        render_video(robot, tmp_path / "clip.avi", cycles=1)
    with pytest.raises(SimError, match="camera"):
        render_video(robot, tmp_path / "other.mp4", camera="overhead")
    with pytest.raises(SimError, match="width"):
        render_video(robot, tmp_path / "other.mp4", width=7)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.mp4"]
