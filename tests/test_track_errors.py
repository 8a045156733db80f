"""Bad input to `locust track`: one clear error, exit code 2, nothing written."""

from __future__ import annotations

import numpy as np
import pytest

from locust.track.predict import predict_next
from locust.track.synth import make_hop_video
from locust.track.template import _gaussian_peak
from probing import assert_clear_error, invoke


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bad")
    mp4 = folder / "small_synthetic.mp4"
    avi = folder / "small_synthetic.avi"
    make_hop_video(mp4, width=320, height=180, n_frames=20, seed=1)
    make_hop_video(avi, width=320, height=180, n_frames=20, seed=1, fourcc="MJPG")
    return folder, mp4, avi


def _fails(args, *words):
    res = invoke(["track", *args])
    assert_clear_error(res, *words)   # exit 2, error: and hint: with the words, no traceback
    return res


def test_not_a_video(tmp_path):
    fake = tmp_path / "notes.mp4"
    fake.write_text("this is not a video\n")
    _fails([fake, "--out", tmp_path / "o.csv"], "not a readable video")
    assert not (tmp_path / "o.csv").exists()


def test_still_image_is_not_a_video(tmp_path):
    import cv2

    cv2.imwrite(str(tmp_path / "frame.png"), np.zeros((40, 60, 3), np.uint8))
    _fails([tmp_path / "frame.png", "--out", tmp_path / "o.csv"], "not a")


@pytest.mark.parametrize("kind", ["mp4", "avi"])
def test_truncated_video(small, tmp_path, kind):
    _, mp4, avi = small
    src = mp4 if kind == "mp4" else avi
    cut = tmp_path / f"cut_synthetic.{kind}"
    data = src.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    _fails([cut, "--out", tmp_path / "o.csv"], "truncated")
    assert list(tmp_path.iterdir()) == [cut]


def test_marker_never_found(small, tmp_path):
    _, mp4, _ = small
    _fails([mp4, "--marker", "green=color:#00ff00", "--color-tol", "20", "--out", tmp_path / "o.csv"],
           "never found", "green")
    assert not any(p.name.startswith("o.") for p in tmp_path.iterdir())


@pytest.mark.parametrize("args,word", [
    (["--marker", "nose=colour:#ff00f"], "#RRGGBB"),
    (["--marker", "ball=template:1,2"], "template:X,Y@FRAME"),
    (["--marker", "x=laser:3"], "unknown marker kind"),
    (["--marker", "a=color:#ff00ff", "--marker", "a=color:#00ffff"], "used twice"),
    (["--scale", "1,2,3=0.1"], "X1,Y1,X2,Y2=LENGTH_M"),
    (["--end", "500"], "--end 500"),
    (["--marker", "b=template:100,80@50"], "key frame 50"),
])
def test_bad_options(small, tmp_path, args, word):
    _, mp4, _ = small
    _fails([mp4, *args, "--out", tmp_path / "o.csv"], word)
    assert not (tmp_path / "o.csv").exists()


def test_existing_output_is_not_overwritten(small, tmp_path):
    _, mp4, _ = small
    out = tmp_path / "o.csv"
    out.write_text("precious\n")
    _fails([mp4, "--out", out], "output exists")
    assert out.read_text() == "precious\n"


def test_lookahead_is_exact_for_constant_acceleration():
    pts = [(2.0 + 3 * t + 0.5 * t * t, 5.0 - 4 * t * t) for t in range(4)]
    assert predict_next(pts) == pytest.approx((2 + 12 + 8, 5 - 64))
    assert predict_next([(1.0, 1.0), (4.0, 2.0)]) == pytest.approx((7.0, 3.0))  # velocity only
    assert predict_next([(1.0, 1.0), None]) is None


def test_gaussian_peak_is_exact_for_a_gaussian():
    for true in (-0.37, 0.0, 0.21):
        vals = [np.exp(-((k - true) ** 2) / 1.7) for k in (-1, 0, 1)]
        assert _gaussian_peak(*vals) == pytest.approx(true, abs=1e-12)
