"""`locust report --side-by-side`: the filmed hop beside the simulation, same camera, same clock.

The filmed trials here are themselves renders of the very rollout the report predicts (the
notebook's robot, one cycle), filmed from a time the report is not told (``T0_S`` on the
schedule's clock), tracked with ``locust track``. The report must then find the first push
in the track, and render the simulation through the trial's ``camera.json``: where both are
right, the two halves show the same pixels, and the marker discs sit in the same place
frame by frame. One trial's camera is fixed, one follows the robot (a camera pose per
frame); one has no camera.json (the simulation's own camera, said so) and one no video.
The page plays each video from the file beside it, in a browser too.
"""

from __future__ import annotations

import dataclasses
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser

import cv2
import mujoco
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.io.camera_json import read_camera_json
from locust.markers import MARKER_COLOURS
from locust.params import preset
from locust.report.sidebyside import OWN_CAMERA, find_video
from locust.sim.camera import CameraView, frame_views
from locust.sim.clip import ClipRecorder, PoseRenderer
from locust.sim.run import run
from locust.trials.measured import load_trial
from test_sim_video import _frames, blob_centroid

W, H, FPS = 320, 240, 30
SETTLE_S = 1.0                 # the model drops onto its feet in the first 0.3 s of it
T0_S = -0.4123                 # the first filmed frame, on the schedule's clock (the report is not told)
SETS = ["--preset", "seed-notebook", "--set", f"solver.settle_s={SETTLE_S}", "--cycles", "1"]
CAPTION_ROWS = 20              # the captions' band at the top of each half


def _robot():
    return preset("seed-notebook").with_values({"solver.settle_s": SETTLE_S})


def _film(traj, robot, path, camera: str) -> int:
    """Render the rollout from T0_S to its end as a filmed clip (hop.mp4, camera.json, truth)."""
    model, s, dt = traj.built.model, traj.built.sensors, traj.timestep_s
    settle = traj.plan.settle_steps
    sd = traj.sensordata[settle - 1:]
    points = np.vstack([sd[:, s.nose_pos], sd[:, s.foot_pos], sd[:, s.chassis_pos], sd[:, s.com_pos]])
    fixed, track = frame_views(points, sd[:, s.chassis_pos][:, 0], robot.geometry.body_length_m, 0.0,
                               float(model.vis.global_.fovy), W / H)
    rec = ClipRecorder(model, path, FPS, W, H, camera, fixed if camera == "fixed" else track, shadows=False)
    times = T0_S + np.arange(int((traj.plan.duration_s - robot.solver.settle_s - T0_S) * FPS)) / FPS
    for k, t in enumerate(times):
        row = int(round(t / dt)) + settle - 1
        rec.add_frame(traj.states[row, 1:1 + model.nq], k / FPS)
    return rec.finish().frames


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    root = tmp_path_factory.mktemp("sbs")
    robot = _robot()
    result = run(robot, cycles=1, keep_states=True)
    assert result.valid
    frames = {}
    for name, camera in (("nb-1", "fixed"), ("nb-2", "track")):
        frames[name] = _film(result.trajectory, robot, root / name / "hop.mp4", camera)
        out = CliRunner().invoke(cli, ["track", str(root / name / "hop.mp4"), "--out", str(root / name)])
        assert out.exit_code == 0, out.output
    # nb-3: the same film without its camera.json (a real camera); nb-4: a track without its video
    (root / "nb-3").mkdir()
    (root / "nb-4").mkdir()
    for f in ("hop.mp4", "hop.tracks.csv"):
        shutil.copy(root / "nb-1" / f, root / "nb-3" / f)
    shutil.copy(root / "nb-1" / "hop.tracks.csv", root / "nb-4" / "hop.tracks.csv")
    measured = [a for n in ("nb-1", "nb-2", "nb-3", "nb-4") for a in ("--measured", str(root / n))]
    out = CliRunner().invoke(cli, ["report", *measured, *SETS, "--out", str(root / "reports"), "--side-by-side"])
    assert out.exit_code == 0, out.output
    folder = root / "reports" / "report"
    doc = json.loads((folder / "report.json").read_text())
    return {"root": root, "folder": folder, "entries": {e["trial"]: e for e in doc["side_by_side"]},
            "frames": frames, "output": out.output}


