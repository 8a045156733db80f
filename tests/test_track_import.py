"""`locust track import`: Tracker text exports, t,x,y CSVs and tracks CSVs in any unit, renamed
and mirrored, through the one conversion (locust.io.importing.import_tracks).

The small exports written here are SYNTHETIC (labelled so in their first line; numbers chosen
to survive the files' decimals exactly); the real ones are Tracker's own example projects
(../shared/data/tracker), written out as Tracker would export them in cm.
"""

from __future__ import annotations

import math
import zipfile
from decimal import Decimal

import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.errors import TrackError
from locust.io import tracker_text as tt
from locust.io import tracks_csv as tc
from locust.io import trk as trk_io
from locust.io.importing import ImportOptions, import_tracks, likely_units, span_warnings, units_hint
from locust.track import trk
from probing import assert_clear_error

# SYNTHETIC: a Tracker export calibrated in cm, one track named "A" (title line), one step missing
CM_EXPORT = ("# SYNTHETIC Tracker export in cm (written by tests/test_track_import.py)\n"
             "A\n"
             "t\tx\ty\tv\n"
             "0\t12.3456\t-3.5\t1.25\n"
             "0.0333333\t13.0625\t-2.75\t\n"
             "0.0666667\t\t\t\n"
             "0.1\t15.875\t0.125\t2.5\n")
CM_X = [12.3456, 13.0625, math.nan, 15.875]
CM_Y = [-3.5, -2.75, math.nan, 0.125]


def track(*args):
    return CliRunner().invoke(cli, ["track", *map(str, args)])


def fails(res, *words):
    assert_clear_error(res, *words)   # exit 2, error: and hint: with the words, no traceback


def test_tracker_export_in_cm_becomes_metres_with_the_new_name(tmp_path):
    src = tmp_path / "export.txt"
    src.write_text(CM_EXPORT)
    out = tmp_path / "hop.tracks.csv"
    res = track("import", src, "--units", "cm", "--rename", "A=nose", "--out", out)
    assert res.exit_code == 0, res.output
    assert f"wrote {out}" in res.output
    # the span a person checks in mm (it was printed in m): the cm values times 10
    xs, ys = [v for v in CM_X if math.isfinite(v)], [v for v in CM_Y if math.isfinite(v)]
    span = (f"nose: 3 rows with a position; x {min(xs) * 10:.1f} .. {max(xs) * 10:.1f} mm, "
            f"y {min(ys) * 10:.1f} .. {max(ys) * 10:.1f} mm")
    assert span in res.output, res.output
    text = out.read_text()
    lines = text.splitlines()
    assert lines[0] == "# SYNTHETIC Tracker export in cm (written by tests/test_track_import.py)"
    assert lines[1] == ("# imported from export.txt (Tracker text export): positions in cm -> m, renamed A -> nose; "
                        "not imported: A v")
    assert lines[2] == ("frame,t_s,nose_px,nose_py,nose_x_m,nose_y_m,nose_ok,"
                        "nose_vx_m_per_s,nose_vy_m_per_s,nose_ax_m_per_s2,nose_ay_m_per_s2")
    # the cells are the cm values / 100, digit for digit (no velocity: a neighbour is lost or missing)
    assert lines[3] == "0,0.000000,nan,nan,0.123456,-0.035000,1,nan,nan,nan,nan"
    assert lines[4] == "1,0.033333,nan,nan,0.130625,-0.027500,1,nan,nan,nan,nan"
    assert lines[5] == "2,0.066667,nan,nan,nan,nan,0,nan,nan,nan,nan"            # a step Tracker does not have: lost
    assert lines[6] == "3,0.100000,nan,nan,0.158750,0.001250,1,nan,nan,nan,nan"
    back = tc.read_tracks_csv(out)
    x, y = back.positions("nose")
    np.testing.assert_array_equal(x, np.array(CM_X) / 100)       # exactly the cm value / 100
    np.testing.assert_array_equal(y, np.array(CM_Y) / 100)
    # the function everything uses gives the same, before the file's 6 decimals
    tracks = import_tracks(src, "cm", {"A": "nose"})
    np.testing.assert_array_equal(tracks.positions("nose")[0], np.array(CM_X) / 100)
    assert list(tracks.markers) == ["nose"] and tracks.t_s[3] == 0.1


