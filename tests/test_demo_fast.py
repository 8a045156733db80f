"""`locust demo`, smallest form, in the default run: flash, hop Small/Medium/Large once on the
virtual robot (real firmware under MicroPython, MuJoCo plant, rendered video), track, calibrate
from the bundled SYNTHETIC recordings, a 2-design sweep, the report (about 40 s).

Known truth at every stage: the virtual robot's hidden values (virtual/truth.json) for the
calibration, the nose marker's true position in the video's frames (hop.truth.csv) for the
tracking, run() on the calibrated robot for the predictions. The full-size demo is tests/test_report_demo.py (slow).
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from locust.io.robot_toml import load_robot
from locust.params import leg_set
from locust.sim.run import run

LEG_SETS = ("small", "medium", "large")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("fastdemo")
    proc = subprocess.run([sys.executable, "-m", "locust.commands", "demo", "--out", str(out), "--cycles", "1",
                           "--trials", "1", "--designs", "2", "--jobs", "1", "--no-fit-hops"],
                          capture_output=True, text=True, timeout=600, check=False)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    for n in range(1, 7):
        assert f"[{n}/6]" in proc.stderr
    folder = out / "run"
    return {"folder": folder, "doc": json.loads((folder / "report" / "report.json").read_text())}


def test_calibration_recovers_the_virtual_robots_hidden_values(demo):
    truth = json.loads((demo["folder"] / "virtual" / "truth.json").read_text())["values"]
    robot = load_robot(demo["folder"] / "calibration" / "robot.toml")
    for key, true in truth.items():
        prov = robot.source_of(key)
        if not prov.source.startswith("fit:"):
            continue     # given, not fitted (the stall torque splits the servo's ratios)
        assert abs(robot.get(key) - true) <= 3 * prov.uncertainty, key     # its own 3-sigma covers the truth
        assert robot.get(key) == pytest.approx(true, rel=0.04), key


def test_tracked_hops_match_the_truth_frames(demo):
    """Measured from the video against the nose marker's true positions in the rendered
    frames: within a quarter pixel at the marker (640x360 frames at 60 frames/s, about 0.66 mm
    a pixel: 0.16 mm). The colour marker's centre is good to about 0.1 px RMS (docs/track.md),
    and one frame decides an apex: at the top of Large's hop the nose moves 1.5 mm between
    frames, so a clock or frame slip would be off by far more than that.

    The truth is the nose's travel, the quantity the report measures. The plant's own figure
    in the hop log is the chassis' travel: it agrees with the nose's to about 1 um when the
    legs come to rest as they started, and was 0.10 mm apart once on Medium (nose and foot
    1.151 mm, chassis 1.2535 mm), where a foot on the edge of slipping can come to rest with
    the hinges holding a different bend.
    """
    folder, doc = demo["folder"], demo["doc"]
    assert [c["name"] for c in doc["configurations"]] == list(LEG_SETS)
    for cfg in doc["configurations"]:
        (hop,) = cfg["hops"]
        label = hop["trial"]
        truth = pd.read_csv(folder / "hops" / label / "hop.truth.csv", comment="#")
        x, z = truth["nose_x_m"].to_numpy(), truth["nose_z_m"].to_numpy()
        settled = truth["t_s"].to_numpy() >= truth["t_s"].iloc[-1] - 0.3
        assert np.ptp(x[settled]) <= 2e-6, label         # at rest over the clip's end (6 decimals written)
        tracks = pd.read_csv(folder / "hops" / label / "hop.tracks.csv", comment="#")
        seen = tracks[["nose_y_m", "nose_py"]].dropna()
        px_per_m = abs(np.polyfit(seen["nose_y_m"], seen["nose_py"], 1)[0])
        quarter_px_m = 0.25 / px_per_m
        assert hop["measured_marker_travel_m"] == pytest.approx(float(x[-1] - x[0]), abs=quarter_px_m), label
        assert hop["measured_apex_m"] == pytest.approx(float(z.max() - z[0]), abs=quarter_px_m), label


def test_predictions_are_run_on_the_calibrated_robot(demo):
    calibrated = load_robot(demo["folder"] / "calibration" / "robot.toml")
    for cfg in demo["doc"]["configurations"]:
        r = run(leg_set(calibrated, cfg["name"]), cycles=1)
        assert cfg["predicted"]["valid"] and r.valid
        assert cfg["predicted"]["distance_m"] == pytest.approx(r.distance_m, abs=1e-12)
        assert cfg["predicted_distance_m"] == pytest.approx(r.distance_m, abs=1e-12)      # locust sim's
    rows = (demo["folder"] / "sweep" / "results.csv").read_text().splitlines()
    assert len(rows) == 3                      # header and the two designs
