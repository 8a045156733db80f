"""`locust track` with Tracker's own examples (../shared/data/tracker): an image sequence
(CupsClips), a .trk written and read back, a project's calibration on its video, a .trz as input."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.io import trk as trk_io
from locust.track import trk


@pytest.fixture(scope="module")
def cups(tracker_example):
    return tracker_example("CupsClips.zip")


@pytest.fixture(scope="module")
def balltoss(tracker_example):
    return tracker_example("BallToss.trz")


@pytest.fixture(scope="module")
def cups_run(cups):
    """Both cups tracked from the points Tracker's user clicked on frame 0, with a .trk out."""
    project = trk_io.read_project(cups / "CupsClips_CupsClips.trk")
    # as Tracker's table shows them (its convention, the default): OpenCV's + 0.5 px
    c3, c7 = ((x - trk_io.TRACKER_TO_OPENCV_PX, y - trk_io.TRACKER_TO_OPENCV_PX)
              for x, y in (project.points["cup 3"][0], project.points["cup 7"][0]))
    res = CliRunner().invoke(cli, ["track", str(cups / "videos" / "CupsClips_CupsClips00.jpg"), "--fps", "10.1",
                                   "--marker", f"cup3=template:{c3[0]:.2f},{c3[1]:.2f}@0",
                                   "--marker", f"cup7=template:{c7[0]:.2f},{c7[1]:.2f}@0",
                                   "--out", str(cups / "cups.csv"), "--trk", str(cups / "cups_out.trk")])
    assert res.exit_code == 0, res.output
    return project, pd.read_csv(cups / "cups.csv"), res.output


@pytest.mark.parametrize("name, theirs", [("cup3", "cup 3"), ("cup7", "cup 7")])
def test_image_sequence_cups_follow_trackers_points(cups_run, name, theirs):
    project, df, _ = cups_run
    assert len(df) == 17                                           # the whole numbered run, frames 0..16
    assert df["t_s"].iloc[-1] == pytest.approx(16 / 10.1)
    ref = project.points[theirs]                                   # Tracker's steps: frames 0..8
    got = df.set_index("frame").loc[sorted(ref)]
    ok = got[f"{name}_ok"].astype(bool).to_numpy()
    err = np.hypot(got[f"{name}_px"] - [ref[f][0] for f in sorted(ref)],
                   got[f"{name}_py"] - [ref[f][1] for f in sorted(ref)]).to_numpy()
    assert (~ok).sum() <= 2                                        # acceptance 2; measured 0
    assert err[0] < 0.01, err             # the key frame: Tracker's numbers, typed in its convention, are its point
    assert err[ok].max() <= 1.2, err                               # acceptance 10 px; measured 0.79 / 0.94
    assert err[ok].mean() <= 0.6, err                              # acceptance 3 px; measured 0.50 / 0.56
    # 0.5 px mean is within this reference's own scatter: Tracker's points here are clicked by
    # hand (each on a grid of 240/959 px, the screen's pixels at Tracker's zoom: see
    # test_trackers_points_are_clicks_on_the_screens_grid). The .trk holds no autotracker data
    # (Tracker 6's source saves none: no key frame, mask, evolve rate or search area), and its
    # autotracker could not have made them: with its defaults (16.2 px elliptic mask, +-40 px
    # search centred on the clicks) the cups' peak height is 0.9-5.5, under its automark of 4
    # on 10 of 16 frames (frame 1: 0.9 and 2.0, where it would stop), and another place in the
    # search area matches better on 10 of 16. Its own steps (square difference, parabola
    # sub-pixel step, 20 % evolve, 5 % tether), written out from its source and run on these
    # frames from the same key points, are 0.50 / 0.56 px mean from the clicks: as here.
    # The clicks scatter about the track by 0.25 / 0.24 px per axis (an upper bound on their
    # own scatter); a tracker with no error of its own, keyed on one click and compared with
    # eight more so scattered, is over 0.5 px mean on a cup one time in seven (simulated,
    # 0.36 px median), so a 0.5 px bound would test the clicks, not the tracker.
    # Most of the error is one constant offset over frames 1..8 (measured 0.46 / 0.59 px: the
    # key frame's click, on a cup still against its holder); about it the track follows the
    # clicks to 0.33 / 0.31 px mean. No evolve rate (0-40 %) or radius (4-8 px) brings both
    # under 0.5, nor (measured on frames 1..8 at the 20 % evolve rate, cup 3 / cup 7, from
    # 0.56 / 0.63): for the sub-pixel step a 3x3 quadratic (0.58 / 0.65) or a parabola on the
    # square difference or on normalised correlation (0.57 / 0.63, 0.56 / 0.62), resampling
    # about the best match in 0.05 px steps (the same to 0.1 px); Tracker's 5 % tether to the
    # key template (0.56 / 0.63; it loses the markerless clip's servo label, 104 of 300
    # frames); a centre-weighted mask (sigma 3-6 px: 0.57 / 0.63; 2 px: 0.45 / 0.59 with a
    # frame lost); the template cut at the sub-pixel key point (0.67-0.72 / 0.54-0.56) or
    # about the marker's centre of symmetry (0.37-0.69 / 0.62-0.65, or cup 3 lost); a mask of
    # the pixels that move by the next frame (0.57 / 0.64). The key frame's template alone,
    # resampled onto each frame, is 0.73 / 0.63 px off: the cup's look against its holder on
    # frame 0 is what sets the offset.


