"""`locust calibrate` with --units, --rename, --mirror (the track layer's one import), and its
plausibility warnings. The recordings are the shipped SYNTHETIC ones, rewritten here in cm or
mm (digit for digit: the decimal point moved) and labelled synthetic in their first line."""

from __future__ import annotations

import json
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from locust.bundled import bundled_recording
from locust.calibrate import beam as B
from locust.calibrate import ramp
from locust.calibrate.recordings import clean_samples, read_table
from locust.commands import cli


def run(*args):
    return CliRunner().invoke(cli, list(map(str, args)))


def shifted(cell: str, factor: int) -> str:
    """A number's text in a unit ``factor`` times smaller: the decimal point moved, nothing rounded."""
    return cell if cell.strip().lower() == "nan" else str(Decimal(cell) * factor)


def beam_tracker_export(path: Path, factor: int, title: str = "tip") -> Path:
    """synthetic_beam.csv (metres) as a Tracker export in a smaller unit."""
    lines = bundled_recording("synthetic_beam.csv").read_text().splitlines()
    head = [ln for ln in lines if not ln.startswith("#")]
    cols = head[0].split(",")
    t, x, y = cols.index("t_s"), cols.index("tip_x_m"), cols.index("tip_y_m")
    rows = []
    for ln in head[1:]:
        f = ln.split(",")
        rows.append("\t".join(["" if v == "nan" else v for v in (f[t], shifted(f[x], factor), shifted(f[y], factor))]))
    path.write_text(f"# SYNTHETIC beam drop (calibration/recordings/synthetic_beam.csv) in 1/{factor} m\n"
                    f"{title}\nt\tx\ty\n" + "\n".join(rows) + "\n")
    return path


def beam_json(*args):
    res = run("calibrate", "beam", *args, "--mass-kg", 0.01, "--length-m", 0.05, "--json", "--no-plot")
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout), res.stderr


def test_beam_in_cm_warns_then_fits_as_metres(tmp_path):
    metres, err = beam_json(bundled_recording("synthetic_beam.csv"))
    assert metres["warnings"] == [] and "warning" not in err
    cm = beam_tracker_export(tmp_path / "beam_cm.txt", 100)
    # read as metres: the tip of a 5 cm beam swings over a metre; the unit that fits is named
    table = read_table(bundled_recording("synthetic_beam.csv"))
    t, x, y = clean_samples(Path("b"), "tip", table.time_s(), *table.marker("tip"), min_samples=20)
    swing_m = float(np.ptp(B.principal_displacement(x, y)))
    assert 0.01 < swing_m < 0.02                                  # 1.4 cm on the 5 cm beam, as filmed
    wrong, err = beam_json(cm)
    assert wrong["warnings"] == [
        f"{cm}: the beam tip swings {swing_m * 100:.3g} m peak to peak, more than 0.05 m is plausible for a "
        f"0.05 m beam: the track is likely in cm, not m ({swing_m:.3g} m then): give --units cm"]
    assert f"warning: {wrong['warnings'][0]}" in err
    # a warning, not a stop: frequency and damping ratio do not depend on the scale; the amplitude does
    assert wrong["natural_frequency_hz"]["value"] == pytest.approx(metres["natural_frequency_hz"]["value"], rel=1e-6)
    assert wrong["amplitude_m"] == pytest.approx(100 * metres["amplitude_m"], rel=1e-6)
    right, err = beam_json(cm, "--units", "cm")
    assert right["warnings"] == [] and "warning" not in err
    for key in ("natural_frequency_hz", "damping_ratio", "stiffness_n_per_m",
                "compliance.hinge_stiffness_nm_per_rad"):
        assert right[key]["value"] == pytest.approx(metres[key]["value"], rel=1e-7), key   # the fit's own tolerance
    assert right["amplitude_m"] == pytest.approx(metres["amplitude_m"], rel=1e-7)
    # mirrored and renamed: the same beam
    flipped, _ = beam_json(cm, "--units", "cm", "--mirror", "--rename", "tip=beam", "--marker", "beam")
    assert flipped["natural_frequency_hz"]["value"] == pytest.approx(metres["natural_frequency_hz"]["value"],
                                                                     rel=1e-7)


