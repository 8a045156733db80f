"""File names that are not UTF-8 (a folder copied from an old camera or another system:
`$'bad\\xff\\xfename'`), read and written by every command that hands a path to OpenCV.

OpenCV takes a name as UTF-8 text, and one holding bytes that are not (Python keeps them as
lone surrogates) crashed it with a segmentation fault: `locust track`, `locust hop --port sim
--video` and `locust sim --video` died with SIGSEGV, the last two leaving a temporary video
behind. Each runs here in a process of its own (a crash ends only that one), on SYNTHETIC
clips with their truth; the files are reached through a UTF-8 link to the same inode only to
check them."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from locust.track.synth import make_hop_video

LOCUST = [sys.executable, "-m", "locust.commands"]
BAD = os.fsdecode(b"bad\xff\xfename")      # 'bad\udcff\udcfename' as Python keeps it


def run(args, cwd: Path, env=None, timeout: float = 240) -> subprocess.CompletedProcess:
    return subprocess.run(LOCUST + [os.fspath(a) for a in args], cwd=cwd, env=env, capture_output=True,
                          timeout=timeout, check=False)


def frames_in(video: Path, tmp_path: Path) -> int:
    """The frames a video decodes to, read through a UTF-8 hard link of it."""
    plain = tmp_path / f"plain{len(list(tmp_path.iterdir()))}{video.suffix}"
    os.link(video, plain)
    cap = cv2.VideoCapture(str(plain))
    n = 0
    while cap.grab():
        n += 1
    cap.release()
    plain.unlink()
    return n


def temporaries(folder: Path) -> list[str]:
    return [p.name for p in folder.rglob(".*")]


@pytest.fixture()
def bad(tmp_path):
    """A folder whose name is not UTF-8 holding a SYNTHETIC hop clip (made under a plain name
    and moved there), and the clip's truth."""
    truth = make_hop_video(tmp_path / "hop.mp4", width=320, height=180, n_frames=20, seed=1)
    folder = tmp_path / BAD
    folder.mkdir()
    os.rename(tmp_path / "hop.mp4", folder / "hop.mp4")
    return folder, truth


def test_track_reads_and_writes_under_a_name_that_is_not_utf8(bad, tmp_path):
    folder, truth = bad
    proc = run(["track", folder / "hop.mp4", "--out", f"{BAD}/", "--overlay", "video"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    df = pd.read_csv(folder / "hop.tracks.csv", comment="#")
    rms = np.sqrt(np.mean((df["nose_px"] - truth.px["nose"]) ** 2 + (df["nose_py"] - truth.py["nose"]) ** 2))
    assert rms <= 0.15, rms                                      # the clip's own track (measured 0.045 px)
    assert frames_in(folder / "hop.tracks.overlay.mp4", tmp_path) == 20
    assert temporaries(folder) == []


def test_an_image_sequence_under_a_name_that_is_not_utf8_tracks_as_its_video(bad, tmp_path):
    folder, _ = bad
    frames = folder / "frames"
    frames.mkdir()
    os.link(folder / "hop.mp4", tmp_path / "plain.mp4")
    cap = cv2.VideoCapture(str(tmp_path / "plain.mp4"))
    for i in range(20):
        ok, image = cap.read()
        assert ok
        (frames / f"f{i:03d}.png").write_bytes(cv2.imencode(".png", image)[1].tobytes())   # lossless
    cap.release()
    proc = run(["track", frames, "--fps", "60", "--out", "seq.csv", "--overlay", "none"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = run(["track", "plain.mp4", "--out", "video.csv", "--overlay", "none"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    seq, video = (pd.read_csv(tmp_path / n, comment="#") for n in ("seq.csv", "video.csv"))
    np.testing.assert_allclose(seq[["nose_px", "nose_py", "foot_px", "foot_py", "t_s"]],
                               video[["nose_px", "nose_py", "foot_px", "foot_py", "t_s"]], atol=1e-9)


def test_sim_video_writes_under_a_name_that_is_not_utf8(tmp_path):
    folder = tmp_path / BAD
    folder.mkdir()
    proc = run(["sim", "--cycles", "1", "--video", folder / "v.mp4"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    truth = pd.read_csv(folder / "v.truth.csv", comment="#")
    assert len(truth) > 10 and frames_in(folder / "v.mp4", tmp_path) == len(truth)
    assert (folder / "v.camera.json").is_file() and temporaries(folder) == []


def test_hop_video_of_the_virtual_robot_under_a_name_that_is_not_utf8(env, tmp_path):
    folder = tmp_path / BAD
    folder.mkdir()
    proc = run(["hop", "--port", "sim", "--cycles", "1", "--video", folder / "h.mp4", "--out", folder / "run"],
               tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr
    truth = pd.read_csv(folder / "h.truth.csv", comment="#")
    assert len(truth) > 10 and frames_in(folder / "h.mp4", tmp_path) == len(truth)
    assert (folder / "run" / "run.json").is_file() and temporaries(folder) == []
