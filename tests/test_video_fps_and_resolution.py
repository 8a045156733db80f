"""The virtual robot's camera rate (`hop --video --fps`, default 60) and the report's
tracking resolution: a difference under one pixel is not shown as a percentage."""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.device.plant import VIDEO_TAIL_S, make_plant
from locust.io.tracks_csv import TracksCsv
from locust.params import preset
from locust.report.page import pct
from locust.sim.live import PREROLL_S
from locust.track.video import probe
from locust.trials.measured import metres_per_pixel


def test_hop_video_rate_defaults_to_60_and_is_passed_on(monkeypatch):
    seen = []

    class Stop(Exception):
        pass

    def fake_open_port(port, **kw):
        seen.append(kw["video_fps"])
        raise Stop

    monkeypatch.setattr("locust.device.session.open_port", fake_open_port)
    for args, want in (([], 60), (["--fps", "120"], 120)):
        res = CliRunner().invoke(cli, ["hop", "--port", "sim", "--video", "x.mp4", *args])
        assert isinstance(res.exception, Stop), res.output
        assert seen[-1] == want


def test_mujoco_plant_films_at_the_rate_asked(tmp_path):
    path = tmp_path / "v.mp4"
    plant = make_plant("mujoco", preset("seed"), path, 60)
    plant.command(0.0, 0.0, 0.0)
    out = plant.close(0.5)
    assert out["frames"] == round((PREROLL_S + 0.5 + VIDEO_TAIL_S) * 60)   # standing before and after
    info = probe(path)
    assert info.file_fps == pytest.approx(60.0)
    assert info.frame_count == out["frames"]


def _tracks(px, x_m):
    px, x_m = np.asarray(px, float), np.asarray(x_m, float)
    zero = np.zeros_like(px)
    return TracksCsv(frame=np.arange(px.size), t_s=np.arange(px.size) / 60, px={"nose": px}, py={"nose": zero},
                     x_m={"nose": x_m}, y_m={"nose": zero}, ok={"nose": np.ones(px.size, bool)})


def test_resolution_is_the_tracks_own_metres_per_pixel():
    # 0.5 mm per pixel; steps under a pixel (0.3 px) are left out of the estimate
    px = np.array([0.0, 0.3, 2.3, 6.3, 7.3, 12.3])
    assert metres_per_pixel(_tracks(px, px * 5e-4), "nose") == pytest.approx(5e-4)
    assert math.isnan(metres_per_pixel(_tracks([0, 0, 0], [0, 0, 0]), "nose"))


def test_sub_pixel_error_reads_within_1_px():
    # a 0.3 mm difference on a 1.1 mm jump: below one pixel of 0.5 mm it is not measured;
    # with 0.1 mm pixels it is a real -27 %
    assert pct(-0.0003, 0.0011, 5e-4) == "within 1 px (0.5 mm)"
    assert pct(-0.0003, 0.0011, 1e-4) == "-27.3 %"
    assert pct(-0.0003, 0.0011) == "-27.3 %"
