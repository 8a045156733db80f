"""Pixels -> world metres through a pinhole camera file (locust.track.camera).

The exact inversion is checked against points projected through the same camera; the
end-to-end check against a MuJoCo render is in tests/test_sim_video.py and
tests/test_sim_live.py.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.track.camera import PlaneCalibration, load
from locust.track.synth import make_hop_video

W, H = 320, 180
# the simulation's side view: camera at +y looking along -y, x runs right to left on screen
ROTATION = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]])
K = np.array([[217.3, 0.0, 159.5], [0.0, 217.3, 89.5], [0.0, 0.0, 1.0]])


def _camera_doc(position=(0.1, 0.6, 0.05), planes=(("nose", 0.0602), ("foot", 0.0602)), width=W, height=H) -> dict:
    return {"camera": "fixed", "width_px": width, "height_px": height, "intrinsics": {"K": K.tolist()},
            "extrinsics": {"rotation_world_to_camera": ROTATION.tolist(), "position_m": list(position)},
            "marker_planes": {"note": "plane y = plane_y_m", **{n: {"plane_y_m": y} for n, y in planes}}}


def _project(points_m: np.ndarray, position) -> np.ndarray:
    cam = (points_m - np.asarray(position)) @ ROTATION.T @ K.T
    return cam[:, :2] / cam[:, 2:]


def test_plane_homography_inverts_the_projection():
    rng = np.random.default_rng(5)
    pos = (0.1, 0.6, 0.05)
    cal = PlaneCalibration("cam.json", K, ROTATION, np.array([pos]), {"nose": 0.0602, "foot": -0.02})
    for name, y in cal.planes_y_m.items():
        world = np.column_stack([rng.uniform(-0.2, 0.4, 50), np.full(50, y), rng.uniform(0.0, 0.15, 50)])
        uv = _project(world, pos)
        x, z = cal.to_world(uv[:, 0], uv[:, 1], name)
        np.testing.assert_allclose(x, world[:, 0], atol=1e-12)
        np.testing.assert_allclose(z, world[:, 2], atol=1e-12)
    x, z = cal.to_world(np.array([np.nan, 100.0]), np.array([np.nan, 50.0]), "nose")
    assert np.isnan(x[0]) and np.isnan(z[0]) and np.isfinite(x[1])
    x, _ = cal.to_world(np.array([100.0]), np.array([50.0]), "tail")     # no plane known: no metres
    assert np.isnan(x).all()


def test_moving_camera_uses_each_frames_position():
    positions = np.array([[0.1 * k, 0.6, 0.05] for k in range(5)])
    cal = PlaneCalibration("cam.json", K, ROTATION, positions, {"nose": 0.0}, camera="track")
    world = np.array([[0.05 + 0.1 * k, 0.0, 0.03] for k in range(5)])      # follows the camera
    uv = np.vstack([_project(world[k:k + 1], positions[k]) for k in range(5)])
    np.testing.assert_allclose(uv[:, 0], uv[0, 0])                        # same pixel every frame...
    x, z = cal.to_world(uv[:, 0], uv[:, 1], "nose", np.arange(5))
    np.testing.assert_allclose(x, world[:, 0], atol=1e-12)                 # ...different world x
    np.testing.assert_allclose(z, 0.03, atol=1e-12)


@pytest.fixture(scope="module")
def video(tmp_path_factory):
    path = tmp_path_factory.mktemp("cam") / "hop_synthetic.mp4"
    make_hop_video(path, width=W, height=H, n_frames=12, seed=2)
    return path


def _track(*args):
    return CliRunner().invoke(cli, ["track", *map(str, args)])


def test_camera_json_beside_the_video_gives_metres(video, tmp_path):
    cam = video.with_name("hop_synthetic.camera.json")
    cam.write_text(json.dumps(_camera_doc()))
    try:
        res = _track(video, "--out", tmp_path / "a.csv", "--overlay", "none")
        assert res.exit_code == 0, res.output
        df = pd.read_csv(tmp_path / "a.csv")
        side = json.loads((tmp_path / "a.json").read_text())
        assert side["calibration"]["source"] == "camera.json"
        # the tracked pixels, mapped by hand through the same camera and plane
        expected = PlaneCalibration("c", K, ROTATION, np.array([[0.1, 0.6, 0.05]]), {"nose": 0.0602})
        x, z = expected.to_world(df.nose_px.to_numpy(), df.nose_py.to_numpy(), "nose")
        np.testing.assert_allclose(df.nose_x_m, x, atol=1e-6)
        np.testing.assert_allclose(df.nose_y_m, z, atol=1e-6)
        # a scale given by hand wins over the camera file
        res = _track(video, "--scale", "0,0,100,0=0.1", "--out", tmp_path / "b.csv", "--overlay", "none")
        assert res.exit_code == 0, res.output
        assert json.loads((tmp_path / "b.json").read_text())["calibration"]["source"].startswith("stick")
    finally:
        cam.unlink()


@pytest.mark.parametrize("doc, words", [
    (_camera_doc(width=640, height=360), "640x360 camera"),
    ({"camera": "fixed", "width_px": W, "height_px": H}, "camera file without"),
    ("{ not json", "not a readable camera file"),
])
def test_bad_camera_files_are_refused(video, tmp_path, doc, words):
    cam = tmp_path / "c.json"
    cam.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    res = _track(video, "--camera-json", cam, "--out", tmp_path / "o.csv")
    assert res.exit_code == 2, res.output
    assert "error:" in res.output and "hint:" in res.output and words in res.output
    assert not (tmp_path / "o.csv").exists()


def test_camera_json_and_scale_conflict(video, tmp_path):
    cam = tmp_path / "c.json"
    cam.write_text(json.dumps(_camera_doc()))
    res = _track(video, "--camera-json", cam, "--scale", "0,0,100,0=0.1", "--out", tmp_path / "o.csv")
    assert res.exit_code == 2 and "not both" in res.output
    assert load(cam, W, H).planes_y_m == {"nose": 0.0602, "foot": 0.0602}
