"""`locust demo` end to end (slow), checked against what its report must show.

The virtual robot (a draw of the robot as built; firmware under MicroPython, MuJoCo plant,
rendered video) hops Small, Medium and Large; the videos are tracked, its SYNTHETIC bench
recordings calibrated, its stance measured from two stills, the hops of Medium and Large
fitted, a sweep run and a report written. Checked: under ten minutes, the report names all three leg sets in at
least three embedded figures, the videos/records/tracks it used are kept, its predictions are
run()'s own on the calibrated robot.toml, and its measured distances agree with what the
virtual robot's own simulation says it travelled.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from locust.io.robot_toml import load_robot
from locust.params import leg_set
from locust.sim.run import run

pytestmark = pytest.mark.slow

LEG_SETS = ("small", "medium", "large")
TRIALS = 2
CYCLES = 3


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "locust.commands", "demo", "--out", str(out)],
                          capture_output=True, text=True, timeout=660)
    wall = time.perf_counter() - t0
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    report = Path(re.search(r"report: (\S+)", proc.stdout).group(1))
    return {"folder": out / "run", "report": report, "wall_s": wall, "stderr": proc.stderr}


def test_demo_finishes_within_ten_minutes_with_progress(demo):
    assert demo["wall_s"] < 600
    for n in range(1, 10):
        assert f"[{n}/9]" in demo["stderr"]
    timings = json.loads((demo["folder"] / "timings.json").read_text())
    assert len(timings["stages"]) == 9 and timings["total_s"] < 600


def test_demo_keeps_what_it_used(demo):
    folder = demo["folder"]
    for name in LEG_SETS:
        for k in range(1, TRIALS + 1):
            trial = folder / "hops" / f"{name}-{k}"
            assert (trial / "hop.mp4").stat().st_size > 10_000
            assert json.loads((trial / "run.json").read_text())["status"] == "complete"
            assert (trial / "hop.tracks.csv").stat().st_size > 1_000
    assert (folder / "calibration" / "robot.toml").is_file()
    assert (folder / "sweep" / "results.csv").is_file()
    assert demo["report"] == folder / "report" / "report.html"
    assert (folder / "report" / "dashboard.png").stat().st_size > 50_000


def test_report_figures_name_the_three_leg_sets(demo):
    text = demo["report"].read_text(encoding="utf-8")
    alts = re.findall(r'<img src="data:image/png;base64,[A-Za-z0-9+/=]{5000,}" alt="([^"]*)"', text)
    naming = [a for a in alts if all(n in a for n in ("Small", "Medium", "Large"))]
    assert len(naming) >= 3, alts


def test_report_numbers_are_the_pipelines_own(demo):
    doc = json.loads((demo["report"].parent / "report.json").read_text())
    calibrated = load_robot(demo["folder"] / "calibration" / "robot.toml")
    assert calibrated.source_of("contact.foot_friction").source.startswith("fit:")
    text = demo["report"].read_text(encoding="utf-8")
    for cfg in doc["configurations"]:
        r = run(leg_set(calibrated, cfg["name"]), cycles=CYCLES)
        assert r.valid and cfg["predicted"]["valid"], r.reasons   # the seed with its leg sets hops validly
        assert cfg["predicted"]["distance_m"] == pytest.approx(r.distance_m, abs=1e-9)
        # the summary's distance is locust sim's; the marker's travel, as the figure draws it, has its
        # own name (tests/test_report_headline.py)
        assert cfg["predicted_distance_m"] == pytest.approx(r.distance_m, abs=1e-9)
        cell = f'data-config="{cfg["name"]}" data-field="predicted_distance_mm">{r.distance_m * 1000:.1f}<'
        assert cell in text
        marker_m = sum(h["distance_m"] for h in cfg["predicted_marker_hops"])
        assert cfg["predicted_marker_travel_m"] == pytest.approx(marker_m, abs=1e-12)
        cell = f'data-config="{cfg["name"]}" data-field="predicted_marker_travel_mm">{marker_m * 1000:.1f}<'
        assert cell in text


def test_measured_hops_match_the_virtual_robots_own(demo):
    """Known truth of the whole chain (video -> track -> report): the distance the virtual
    robot's own audited simulation says it travelled (printed by `locust hop`), within 0.3 mm
    over three hops, and the nose marker's true height in the video's frames
    (hop.truth.csv, sampled at the same 30 frames/s), within 0.1 mm (one-cycle runs of the
    same chain reach 0.02 mm: tests/test_demo_fast.py)."""
    import pandas as pd

    doc = json.loads((demo["report"].parent / "report.json").read_text())
    checked = 0
    for cfg in doc["configurations"]:
        for trial in cfg["trials"]:
            label = trial["label"]
            hops = [h for h in cfg["hops"] if h["trial"] == label]
            assert len(hops) == CYCLES
            log = next(p for p in (demo["folder"] / "logs").glob("*-hop.log")
                       if p.name.split("-", 1)[1] == "hop.log" and f"/{label}/" in p.read_text())
            plant_m = float(re.search(r"total distance (-?[\d.]+) mm", log.read_text()).group(1)) / 1000
            measured_m = sum(h["measured_marker_travel_m"] for h in hops)
            assert measured_m == pytest.approx(plant_m, abs=0.0003), (label, measured_m, plant_m)
            truth = pd.read_csv(demo["folder"] / "hops" / label / "hop.truth.csv", comment="#")
            z = truth["nose_z_m"].to_numpy()
            true_jump = float(z.max() - z[0])       # the first frame: standing, before the first push
            assert max(h["measured_apex_m"] for h in hops) == pytest.approx(true_jump, abs=0.0001)
            checked += 1
    assert checked == len(LEG_SETS) * TRIALS


def test_demo_closes_the_loop(demo):
    """The filmed hops of Medium and Large (which rear and come back down, as the virtual
    robot's draw was chosen to) are fitted: each default key identifiable or said not to be,
    what is identifiable written with source fit:hops over the bench robot's; the report draws
    the prediction before the fit."""
    fitted = load_robot(demo["folder"] / "calibration" / "robot.toml")
    bench = load_robot(demo["folder"] / "calibration" / "robot-bench.toml")
    log = next(demo["folder"].glob("logs/*-calibrate-hop.log")).read_text()
    written = re.search(r"wrote (.+) to ", log).group(1).split(", ")
    assert "contact.foot_friction" in written
    for key in written:
        assert fitted.source_of(key).source == "fit:hops", key
        assert bench.source_of(key).source != "fit:hops", key
    doc = json.loads((demo["report"].parent / "report.json").read_text())
    for cfg in doc["configurations"]:     # the fitted model ends each leg set's hops as the virtual robot did
        ends = {t["outcome"] for t in cfg["measured"]["outcomes"]}
        assert ends == {cfg["predicted_outcome"]["outcome"]}, cfg["name"]
    assert {c["name"]: c["predicted_outcome"]["outcome"] for c in doc["configurations"]} == {
        "small": "stays_low", "medium": "rears_and_returns", "large": "rears_and_returns"}
    for row in doc["timing"]:             # the firmware's clock, as the demo films two hops at once
        assert row["jitter"]["max_late_ms"] <= 2.0 or row["timing_note"], row
    doc = json.loads((demo["report"].parent / "report.json").read_text())
    for cfg in doc["configurations"]:
        assert cfg["predicted_before_fit"]["valid"]
        assert cfg["predicted_spread"]["n_valid"] >= 2
        shares = [o["share"] for o in cfg["predicted_spread"]["outcomes"].values()]
        assert sum(shares) == pytest.approx(1.0, abs=1e-12), cfg["name"]
    assert 'id="outcomes"' in demo["report"].read_text()
