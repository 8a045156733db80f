"""Where `locust track` writes: into one output folder, named on the
first stderr line as `output folder: <absolute path>`. An input in a folder of its own (a
read-only data folder) is tracked into the current folder, never beside it; a video copied
into a `locust hop --out` run folder is tracked into that folder, where `locust calibrate hop`
and `locust report` read its track; an existing output is never replaced without --force.

Videos: SYNTHETIC hop clips (locust.track.synth, with their true marker centres) and
Tracker's BallToss project, real footage, read where it lies in ../shared/data (a read-only
folder)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.io import trk as trk_io
from locust.track.synth import make_hop_video
from locust.trials.measured import load_trial
from probing import assert_clear_error, tree

OUTPUTS = ["hop.tracks.csv", "hop.tracks.json", "hop.tracks.png"]
SCALE = "0,0,100,0=0.1"    # 1 mm a pixel: the run folder's track in metres, as calibrate and report need


def track(*args):
    return CliRunner().invoke(cli, ["track", *map(str, args)])


def first_line(res) -> str:
    return res.stderr.splitlines()[0]


def nose_rms_px(csv: Path, truth) -> float:
    df = pd.read_csv(csv, comment="#")
    return float(np.sqrt(np.mean((df["nose_px"] - truth.px["nose"]) ** 2 + (df["nose_py"] - truth.py["nose"]) ** 2)))


@pytest.fixture()
def read_only(tmp_path):
    """A SYNTHETIC hop clip (with its truth) and a t,x,y CSV in a folder chmod 555, as a data
    folder the student does not own; writable again at teardown so pytest can remove it."""
    folder = tmp_path / "data"
    folder.mkdir()
    truth = make_hop_video(folder / "hop.mp4", width=320, height=180, n_frames=20, seed=1)
    (folder / "toss.csv").write_text("t,x,y\n0.0,10.0,20.0\n0.1,12.5,18.0\n0.2,15.0,14.5\n")   # SYNTHETIC, cm
    folder.chmod(0o555)
    yield folder, truth
    folder.chmod(0o755)


@pytest.fixture()
def work(tmp_path, monkeypatch):
    """The current folder of the command, empty."""
    folder = tmp_path / "work"
    folder.mkdir()
    monkeypatch.chdir(folder)
    return folder


def test_a_video_in_a_read_only_folder_is_tracked_into_the_current_folder(read_only, work):
    data, truth = read_only
    before = tree(data)
    res = track(data / "hop.mp4")
    assert res.exit_code == 0, res.output
    assert first_line(res) == f"output folder: {work.resolve()}"
    assert sorted(os.listdir(work)) == OUTPUTS
    assert tree(data) == before                                  # nothing beside the video
    assert nose_rms_px(work / "hop.tracks.csv", truth) <= 0.15   # the clip's own track (measured 0.045 px)
    sidecar = json.loads((work / "hop.tracks.json").read_text())
    assert sidecar["source"]["video"] == str((data / "hop.mp4").resolve())   # found again from anywhere


@pytest.mark.parametrize("args, written", [
    (["preview", "{data}/hop.mp4"], ["hop.tracks.preview.png"]),
    (["import", "{data}/toss.csv", "--units", "cm"], ["toss.tracks.csv"]),
    (["board", "boards/b.png"], ["boards"]),
])
def test_every_subcommand_names_its_folder_first_and_writes_there(read_only, work, args, written):
    data, _ = read_only
    before = tree(data)
    res = track(*(a.format(data=data) for a in args))
    assert res.exit_code == 0, res.output
    folder = work / "boards" if args[0] == "board" else work
    assert first_line(res) == f"output folder: {folder.resolve()}"
    assert sorted(os.listdir(work)) == written and tree(data) == before
    if args[0] == "import":    # cm -> m, into the current folder
        df = pd.read_csv(work / "toss.tracks.csv", comment="#")
        np.testing.assert_allclose(df["nose_x_m"], [0.100, 0.125, 0.150], rtol=1e-12)


def test_trackers_project_in_the_shared_data_is_converted_and_tracked_into_the_current_folder(shared_data, work):
    """BallToss.trz lies in ../shared/data/tracker (mode 555): before, every default run there
    stopped with `cannot write in ...: the folder is read-only`."""
    trz = shared_data / "tracker" / "BallToss.trz"
    steps = trk_io.read_project(trz).points["ball"]       # Tracker's own steps, OpenCV's pixels
    res = track("from-trk", trz, "--track", "ball")
    assert res.exit_code == 0, res.output
    assert first_line(res) == f"output folder: {work.resolve()}"
    assert sorted(os.listdir(work)) == ["BallToss.tracks.csv", "BallToss.tracks.json"]
    df = pd.read_csv(work / "BallToss.tracks.csv", comment="#").set_index("frame")
    assert int(df["ball_ok"].sum()) == len(steps) == 11
    got = df.loc[sorted(steps), ["ball_px", "ball_py"]].to_numpy()
    np.testing.assert_allclose(got, [steps[f] for f in sorted(steps)], atol=1e-4)   # the CSV's 4 decimals
    res = track("video", trz, "--marker", "ball=template:131.28,207.86@2", "--out", "redo.csv", "--overlay", "none")
    assert res.exit_code == 0, res.output
    assert first_line(res) == f"output folder: {work.resolve()}"
    redo = pd.read_csv(work / "redo.csv", comment="#").set_index("frame").loc[3:12]
    err = np.hypot(*(redo[["ball_px", "ball_py"]].to_numpy() - [steps[f] for f in range(3, 13)]).T)
    assert err.max() < 0.8, err     # Tracker's hand-clicked points (measured 0.44 px mean, 0.72 max)


@pytest.fixture(scope="module")
def run_json(env, tmp_path_factory) -> Path:
    """A real run record: `locust hop --port sim --out` on the virtual robot, one cycle."""
    folder = tmp_path_factory.mktemp("hops") / "small-1"
    proc = subprocess.run([sys.executable, "-m", "locust.commands", "hop", "--port", "sim", "--preset", "small",
                           "--cycles", "1", "--out", str(folder)], capture_output=True, text=True, env=env,
                          timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr
    return folder / "run.json"


def _run_folder(tmp_path: Path, run_json: Path):
    """A run folder with the camera's clip copied in beside its run.json (docs/hardware.md)."""
    run = tmp_path / "hops" / "small-1"
    run.mkdir(parents=True)
    shutil.copy(run_json, run / "run.json")
    return run, make_hop_video(run / "hop.mp4", width=320, height=180, n_frames=20, seed=2)


