"""`locust demo`, smallest form, in the default run: flash, hop Small/Medium/Large once on the
virtual robot (real firmware under MicroPython, MuJoCo plant, rendered video), track, calibrate
from the virtual robot's SYNTHETIC bench recordings, the stance from its stills, outcome
shares, a 2-design sweep, the report.

Known truth at every stage: the virtual robot (virtual/truth.toml, a draw of the robot as
built) for the calibration and the stance, the nose marker's true position in the video's
frames (hop.truth.csv) for the tracking, run() on the calibrated robot for the predictions.
The full-size demo is tests/test_report_demo.py (slow).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from locust.demo.virtual_robot import hidden_values, virtual_robot
from locust.io.robot_toml import load_robot
from locust.params import leg_set, preset
from locust.sim.run import run

LEG_SETS = ("small", "medium", "large")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("fastdemo")
    proc = subprocess.run([sys.executable, "-m", "locust.commands", "demo", "--out", str(out), "--cycles", "1",
                           "--trials", "1", "--designs", "2", "--jobs", "1", "--no-fit-hops"],
                          capture_output=True, text=True, timeout=600, check=False, cwd=out)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    for n in range(1, 9):
        assert f"[{n}/8]" in proc.stderr
    folder = out / "run"
    return {"folder": folder, "doc": json.loads((folder / "report" / "report.json").read_text()),
            "stderr": proc.stderr}


def test_the_virtual_robot_is_the_robot_as_built_drawn(demo):
    truth = load_robot(demo["folder"] / "virtual" / "truth.toml")
    assert truth == virtual_robot()
    assert truth.leg_set == "small"
    hidden = json.loads((demo["folder"] / "virtual" / "truth.json").read_text())["values"]
    assert hidden == pytest.approx(hidden_values(truth), rel=1e-12)
    assert "a draw of the robot as built" in demo["stderr"]


def test_every_robot_file_it_writes_has_the_film_hinge_and_the_robot_as_built(demo):
    """The seed's mistake (a beam's 0.056 N*m/rad for a fold) is nowhere: each robot file's
    hinge is on the film hinge's scale (1.46e-4 N*m/rad), its links the as-built strip's."""
    files = sorted(demo["folder"].rglob("*.toml"))
    assert len(files) >= 3       # the virtual robot, the calibrated one, the bench one
    for path in files:
        robot = load_robot(path)
        assert 1e-4 < robot.compliance.hinge_stiffness_nm_per_rad < 2e-4, path
        assert robot.link_lengths_m() == preset("small").link_lengths_m(), path
        assert robot.geometry.body_mass_kg < 0.01, path          # the as-built plate, not the seed's 50 g


def test_calibration_recovers_the_virtual_robots_values(demo):
    """Each value the bench fitted (source fit:) or the stills measured (measured:) against the
    virtual robot's: within three of its own standard deviations and 4 %; the servo axis'
    place, which the stance fits through every other geometry value it holds at the robot
    file's, within 1.5 mm (1.1 mm off in this draw, against a 0.12 mm standard deviation)."""
    truth = load_robot(demo["folder"] / "virtual" / "truth.toml")
    robot = load_robot(demo["folder"] / "calibration" / "robot.toml")
    checked = []
    for key in robot.flat():
        prov = robot.source_of(key)
        if not prov.source.startswith(("fit:", "measured:")):
            continue
        checked.append(key)
        if key == "geometry.servo_axis_x_m":
            assert robot.get(key) == pytest.approx(truth.get(key), abs=0.0015)
            continue
        assert abs(robot.get(key) - truth.get(key)) <= 3 * prov.uncertainty, key
        assert robot.get(key) == pytest.approx(truth.get(key), rel=0.04, abs=0.3), key
    assert {"compliance.hinge_stiffness_nm_per_rad", "servo.stall_torque_nm", "servo.noload_speed_rad_per_s",
            "contact.foot_friction", "geometry.crank_start_deg", "geometry.ground_angle_deg"} <= set(checked)
    # the plate on a 0.1 g kitchen scale, given by hand (--set)
    assert robot.source_of("geometry.body_mass_kg").source == "override"
    assert robot.geometry.body_mass_kg == pytest.approx(truth.geometry.body_mass_kg, abs=0.05e-3)


def test_outcome_shares_are_said_for_each_leg_set(demo):
    logs = sorted(demo["folder"].glob("logs/*-sim.log"))
    shares = [p.read_text() for p in logs if "--samples" in p.read_text().splitlines()[0]]
    assert len(shares) == 3
    for text, name in zip(shares, ("small", "medium", "large")):
        assert f"--leg-set {name}" in text.splitlines()[0]
        counts = [int(n) for n in re.findall(r"(?:goes over|rears and returns|stays low)\s+(\d+) of 16", text)]
        assert len(counts) == 3 and sum(counts) == 16, text


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
