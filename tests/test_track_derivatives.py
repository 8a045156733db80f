"""Velocity and acceleration in every track, by Tracker's finite-difference rule.

Tracker's point mass (its default "finite difference" algorithm; ``PointMass``,
``FirstDerivative``, ``SecondDerivative`` in OpenSourcePhysics/tracker) takes the velocity at
step i as ``(x[i+1] - x[i-1]) / (2 dt)`` and the acceleration as ``(2 x[i-2] - x[i-1] - 2 x[i]
- x[i+1] + 2 x[i+2]) / (7 dt^2)``, dt the clip's step (frame interval times step size), each
blank unless every step it reads is marked. The reference below writes that rule out step by
step on the points and the clip of Tracker's own BallToss project, read from its XML here,
apart from locust's reader.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import locust
from locust.commands import cli
from locust.io import delimited
from locust.io.tracks_csv import TracksCsv, read_tracks_csv, write_tracks_csv

G = 9.81


def _props(obj):
    return {p.get("name"): p for p in obj.findall("property")}


def trackers_rule_on_balltoss(trz):
    """Tracker's v and a of the ball, per frame (NaN where Tracker leaves the cell blank),
    computed from the .trk's own points, axes and clip as Tracker does."""
    with zipfile.ZipFile(trz) as z:
        root = ET.fromstring(z.read(next(n for n in z.namelist() if n.endswith(".trk"))))
    top = _props(root)
    clip = _props(top["videoclip"].find("object"))
    control = _props(top["clipcontrol"].find("object"))
    frames = int(clip["stepcount"].text)
    step = int(clip["stepsize"].text)
    dt = float(control["delta_t"].text) / 1000.0 * step      # Tracker's mean step duration
    axes = _props(_props(top["coords"].find("object"))["framedata"].find("property").find("object"))
    ox, oy, scale = (float(axes[k].text) for k in ("xorigin", "yorigin", "xscale"))
    angle = math.radians(float(axes["angle"].text))          # degrees in the file
    ball = next(o for o in root.iter("object") if o.get("class", "").endswith(".PointMass"))
    x = np.full(frames, np.nan)
    y = np.full(frames, np.nan)
    for entry in _props(ball)["framedata"].findall("property"):
        n = int(entry.get("name").strip("[]"))
        p = _props(entry.find("object"))
        dx, dy = float(p["x"].text) - ox, -(float(p["y"].text) - oy)    # world y up
        x[n] = (dx * math.cos(angle) + dy * math.sin(angle)) / scale
        y[n] = (-dx * math.sin(angle) + dy * math.cos(angle)) / scale
    out = {k: np.full(frames, np.nan) for k in ("vx", "vy", "ax", "ay")}
    for i in range(frames):
        if all(0 <= j < frames and np.isfinite(x[j]) for j in (i - 1, i, i + 1)):
            out["vx"][i] = (x[i + 1] - x[i - 1]) / 2 / dt
            out["vy"][i] = (y[i + 1] - y[i - 1]) / 2 / dt
        if all(0 <= j < frames and np.isfinite(x[j]) for j in range(i - 2, i + 3)):
            out["ax"][i] = (2 * x[i - 2] - x[i - 1] - 2 * x[i] - x[i + 1] + 2 * x[i + 2]) / 7 / dt ** 2
            out["ay"][i] = (2 * y[i - 2] - y[i - 1] - 2 * y[i] - y[i + 1] + 2 * y[i + 2]) / 7 / dt ** 2
    return out