def test_videos_written_with_the_filmed_size_rate_and_frames(report):
    entries, folder = report["entries"], report["folder"]
    assert set(entries) == {"nb-1", "nb-2", "nb-3", "nb-4"}
    for name in ("nb-1", "nb-2", "nb-3"):
        path = folder / f"{name}.side_by_side.webm"
        assert entries[name]["path"] == str(path) and path.is_file()
        cap = cv2.VideoCapture(str(path))
        size = (int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)))
        fps = cap.get(cv2.CAP_PROP_FPS)
        cap.release()
        assert size == (2 * W, H) and fps == pytest.approx(FPS)
        assert len(_frames(path)) == report["frames"]["nb-1"] == entries[name]["frames"]
        assert f"side by side: {path}" in report["output"]
    assert entries["nb-1"]["camera"] == entries["nb-2"]["camera"] == "camera.json"
    assert "track camera" in entries["nb-2"]["note"]


def test_the_first_push_is_found_as_the_report_finds_it(report):
    """The first filmed frame's time on the schedule's clock, which the report was not told."""
    for name in ("nb-1", "nb-2", "nb-3"):
        assert report["entries"][name]["t0_s"] == pytest.approx(T0_S, abs=0.004), name


def _halves(path):
    frames = _frames(path)
    return frames[:, :, :W], frames[:, :, W:]


@pytest.mark.parametrize("name", ["nb-1", "nb-2"])
def test_simulated_half_matches_the_filmed_half(report, name):
    """Same rollout, same camera (fixed, or one pose per frame), same clock: the same pixels,
    and each marker disc where the film has it, in every frame, but for how far the marker
    moves in the time the report's first push is off (the onset it finds between two 30 fps
    frames; ``T0_S`` is the truth): sub-pixel standing, pushing and landed, a few pixels in
    flight. Offset by two frames, the discs are far apart: the check sees timing."""
    left, right = _halves(report["folder"] / f"{name}.side_by_side.webm")
    diff = np.abs(left[:, CAPTION_ROWS:].astype(int) - right[:, CAPTION_ROWS:])
    assert diff.mean() < 1.5, f"mean |filmed - simulated| = {diff.mean():.2f} grey levels"
    clock_error_s = abs(report["entries"][name]["t0_s"] - T0_S)
    truth = pd.read_csv(report["root"] / name / "hop.truth.csv", comment="#")
    camera = read_camera_json(report["root"] / name / "hop.camera.json")
    errors, allowed, shifted = [], [], []
    for marker, (hex_colour, _) in MARKER_COLOURS.items():
        # the marker's own speed, in pixels of its plane: a camera that follows the robot
        # is held where it was in that frame, so the marker moves in the image this fast
        world = truth[[f"{marker}_x_m", f"{marker}_z_m"]].to_numpy()
        px_per_m = 1.0 / camera.m_per_px_at(camera.marker_planes[marker].plane_y_m)
        speed = np.hypot(*np.gradient(world, axis=0).T) * FPS * px_per_m
        for k in range(len(left)):
            a, b = blob_centroid(left[k], hex_colour), blob_centroid(right[k], hex_colour)
            assert a is not None and b is not None, (k, marker)
            errors.append(np.hypot(a[0] - b[0], a[1] - b[1]))
            allowed.append(0.5 + 1.5 * speed[k] * clock_error_s)
            c = blob_centroid(right[min(k + 2, len(left) - 1)], hex_colour)
            shifted.append(np.hypot(a[0] - c[0], a[1] - c[1]))
    errors, allowed = np.array(errors), np.array(allowed)
    worst = int(np.argmax(errors - allowed))
    assert (errors <= allowed).all(), f"disc {errors[worst]:.2f} px off where {allowed[worst]:.2f} is allowed"
    assert np.median(errors) < 0.2 and np.mean(errors < 0.5) > 0.8
    assert np.max(shifted) > 10 * np.median(errors) + 5
    for half in (left, right):   # a caption on each half: white text on black
        assert (half[:, :CAPTION_ROWS].min(axis=-1) > 200).any(axis=(1, 2)).all()


