"""`locust report` with --units/--rename/--mirror, its plausibility warnings, and what it says
about where the "measured" trials came from (a guessed leg set, the virtual robot).

The trials are SYNTHETIC: the staircase nose of tests/test_report_inputs.py (stands 0.4 s,
then hops 20, 25 and 15 cm on the seed's 1.3 s schedule, apexes 5, 8 and 3 cm; exactly still
when standing, as Tracker's autotracker gives a still target), written as Tracker would
export it filmed right-to-left and calibrated in mm (digit for digit: the decimal point
moved, the sign flipped), and as a `locust hop --port sim` run's tracks CSV and run record."""

from __future__ import annotations

import json
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.io.run_record import HopSchedule, Phase, RunRecord
from locust.io.run_record import write as write_record
from locust.io.tracks_csv import TracksCsv, write_tracks_csv
from locust.report.checks import ROBOT, SYNTHETIC, VIRTUAL, recorded_on
from test_report import parse
from test_report_inputs import staircase

HOPS_M = (0.20, 0.25, 0.15)
APEX_M = (0.05, 0.08, 0.03)
CYCLES = 3


def invoke(*args):
    return CliRunner().invoke(cli, ["report", *map(str, args)])


def tracker_mm_mirrored(path: Path, t, x, y) -> Path:
    """A nose as a Tracker export titled "A", in mm, x mirrored: each value's exact decimal x 1000."""
    rows = [f"{float(ti)!r}\t{-Decimal(repr(float(xi))) * 1000}\t{Decimal(repr(float(yi))) * 1000}"
            for ti, xi, yi in zip(t, x, y)]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("# SYNTHETIC staircase hop (tests/test_report_import.py), exported as Tracker in mm, "
                    "filmed right-to-left\nA\nt\tx\ty\n" + "\n".join(rows) + "\n")
    return path


@pytest.fixture(scope="module")
def trials(tmp_path_factory):
    root = tmp_path_factory.mktemp("report-import")
    t, x, y = staircase(hops=HOPS_M, apex=APEX_M)
    export = tracker_mm_mirrored(root / "tracker" / "hop_mm.txt", t, x, y)
    noisy = tracker_mm_mirrored(root / "noisy" / "hop_mm.txt", *staircase(hops=HOPS_M, apex=APEX_M, noise=0.0005))
    # a trial as `locust hop --port sim` and `locust track` leave it: run.json from the virtual robot's pty
    folder = root / "hops" / "small-1"
    folder.mkdir(parents=True)
    ok = np.ones(t.size, bool)
    nan = np.full(t.size, np.nan)
    write_tracks_csv(folder / "hop.tracks.csv", TracksCsv(
        frame=np.arange(t.size), t_s=t, px={"nose": nan}, py={"nose": nan}, x_m={"nose": x}, y_m={"nose": y},
        ok={"nose": ok},
        comments=("synthetic: staircase nose (tests/test_report_import.py)",)))
    record = RunRecord(schedule=HopSchedule(cycles=CYCLES, push_deg=-30.0, push_ms=300, wait_ms=1000),
                       port="/dev/pts/7", status="complete", firmware_version="0.3.0", firmware_status="complete")
    for c in range(CYCLES):
        for name, at_us in (("push", c * 1_300_000), ("wait", c * 1_300_000 + 300_000)):
            record.add_phase(Phase(c + 1, name, at_us, at_us + 150))
    write_record(record, folder)
    return {"root": root, "export": export, "noisy": noisy, "folder": folder}


def report_of(res):
    assert res.exit_code == 0, res.output
    html = Path(res.stdout.strip().splitlines()[-1])
    return html, parse(html).cells, json.loads((html.parent / "report.json").read_text())


def test_units_mirror_rename_give_the_true_hops(trials):
    res = invoke("--measured", f"small={trials['export']}", "--units", "mm", "--mirror", "--rename", "A=nose",
                 "--preset", "seed", "--cycles", CYCLES, "--out", trials["root"] / "out-mm")
    html, cells, doc = report_of(res)
    for k, (d, a) in enumerate(zip(HOPS_M, APEX_M), start=1):
        assert cells[("small", f"hop_measured_marker_travel_mm:tracker#{k}")] == f"{d * 1000:.1f}"
        apex = float(cells[("small", f"hop_measured_apex_mm:tracker#{k}")]) / 1000
        assert a * (1 - 0.0278) - 1e-4 <= apex <= a + 1e-4      # 30 frames/s samples the arc's top
    assert cells[("small", "measured_marker_travel_mm")] == f"{sum(HOPS_M) * 1000:.1f}"
    # given name, converted, no run record: nothing to warn about
    assert doc["warnings"] == [] and "warning" not in res.stderr and 'id="warnings"' not in html.read_text()
    (trial,) = doc["configurations"][0]["trials"]
    assert trial["track_units"] == "mm" and trial["track_mirrored"] is True
    assert trial["config_from"] == "given" and trial["recorded_on"] is None