def test_balltoss_velocity_and_acceleration_are_trackers(shared_data, tmp_path):
    """Tracker's ball, frames 2-12: v defined on 3-11, a on 4-10, both within 1e-9 of
    Tracker's rule (measured: 1.6e-15 m/s and 3.2e-14 m/s²); the CSV `locust track from-trk`
    writes holds the same figures to its 4 and 3 decimals (Tracker's rule on the file's own
    6-decimal positions: within 1e-4 m/s and 1e-3 m/s² of the project's, half a printed digit
    plus what rounding the positions to 1 um moves them, 8e-6 m/s and 2e-4 m/s² at 66 ms)."""
    trz = shared_data / "tracker" / "BallToss.trz"
    ref = trackers_rule_on_balltoss(trz)
    ball = locust.read_tracks(trz).tidy().set_index("frame")
    columns = {"vx": "vx_m_per_s", "vy": "vy_m_per_s", "ax": "ax_m_per_s2", "ay": "ay_m_per_s2"}
    for key, column in columns.items():
        ours = ball[column].to_numpy()
        assert np.array_equal(np.isnan(ours), np.isnan(ref[key])), key
        assert np.nanmax(np.abs(ours - ref[key])) <= 1e-9, key
    assert list(np.flatnonzero(np.isfinite(ref["vy"]))) == list(range(3, 12))
    assert list(np.flatnonzero(np.isfinite(ref["ay"]))) == list(range(4, 11))
    # the ball falls at about Tracker's 10.3 m/s² on these clicks, not textbook g
    assert np.nanmean(ref["ay"]) == pytest.approx(-10.3, abs=0.5)

    out = tmp_path / "ball.tracks.csv"
    res = CliRunner().invoke(cli, ["track", "from-trk", str(trz), "--out", str(out)])
    assert res.exit_code == 0, res.output
    csv = pd.read_csv(out, comment="#")
    for key, column in columns.items():
        written = csv[f"ball_{column}"].to_numpy()
        assert np.array_equal(np.isnan(written), np.isnan(ref[key])), key
        assert np.nanmax(np.abs(written - ref[key])) <= (1e-4 if key.startswith("v") else 1e-3), key


def test_a_tracked_synthetic_parabola_falls_at_its_g(tmp_path, monkeypatch):
    """SYNTHETIC: the rendered hop clip's nose flies an exact parabola (``track.synth.hop_truth``:
    8 apex / T^2 px/s² at 30 frames/s), the clip's scale set so that it is 9.81 m/s²; `locust
    track` through the codec, and the CSV's ay over the flight is -9.81 within 1 % (measured:
    -9.809 mean, 0.12 m/s² frame to frame), its vx the clip's own 0.55 W / T within 1 %."""
    from locust.track.synth import make_hop_video

    monkeypatch.chdir(tmp_path)
    fps, frames, width, height = 30.0, 24, 640, 360
    make_hop_video(tmp_path / "toss.mp4", width=width, height=height, n_frames=frames, fps=fps, seed=3)
    duration = (frames - 1) / fps
    m_per_px = G / (8 * 0.35 * height / duration ** 2)
    res = CliRunner().invoke(cli, ["track", "video", "toss.mp4", "--scale", f"0,0,100,0={100 * m_per_px!r}",
                                   "--overlay", "none", "--out", "toss.tracks.csv"])
    assert res.exit_code == 0, res.output
    nose = pd.read_csv("toss.tracks.csv", comment="#")
    ay, vx = nose.nose_ay_m_per_s2.dropna(), nose.nose_vx_m_per_s.dropna()
    assert len(ay) == frames - 4 and len(vx) == frames - 2
    assert ay.mean() == pytest.approx(-G, rel=0.01) and ay.median() == pytest.approx(-G, rel=0.01)
    assert vx.mean() == pytest.approx(0.55 * width / duration * m_per_px, rel=0.01)