def test_multi_export_renamed_by_tracker_name_and_by_marker_name(tmp_path):
    # SYNTHETIC Tracker 6 export, decimal commas, in mm: "cm A" by its Tracker name, "cm B" by its marker name
    src = tmp_path / "multi.txt"
    src.write_text("#multi:\n\tcm A\t\tcm B\t\nt\tx\ty\tx\ty\n0,0\t1,5\t2,0\t3,0\t4,0\n0,1\t1,6\t2,5\t-3,1\t4,1\n")
    tracks = import_tracks(src, "mm", ["cm A=nose", "cm_B=foot"])
    assert list(tracks.markers) == ["nose", "foot"]
    np.testing.assert_array_equal(tracks.positions("nose")[0], np.array([1.5, 1.6]) / 1000)
    np.testing.assert_array_equal(tracks.positions("foot")[0], np.array([3.0, -3.1]) / 1000)
    np.testing.assert_array_equal(tracks.positions("foot")[1], np.array([4.0, 4.1]) / 1000)
    np.testing.assert_array_equal(tracks.t_s, [0.0, 0.1])


def test_plain_txy_csv_is_the_nose_and_mirror_flips_x(tmp_path):
    src = tmp_path / "hop.csv"          # SYNTHETIC: a hop filmed right-to-left, in cm
    src.write_text("t,x,y\n0,50.0,2.0\n0.5,40.25,9.5\n1.0,30.0,2.0\n")
    tracks = import_tracks(src, "cm", mirror=True)
    assert list(tracks.markers) == ["nose"]                         # a track with no name is the nose
    np.testing.assert_array_equal(tracks.positions("nose")[0], -np.array([50.0, 40.25, 30.0]) / 100)
    np.testing.assert_array_equal(tracks.positions("nose")[1], np.array([2.0, 9.5, 2.0]) / 100)
    assert np.all(np.diff(tracks.positions("nose")[0]) > 0)         # now it goes left to right
    # t_s (or time) for t, and other columns left out; --rename names the nose otherwise
    other = tmp_path / "tip.csv"
    other.write_text("time,x,y,note\n0,1,2,7\n0.25,3,4,8\n")
    tracks = import_tracks(other, rename=["nose=tip"])
    assert list(tracks.markers) == ["tip"] and tracks.positions("tip")[0].tolist() == [1.0, 3.0]
    assert tracks.comments[-1].endswith("renamed nose -> tip; not imported: note")
    out = tmp_path / "tip.tracks.csv"
    res = track("import", other, "--rename", "nose=tip", "--mirror", "--out", out)
    assert res.exit_code == 0, res.output
    assert tc.read_tracks_csv(out).positions("tip")[0].tolist() == [-1.0, -3.0]


def test_tracks_csv_in_mm_keeps_pixels_and_renames_columns(tmp_path):
    src = tmp_path / "mm.tracks.csv"    # SYNTHETIC: a tracks CSV whose _x_m/_y_m columns hold millimetres
    src.write_text("# synthetic: two frames in mm\nframe,t_s,A_px,A_py,A_x_m,A_y_m,A_ok\n"
                   "5,0.0,100.5,200.25,125.0,40.0,1\n6,0.5,nan,nan,nan,nan,0\n")
    out = tmp_path / "m.tracks.csv"
    res = track("import", src, "--units", "mm", "--rename", "A=nose", "--out", out)
    assert res.exit_code == 0, res.output
    back = tc.read_tracks_csv(out)
    assert back.columns == ("frame", "t_s", "nose_px", "nose_py", "nose_x_m", "nose_y_m", "nose_ok", "nose_vx_m_per_s",
                            "nose_vy_m_per_s", "nose_ax_m_per_s2", "nose_ay_m_per_s2")
    assert list(back.frame) == [5, 6] and back.px["nose"][0] == 100.5 and back.py["nose"][0] == 200.25   # pixels stay
    assert back.x_m["nose"][0] == 0.125 and back.y_m["nose"][0] == 0.04 and not back.ok["nose"][1]
    assert back.comments[0] == "synthetic: two frames in mm"
    # the identity returns the file as read
    assert import_tracks(src) == tc.read_tracks_csv(src)


