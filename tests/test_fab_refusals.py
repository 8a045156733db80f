"""`locust fab` refuses what it cannot make rather than succeed without it:
a spline too large to flatten (within seconds, in bounded memory), a cut of no length,
a NaN vertex, an unknown $INSUNITS, a hinge width that is no width. The drawings are
synthetic, made here with ezdxf."""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.fab.dxf_limits import MAX_SPLINE_POINTS
from locust.fab.dxf_read import read_drawing


def drawing(path: Path, cut=None, insunits: int = 4, square=((20, 10), (30, 10), (30, 20), (20, 20))) -> Path:
    """A 100 x 50 mm body with a 10 x 10 mm square hole; ``cut(msp)`` adds to the cuts layer."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = insunits
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 50), (0, 50)], close=True, dxfattribs={"layer": "outline"})
    msp.add_lwpolyline(square, close=True, dxfattribs={"layer": "holes"})
    if cut is not None:
        cut(msp)
    doc.saveas(path)
    return path


def fab(*args):
    return CliRunner().invoke(cli, ["fab", *map(str, args)])


def spline(n: int):
    t = np.linspace(0, 1, n)
    pts = np.c_[10 + 80 * t, 25 + 20 * np.sin(t * 20 * np.pi), 0 * t]
    return lambda msp: msp.add_open_spline(pts, degree=3, dxfattribs={"layer": "cuts"})


def test_a_spline_over_the_limit_is_refused_before_flattening(tmp_path):
    path = drawing(tmp_path / "big.dxf", spline(MAX_SPLINE_POINTS + 1))
    res = fab(path, "--json")
    assert res.exit_code == 2 and f"has {MAX_SPLINE_POINTS + 1:,} points" in res.output and "hint:" in res.output
    ok = drawing(tmp_path / "ok.dxf", spline(400))    # a spline of an ordinary size is a slit
    res = fab(ok, "--json")
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["slits"] == 1


@pytest.mark.slow
def test_the_200k_point_spline_is_refused_within_seconds_in_bounded_memory(tmp_path):
    """A drawing of 200,000 control points on `cuts` (13 MB). It grew memory by 300 MB/s
    to an OOM kill, or under a 4 GB limit made cut files with `slits: 0`. Now: exit 2 under a
    1.5 GB address-space limit (about 10 s to read the file on a loaded 2-core machine)."""
    path = drawing(tmp_path / "huge.dxf", spline(200_000))
    limit = 1536 * 2**20

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    t0 = time.monotonic()
    proc = subprocess.run([sys.executable, "-c", "from locust.commands import main; main()",
                           "fab", str(path), "--json"],
                          capture_output=True, text=True, timeout=120, preexec_fn=cap)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "has 200,000 points" in proc.stderr and "hint:" in proc.stderr and "Traceback" not in proc.stderr
    assert time.monotonic() - t0 < 60


def test_a_nan_vertex_is_refused_not_dropped(tmp_path):
    """A 100 mm^2 square with one NaN vertex became a 50 mm^2 triangle."""
    path = drawing(tmp_path / "nan.dxf", square=((20, 10), (30, 10), (float("nan"), 20), (20, 20)))
    res = fab(path, "--json")
    assert res.exit_code == 2 and "not a finite number" in res.output and "hint:" in res.output, res.output
    whole = drawing(tmp_path / "whole.dxf")
    holes = [c for c in read_drawing(whole).contours if c.layer == "holes"]
    assert len(holes) == 1 and len(holes[0].points_mm) == 4   # the same square, finite: all four corners


def test_an_unknown_insunits_is_refused(tmp_path):
    res = fab(drawing(tmp_path / "u99.dxf", insunits=99), "--json")
    assert res.exit_code == 2 and "$INSUNITS = 99 is not a drawing unit" in res.output and "--units" in res.output
    assert fab(drawing(tmp_path / "u99b.dxf", insunits=99), "--json", "--units", "mm").exit_code == 0
    res = fab(drawing(tmp_path / "u0.dxf", insunits=0), "--json")
    assert res.exit_code == 0 and json.loads(res.stdout)["units"]["from"] == "assumed (no $INSUNITS)"


def test_a_cut_of_no_length_is_an_error_not_an_empty_success(tmp_path):
    path = drawing(tmp_path / "dot.dxf", lambda msp: msp.add_circle((50, 25), 0.0, dxfattribs={"layer": "cuts"}))
    res = fab(path, "--json")
    assert res.exit_code == 2 and "cut CIRCLE" in res.output and "has no length" in res.output, res.output


@pytest.mark.parametrize("width, message", [("-5", "must be above 0"), ("0", "must be above 0"),
                                            ("1e300", "is above 50"), ("nan", "not a finite number")])
def test_hinge_width_must_be_a_width(tmp_path, width, message):
    res = fab(drawing(tmp_path / "d.dxf"), "--json", "--hinge-width-mm", width)
    assert res.exit_code == 2 and message in res.output and "hint:" in res.output