def test_a_video_in_a_run_folder_is_tracked_into_it_where_report_and_calibrate_read_it(run_json, tmp_path, work):
    run, truth = _run_folder(tmp_path, run_json)
    res = track(run / "hop.mp4", "--scale", SCALE, "--pixels", "opencv")
    assert res.exit_code == 0, res.output
    assert first_line(res) == f"output folder: {run.resolve()}"
    assert os.listdir(work) == []
    assert sorted(os.listdir(run)) == sorted([*OUTPUTS, "hop.mp4", "hop.truth.csv", "run.json"])
    assert nose_rms_px(run / "hop.tracks.csv", truth) <= 0.15     # measured 0.049 px
    trial = load_trial(run, "small")     # what `locust report` and `locust calibrate hop` take from the folder
    assert trial.track.path == run / "hop.tracks.csv" and trial.run_path == run / "run.json"


def test_a_read_only_run_folder_is_someone_elses_its_track_goes_to_the_current_folder(run_json, tmp_path, work):
    run, _ = _run_folder(tmp_path, run_json)
    run.chmod(0o555)
    try:
        before = tree(run)
        res = track(run / "hop.mp4", "--overlay", "none")
        assert res.exit_code == 0, res.output
        assert first_line(res) == f"output folder: {work.resolve()}"
        assert sorted(os.listdir(work)) == OUTPUTS[:2] and tree(run) == before
    finally:
        run.chmod(0o755)


@pytest.mark.parametrize("args", [["video", "{data}/hop.mp4"], ["preview", "{data}/hop.mp4"],
                                  ["import", "{data}/toss.csv", "--units", "cm"]])
def test_an_existing_output_is_never_replaced_without_force(read_only, work, args):
    data, _ = read_only
    args = [a.format(data=data) for a in args]
    assert track(*args).exit_code == 0
    written = {p.name: p.stat().st_ino for p in work.iterdir()}
    before = tree(work)
    res = track(*args)
    assert res.exit_code == 2 and "output exists" in res.stderr and "--force" in res.stderr, res.output
    assert first_line(res) == f"output folder: {work.resolve()}"
    assert tree(work) == before
    res = track(*args, "--force")
    assert res.exit_code == 0, res.output
    assert all(p.stat().st_ino != written[p.name] for p in work.iterdir())   # each replaced (atomically: new file)
    assert {p.name for p in work.iterdir()} == set(written)