@pytest.mark.parametrize("args, words", [
    (["--units", "in"], ["unknown unit 'in' for --units", "--units takes m, cm or mm"]),
    (["--units", "cm", "--rename", "B=nose"], ["--rename B=nose: the file has no marker 'B' (markers: A)",
                                               "takes the name of a marker the file has"]),
    (["--rename", "A=no se"], ["'no se' is not a marker name"]),
    (["--rename", "A"], ["--rename 'A' is not OLD=NEW"]),
    (["--rename", "A=x", "--rename", "A=y"], ["renamed twice"]),
])
def test_bad_import_options(tmp_path, args, words):
    src = tmp_path / "export.txt"
    src.write_text(CM_EXPORT)
    out = tmp_path / "out.csv"
    fails(track("import", src, *args, "--out", out), *words)
    assert not out.exists()


def test_a_file_of_neither_format_and_clashing_names(tmp_path):
    angles = tmp_path / "servo.csv"
    angles.write_text("t_s,angle_deg,command_deg\n0,1,0\n0.1,2,0\n")
    fails(track("import", angles, "--out", tmp_path / "o.csv"),
          "neither a Tracker text export, a t,x,y CSV nor a tracks CSV (columns: t_s, angle_deg, command_deg)",
          "File > Export > Data")
    notes = tmp_path / "notes.txt"
    notes.write_text("just some words\n")
    fails(track("import", notes, "--out", tmp_path / "o.csv"), "no numeric rows")
    fails(track("import", tmp_path / "nope.txt"), "nope.txt: no such file")
    two = tmp_path / "two.txt"
    two.write_text("a\t\t\tb\t\t\nt\tx\ty\tt\tx\ty\n0\t1\t2\t0\t3\t4\n")
    fails(track("import", two, "--rename", "a=b"), "two markers would be named 'b' (a, b)")
    assert not (tmp_path / "o.csv").exists()
    with pytest.raises(TrackError, match="no track with x and y"):
        (tmp_path / "angle.txt").write_text("theta\nt\ttheta\n0\t1\n")
        import_tracks(tmp_path / "angle.txt")


def test_existing_out_is_never_overwritten(tmp_path):
    src = tmp_path / "export.txt"
    src.write_text(CM_EXPORT)
    out = tmp_path / "hop.tracks.csv"
    out.write_text("keep me\n")
    fails(track("import", src, "--units", "cm", "--rename", "A=nose", "--out", out), "output exists")
    assert out.read_text() == "keep me\n"
    fails(track("import", src, "--out", src), "is the file being imported")
    assert src.read_text() == CM_EXPORT
    # each subcommand has only its own options; the old one-command form names the new one
    fails(track("video", "video.mp4", "--units", "cm"), "No such option '--units'")
    fails(track("import", src, "--format", "tracker"), "No such option '--format'")
    fails(track("--import", src), "locust track import FILE")


def test_units_suggestions_name_the_unit():
    # a 5 cm beam's tip swinging 0.9 m: in cm it would swing 9 mm
    assert likely_units(0.9, 0.05 / 500, 0.05, 0.005, "m") == "cm"
    assert "give --units cm" in units_hint(0.9, 0.05 / 500, 0.05, 0.005, "m")
    # 300 m a hop: in mm, 0.3 m; in cm it would still be 3 m
    assert likely_units(300.0, 1e-3, 2.0, 0.25, "m") == "mm"
    # a track read in mm that is really in metres: 0.3 mm a hop
    assert likely_units(0.0003, 0.01, 2.0, 0.25, "mm") == "m"
    assert likely_units(1e6, 1e-3, 2.0, 0.25, "m") is None
    assert "check the track's scale" in units_hint(1e6, 1e-3, 2.0, 0.25, "m")


def test_an_import_spanning_more_than_a_desk_warns(tmp_path):
    src = tmp_path / "hop_cm.csv"       # SYNTHETIC: 30 cm of travel, in cm, read as metres
    src.write_text("t,x,y\n0,0,2\n1,30,2\n")
    res = track("import", src, "--out", tmp_path / "a.csv")
    assert res.exit_code == 0
    assert ("warning: hop_cm.csv: marker nose spans 30 m, more than the 5 m of a desk experiment: the track is "
            "likely in cm, not m (0.3 m then): give --units cm") in res.stderr
    assert span_warnings(import_tracks(src, "cm")) == []
    res = track("import", src, "--units", "cm", "--out", tmp_path / "b.csv")
    assert res.exit_code == 0 and "warning" not in res.stderr


