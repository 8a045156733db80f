"""``locust measure stance --side right``: a crank a tooth off on the robot's right, found from
SYNTHETIC stills (MuJoCo renders from the robot's right, the camera at -y, re-encoded as noisy
JPEGs so that only the picture carries over) of robots whose stance and tooth are hidden."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from locust.arucoboard import DEFAULT_BOARD, parse_board
from locust.commands import cli
from locust.errors import MeasureError
from locust.measure.stance import STANCE_KEYS, fit_stance, model_servo_give, read_photo, with_stance
from locust.params import preset, tooth_deg
from locust.sim.still import render_stills
from test_measure_stance import as_photo, read_truth

# Medium with its right crank a tooth on (+), the stance measured first (an override: no uncertainty)
TRUTH = {"geometry.crank_start_deg": -97.0, "geometry.ground_angle_deg": 4.0, "geometry.servo_axis_x_m": 0.026}


def run_cli(*args: str):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


@pytest.fixture(scope="module")
def stills(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sides")
    robot = preset("medium").with_values({**TRUTH, "right.crank_tooth": 1})
    out = {}
    for side in ("L", "R"):
        info, = render_stills(robot, folder / f"rest_{side}.png", side=side)
        out[side] = {"jpg": as_photo(info.path, folder / f"rest_{side}.jpg", seed=len(out)),
                     "truth": read_truth(info.truth_path)}
    return out


def test_a_right_crank_a_tooth_off_is_found_and_written(stills, tmp_path):
    out = tmp_path / "measured.toml"
    sets = sum((["--set", f"{k}={v}"] for k, v in TRUTH.items()), [])
    result = run_cli("measure", "stance", str(stills["R"]["jpg"]), "--preset", "medium", *sets, "--side", "right",
                     "--write", str(out), "--json")
    assert result.exit_code == 0, result.output
    got = json.loads(result.stdout)
    assert got["mirrored"] is True
    tooth = got["tooth"]
    assert tooth["key"] == "right.crank_tooth" and tooth["tooth"] == 1 and tooth["file_tooth"] == 0
    assert tooth["offset_teeth"] == pytest.approx(1.0, abs=0.06)    # a tooth's 17.14 deg, to 1 deg
    assert tooth["probability"] > 0.999 and tooth["margin_sd"] > 4
    assert 1.5 / (360.0 / 21) <= tooth["sd_teeth"] < 2.0 / (360.0 / 21)     # the roll's 1.5 deg, mostly
    # the side's crank as the truth has it (the tooth on the spline): within the roll's 0.7 deg
    truth = TRUTH["geometry.crank_start_deg"] + 360.0 / 21
    assert got["side_crank_deg"]["value"] == pytest.approx(truth, abs=1.0)
    params = json.loads(run_cli("params", "--config", str(out), "--json").stdout)
    assert json.dumps(params).count('"measured:rest_R.jpg"') == 1
    again = run_cli("measure", "stance", str(stills["R"]["jpg"]), "--config", str(out), "--side", "right", "--json")
    assert json.loads(again.stdout)["tooth"]["tooth"] == 1 and json.loads(again.stdout)["tooth"]["file_tooth"] == 1


def test_the_tooths_probability_counts_the_reference_uncertainty(stills):
    """Against the preset's crank start (-100 +- 10 deg estimated) the same photo gives the
    nearest tooth with the probability a 10 deg reference leaves (about 0.6), not certainty."""
    result = run_cli("measure", "stance", str(stills["R"]["jpg"]), "--preset", "medium", "--side", "right", "--json")
    tooth = json.loads(result.stdout)["tooth"]
    assert tooth["reference_sd_deg"] == pytest.approx(10.0)
    assert tooth["sd_teeth"] == pytest.approx(math.hypot(10.0, 1.5) / (360.0 / 21), rel=0.02)
    assert 0.4 < tooth["probability"] < 0.75
    text = run_cli("measure", "stance", str(stills["R"]["jpg"]), "--preset", "medium", "--side", "right").output
    assert "right.crank_tooth = 1 (was 0)" in text and "probability 0." in text


def test_a_still_of_the_other_side_is_refused(stills):
    result = run_cli("measure", "stance", str(stills["L"]["jpg"]), "--preset", "medium", "--side", "right")
    assert result.exit_code == 2
    assert "error: rest_L.jpg shows the robot's left side, not its right" in result.output
    assert "hint: photograph the robot from its right" in result.output and "--side left" in result.output
    spec = parse_board(DEFAULT_BOARD)
    with pytest.raises(MeasureError, match="shows the robot's right side, not its left"):
        photo = read_photo(stills["R"]["jpg"], spec, {})
        robot = preset("medium")
        fit_stance(robot, [photo], model_servo_give(robot, "L"), draws=20, side="L")


# -- ten robots, a tooth off on the right (slow) ----------------------------------------
@pytest.mark.slow
def test_ten_robots_their_right_crank_tooth_found(tmp_path):
    """Ten robots, each on a leg set of its own with its stance drawn (crank -108 to -92 deg,
    ground -10 to 10 deg, axis 18 to 32 mm) and its right crank a tooth off either way; the
    stance measured from the left photos (rest and push) onto the leg set's preset, then the
    right rest photo measured with --side right against that: the tooth found in at least 8."""
    spec = parse_board(DEFAULT_BOARD)
    rows = []
    for seed in range(10):
        rng = np.random.default_rng(200 + seed)
        leg = ("small", "medium", "large")[seed % 3]
        stance = dict(zip(STANCE_KEYS, (float(rng.uniform(-108, -92)), float(rng.uniform(-10, 10)),
                                        float(rng.uniform(0.018, 0.032)))))
        tooth = int(rng.choice([-1, 1]))
        truth = preset(leg).with_values({**stance, "right.crank_tooth": tooth})
        left = render_stills(truth, tmp_path / f"l{seed}.png", tmp_path / f"lp{seed}.png", board=spec)
        right, = render_stills(truth, tmp_path / f"r{seed}.png", board=spec, side="R")
        photos = [read_photo(as_photo(i.path, i.path.with_suffix(".jpg"), seed=10 * seed + k), spec, {})
                  for k, i in enumerate(left)]
        base = preset(leg)
        first = fit_stance(base, photos, model_servo_give(base), seed=seed)
        measured = with_stance(base, first, photos[0].path)
        photo = read_photo(as_photo(right.path, right.path.with_suffix(".jpg"), seed=10 * seed + 5), spec, {})
        got = fit_stance(measured, [photo], model_servo_give(measured, "R"), seed=seed, side="R")
        side_truth = stance["geometry.crank_start_deg"] + tooth * tooth_deg(truth)
        rows.append((seed, leg, tooth, got.tooth, got.side_crank_deg.value - side_truth,
                     first.crank_start_deg.value - stance["geometry.crank_start_deg"]))
    print(f"\n{'seed':>4s} {'leg':7s} {'tooth':>5s} {'found':>5s} {'offset':>7s} {'sd':>6s} {'prob':>6s} "
          f"{'margin':>6s} {'R crank err':>11s} {'L crank err':>11s}")
    for seed, leg, tooth, t, err, left_err in rows:
        print(f"{seed:4d} {leg:7s} {tooth:5d} {t.tooth:5d} {t.offset_teeth:+7.3f} {t.sd_teeth:6.3f} "
              f"{t.probability:6.3f} {t.margin_sd:6.1f} {err:+11.3f} {left_err:+11.3f}")
    found = sum(t.tooth == tooth for _, _, tooth, t, _, _ in rows)
    print(f"found {found} of 10")
    assert found >= 8
