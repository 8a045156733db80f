"""`locust track video` and `locust.track_markers` are one job (locust.track.pipeline.track_job):
both call it, the API takes every option of the command, and the two write the same files.

- read from the source with `ast`: the command's `video_command` and the API's `track_markers`
  each call `track_job`, imported from `locust.track.pipeline`, and neither runs the frame
  loop (`track_video`) or a calibration of its own;
- every option of `locust track video` is a keyword of `track_markers` (three under a name
  with its unit or the API's word: `template_radius_px`, `evolve_percent`, `overwrite`);
- on a SYNTHETIC hop clip (locust.track.synth), the same options through the command and
  through the API write the same tracks CSV, sidecar and overlay, byte for byte.
"""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import click
import numpy as np
import pytest
from click.testing import CliRunner

import locust
from locust.commands import cli
from locust.commands.track import video_command
from locust.track.synth import make_hop_video

HOST = Path(__file__).resolve().parents[1] / "host" / "locust"
# the command's option -> the API's keyword, where the two words differ
API_NAME = {"template_radius": "template_radius_px", "evolve": "evolve_percent", "force": "overwrite"}


def _function(path: Path, name: str) -> ast.FunctionDef:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == name)


def _called(func: ast.FunctionDef) -> set[str]:
    """The names a function calls (``f(...)`` and ``x.f(...)``)."""
    out = set()
    for node in ast.walk(func):
        if isinstance(node, ast.Call):
            f = node.func
            out.add(f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else "")
    return out


def _imported_from(path: Path, name: str) -> set[str]:
    """The absolute modules ``path`` imports ``name`` from (at module level or in a function)."""
    package = ".".join(path.relative_to(HOST.parent).with_suffix("").parts[:-1])
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and any(a.name == name for a in node.names):
            base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
            out.add(".".join([*base, *(node.module or "").split(".")]))
    return out


@pytest.mark.parametrize("path, func", [("commands/track.py", "video_command"), ("api/tracking.py", "track_markers")])
def test_the_command_and_the_api_call_the_one_job_function(path, func):
    source = HOST / path
    called = _called(_function(source, func))
    assert "track_job" in called
    assert _imported_from(source, "track_job") == {"locust.track.pipeline"}
    assert not called & {"track_video", "_calibration", "_track", "_write", "write_project"}   # the job's own steps
    defined = {n.name for n in ast.walk(ast.parse(source.read_text())) if isinstance(n, ast.FunctionDef)}
    assert "_calibration" not in defined                          # no calibration of its own


def test_the_api_takes_every_option_of_track_video():
    options = {p.name for p in video_command.params if isinstance(p, click.Option)}
    assert len(options) == 26                                     # as `locust track video --help` lists them
    keywords = set(inspect.signature(locust.track_markers).parameters)
    assert {API_NAME.get(o, o) for o in options} - keywords == set()


@pytest.fixture(scope="module")
def hop(tmp_path_factory):
    folder = tmp_path_factory.mktemp("clip")
    make_hop_video(folder / "hop.mp4", width=320, height=180, n_frames=20, seed=1)   # SYNTHETIC, 60 frames/s
    return folder / "hop.mp4"


CLIP = {"start": 1, "end": 15, "fps": 30.0}
CALIBRATIONS = {   # the command's options and the API's keywords for one calibration
    "stick": (["--scale", "0,0,100,0=0.1", "--origin", "10,170", "--angle", "2.5"],
              {"scale": "0,0,100,0=0.1", "origin": "10,170", "angle_deg": 2.5}),
    "plane points": (["--plane-points", "0,180=0,0;320,180=0.32,0;320,0=0.32,0.18;0,0=0,0.18", "--pixels", "opencv"],
                     {"plane_points": "0,180=0,0;320,180=0.32,0;320,0=0.32,0.18;0,0=0,0.18", "pixels": "opencv"}),
}


@pytest.mark.parametrize("calibration", list(CALIBRATIONS))
def test_the_command_and_the_api_write_the_same_files(hop, tmp_path, calibration):
    args, keywords = CALIBRATIONS[calibration]
    res = CliRunner().invoke(cli, ["track", "video", str(hop), "--start", "1", "--end", "15", "--fps", "30",
                                   "--search", "30", *args, "--out", f"{tmp_path / 'cli'}/"])
    assert res.exit_code == 0, res.output
    frames = []
    tracks = locust.track_markers(hop, search_px=30, **CLIP, **keywords, out=f"{tmp_path / 'api'}/",
                                  progress=frames.append)
    names = ["hop.tracks.csv", "hop.tracks.json", "hop.tracks.png"]
    assert sorted(p.name for p in (tmp_path / "cli").iterdir()) == sorted(names)
    assert [p.name for p in tracks.result.written] == names
    for name in names:
        assert (tmp_path / "api" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert sum(frames) == 15                                      # frames 1..15 tracked, one call each
    x, y = tracks.positions("nose")
    assert np.isfinite(x).all() and np.isfinite(y).all()          # found on every frame: metres in each


def test_the_api_writes_nothing_without_out_and_takes_numbers_for_the_stick(hop, tmp_path, monkeypatch):
    """Without out= only the tracks come back (a notebook's cell writes no file); a stick given
    as numbers is the stick given as text, to the same metres."""
    monkeypatch.chdir(tmp_path)
    as_numbers = locust.track_markers(hop, **CLIP, scale=(0, 0, 100, 0, 0.1), origin=(10, 170))
    as_text = locust.track_markers(hop, **CLIP, scale="0,0,100,0=0.1", origin="10,170")
    assert list(tmp_path.iterdir()) == [] and as_numbers.result.written == ()
    assert as_numbers.tracks == as_text.tracks
    x, _ = as_text.positions("nose")
    px = as_text.tracks.px["nose"]
    np.testing.assert_allclose(x, (px - (10 - 0.5)) * 0.001, rtol=0, atol=1e-12)   # 1 mm a pixel, Tracker's origin
