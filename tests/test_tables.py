"""The tables `locust sim`, `locust hop` and `locust virtual` print: every figure is the
result's own, in mm, to the printed precision (0.005 mm)."""

import math
import re

import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.params import preset
from locust.sim.run import run
from locust.tables import for_person, mean_sd, mm, plant_lines, sensitivity_lines, sim_lines, table

ROUNDING_MM = 0.005     # two decimals


def _rows(lines: list[str], header: str) -> list[list[str]]:
    at = next(i for i, line in enumerate(lines) if line.split() == header.split())
    return [line.split() for line in lines[at + 1:] if re.match(r"^\s+\d+\s", line)]


def test_sim_table_is_the_results_own_numbers_in_mm():
    r = run(preset("seed"), cycles=3)
    assert r.valid
    res = CliRunner().invoke(cli, ["sim", "--preset", "seed", "--cycles", "3"])
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[0].startswith(f"seed: valid, {r.outcome.replace('_', ' ')} (3 cycles, time step 0.001 s")
    rows = _rows(lines, "hop  distance mm  nose rise mm  CoM rise mm  flight ms")
    assert [int(row[0]) for row in rows] == [1, 2, 3]
    for row, hop in zip(rows, r.hops, strict=True):
        assert abs(float(row[1]) - hop.distance_m * 1000) <= ROUNDING_MM
        assert abs(float(row[2]) - hop.nose_apex_m * 1000) <= ROUNDING_MM
        assert abs(float(row[3]) - hop.com_apex_m * 1000) <= ROUNDING_MM
        assert abs(float(row[4]) - hop.flight_s * 1000) <= 0.05
    total = re.search(r"total distance (-?[\d.]+) mm; highest nose (-?[\d.]+) mm", res.output)
    assert abs(float(total.group(1)) - r.distance_m * 1000) <= ROUNDING_MM
    assert abs(float(total.group(2)) - r.max_nose_height_m * 1000) <= ROUNDING_MM
    assert "distance_m=" not in res.output and "e-0" not in res.output
    # the linkage's kinematics in its own words only under --verbose, with the result's figure
    assert "Grashof" not in res.output and "transmission" not in res.output
    verbose = CliRunner().invoke(cli, ["sim", "--preset", "seed", "--cycles", "3", "--verbose"])
    line = next(ln for ln in verbose.output.splitlines() if "transmission angle" in ln)
    assert f"linkage: {r.grashof} (Grashof class), worst transmission angle {r.transmission_deg:.0f} deg" in line


def test_invalid_run_prints_its_reasons_and_no_table():
    r = run(preset("seed"), cycles=1)
    bad = type(r)(**{**vars(r), "valid": False, "reasons": ["energy from nowhere"]})
    assert sim_lines(bad) == [sim_lines(r)[0].replace("valid", "INVALID", 1), "  reason: energy from nowhere"]


def test_table_right_aligns_each_column():
    assert table(["hop", "distance mm"], [["1", "18.59"], ["10", "-0.40"]]) == [
        "  hop  distance mm",
        "    1        18.59",
        "   10        -0.40"]
    assert mm(0.018585325) == "18.59" and mm(math.nan) == "nan" and mm(1e-9, 3) == "0.000"


def test_plant_lines_give_the_live_runs_figures_in_mm():
    hop = {"cycle": 1, "distance_m": 0.01858532534294068, "nose_apex_m": 0.0412, "com_apex_m": 0.0101,
           "flight_s": 0.0453}
    summary = {"plant": "mujoco", "distance_m": 0.01858532534294068, "max_nose_height_m": 0.0612, "sim_time_s": 2.829,
               "valid": True, "reasons": [], "realtime_factor": 23.7, "video_path": None, "frames": 0, "hops": [hop],
               "outcome": "rears_and_returns"}
    assert plant_lines(summary) == ["simulated robot: valid, rears and returns (2.829 s simulated, 23.7x real time)",
                                    "  hop  distance mm  nose rise mm  CoM rise mm  flight ms",
                                    "    1        18.59         41.20        10.10       45.3",
                                    "  total distance 18.59 mm; highest nose 61.20 mm above the floor"]
    bad = {**summary, "valid": False, "reasons": ["aborted"], "hops": [], "outcome": None}
    assert plant_lines(bad) == ["simulated robot: INVALID (2.829 s simulated, 23.7x real time)", "  reason: aborted"]
    assert plant_lines({"plant": "record", "commands": 7}) == ["servo commands recorded: 7"]


@pytest.mark.parametrize("mean_m, sd_m, text", [
    (-0.0671, 0.0104, "-67 ± 10"),          # sd to two figures, the mean to the same place
    (0.0133, 0.0096, "13.3 ± 9.6"),
    (0.1238, 0.00097, "123.80 ± 0.97"),
    (0.0082, float("nan"), "8.2"),          # one draw: no sd
    (float("nan"), float("nan"), "nan"),
])
def test_mean_sd_keeps_sensible_digits(mean_m, sd_m, text):
    assert mean_sd(mean_m, sd_m) == text


def test_sensitivity_names_each_value_in_the_unit_a_person_reads():
    """The deciding values in mm, deg or their own unit, each with it (they were printed in the
    key's unit with none: `geometry.servo_axis_x_m (sd 0.003): 0.022 goes over`)."""
    from types import SimpleNamespace as E

    axis = E(key="geometry.servo_axis_x_m", sd=0.003, low_value=0.022, low_outcome="goes_over",
             high_value=0.034, high_outcome="stays_low")
    crank = E(key="geometry.crank_start_deg", sd=10.0, low_value=-120.0, low_outcome="goes_over",
              high_value=-80.0, high_outcome=None)
    sens = E(nominal="goes_over", k_sd=2.0, deciding=[axis, crank])
    assert sensitivity_lines(sens)[1:] == [
        "    geometry.servo_axis_x (sd 3 mm): 22 mm goes over; 34 mm stays low",
        "    geometry.crank_start (sd 10 deg): -120 deg goes over; -80 deg invalid"]
    assert for_person("geometry.link_density_kg_per_m3") == ("geometry.link_density", 1.0, "kg/m³")
    assert for_person("geometry.body_mass_kg") == ("geometry.body_mass", 1000.0, "g")
