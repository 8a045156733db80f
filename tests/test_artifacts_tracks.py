"""The track layer's files, each through its one owner: write -> read back -> equal.

- the tracks CSV (locust.io.tracks_csv), lost frames (NaN, ok 0) included, and what
  other programs make of it (true/false, semicolons and decimal commas);
- Tracker's text export (locust.io.tracker_text): steps a track does not have, a frame
  no track has, Tracker 6's shared time column, per-track time columns;
- camera.json (locust.io.camera_json): a fixed and a following camera, a plane without its
  stray distance (null in JSON, NaN here);
- a Tracker project (.trk) written from a tracking result (locust.track.trk) and read back by
  its reader (locust.io.trk): steps, clip, calibration, and the tracks in metres.

Numbers here are SYNTHETIC (chosen to survive the files' decimals exactly).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from locust.calibrate.recordings import read_table
from locust.errors import TrackError
from locust.io import camera_json as cam
from locust.io import tracker_text as tt
from locust.io import tracks_csv as tc
from locust.io import trk as trk_io
from locust.track import camera as track_camera
from locust.track import trk
from locust.track.runner import TrackResult
from locust.track.video import Clip, VideoInfo

NAN = math.nan


def _tracks() -> tc.TracksCsv:
    ok = np.array([True, True, False, True])
    return tc.TracksCsv(frame=np.array([3, 4, 5, 6]), t_s=np.array([0.0, 1 / 30, 2 / 30, 0.1]),
                        px={"nose": np.array([10.5, 11.25, NAN, 13.0]), "foot": np.array([5.0, 5.5, 6.0, 6.5])},
                        py={"nose": np.array([200.0, 199.5, NAN, 197.125]), "foot": np.array([220.0] * 4)},
                        x_m={"nose": np.array([0.1, 0.105, NAN, 0.115]), "foot": np.full(4, NAN)},  # foot: no scale
                        y_m={"nose": np.array([0.02, 0.025, NAN, 0.03]), "foot": np.full(4, NAN)},
                        ok={"nose": ok, "foot": np.ones(4, bool)}, comments=("synthetic: four frames", "truth: none"))


def test_tracks_csv_round_trip_keeps_lost_frames_and_notes(tmp_path):
    tracks = _tracks()
    path = tc.write_tracks_csv(tmp_path / "hop.tracks.csv", tracks)
    text = path.read_text()
    derived = "vx_m_per_s,{0}_vy_m_per_s,{0}_ax_m_per_s2,{0}_ay_m_per_s2"
    header = (f"frame,t_s,nose_px,nose_py,nose_x_m,nose_y_m,nose_ok,nose_{derived.format('nose')},"
              f"foot_px,foot_py,foot_x_m,foot_y_m,foot_ok,foot_{derived.format('foot')}")
    assert text.splitlines()[:3] == ["# synthetic: four frames", "# truth: none", header]
    # the nose lost on frame 5 has no velocity next to it; the foot has no metres, so none
    assert text.splitlines()[5] == ("5,0.066667,nan,nan,nan,nan,0,nan,nan,nan,nan,"
                                    "6.0000,220.0000,nan,nan,1,nan,nan,nan,nan")
    back = tc.read_tracks_csv(path)
    t_written = np.round(tracks.t_s, 6)
    assert back == tc.TracksCsv(tracks.frame, t_written, tracks.px, tracks.py, tracks.x_m, tracks.y_m, tracks.ok,
                                tracks.comments)
    assert back.path == path and back.columns == tuple(text.splitlines()[2].split(","))
    assert tc.tracks_csv_text(back) == text                               # and the text again, byte for byte
    x, y = back.positions("nose")
    assert np.isnan(x[2]) and np.isnan(y[2]) and x[3] == 0.115
    assert back.markers_with_positions() == ["nose", "foot"]
    assert back.has_pixels("foot") and not back.has_pixels("tail")
    assert back != _tracks() and back.frame.dtype.kind == "i"            # time was rounded to 6 decimals


def test_tracks_csv_reader_takes_what_other_programs_write(tmp_path):
    ours = "frame,t_s,n_px,n_py,n_x_m,n_y_m,n_ok\n0,0.5,1.25,2.0,0.1,0.2,1\n1,0.6,nan,nan,nan,nan,0\n"
    theirs = "frame;t_s;n_px;n_py;n_x_m;n_y_m;n_ok\n0;0,5;1,25;2;0,1;0,2;true\n1;0,6;;;;;false\n"
    assert tc.parse_tracks_csv(theirs, "theirs.csv") == tc.parse_tracks_csv(ours, "ours.csv")
    # columns left out are NaN, no _ok counts every row as found, columns of no marker are kept
    part = tc.parse_tracks_csv("t_s,tip_x_m,tip_y_m,temp_c\n0,1,2,20.5\n", "part.csv")
    assert list(part.frame) == [0] and np.isnan(part.px["tip"]).all() and part.ok["tip"].all()
    assert part.other["temp_c"][0] == 20.5 and part.columns == ("t_s", "tip_x_m", "tip_y_m", "temp_c")
    assert tc.parse_tracks_csv(tc.tracks_csv_text(part), "again.csv") == part


@pytest.mark.parametrize("text, words", [
    ("frame,t_s,n_x_m,n_y_m\n0,0.0,0.1,0.1\n1,0.03,abc,0.1\n", "line 3: column 'n_x_m' holds 'abc'"),
    ("frame,t_s,n_x_m,n_x_m\n0,0,1,2\n", "appears twice"),
    ("frame,t_s,n_x_m,n_y_m\n0.5,0,1,2\n", "line 2: frame 0.5 is not a frame number"),
    ("", "empty recording"),
])
def test_bad_tracks_csv_names_file_and_line(tmp_path, text, words):
    path = tmp_path / "bad.tracks.csv"
    path.write_text(text)
    with pytest.raises(TrackError, match=words) as err:
        tc.read_tracks_csv(path)
    assert str(path) in err.value.message and err.value.hint


def test_track_files_are_named_after_the_video(tmp_path):
    video = tmp_path / "hop.mp4"
    assert tc.tracks_csv_in(tmp_path / "out", video) == tmp_path / "out" / "hop.tracks.csv"   # in the output folder
    assert cam.camera_json_beside(video) == tmp_path / "hop.camera.json"


def test_report_synthetic_track_is_what_the_owner_writes(tmp_path):
    """The SYNTHETIC trial the report tests use reads back and writes out to the same bytes."""
    from locust.params import preset
    from locust.report.synthetic import write_synthetic_trial

    truth = write_synthetic_trial(tmp_path, preset("seed"), 1, lost_frames=3)
    tracks = tc.read_tracks_csv(truth.track_path)
    assert tracks.comments[0].startswith("synthetic:") and int((~tracks.ok["nose"]).sum()) == 3
    assert tc.tracks_csv_text(tracks) == truth.track_path.read_text()


def _export() -> tt.TrackerExport:
    # row 4: a frame where no track has a step (a row of empty cells in the file)
    return tt.TrackerExport(names={"ball": "ball", "cup_3": "cup 3"},
                            t_s={"ball": np.array([NAN, 0.05, 0.1, NAN]), "cup_3": np.array([0.0, 0.05, NAN, NAN])},
                            x_m={"ball": np.array([NAN, 0.125, 0.25, NAN]), "cup_3": np.array([1.0, 1.5, NAN, NAN])},
                            y_m={"ball": np.array([NAN, 1.5, 1.25, NAN]), "cup_3": np.array([2.0, 2.5, NAN, NAN])},
                            other={"cup_3": {"v": np.array([3.0, NAN, NAN, NAN])}})


def test_tracker_text_round_trip_keeps_missing_steps_and_empty_frames(tmp_path):
    export = _export()
    path = tt.write_tracker_export(tmp_path / "e.txt", export)
    lines = path.read_text().splitlines()
    assert lines[:2] == ["ball\t\t\tcup 3\t\t\t", "t\tx\ty\tt\tx\ty\tv"]
    assert lines[-1] == "\t\t\t\t\t\t"
    back = tt.read_tracker_export(path)
    assert back == export and back.n_rows == 4
    assert tt.tracker_export_text(back) == path.read_text()
    np.testing.assert_array_equal(back.time_s(), [0.0, 0.05, 0.1, NAN])   # the tracks' times as one
    x, _ = back.positions("cup_3")
    assert x[0] == 1.0 and np.isnan(x[2])
    assert back.columns == ("t_s", "ball_x_m", "ball_y_m", "cup_3_x_m", "cup_3_y_m", "cup_3_v")
    assert tc.read_track_file(path) == export                             # the dispatcher sees Tracker


def test_tracker_6_multi_export_shares_one_time_column():
    text = "#multi:\n\tcm A\t\tcm B\t\nt\tx\ty\tx\ty\n0,0\t1,5\t2,0\t3,0\t4,0\n0,1\t1,6\t\t3,1\t4,1\n"
    export = tt.parse_tracker_export(text, "multi.txt")
    assert export.markers == ("cm_A", "cm_B") and export.names["cm_A"] == "cm A"
    assert export.t_s["cm_A"] is export.t_s["cm_B"]
    np.testing.assert_array_equal(export.y_m["cm_A"], [2.0, NAN])
    titled = tt.parse_tracker_export("tip\nt\tx\ty\n0\t1\t2\n", "tip.txt")
    assert titled.markers == ("tip",) and titled.x_m["tip"][0] == 1.0
    with pytest.raises(TrackError, match="times disagree in data row 1"):
        tt.parse_tracker_export("a\t\t\tb\t\t\nt\tx\ty\tt\tx\ty\n0\t1\t2\t0.5\t3\t4\n", "x.txt").time_s()


def test_calibration_tables_come_from_the_owners(tmp_path):
    csv_path = tc.write_tracks_csv(tmp_path / "a.tracks.csv", _tracks())
    txt_path = tt.write_tracker_export(tmp_path / "a.txt", _export())
    table = read_table(csv_path)
    assert isinstance(table.tracks, tc.TracksCsv) and table.kind == "csv" and table.markers() == ["nose", "foot"]
    assert np.isnan(table.marker("nose")[0][2])                          # ok 0 is never a position
    table = read_table(txt_path)
    # a Tracker export comes through the track layer's one import (locust.io.importing), as tracks
    assert isinstance(table.tracks, tc.TracksCsv) and table.kind == "tracker"
    for marker in ("ball", "cup_3"):
        for got, want in zip(table.marker(marker), _export().positions(marker)):
            np.testing.assert_array_equal(got, want)
    np.testing.assert_array_equal(table.time_s(), [0.0, 0.05, 0.1, NAN])
    (tmp_path / "servo.csv").write_text("t_s,angle_deg,command_deg\n0,1,0\n")
    assert read_table(tmp_path / "servo.csv").tracks is None


K = np.array([[217.25, 0.0, 159.5], [0.0, 217.25, 89.5], [0.0, 0.0, 1.0]])
ROTATION = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]])


@pytest.mark.parametrize("kind", ["fixed", "track"])
def test_camera_json_round_trip(tmp_path, kind):
    n = 1 if kind == "fixed" else 3
    camera = cam.CameraFile(camera=kind, width_px=320, height_px=180, K=K, rotation=ROTATION,
                            positions_m=np.array([[0.1 * k, 0.6, 0.05] for k in range(n)]),
                            marker_planes={"nose": cam.MarkerPlane(0.0602, 0.0015), "foot": cam.MarkerPlane(-0.02)},
                            fps=30, frames=n, frame_t_s=None if kind == "fixed" else np.arange(n) / 30,
                            view={"lookat_m": [0.1, 0.0, 0.05], "distance_m": 0.6, "azimuth_deg": 90.0,
                                  "elevation_deg": 0.0})
    path = cam.write_camera_json(cam.camera_json_beside(tmp_path / "hop.mp4"), camera)
    doc = json.loads(path.read_text())
    assert doc["marker_planes"]["foot"]["max_off_plane_m"] is None         # NaN is null in the file
    assert ("m_per_px" in doc) == (kind == "fixed")
    back = cam.read_camera_json(path)
    assert back == camera and math.isnan(back.marker_planes["foot"].max_off_plane_m)
    cal = track_camera.load(path, 320, 180)
    assert cal.planes_y_m == {"nose": 0.0602, "foot": -0.02} and cal.camera == kind
    np.testing.assert_array_equal(cal.positions_m, camera.positions_m)
    with pytest.raises(TrackError, match="describes a 320x180 camera"):
        track_camera.load(path, 640, 360)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["fixed", "track"])
def test_simulations_camera_json_reads_back_to_the_same_bytes(tmp_path, kind):
    """What the MuJoCo render writes is a CameraFile: read and written again, byte for byte."""
    from locust.params import preset
    from locust.sim.clip import render_video

    info = render_video(preset("seed"), tmp_path / "hop.mp4", cycles=1, camera=kind, fps=30, width=160, height=120)
    assert info.camera_path == cam.camera_json_beside(info.video_path)
    again = cam.write_camera_json(tmp_path / "again.json", cam.read_camera_json(info.camera_path))
    assert again.read_text() == info.camera_path.read_text()


def test_tracker_project_round_trip(tmp_path):
    """A result written as a .trk reads back with the same steps (Tracker's pixel convention
    undone), clip, calibration and, through that calibration, the same metres."""
    frames = np.arange(2, 8)
    ok = np.array([True, True, False, True, True, True])
    px = np.where(ok, 100.0 + 4.25 * (frames - 2), NAN)
    py = np.where(ok, 300.0 - 2.5 * (frames - 2), NAN)
    cal = trk_io.Calibration(m_per_px=1 / 2048, origin_x_px=12.5, origin_y_px=350.25, angle_deg=2.5, source="stick")
    clip = Clip(2, 7, 1, 30.0)
    video = VideoInfo(tmp_path / "hop.mp4", 640, 360, 12, 30.0)
    result = TrackResult.from_pixels(frames, (frames - 2) / 30.0, {"nose": px}, {"nose": py}, {"nose": ok},
                                     {"nose": "colour:pink"}, {"nose": np.where(ok, 1.0, NAN)}, cal, clip, video=video)
    path = trk.write_project(result, tmp_path / "hop.trk")

    back = trk_io.read_project(path)
    assert back.video_path == "hop.mp4"
    assert back.points["nose"] == {int(f): (x, y) for f, x, y, k in zip(frames, px, py, ok) if k}
    assert (back.clip.start, back.clip.end, back.clip.step) == (2, 7, 1)
    assert back.clip.fps == pytest.approx(30.0, rel=1e-12)
    c = back.calibration
    assert (c.origin_x_px, c.origin_y_px, c.angle_deg) == (12.5, 350.25, 2.5)
    assert c.m_per_px == pytest.approx(1 / 2048, rel=1e-12)
    mine, theirs = result.tracks, trk_io.project_tracks(back)
    np.testing.assert_array_equal(theirs.frame, mine.frame)
    np.testing.assert_allclose(theirs.t_s, mine.t_s, rtol=1e-12)
    for col in ("px", "py", "x_m", "y_m", "ok"):
        np.testing.assert_allclose(getattr(theirs, col)["nose"], getattr(mine, col)["nose"], rtol=1e-12, atol=0)