def _real_export_in_cm(project, names: dict[str, str]) -> tt.TrackerExport:
    """Tracker's own world points (metres) as Tracker would export them calibrated in cm."""
    result = trk.project_result(project)
    tr = result.tracks
    cm = {kind: {m: np.where(tr.ok[m], column[m] * 100, np.nan) for m in tr.markers}
          for kind, column in (("x_m", tr.x_m), ("y_m", tr.y_m))}
    export = tt.TrackerExport({m: names[m] for m in tr.markers},
                              {m: np.where(tr.ok[m], tr.t_s, np.nan) for m in tr.markers}, **cm)
    return export, result


def test_real_balltoss_exported_in_cm_gives_trackers_metres_and_g(shared_data, tmp_path):
    """BallToss (Tracker's example): the ball's steps exported in cm under Tracker's name come
    back as the nose in metres, Tracker's own numbers to the export's 6 digits, and the
    parabola through them gives the published g of about 10.3 m/s^2."""
    project = trk_io.read_project(shared_data / "tracker" / "BallToss.trz")
    export, result = _real_export_in_cm(project, {"ball": "ball"})
    src = tt.write_tracker_export(tmp_path / "balltoss_cm.txt", export)
    out = tmp_path / "balltoss.tracks.csv"
    res = track("import", src, "--units", "cm", "--rename", "ball=nose", "--out", out)
    assert res.exit_code == 0, res.output
    back = tc.read_tracks_csv(out)
    x, y = back.positions("nose")
    wx, wy, ok = result.tracks.x_m["ball"], result.tracks.y_m["ball"], result.tracks.ok["ball"]
    assert int(back.ok["nose"].sum()) == int(ok.sum()) == 11
    # each cell: the export's cm text / 100, and Tracker's metres to the export's 6 significant digits
    cells = [line.split("\t") for line in src.read_text().splitlines()[2:]]
    for i in np.flatnonzero(ok):
        assert x[i] == round(float(Decimal(cells[i][1]) / 100), 6)
        assert x[i] == pytest.approx(wx[i], rel=5e-6, abs=1e-6) and y[i] == pytest.approx(wy[i], rel=5e-6, abs=1e-6)
    c = np.polyfit(back.t_s[ok], y[ok], 2)
    assert -2 * c[0] == pytest.approx(10.3, abs=0.1)


def test_real_cupsclips_renamed_by_trackers_own_names(shared_data, tmp_path):
    with zipfile.ZipFile(shared_data / "tracker" / "CupsClips.zip") as z:
        name = next(n for n in z.namelist() if n.lower().endswith(".trk"))
        z.extract(name, tmp_path)
    project = trk_io.read_project(tmp_path / name)
    export, result = _real_export_in_cm(project, {"cup_3": "cup 3", "cup_7": "cup 7"})
    src = tt.write_tracker_export(tmp_path / "cups_cm.txt", export)
    assert src.read_text().splitlines()[0].split("\t")[0] == "cup 3"     # Tracker's name, with its space
    tracks = import_tracks(src, "cm", ["cup 3=nose", "cup 7=foot"], mirror=True)
    assert list(tracks.markers) == ["nose", "foot"]
    for marker, m in zip(("nose", "foot"), result.tracks.markers):
        wx, wy, ok = result.tracks.x_m[m], result.tracks.y_m[m], result.tracks.ok[m]
        x, y = tracks.positions(marker)
        assert np.isfinite(x).sum() == int(ok.sum()) == 9
        np.testing.assert_allclose(-x[ok], wx[ok], rtol=5e-6, atol=1e-7)      # mirrored
        np.testing.assert_allclose(y[ok], wy[ok], rtol=5e-6, atol=1e-7)
    with pytest.raises(TrackError, match=r"no marker 'cup 9' \(markers: cup_3 \('cup 3' in Tracker\)"):
        import_tracks(src, "cm", ["cup 9=nose"])


def test_options_parse_and_describe():
    opts = ImportOptions.parse("CM", ["cm A=nose"], True)
    assert opts == ImportOptions("cm", (("cm A", "nose"),), True) and not opts.identity
    assert opts.describe() == "positions in cm -> m, renamed cm A -> nose, x mirrored"
    assert opts.options_text() == "--units cm --rename 'cm A=nose' --mirror"
    assert ImportOptions.parse().identity and ImportOptions.parse(None).units == "m"
