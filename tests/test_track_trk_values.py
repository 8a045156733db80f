"""`locust track from-trk` refuses a clip or scale Tracker would not save:
a step of -1 (times counting down), a step count of -5 (an empty CSV, exit 0 before), a
negative scale (every position mirrored). The projects are SYNTHETIC (tests/test_calibrate_hinge.py)."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from test_calibrate_hinge import write_trk


@pytest.mark.parametrize("old, new, message", [
    ('"stepsize" type="int">1<', '"stepsize" type="int">-1<', "stepsize is -1; it must be at least 1"),
    ('"stepsize" type="int">1<', '"stepsize" type="int">0<', "stepsize is 0; it must be at least 1"),
    ('"stepcount" type="int">40<', '"stepcount" type="int">-5<', "stepcount is -5; it must be at least 1"),
    ('"startframe" type="int">0<', '"startframe" type="int">-3<', "startframe is -3; it must be at least 0"),
    ('"xscale" type="double">7200.0<', '"xscale" type="double">-7200.0<', "(xscale) is -7200 px per unit"),
])
def test_a_wrong_clip_or_scale_is_refused(tmp_path, old, new, message):
    t = np.arange(40) / 100
    path = write_trk(tmp_path / "p.trk", t, 0.01 * np.sin(t), 0.02 + 0 * t)
    good = CliRunner().invoke(cli, ["track", "from-trk", str(path), "--out", str(tmp_path / "good.csv")])
    assert good.exit_code == 0, good.output
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))
    res = CliRunner().invoke(cli, ["track", "from-trk", str(path), "--out", str(tmp_path / "bad.csv")])
    assert res.exit_code == 2 and message in res.output and "hint:" in res.output, res.output
    assert not (tmp_path / "bad.csv").exists()