def test_uneven_frame_times_keep_each_frames_own_time():
    """SYNTHETIC: a parabola (g = 9.81) sampled at jittered times (a phone's variable frame
    rate, +-20 % of 1/30 s): the least-squares parabola through five samples at their own
    times is exact, so ay = -9.81 and vy the true slope to 1e-9; a mean step would miss by
    up to a few per cent."""
    rng = np.random.default_rng(7)
    t = np.cumsum(np.r_[0.0, (1 + rng.uniform(-0.2, 0.2, 29)) / 30])
    y = 2.0 * t - G / 2 * t ** 2
    nan = np.full(30, np.nan)
    tracks = TracksCsv(np.arange(30), t, px={"ball": nan}, py={"ball": nan}, x_m={"ball": 0.5 * t}, y_m={"ball": y},
                       ok={"ball": np.ones(30, bool)})
    d = tracks.derived("ball")
    assert d["ay_m_per_s2"][2:-2] == pytest.approx(np.full(26, -G), abs=1e-9)
    assert d["ax_m_per_s2"][2:-2] == pytest.approx(np.zeros(26), abs=1e-9)
    # the secant over the neighbours is the slope at their mid-time, not quite at t[i]
    mid = (t[2:] + t[:-2]) / 2
    assert d["vy_m_per_s"][1:-1] == pytest.approx(2.0 - G * mid, abs=1e-9)


def test_the_csv_gives_its_own_velocity_back_and_old_files_still_read(tmp_path):
    """The file's v and a are Tracker's rule on the file's own columns: read back (where they
    are computed again from the positions read) and written again, byte for byte. A tracks CSV
    written before they existed reads as it did, with them computed; a full-length track
    (the reader's 200,000 lines) of the two default markers stays within its 64 MB."""
    rng = np.random.default_rng(0)
    n = 40
    t = np.arange(n) / 240.0
    x, y = 0.1 + 1.234567891 * t, 0.05 + 1.5 * t - G / 2 * t ** 2 + rng.normal(0, 2e-4, n)
    ok = np.ones(n, bool)
    ok[17] = False
    m = TracksCsv(np.arange(n), t, px={"nose": rng.uniform(0, 1920, n)}, py={"nose": rng.uniform(0, 1080, n)},
                  x_m={"nose": x}, y_m={"nose": y}, ok={"nose": ok})
    path = write_tracks_csv(tmp_path / "a.tracks.csv", m)
    text = path.read_text()
    back = read_tracks_csv(path)
    rows = pd.read_csv(path)
    d = back.derived("nose")
    assert rows.nose_vy_m_per_s.to_numpy() == pytest.approx(d["vy_m_per_s"], abs=0.5e-4, nan_ok=True)
    assert rows.nose_ay_m_per_s2.to_numpy() == pytest.approx(d["ay_m_per_s2"], abs=0.5e-3, nan_ok=True)
    assert np.isnan(d["vy_m_per_s"][16:19]).all() and np.isnan(d["ay_m_per_s2"][15:20]).all()
    assert write_tracks_csv(tmp_path / "b.tracks.csv", back).read_text() == text

    old = tmp_path / "old.tracks.csv"
    old.write_text("frame,t_s,nose_px,nose_py,nose_x_m,nose_y_m,nose_ok\n"
                   + "".join(f"{k},{k / 30:.6f},1,2,0.000000,{-G / 2 * (k / 30) ** 2:.6f},1\n" for k in range(8)))
    read = read_tracks_csv(old)
    assert read.columns == ("frame", "t_s", "nose_px", "nose_py", "nose_x_m", "nose_y_m", "nose_ok")
    assert read.derived("nose")["ay_m_per_s2"][2:-2] == pytest.approx(np.full(4, -G), abs=2e-3)

    rows_max = delimited.MAX_LINES - 1                       # the header is the other line
    t = np.arange(rows_max) / 240.0 + 100.0                  # 14 minutes at 240 frames/s
    swing = -1.1 - 0.1 * np.sin(2 * np.pi * t)               # 4-digit pixels, a metre off the origin
    both = ("nose", "foot")
    tracks = TracksCsv(np.arange(rows_max) + 10 ** 5, t, px={m: 1919.1234 + 0 * t for m in both},
                       py={m: 1079.1234 + 0 * t for m in both}, x_m={m: swing for m in both},
                       y_m={m: swing for m in both}, ok={m: np.ones(rows_max, bool) for m in both})
    full = write_tracks_csv(tmp_path / "full.tracks.csv", tracks)     # refused were it over a limit
    assert full.stat().st_size == pytest.approx(30.1 * 2**20, rel=0.01)  # 158 bytes a row: 47 % of the 64 MB