def test_without_camera_json_the_simulations_own_camera_is_said(report):
    entry = report["entries"]["nb-3"]
    assert entry["camera"] == OWN_CAMERA and "cameras differ" in entry["note"]
    _, right = _halves(report["folder"] / "nb-3.side_by_side.webm")
    for hex_colour, _ in MARKER_COLOURS.values():   # the robot is in its view in every frame
        assert all(blob_centroid(frame, hex_colour) is not None for frame in right)


def test_a_trial_without_video_is_skipped_with_the_reason(report):
    entry = report["entries"]["nb-4"]
    assert entry["path"] is None and "no video" in entry["note"]
    assert not (report["folder"] / "nb-4.side_by_side.webm").exists()
    assert "nb-4 skipped (no video" in report["output"]


class Videos(HTMLParser):
    """Every <video> element's attributes, and the page's Content-Security-Policy."""

    def __init__(self):
        super().__init__()
        self.videos: list[dict] = []
        self.csp = ""

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "video":
            self.videos.append(a)
        if tag == "meta" and a.get("http-equiv") == "Content-Security-Policy":
            self.csp = a["content"]


def _page(report) -> Videos:
    parsed = Videos()
    parsed.feed((report["folder"] / "report.html").read_text(encoding="utf-8"))
    return parsed


def test_the_page_plays_each_video_from_beside_it(report):
    """One <video controls> per written video, its src the file's name (relative: the page lies
    beside it), none for the trial without one (listed with its reason); the policy lets media
    come from the page's own folder and nowhere else."""
    parsed, folder = _page(report), report["folder"]
    srcs = [v["src"] for v in parsed.videos]
    assert srcs == [f"{name}.side_by_side.webm" for name in ("nb-1", "nb-2", "nb-3")]
    for v in parsed.videos:
        assert "controls" in v and (folder / v["src"]).is_file()
        assert "/" not in v["src"] and ":" not in v["src"]
    assert report["entries"]["nb-1"]["path"] == str(folder / srcs[0])
    assert "media-src 'self'" in parsed.csp and "default-src 'none'" in parsed.csp
    assert "nb-4: no video" in (folder / "report.html").read_text(encoding="utf-8")


VIDEO_PROBE = """<script>
window.__errors = [];
document.addEventListener('securitypolicyviolation', e => window.__errors.push('csp: ' + e.blockedURI));
const vids = Array.from(document.querySelectorAll('video'));
let left = vids.length;
const done = () => { if (--left === 0) document.body.setAttribute('data-errors', window.__errors.join(' | ')); };
vids.forEach((v, i) => {
  v.addEventListener('loadeddata', () => { document.body.setAttribute('data-video-' + i,
    v.videoWidth + 'x' + v.videoHeight + ' ' + v.duration); done(); });
  v.addEventListener('error', () => { window.__errors.push('video ' + i + ': ' + (v.error && v.error.code)); done(); });
  v.preload = 'auto'; v.load();
});
</script>"""