@pytest.fixture()
def frames(tmp_path) -> Path:
    """A SYNTHETIC image sequence: a 10x10 px patch of #e8308c on black, 5 px further right each frame."""
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(4):
        img = np.zeros((60, 80, 3), np.uint8)
        img[20:30, 10 + 5 * i:20 + 5 * i] = (140, 48, 232)
        cv2.imwrite(str(folder / f"f{i:03d}.png"), img)
    return folder


def test_a_sequence_tracked_from_inside_its_folder_is_refused_there_and_written_with_out(frames, tmp_path,
                                                                                         monkeypatch):
    """`locust track .` inside the frames' folder: the outputs would land among the frames (a
    `frames.tracks.png` the next run reads as one), so it is refused, as a clear error (it was a
    traceback: `.` has no name); `--out ..` writes them beside the folder."""
    monkeypatch.chdir(frames)
    before = tree(frames)
    args = [".", "--fps", 10, "--marker", "spot=color:#e8308c", "--pixels", "opencv"]
    res = track(*args)
    assert_clear_error(res, "a frame of the image sequence")
    assert first_line(res) == f"output folder: {frames.resolve()}"
    assert tree(frames) == before
    res = track(*args, "--out", "..")
    assert res.exit_code == 0, res.output
    assert first_line(res) == f"output folder: {tmp_path.resolve()}" and tree(frames) == before
    df = pd.read_csv(tmp_path / "frames.tracks.csv", comment="#")
    np.testing.assert_allclose(df["spot_px"], [14.5, 19.5, 24.5, 29.5], atol=0.01)   # the patch's centres


def test_preview_of_an_image_sequence_needs_no_frame_rate(frames, work):
    before = tree(frames)
    res = track("preview", frames, "--frame", 2)
    assert res.exit_code == 0, res.output      # was: `an image sequence has no frame rate`, and no --fps to give
    assert first_line(res) == f"output folder: {work.resolve()}"
    assert "#e8308c" in res.stdout and "(100 px)" in res.stdout, res.stdout    # the 10x10 patch
    assert os.listdir(work) == ["frames.tracks.preview.png"] and tree(frames) == before


def test_out_naming_a_folder_not_there_yet_makes_it(tmp_path, monkeypatch):
    """`--out newdir/`: the folder, made, the tracks in it (it was a file `newdir.csv` in the
    current folder); `--out name` without the slash stays the outputs' name."""
    make_hop_video(tmp_path / "hop.mp4", width=320, height=180, n_frames=20, seed=1)
    monkeypatch.chdir(tmp_path)
    res = track(tmp_path / "hop.mp4", "--out", "newdir/")
    assert res.exit_code == 0, res.output
    folder = tmp_path / "newdir"
    assert folder.is_dir() and (folder / "hop.tracks.csv").is_file()
    assert first_line(res) == f"output folder: {folder}"
    assert not (tmp_path / "newdir.csv").exists()
    res = track(tmp_path / "hop.mp4", "--out", "named")
    assert res.exit_code == 0, res.output
    assert (tmp_path / "named.csv").is_file() and not (tmp_path / "named").exists()


def test_a_track_onto_a_name_another_track_is_writing_is_refused(tmp_path):
    """Two `locust track --out same` at once: the names are claimed before tracking (the lock
    the first holds while it tracks and writes, held here by the test), so the second is refused
    at once and writes nothing (both used to exit 0, one replacing the other)."""
    from locust.fileio import locked

    video = tmp_path / "hop.mp4"
    make_hop_video(video, width=320, height=180, n_frames=20, seed=2)
    out = tmp_path / "same"
    out.mkdir()
    with locked(out / "hop.tracks.csv", wait_s=0):
        res = subprocess.run([sys.executable, "-m", "locust.commands", "track", str(video), "--out", str(out)],
                             capture_output=True, text=True, timeout=120)
        assert res.returncode == 2, res.stderr
        assert f"error: {out / 'hop.tracks.csv'} is being written by another `locust track` now" in res.stderr
        assert "hint:" in res.stderr and "Traceback" not in res.stderr
        assert [p.name for p in out.iterdir()] == [".hop.tracks.csv.lock"]     # nothing of its own
    done = track(video, "--out", out)
    assert done.exit_code == 0, done.output                                       # once the name is free
    assert (out / "hop.tracks.csv").is_file() and not (out / ".hop.tracks.csv.lock").exists()
