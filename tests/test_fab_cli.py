"""``locust fab`` end to end through the real CLI root (errors become exit code 2)."""

from __future__ import annotations

import json
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from click.testing import CliRunner

from locust import params
from locust.commands import cli
from locust.io import robot_toml

ZZ = Path(__file__).resolve().parents[1] / "data" / "dxf" / "zz.dxf"


def _run(*args):
    result = CliRunner().invoke(cli, ["fab", *map(str, args)])
    assert "Traceback" not in result.output
    if result.exception and not isinstance(result.exception, SystemExit):
        raise result.exception
    return result


@pytest.mark.parametrize("name,hinges", [("seed", [40, 80, 100, 160]), ("medium", [50, 100, 130, 200]),
                                         ("large", [60, 120, 160, 240])])
def test_from_robot_json_hinges(name, hinges):
    result = _run("--from-robot", name, "--json")
    assert result.exit_code == 0, result.output
    s = json.loads(result.stdout)
    assert s["hinges_x_mm"] == pytest.approx(hinges, abs=1e-6)
    assert s["files"] == [] and s["out"] is None


def test_from_robot_toml_follows_its_link_lengths(tmp_path):
    robot = params.preset("seed").with_values({"geometry.ground_m": 0.045, "geometry.leg_m": 0.07})
    robot_toml.save_robot(robot, tmp_path / "robot.toml")
    s = json.loads(_run("--from-robot", tmp_path / "robot.toml", "--json").stdout)
    assert s["hinges_x_mm"] == pytest.approx([45, 85, 105, 175], abs=1e-6)
    assert s["bounds_mm"]["width"] == pytest.approx(195)
    # its values are not the seed's, though the file kept the name "seed": named by the file
    assert s["source"] == "flat pattern of robot"
    robot_toml.save_robot(robot.renamed("optimize best of opt"), tmp_path / "best.toml")
    assert json.loads(_run("--from-robot", tmp_path / "best.toml", "--json").stdout)["source"] == \
        "flat pattern of optimize best of opt"
    robot_toml.save_robot(params.preset("seed"), tmp_path / "plain.toml")   # the seed itself keeps its name
    assert json.loads(_run("--from-robot", tmp_path / "plain.toml", "--json").stdout)["source"] == \
        "flat pattern of seed"


def test_from_robot_carries_the_designs_crank_angle_servo_axis_and_push(tmp_path):
    """docs/sweep.md's knee of the front: links +36 mm, crank at rest -82 deg, push -26 deg, as
    `locust optimize` writes knee.toml. The strip holds the links; the crank's angle (the horn's
    spline position), the servo axis and the push are in the summary, its text and
    summary.json, to the value in the file (they were dropped: a knee built from the cut files
    alone got the robot as built's -100 deg and -30 deg)."""
    small = params.preset("small")
    g = small.geometry
    knee = small.with_values({"geometry.ground_m": g.ground_m + 0.036, "geometry.crank_m": g.crank_m + 0.036,
                              "geometry.coupler_m": g.coupler_m + 0.036, "geometry.leg_m": g.leg_m + 0.036,
                              "geometry.crank_start_deg": -82.0, "schedule.push_deg": -26.0},
                             "optimize").renamed("optimize knee of opt")
    robot_toml.save_robot(knee, tmp_path / "knee.toml")
    out = tmp_path / "cut"
    s = json.loads(_run("--from-robot", tmp_path / "knee.toml", "--out", out, "--no-preview", "--json").stdout)
    assert s["assembly"] == {"robot": "optimize knee of opt",
                             "links_mm": {"ground": 76.0, "crank": 76.0, "coupler": 56.0, "leg": 96.0},
                             "link_width_mm": 30.0, "crank_start_deg": -82.0,
                             "servo_axis_x_mm": pytest.approx(1000 * g.servo_axis_x_m), "push_deg": -26.0,
                             "push_s": small.schedule.push_s}
    assert s["hinges_x_mm"] == pytest.approx([76, 152, 208, 304], abs=1e-6)
    assert json.loads((out / "summary.json").read_text())["assembly"] == s["assembly"]
    text = _run("--from-robot", tmp_path / "knee.toml").stdout
    assert "assemble: the crank at rest at -82.0 deg from the ground link" in text
    assert "hop: push -26.0 deg for 300 ms" in text and "--push-deg -26 --push-ms 300" in text
    assert "assembly" not in json.loads(_run(ZZ, "--json").stdout)          # a drawing has no robot


