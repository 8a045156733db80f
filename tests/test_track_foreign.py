"""`locust track` on a hard clip it was not written against: SYNTHETIC sticker, pen cap, shadow and
ArUco board composited over REAL footage (Tracker's CupsClips sample, read from ../shared/data),
by ``bench/track_foreign.py``, small version (640x360, 30 fps, 60 frames), scored against the
clip's own truth."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow


def _bench():
    spec = importlib.util.spec_from_file_location(
        "track_foreign", Path(__file__).resolve().parents[1] / "bench" / "track_foreign.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module   # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def foreign(shared_data, tmp_path_factory):
    bench = _bench()
    truth, figures, summary = bench.run(tmp_path_factory.mktemp("foreign"), 640, 360, 30.0, "cups", progress=False)
    print(summary)
    print("\n".join(figures.details))
    print(bench.last_line(figures))
    return truth, figures


def test_foreign_clip_has_what_it_promises(foreign):
    truth, _ = foreign
    # the scene itself, before any tracking: the sticker leaves the picture, is shadowed and blurred
    assert truth.out.sum() >= 10
    assert (truth.shadow < 0.8).sum() >= 10
    assert truth.streak_px.max() > 2 * truth.radius_px.mean() * 0.9
    assert truth.homography_err_mm < 0.05


def test_foreign_clip_acceptance(foreign):
    _, f = foreign
    detail = "\n".join(f.details)
    assert f.out_found == 0, f"found while out of the picture:\n{detail}"
    assert f.wrong_pct <= 1.0, f"wrong by > 8 px on {f.wrong_pct:.1f} % of found frames:\n{detail}"
    assert f.found_pct >= 90.0
    assert f.rms_px <= 1.5
    assert f.metric_rms_mm <= 2.0