def test_beam_in_metres_read_as_mm_warns_the_other_way(tmp_path):
    res = run("calibrate", "beam", bundled_recording("synthetic_beam.csv"), "--mass-kg", 0.01, "--length-m", 0.05,
              "--units", "mm", "--no-plot")
    assert res.exit_code == 0, res.output
    assert "less than 0.0001 m is plausible for a 0.05 m beam" in res.stderr
    assert "the track is likely in m, not mm" in res.stderr and "give --units m" in res.stderr
    assert B.tip_swing_warning(0.9, None) == (
        "beam: the beam tip swings 0.9 m peak to peak, more than 0.25 m is plausible for a desk-sized beam "
        "(no --length-m): the track is likely in cm, not m (0.009 m then): give --units cm")


def test_ramp_track_in_mm(tmp_path):
    lines = bundled_recording("synthetic_ramp_track.csv").read_text().splitlines()
    header = next(ln for ln in lines if not ln.startswith("#"))
    cols = header.split(",")
    metric = [j for j, c in enumerate(cols) if c.endswith(("_x_m", "_y_m"))]
    out = ["# SYNTHETIC ramp tilt (calibration/recordings/synthetic_ramp_track.csv) with positions in mm", header]
    for ln in lines[lines.index(header) + 1:]:
        f = ln.split(",")
        out.append(",".join(shifted(v, 1000) if j in metric else v for j, v in enumerate(f)))
    mm = tmp_path / "ramp_mm.csv"
    mm.write_text("\n".join(out) + "\n")
    metres = json.loads(run("calibrate", "ramp", bundled_recording("synthetic_ramp_track.csv"),
                            bundled_recording("synthetic_ramp.csv"), "--json", "--no-plot").stdout)
    res = run("calibrate", "ramp", mm, bundled_recording("synthetic_ramp.csv"), "--json", "--no-plot")
    assert res.exit_code == 0, res.output
    warn = json.loads(res.stdout)["warnings"]
    assert len(warn) == 1 and "ramp's markers are 300 m apart" in warn[0] and "give --units mm" in warn[0]
    res = run("calibrate", "ramp", mm, bundled_recording("synthetic_ramp.csv"), "--units", "mm",
              "--rename", "robot=body", "--robot-marker", "body", "--json", "--no-plot")
    assert res.exit_code == 0, res.output
    got = json.loads(res.stdout)
    assert got["warnings"] == [] and got["angles_deg"][0] == pytest.approx(metres["angles_deg"][0], rel=1e-9)
    assert got["contact.foot_friction"]["value"] == pytest.approx(metres["contact.foot_friction"]["value"], rel=1e-9)
    assert ramp.board_length_warning(0.3) is None


def test_import_options_need_a_track():
    res = run("calibrate", "servo", bundled_recording("synthetic_servo.csv"), "--inertia-kgm2", 1.5e-5, "--units", "cm")
    assert res.exit_code == 2 and "apply to a horn track (--pivot)" in res.output and "hint:" in res.output
    res = run("calibrate", "ramp", bundled_recording("synthetic_ramp.csv"), "--mirror")
    assert res.exit_code == 2 and "these are angle tables" in res.output
    res = run("calibrate", "beam", bundled_recording("synthetic_beam.csv"), "--mass-kg", 0.01, "--units", "ft")
    assert res.exit_code == 2 and "unknown unit 'ft'" in res.output and "Traceback" not in res.output
    res = run("calibrate", "beam", bundled_recording("synthetic_beam.csv"), "--mass-kg", 0.01, "--rename", "nose=tip")
    assert res.exit_code == 2 and "no marker 'nose' (markers: tip)" in res.output