def test_mirrored_mm_read_as_metres_is_warned_not_stopped(trials):
    res = invoke("--measured", f"small={trials['export']}", "--rename", "A=nose", "--preset", "seed",
                 "--cycles", CYCLES, "--out", trials["root"] / "out-warn")
    html, cells, doc = report_of(res)
    kinds = {w["kind"]: w["message"] for w in doc["warnings"]}
    assert set(kinds) == {"mirrored", "units"}
    predicted = doc["configurations"][0]["predicted_marker_travel_m"]    # the same marker's
    assert predicted > 0.002                                  # the seed hops forward (a few mm)
    assert kinds["mirrored"] == (f"tracker: the tracked nose travels -600 m overall where the model predicts "
                                 f"+{predicted * 1000:.1f} mm: the camera likely saw the hop mirrored (filmed "
                                 "right-to-left): give --mirror")
    # hundreds of metres a hop: 250 m read, 0.25 m in mm
    assert [float(cells[("small", f"hop_measured_marker_travel_mm:tracker#{k}")]) / 1000 for k in (1, 2, 3)] == \
        pytest.approx([-200.0, -250.0, -150.0], abs=1e-4)
    assert kinds["units"] == ("tracker: 250 m in one hop is not this robot's (at most 2 m): the track is likely "
                              "in mm, not m (0.25 m then): give --units mm")
    for message in kinds.values():
        assert f"warning: {message}" in res.stderr
    text = html.read_text()
    assert 'data-kind="mirrored"' in text and 'data-kind="units"' in text
    assert text.index('id="warnings"') < text.index('id="summary"')      # at the top of the page
    # only mirrored, in mm: the direction alone
    _, _, doc = report_of(invoke("--measured", f"small={trials['export']}", "--rename", "A=nose", "--units", "mm",
                                 "--preset", "seed", "--cycles", CYCLES, "--out", trials["root"] / "out-dir"))
    assert [w["kind"] for w in doc["warnings"]] == ["mirrored"]
    assert "travels -600.0 mm overall" in doc["warnings"][0]["message"]


def test_noisy_mm_read_as_metres_stops_with_the_unit_in_the_hint(trials):
    """0.5 mm of camera noise read as 0.5 m looks like a robot already moving at the first frame:
    no hop can be measured, so it stops, and the hint names the unit."""
    out = trials["root"] / "out-noisy"
    res = invoke("--measured", f"small={trials['noisy']}", "--rename", "A=nose", "--mirror", "--preset", "seed",
                 "--cycles", CYCLES, "--out", out)
    assert res.exit_code == 2 and "error:" in res.output and "Traceback" not in res.output
    assert "already moving" in res.output
    assert "hint: the nose track spans" in res.output
    assert "the track is likely in mm, not m" in res.output and "give --units mm" in res.output
    assert not out.exists()


def test_guessed_leg_set_and_virtual_robot_are_said(trials):
    root = trials["root"]
    res = invoke("--measured", trials["folder"], "--preset", "seed", "--out", root / "out-virtual")
    html, cells, doc = report_of(res)
    kinds = {w["kind"]: w for w in doc["warnings"]}
    assert set(kinds) == {"configuration-guessed", "virtual-robot"}
    guessed = kinds["configuration-guessed"]["message"]
    assert guessed.startswith("small-1: leg set 'small' was guessed from the folder name (")
    assert guessed.endswith("say which leg set was filmed with --measured small=PATH")
    virtual = kinds["virtual-robot"]["message"]
    assert virtual == ("small-1: the 'measured' trial comes from the virtual robot (its run record's port "
                       "/dev/pts/7 is a pseudo-terminal, as the virtual robot's (--port sim)): it measures the "
                       "simulated robot, not the physical one")
    (trial,) = doc["configurations"][0]["trials"]
    assert trial["config_from"] == "folder name" and trial["recorded_on"] == VIRTUAL
    assert cells[("small", "recorded_on:small-1")] == VIRTUAL
    assert cells[("small", "config_from:small-1")] == "folder name"
    text = html.read_text()
    assert "measured trials: 1 of 1 recorded on the virtual robot (the simulated robot, not the physical one)" in text
    assert f"warning: {virtual}" in res.stderr and f"warning: {guessed}" in res.stderr
    # the warnings change no number: the staircase's hops, as measured from the tracks CSV in metres
    assert [h["measured_marker_travel_m"] for h in doc["configurations"][0]["hops"]] == pytest.approx(HOPS_M, abs=1e-9)


@pytest.mark.parametrize("fields, where, because", [
    ({"port": "sim"}, VIRTUAL, "its run record's port is 'sim'"),
    ({"port": "/dev/pts/3"}, VIRTUAL, "pseudo-terminal"),
    ({"port": "/dev/ttys004"}, VIRTUAL, "pseudo-terminal"),
    ({"port": "/dev/ttyUSB0", "firmware_status": "complete"}, ROBOT, "port /dev/ttyUSB0"),
    ({"port": "/dev/ttyUSB0", "firmware_version": "0.3.0 (virtual)"}, VIRTUAL, "its firmware version says"),
    ({"port": "COM3", "message": "simulated"}, VIRTUAL, "its record's message says 'simulated'"),
    ({"port": "synthetic", "firmware_version": "synthetic"}, SYNTHETIC, "labelled synthetic"),
])
def test_where_a_run_was_recorded(fields, where, because):
    got = recorded_on(RunRecord(schedule=HopSchedule(), **fields))
    assert got[0] == where and because in got[1]
    assert recorded_on(None) == (None, "no run record")