def test_zz_out_writes_every_file_and_previews(tmp_path):
    out = tmp_path / "cut"
    result = _run(ZZ, "--out", out, "--json")
    assert result.exit_code == 0, result.output
    s = json.loads(result.stdout)
    assert s["areas_mm2"]["rigid_top"] == pytest.approx(5348.86, rel=5e-4)
    assert s["areas_mm2"]["flexible"] == pytest.approx(5400.0, rel=5e-4)
    assert [row["center_x_mm"] for row in s["slots"]] == pytest.approx([40, 80, 100, 160])
    assert [row["height_mm"] for row in s["slots"]] == pytest.approx([13.0] * 4, abs=1e-3)
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(s["files"])
    for stem in ("rigid_top", "adhesive_top", "flexible", "adhesive_bottom", "rigid_bottom",
                 "combined_cut_pattern", "first_pass_cuts", "final_perimeter"):
        ezdxf.readfile(out / f"{stem}.dxf")                      # strict read
    assert json.loads((out / "summary.json").read_text())["areas_mm2"] == s["areas_mm2"]
    import matplotlib.image as mpimg
    img = mpimg.imread(out / "cut_pattern.png")[..., :3]
    red = (img[..., 0] > 0.8) & (img[..., 1] < 0.5) & (img[..., 2] < 0.5)   # hinge cut-outs drawn
    assert red.sum() > 50 and img.std() > 0.05
    assert "wrote" in _run(ZZ, "--out", tmp_path / "again").output


@pytest.mark.parametrize("content", [b"\x00\x01garbage" * 200, "TRUNCATED"])
def test_bad_dxf_clear_error_nothing_written(tmp_path, content):
    bad = tmp_path / "bad.dxf"
    if content == "TRUNCATED":
        text = ZZ.read_text()
        content = text[: len(text) * 2 // 3].encode()
    bad.write_bytes(content)
    out = tmp_path / "out"
    result = _run(bad, "--out", out)
    assert result.exit_code == 2
    assert result.output.startswith("error: ") and "not a readable DXF" in result.output
    assert "hint:" in result.output
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.dxf"]     # no staging left over


def test_existing_out_folder_is_never_overwritten(tmp_path):
    out = tmp_path / "cut"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    result = _run(ZZ, "--out", out)
    assert result.exit_code == 2 and "never overwritten" in result.output
    assert [p.name for p in out.iterdir()] == ["mine.txt"] and (out / "mine.txt").read_text() == "keep"


def test_usage_errors(tmp_path):
    assert _run().exit_code == 2
    assert _run(ZZ, "--from-robot", "seed").exit_code == 2
    r = _run("--from-robot", "nonesuch")
    assert r.exit_code == 2 and "neither a preset nor a robot.toml" in r.output
    r = _run(ZZ, "--layer", "body=nothing_here")
    assert r.exit_code == 2 and "no body outline" in r.output


def test_fold_line_drawing_with_layer_mapping_and_mirror(tmp_path):
    doc = ezdxf.new("R2010", units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (60, 0), (60, 20), (0, 20)], close=True, dxfattribs={"layer": "Outline"})
    msp.add_line((20, 0), (20, 20), dxfattribs={"layer": "creases"})
    doc.saveas(tmp_path / "synthetic_strip.dxf")
    result = _run(tmp_path / "synthetic_strip.dxf", "--layer", "body=outline", "--layer", "hinge=creases",
                  "--hinge-width-mm", "2", "--mirror", "rigid_bottom", "--json")
    s = json.loads(result.stdout)
    assert s["areas_mm2"]["rigid_top"] == pytest.approx(1200 - 40)
    assert s["areas_mm2"]["flexible"] == pytest.approx(1200)
    assert s["stack"][-1] == {"name": "rigid_bottom", "material": "rigid", "mirror": True}
    assert np.isclose(s["hinges_x_mm"], [20]).all()
