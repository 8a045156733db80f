"""The nose's load on a kitchen scale: the model's prediction (locust.sim.statics) and the
measurement that places the servo axis from it (locust measure nose-load), on virtual robots
whose truth is known (synthetic readings: the truth's own model load, rounded to the scale)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from locust import params
from locust.commands import cli
from locust.io import robot_toml
from locust.measure.nose_load import AXIS_KEY, PLATE_KEY, measure_nose_load
from locust.sim.samples import uncertain_values
from locust.sim.statics import standing_load

# the stance as `locust measure stance` would give it: crank and ground angle to about a
# degree; the plate's length and mass as the photo and the datasheet give them
MEASURED = {"geometry.crank_start_deg": 1.0, "geometry.ground_angle_deg": 1.5, "geometry.body_length_m": 0.002,
            PLATE_KEY: 0.001}


def robot_with(uncertain: dict[str, float]) -> params.Robot:
    """Medium with only ``uncertain`` (key -> sd) carrying an uncertainty; the axis none."""
    base = params.preset("medium")
    robot = base.with_values({k: base.get(k) for k in uncertain_values(base)}, params.Provenance("test"))
    for key, sd in uncertain.items():
        robot = robot.with_values({key: robot.get(key)}, params.Provenance("estimate", uncertainty=sd))
    return robot


def test_the_nose_carries_more_as_the_servos_move_toward_it():
    """Medium standing at rest: the floor carries its 31.1 g, 4.2 g of it under the nose;
    moving the servos (18 g of it) 5 mm toward the nose at a time raises the nose's share
    each time, by 0.3-0.7 g, and the centre of mass moves toward the nose by about 4.4 mm."""
    loads = [standing_load(params.preset("medium").with_values({AXIS_KEY: a}))
             for a in (0.043, 0.038, 0.033, 0.028, 0.023, 0.018, 0.013)]
    assert loads[3].nose_load_kg == pytest.approx(0.00420, abs=2e-5)
    assert loads[3].total_mass_kg == pytest.approx(0.03113, abs=2e-5)
    steps = np.diff([x.nose_load_kg for x in loads])
    assert np.all((steps > 0.0002) & (steps < 0.0008)), steps
    com = np.diff([x.com_from_nose_m for x in loads])
    assert np.all(np.abs(com + 0.0044) < 0.0004), com


def test_a_reading_without_rounding_gives_back_the_axis():
    """The truth's own load read exactly (a resolution of a microgram) places the axis
    within 0.05 mm of the truth, with no robot-file interval to lean on."""
    robot = robot_with({})
    truth = robot.with_values({AXIS_KEY: 0.021})
    reading = standing_load(truth).nose_load_kg
    res = measure_nose_load(robot, reading, resolution_kg=1e-9)
    assert res.axis_before is None and res.axis == res.axis_from_scale
    assert res.axis.value == pytest.approx(0.021, abs=5e-5)
    assert res.robot.get(AXIS_KEY) == res.axis.value
    assert res.robot.source_of(AXIS_KEY).source == "measured:kitchen_scale"


@pytest.mark.slow
def test_intervals_cover_the_truth_over_drawn_robots():
    """Twelve virtual Medium robots: the axis drawn anywhere from 18 to 38 mm, the stance,
    the plate's length and mass drawn within MEASURED; the nose and the whole robot read on a
    0.1 g scale (rounded). The robot file holds the central values and MEASURED's sds, no
    interval for the axis: the 95 % intervals of the axis and of the plate's mass hold the
    truth in at least 10 of 12, and the axis's is under 30 mm wide (12-25 mm measured)."""
    robot = robot_with(MEASURED)
    rng = np.random.default_rng(7)
    res_g = 0.1
    cover_axis = cover_plate = 0
    widths = []
    for _ in range(12):
        truth = robot.with_values({AXIS_KEY: float(rng.uniform(0.018, 0.038)),
                                   **{k: robot.get(k) + float(rng.normal()) * sd for k, sd in MEASURED.items()}})
        load = standing_load(truth)
        nose_g = round(load.nose_load_kg * 1000 / res_g) * res_g
        total_g = round(load.total_mass_kg * 1000 / res_g) * res_g
        res = measure_nose_load(robot, nose_g / 1000, res_g / 1000, total_g / 1000)
        lo, hi = res.axis.ci95
        cover_axis += lo <= truth.get(AXIS_KEY) <= hi
        widths.append(hi - lo)
        plo, phi = res.plate_mass.ci95
        cover_plate += plo <= truth.get(PLATE_KEY) <= phi
    assert cover_axis >= 10 and cover_plate >= 10, (cover_axis, cover_plate)
    assert max(widths) < 0.03, widths


def test_the_command_writes_the_robot_with_the_axis_measured(tmp_path):
    """``locust measure nose-load`` on Medium as preset, the model's own 4.2 g read at 1 g:
    the axis stays near the photo's 28 mm, its sd no wider than the photo's 3 mm, and the
    written robot reads back with the measured source; an existing file is not overwritten."""
    out = tmp_path / "robot.toml"
    res = CliRunner().invoke(cli, ["measure", "nose-load", "4.2", "--preset", "medium", "--write", str(out),
                                   "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    assert doc["key"] == AXIS_KEY and doc["axis_before"]["sd"] == 0.003
    assert doc["axis"]["value"] == pytest.approx(0.028, abs=5e-4) and doc["axis"]["sd"] <= 0.003
    rounding = 0.001 / math.sqrt(12)        # 1 g: an error uniform over one gram
    assert doc["axis_sd_terms_m"]["scale resolution"] == pytest.approx(rounding / abs(doc["slope_kg_per_m"]))
    written = robot_toml.load_robot(out)
    assert written.get(AXIS_KEY) == pytest.approx(doc["axis"]["value"], abs=1e-9)
    assert written.source_of(AXIS_KEY).source == "measured:kitchen_scale"
    before = out.read_bytes()
    again = CliRunner().invoke(cli, ["measure", "nose-load", "4.2", "--preset", "medium", "--write", str(out)])
    assert again.exit_code == 2 and "exists" in again.output and out.read_bytes() == before


@pytest.mark.parametrize("args, said", [
    (["40"], "the model reads"),                                   # more than any place of the axis gives
    (["4", "--total-g", "10"], "its servos and links alone weigh"),
    (["0"], "must be above 0"),
    (["4", "--resolution-g", "nan"], "not a finite number"),
])
def test_bad_readings_are_refused_with_a_hint(args, said):
    res = CliRunner().invoke(cli, ["measure", "nose-load", *args, "--preset", "medium"])
    assert res.exit_code == 2, res.output
    assert said in res.output and "hint:" in res.output