def _screen_grid_residual(points: dict[int, tuple[float, float]], image_height_px: int) -> float:
    """Largest distance (in grid steps) of Tracker's points from the grid of the screen's pixels
    at a zoom that draws the image 959 screen pixels high: x on (k - 1/6) steps, y on whole steps."""
    step = image_height_px / 959
    xy = np.array([(x - trk_io.TRACKER_TO_OPENCV_PX, y - trk_io.TRACKER_TO_OPENCV_PX)    # Tracker's own numbers
                   for x, y in points.values()]) / step
    xy[:, 0] += 1 / 6
    return float(np.abs(xy - np.round(xy)).max())


def test_trackers_points_are_clicks_on_the_screens_grid(cups, balltoss):
    """The reference is hand clicks: every step of both cups (frames 0..8) and of the ball
    (frames 3..12; frame 2 sits on the axes' origin) lies on the grid of the screen's pixels,
    240/959 px (CupsClips, zoomed about 4x) and 480/959 px (BallToss, about 2x), to 1e-4 of a
    step (measured below 1e-9). An autotracker's sub-pixel peak lands that near the grid by chance
    with a probability of 2e-4 per number; all 56 numbers do. A step off the grid by 0.1 px fails."""
    cups_project = trk_io.read_project(cups / "CupsClips_CupsClips.trk")
    ball = trk_io.read_project(balltoss / "BallToss_BallToss.trk").points["ball"]
    for name in ("cup 3", "cup 7"):
        assert len(cups_project.points[name]) == 9
        assert _screen_grid_residual(cups_project.points[name], 240) < 1e-4
    assert _screen_grid_residual({f: ball[f] for f in range(3, 13)}, 480) < 1e-4
    moved = dict(cups_project.points["cup 3"])
    moved[4] = (moved[4][0] + 0.1, moved[4][1])
    assert _screen_grid_residual(moved, 240) > 0.3


def _cups_keyed_on(cups, key):
    """Both cups tracked from the points Tracker's user clicked on frame ``key`` (Tracker's
    convention, as its table shows them): frame -> (x, y) or None, per cup, for frames key+1..16."""
    project = trk_io.read_project(cups / "CupsClips_CupsClips.trk")
    args = ["track", str(cups / "videos" / "CupsClips_CupsClips00.jpg"), "--fps", "10.1", "--overlay", "none",
            "--out", str(cups / f"key{key}.csv"), "--force"]
    for name, theirs in (("cup3", "cup 3"), ("cup7", "cup 7")):
        x, y = (v - trk_io.TRACKER_TO_OPENCV_PX for v in project.points[theirs][key])
        args += ["--marker", f"{name}=template:{x:.2f},{y:.2f}@{key}"]
    res = CliRunner().invoke(cli, args)
    assert res.exit_code == 0, res.output
    df = pd.read_csv(cups / f"key{key}.csv").set_index("frame").loc[key + 1:]
    return {name: {f: (row[f"{name}_px"], row[f"{name}_py"]) if row[f"{name}_ok"] else None
                   for f, row in df.iterrows()} for name in ("cup3", "cup7")}