def test_the_videos_play_in_headless_chromium(report):
    """Chromium decodes every embedded video from the page's folder (file://), at twice the
    filmed width, for as long as the film, and the page's policy blocks nothing."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        pytest.skip("chromium not installed (Debian package `chromium`)")
    folder = report["folder"]
    text = (folder / "report.html").read_text(encoding="utf-8")
    # the probe goes into a copy beside the page (so each src resolves as it does for the page);
    # its policy allows inline script, nothing else changes
    probe = text.replace("style-src 'unsafe-inline'", "style-src 'unsafe-inline'; script-src 'unsafe-inline'")
    page = folder / "probe.html"
    page.write_text(probe.replace("</body>", VIDEO_PROBE + "</body>"), encoding="utf-8")
    try:
        proc = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--autoplay-policy="
                               "no-user-gesture-required", "--virtual-time-budget=10000", "--dump-dom", page.as_uri()],
                              capture_output=True, text=True, timeout=120)
    finally:
        page.unlink()
    assert proc.returncode == 0, proc.stderr[-2000:]
    attrs = dict(re.findall(r'(data-[\w-]+)="([^"]*)"', re.search(r"<body([^>]*)>", proc.stdout).group(1)))
    assert attrs.get("data-errors") == "", attrs
    duration_s = report["frames"]["nb-1"] / FPS
    for i in range(3):
        size, duration = attrs[f"data-video-{i}"].split()
        assert size == f"{2 * W}x{H}"
        assert float(duration) == pytest.approx(duration_s, abs=1.5 / FPS)


def test_pose_renderer_takes_any_pinhole_camera():
    """A camera.json's pose and intrinsics, rolled, off-centre and with non-square pixels:
    rendered exactly so (each marker's blob within 0.5 px of its projection)."""
    traj = run(_robot(), cycles=1, keep_states=True).trajectory
    model = traj.built.model
    poser = PoseRenderer(model, W, H, shadows=False)
    try:
        data = poser.pose(traj.states[traj.plan.settle_steps + 1500, 1:1 + model.nq])   # in flight
        _, cam = poser.render(CameraView((0.05, 0.0, 0.05), 0.35))
        roll = np.radians(10.0)
        rz = np.array([[np.cos(roll), -np.sin(roll), 0.0], [np.sin(roll), np.cos(roll), 0.0], [0.0, 0.0, 1.0]])
        odd = dataclasses.replace(cam, fx_px=cam.fx_px * 1.1, fy_px=cam.fy_px * 0.95, cx_px=cam.cx_px + 20,
                                  cy_px=cam.cy_px - 15, rotation=rz @ cam.rotation)
        rgb, used = poser.render(odd)
    finally:
        poser.close()
    assert used.fx_px == pytest.approx(odd.fx_px, rel=1e-6) and used.cy_px == pytest.approx(odd.cy_px, abs=1e-4)
    np.testing.assert_allclose(used.rotation, odd.rotation, atol=1e-6)
    bgr = cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)
    for name, (hex_colour, _) in MARKER_COLOURS.items():
        gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"marker_{name}")
        axis = data.geom_xmat[gid].reshape(3, 3)[:, 2]
        face = data.geom_xpos[gid] + np.sign(axis[1]) * axis * float(model.geom_size[gid][1])
        blob = blob_centroid(bgr, hex_colour)
        assert blob is not None
        assert np.hypot(*(np.array(blob) - odd.project(face)[0])) < 0.5, name


def test_a_track_written_away_from_its_video_finds_it_through_its_sidecar(report, tmp_path, monkeypatch):
    """`locust track` writes into the current folder, away from the video: the report finds
    the video the track's sidecar records; a track without its sidecar, or whose video has
    moved, has none."""
    root = report["root"]
    monkeypatch.chdir(tmp_path)
    out = CliRunner().invoke(cli, ["track", str(root / "nb-1" / "hop.mp4")])
    assert out.exit_code == 0, out.output
    assert (tmp_path / "hop.tracks.csv").is_file() and not (tmp_path / "hop.mp4").exists()
    assert find_video(load_trial(tmp_path / "hop.tracks.csv", "seed-notebook")) == (root / "nb-1" / "hop.mp4").resolve()
    (tmp_path / "hop.tracks.json").rename(tmp_path / "kept.json")
    assert find_video(load_trial(tmp_path / "hop.tracks.csv", "seed-notebook")) is None
    doc = json.loads((tmp_path / "kept.json").read_text())
    doc["source"]["video"] = str(tmp_path / "moved.mp4")
    (tmp_path / "hop.tracks.json").write_text(json.dumps(doc))
    assert find_video(load_trial(tmp_path / "hop.tracks.csv", "seed-notebook")) is None
