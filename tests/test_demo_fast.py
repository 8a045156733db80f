"""`locust demo`, smallest form, in the default run: flash, hop Small/Medium/Large once on the
virtual robot (real firmware under MicroPython, MuJoCo plant, rendered video), track, calibrate
from the bundled SYNTHETIC recordings, a 2-design sweep, the report (about 40 s).

Known truth at every stage: the virtual robot's hidden values (virtual/truth.json) for the
calibration, the plant's own audited distance (printed by `locust hop`) and the nose marker's
true height in the video's frames (hop.truth.csv) for the tracking, run() on the calibrated
robot for the predictions. The full-size demo is tests/test_report_demo.py (slow).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pandas as pd
import pytest

from locust.params import leg_set, load_robot
from locust.sim.run import run

LEG_SETS = ("small", "medium", "large")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("fastdemo")
    proc = subprocess.run([sys.executable, "-m", "locust.cli", "demo", "--out", str(out), "--cycles", "1",
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


def test_tracked_hops_match_the_plant_and_the_truth_frames(demo):
    """Measured from the video against the plant's own numbers: within 0.1 mm (the chain
    reached 0.02 mm: 640x360 frames, about 2.5 mm per pixel, sub-pixel marker centroids)."""
    folder, doc = demo["folder"], demo["doc"]
    assert [c["name"] for c in doc["configurations"]] == list(LEG_SETS)
    for cfg in doc["configurations"]:
        (hop,) = cfg["hops"]
        label = hop["trial"]
        log = next(p for p in (folder / "logs").glob("*-hop.log") if f"/{label}/" in p.read_text())
        plant_m = float(re.search(r"distance_m=(-?[\d.e-]+)", log.read_text()).group(1))
        assert hop["measured_distance_m"] == pytest.approx(plant_m, abs=1e-4), label
        z = pd.read_csv(folder / "hops" / label / "hop.truth.csv", comment="#")["nose_z_m"].to_numpy()
        assert hop["measured_apex_m"] == pytest.approx(float(z.max() - z[0]), abs=1e-4), label


def test_predictions_are_run_on_the_calibrated_robot(demo):
    calibrated = load_robot(demo["folder"] / "calibration" / "robot.toml")
    for cfg in demo["doc"]["configurations"]:
        r = run(leg_set(calibrated, cfg["name"]), cycles=1)
        assert cfg["predicted"]["valid"] and r.valid
        assert cfg["predicted"]["distance_m"] == pytest.approx(r.distance_m, abs=1e-12)
    rows = (demo["folder"] / "sweep" / "results.csv").read_text().splitlines()
    assert len(rows) == 3                      # header and the two designs