def test_cups_keyed_mid_fall_are_lost_not_followed_onto_a_neighbour(cups):
    """Keyed on a falling cup (Tracker's clicks on frames 1..7), the first step has no path to go
    by, and the row of look-alike cups (11-12 px apart, the cup falling 10-30 px a frame) offers a
    neighbour as near: that step is lost, not taken. (Before, the track hopped to the neighbour
    and on down the row at the row's slope, reported found 11-70 px from the cup.) Cup 7 keyed
    on frames 2 and 3 has one match standing out and is followed to frame 8 (measured within
    0.65 px of Tracker's clicks); every other key loses its cup for good: no frame is reported
    anywhere else."""
    project = trk_io.read_project(cups / "CupsClips_CupsClips.trk")
    followed = {}
    for key in range(1, 8):
        for name, found in _cups_keyed_on(cups, key).items():
            ref = project.points["cup 3" if name == "cup3" else "cup 7"]
            ok = [f for f, p in found.items() if p is not None]
            followed[name, key] = ok
            err = [np.hypot(found[f][0] - ref[f][0], found[f][1] - ref[f][1]) for f in ok if f in ref]
            assert all(f in ref for f in ok), (name, key, ok)       # nothing past Tracker's last click
            assert max(err, default=0.0) <= 1.0, (name, key, err)   # measured 0.65; was up to 69.8
    assert {k: v for k, v in followed.items() if v} == {("cup7", 2): [3, 4, 5, 6, 7, 8],
                                                         ("cup7", 3): [4, 5, 6, 7, 8]}


def test_cup_out_of_view_is_lost_not_stuck(cups_run):
    """Cup 7 leaves the picture after frame 8 (Tracker's last step at y = 211 px of 240, falling
    30 px a frame): it is reported lost there, never found on a still look-alike."""
    _, df, output = cups_run
    after = df[df["frame"] >= 10]
    assert not after["cup7_ok"].any()
    assert after["cup7_px"].isna().all()
    assert "hint: cup3, cup7: lost" in output


def test_trk_out_reads_back_to_the_same_points(cups, cups_run):
    _, df, _ = cups_run
    res = CliRunner().invoke(cli, ["track", "from-trk", str(cups / "cups_out.trk"), "--out", str(cups / "back.csv")])
    assert res.exit_code == 0, res.output
    back = pd.read_csv(cups / "back.csv")
    assert list(back.columns) == list(df.columns)
    assert (back["frame"] == df["frame"]).all()
    assert np.abs(back["t_s"] - df["t_s"]).max() < 1e-9
    for name in ("cup3", "cup7"):
        assert (back[f"{name}_ok"] == df[f"{name}_ok"]).all()
        for axis in ("px", "py"):
            assert np.nanmax(np.abs(back[f"{name}_{axis}"] - df[f"{name}_{axis}"])) <= 0.01
    project = trk_io.read_project(cups / "cups_out.trk")
    assert project.video_path == "videos/CupsClips_CupsClips00.jpg"     # relative to the .trk, as Tracker saves
    assert project.clip.fps == pytest.approx(10.1)


