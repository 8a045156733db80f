"""A phone video's clock: track times are the video file's own timestamps.

Phones record at a variable frame rate, and their MP4s say when each frame was taken. Tracks
were timed `t = frame / fps` with the file's nominal rate: on a clip of 120 frames at 60 fps
then 120 at 20 fps (OpenCV states 30 frames/s for it), frame 120 was written at 4.000 s, taken
at 2.000 s; on real phone footage (../shared/data/video, frames 15 to 50 ms apart) frames were
up to 34 ms (two frames) off. The truth here is the MP4's own boxes, read by tests/mp4boxes.py
with no OpenCV or FFmpeg: every frame's time within half a frame of them (to the CSV's 1 us,
in fact). A rate given with --fps spaces frames evenly, so it is refused for such a file, as
is a Tracker project (which times frames as frame x delta_t) of one."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from locust.track.synth import make_hop_video
from mp4boxes import presentation_times_s, retime
from probing import assert_clear_error, invoke, tree

RUNS = [(120, 1 / 60), (120, 1 / 20)]      # 60 frames/s for 2 s, then 20 frames/s for 6 s


@pytest.fixture(scope="module")
def vfr(tmp_path_factory):
    """A SYNTHETIC hop clip (known dot centres per frame) whose MP4 states 120 frames 1/60 s
    apart, then 120 frames 1/20 s apart."""
    folder = tmp_path_factory.mktemp("vfr")
    truth = make_hop_video(folder / "hop.mp4", width=320, height=180, n_frames=240, seed=1)
    retime(folder / "hop.mp4", RUNS)
    return folder / "hop.mp4", truth


def test_the_retimed_clip_states_what_a_variable_rate_phone_file_does(vfr):
    video, _ = vfr
    t = presentation_times_s(video)
    assert len(t) == 240 and t[120] == pytest.approx(2.0, abs=1e-9) and t[-1] == pytest.approx(7.95, abs=1e-9)


def test_a_variable_frame_rate_clip_is_timed_by_its_container(vfr, tmp_path):
    video, truth = vfr
    res = invoke(["track", video, "--out", tmp_path / "t.csv", "--overlay", "none"])
    assert res.exit_code == 0, res.output
    df = pd.read_csv(tmp_path / "t.csv")
    stamps = presentation_times_s(video)
    half_frame_s = 0.5 * np.diff(stamps)                      # each frame's own interval
    off = np.abs(df["t_s"].to_numpy() - (stamps - stamps[0]))
    assert np.all(off[1:] <= half_frame_s), off.max()
    assert off.max() <= 1e-6                                  # the CSV's precision
    assert df.loc[120, "t_s"] == pytest.approx(2.0, abs=1e-6)
    # the positions are the clip's own (retiming moves no pixel): measured 0.045 px rms
    rms = np.sqrt(np.mean((df["nose_px"] - truth.px["nose"]) ** 2 + (df["nose_py"] - truth.py["nose"]) ** 2))
    assert rms <= 0.15, rms
    sidecar = json.loads((tmp_path / "t.json").read_text())
    assert sidecar["clip"]["time"].startswith("t_s = the frame's timestamp in the video file")
    assert "times: the video's own timestamps, its frames 16.7 to 50.0 ms apart" in res.output


def test_real_phone_footage_is_timed_by_its_container(shared_data, tmp_path):
    video = shared_data / "video" / "fourbar_robot_walk_oblique_1.mp4"
    stamps = presentation_times_s(video)[:60]
    nominal = np.arange(60) / 59.87590313218457               # the rate the file states
    assert np.abs(stamps - nominal).max() > 0.030             # frames up to 34 ms off frame / fps
    res = invoke(["track", video, "--end", "59", "--out", tmp_path / "t.csv", "--overlay", "none",
                  "--pixels", "opencv", "--marker", "servo=template:425,272@0"])
    assert res.exit_code == 0, res.output
    t = pd.read_csv(tmp_path / "t.csv")["t_s"].to_numpy()
    off = np.abs(t - (stamps - stamps[0]))
    assert np.all(off[1:] <= 0.5 * np.diff(stamps)) and off.max() <= 1e-6, off.max()


def test_a_rate_given_for_a_variable_frame_rate_clip_is_refused(vfr, tmp_path):
    video, _ = vfr
    before = tree(tmp_path)
    res = invoke(["track", video, "--fps", "60", "--out", tmp_path / "t.csv", "--overlay", "none"])
    assert_clear_error(res, "a rate of 60 frames/s", "16.7 to 50.0 ms apart", "frame 120 stamped 2.000 s",
                       "leave out --fps")
    assert tree(tmp_path) == before


def test_a_tracker_project_of_a_variable_frame_rate_clip_is_refused(vfr, tmp_path):
    video, _ = vfr
    before = tree(tmp_path)
    res = invoke(["track", video, "--out", tmp_path / "t.csv", "--overlay", "none", "--trk", tmp_path / "t.trk"])
    assert_clear_error(res, "frame x delta_t", "nothing was written", "leave out --trk")
    assert tree(tmp_path) == before


def test_timestamps_that_go_back_are_refused(tmp_path):
    make_hop_video(tmp_path / "hop.mp4", width=160, height=120, n_frames=40, seed=2)
    retime(tmp_path / "hop.mp4", [(20, 1 / 60), (1, 0.0), (19, 1 / 60)])   # frames 20 and 21 at one time
    stamps = presentation_times_s(tmp_path / "hop.mp4")
    assert stamps[21] == stamps[20]
    before = tree(tmp_path)
    res = invoke(["track", tmp_path / "hop.mp4", "--out", tmp_path / "t.csv", "--overlay", "none"])
    assert_clear_error(res, "frame 21 is stamped 0.3333 s, not after frame 20", "damaged", "constant frame rate")
    assert tree(tmp_path) == before


def test_a_constant_rate_file_keeps_frame_over_fps(tmp_path):
    """Guard: a file whose stamps are frame / fps (rounded to its time base) keeps exactly those
    times, as before."""
    make_hop_video(Path(tmp_path) / "cfr.mp4", width=160, height=120, n_frames=30, fps=240.0, seed=4)
    res = invoke(["track", tmp_path / "cfr.mp4", "--start", "4", "--out", tmp_path / "t.csv", "--overlay", "none"])
    assert res.exit_code == 0, res.output
    np.testing.assert_allclose(pd.read_csv(tmp_path / "t.csv")["t_s"], np.arange(26) / 240, atol=5e-7)
    assert json.loads((tmp_path / "t.json").read_text())["clip"]["time"] == "t_s = (frame - start) / fps"