def test_calibration_from_trk_gives_trackers_metres(balltoss, tmp_path):
    res = CliRunner().invoke(cli, ["track", str(balltoss / "videos" / "BallToss_new_BallToss.mp4"),
                                   "--marker", "ball=template:131.28,207.86@2",
                                   "--calibration-from", str(balltoss / "BallToss_BallToss.trk"),
                                   "--out", str(tmp_path / "ball.csv"), "--trk", str(tmp_path / "ball.trk")])
    assert res.exit_code == 0, res.output
    df = pd.read_csv(tmp_path / "ball.csv")
    theirs = trk.project_result(trk_io.read_project(balltoss / "BallToss_BallToss.trk"))
    x, y = theirs.tracks.x_m["ball"], theirs.tracks.y_m["ball"]
    ok = df["ball_ok"].astype(bool).to_numpy()
    assert ok[2:].all() and not ok[:2].any()                       # Tracker's steps: frames 2..12
    assert np.abs(df["t_s"] - theirs.tracks.t_s).max() < 1e-9             # the project's 66 ms frame interval
    err_mm = 1000 * np.hypot(df["ball_x_m"] - x, df["ball_y_m"] - y)[ok]
    assert err_mm.max() <= 2.5, err_mm                              # acceptance 5 mm; measured 1.8, mean 1.0
    written = trk_io.read_project(tmp_path / "ball.trk")
    assert written.calibration.m_per_px == pytest.approx(theirs.calibration.m_per_px, rel=1e-12)
    assert written.calibration.angle_deg == pytest.approx(theirs.calibration.angle_deg, abs=1e-12)
    assert written.calibration.origin_x_px == pytest.approx(theirs.calibration.origin_x_px, abs=1e-9)


def test_trz_is_a_video_and_an_import(shared_data, tmp_path):
    trz = shared_data / "tracker" / "BallToss.trz"
    res = CliRunner().invoke(cli, ["track", str(trz), "--marker", "ball=template:131.28,207.86@2",
                                   "--out", str(tmp_path / "t.csv"), "--trk", str(tmp_path / "t.trk")])
    assert res.exit_code == 0, res.output
    assert pd.read_csv(tmp_path / "t.csv")["ball_ok"].sum() == 11
    assert trk_io.read_project(tmp_path / "t.trk").video_path.endswith("BallToss.trz!/videos/BallToss_new_BallToss.mp4")
    res = CliRunner().invoke(cli, ["track", "import", str(trz), "--out", str(tmp_path / "i.csv")])
    assert res.exit_code == 0, res.output
    imported = pd.read_csv(tmp_path / "i.csv")
    assert imported["ball_ok"].sum() == 11                         # Tracker's steps, frames 2..12
    assert imported["ball_x_m"].iloc[2] == pytest.approx(0.0, abs=1e-12)


def test_image_sequence_needs_a_frame_rate(cups):
    res = CliRunner().invoke(cli, ["track", str(cups / "videos" / "CupsClips_CupsClips00.jpg"),
                                   "--marker", "c=template:203.4,34.5@0", "--out", str(cups / "nofps.csv")])
    assert res.exit_code == 2
    assert "no frame rate" in res.output and "--fps" in res.output


def test_a_folder_is_the_same_sequence_and_a_lone_image_is_refused(cups, cups_run, tmp_path):
    _, df, _ = cups_run
    project = trk_io.read_project(cups / "CupsClips_CupsClips.trk")
    c3 = project.points["cup 3"][0]        # in OpenCV's pixels: the same point as the fixture's
    res = CliRunner().invoke(cli, ["track", str(cups / "videos"), "--fps", "10.1", "--overlay", "none",
                                   "--pixels", "opencv", "--marker", f"cup3=template:{c3[0]:.2f},{c3[1]:.2f}@0",
                                   "--out", str(tmp_path / "folder.csv")])
    assert res.exit_code == 0, res.output
    folder = pd.read_csv(tmp_path / "folder.csv")
    assert np.array_equal(folder["cup3_px"].to_numpy(), df["cup3_px"].to_numpy(), equal_nan=True)
    lone = tmp_path / "shot.jpg"
    lone.write_bytes((cups / "videos" / "CupsClips_CupsClips00.jpg").read_bytes())
    res = CliRunner().invoke(cli, ["track", str(lone), "--fps", "10", "--marker", "c=template:203.4,34.5@0"])
    assert res.exit_code == 2 and "a single image" in res.output
