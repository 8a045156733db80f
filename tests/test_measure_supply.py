"""``locust measure supply`` (locust.measure.supply): the arithmetic against hand-computed values,
refusals of readings no supply gives, and a hidden current-limited supply recovered from a
virtual meter's readings (synthetic: the circuit of locust.sim.supply through a meter's error)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.errors import MeasureError
from locust.io.robot_toml import load_robot
from locust.measure.meter import MeterSpec
from locust.measure.supply import SOURCE, SupplyReadings, measure_supply, virtual_readings
from locust.params import Provenance, preset

VOLTS = MeterSpec(0.5, 2, 0.01)          # ±(0.5 % + 2 digits) on a 20 V range
AMPS = MeterSpec(1.2, 3, 0.01)           # ±(1.2 % + 3 digits) on a 10 A range
S3 = math.sqrt(3)


@pytest.fixture(scope="module")
def small():
    """Small as built (servo winding 10 ± 1.5 ohm, 0.5 ohm, 1.5 A), its board's 0.05 A given an
    sd of 0.02 A (as built it has none)."""
    return preset("small").with_values({"power.board_current_a": 0.05},
                                       Provenance("estimate:ESP32 dev board", uncertainty=0.02))


def test_the_resistance_from_the_two_voltages_by_hand(small):
    res = measure_supply(small, SupplyReadings(4.97, 4.52), VOLTS)
    assert res.value.value == pytest.approx(10 * 0.45 / (2 * 4.52), rel=1e-12)            # R (Vr - Vs) / 2 Vs
    digit = 2 * 0.01 / S3                                                                  # 2 digits, uniform
    terms = {"rest reading": 10 / (2 * 4.52) * digit, "stalled reading": 10 * 4.97 / (2 * 4.52 ** 2) * digit,
             "servo.winding_resistance_ohm": 0.45 / (2 * 4.52) * 1.5}                      # the gain cancels
    assert res.sd_terms == pytest.approx(terms, rel=1e-12)
    assert res.value.sd == pytest.approx(math.sqrt(sum(t * t for t in terms.values())), rel=1e-12)
    assert res.rest.value == 4.97 and res.rest.sd == pytest.approx(math.hypot(0.005 * 4.97 / S3, digit), rel=1e-12)
    assert res.bound == pytest.approx(2 * 4.52 / 10 + 0.05, rel=1e-12)                     # the limit at least
    # the robot written reads what the meter read, and says where its values came from
    assert res.predicted.stall_v == pytest.approx(4.52, rel=1e-12)
    for key, est in (("power.source_resistance_ohm", res.value), ("power.supply_voltage_v", res.rest)):
        assert res.robot.get(key) == est.value
        prov = res.robot.source_of(key)
        assert prov.source == SOURCE == "data:measure supply" and prov.uncertainty == est.sd


def test_the_resistance_with_the_current_by_hand(small):
    res = measure_supply(small, SupplyReadings(4.97, 4.52, 0.91), VOLTS, AMPS)
    assert res.value.value == pytest.approx(0.45 / 0.91, rel=1e-12)                        # (Vr - Vs) / I
    digit = 2 * 0.01 / S3
    amps_sd = math.hypot(0.012 * 0.91 / S3, 3 * 0.01 / S3)
    terms = {"rest reading": digit / 0.91, "stalled reading": digit / 0.91,
             "the volts' gain": 0.45 / 0.91 * 0.005 / S3, "current reading": 0.45 / 0.91 ** 2 * amps_sd}
    assert res.sd_terms == pytest.approx(terms, rel=1e-12)                                 # no winding term
    assert res.winding_ohm == pytest.approx(2 * 4.52 / 0.91, rel=1e-12)
    assert res.bound == pytest.approx(0.91 + 0.05, rel=1e-12)


def test_the_current_limit_by_hand(small):
    res = measure_supply(small, SupplyReadings(4.98, 3.80), VOLTS, solve="limit")
    assert res.key == "power.current_limit_a"
    assert res.value.value == pytest.approx(2 * 3.80 / 10 + 0.05, rel=1e-12)               # 2 Vs / R + I_board
    volts_sd = math.hypot(0.005 * 3.80 / S3, 2 * 0.01 / S3)                                # the gain counts alone
    terms = {"stalled reading": 2 / 10 * volts_sd, "servo.winding_resistance_ohm": 2 * 3.80 / 10 ** 2 * 1.5,
             "power.board_current_a": 0.02}
    assert res.sd_terms == pytest.approx(terms, rel=1e-12)
    assert res.bound == pytest.approx(10 * 1.18 / (2 * 3.80), rel=1e-12)                   # the resistance at most
    assert res.predicted.stall_v == pytest.approx(3.80, rel=1e-12) and res.notes == []
    # the robot as built gives the board's draw no sd: counted as exact, and said so
    exact = measure_supply(preset("small"), SupplyReadings(4.98, 3.80), VOLTS, solve="limit")
    assert "power.board_current_a" not in exact.sd_terms and "no uncertainty" in exact.notes[0]
    with_amps = measure_supply(small, SupplyReadings(4.98, 3.80, 0.76), VOLTS, AMPS, solve="limit")
    assert with_amps.value.value == pytest.approx(0.76 + 0.05, rel=1e-12)
    assert with_amps.value.sd == pytest.approx(math.hypot(math.hypot(0.012 * 0.76 / S3, 0.03 / S3), 0.02), rel=1e-12)


@pytest.mark.parametrize("readings, match", [
    (SupplyReadings(4.97, -4.52), "positive number of volts"),
    (SupplyReadings(-4.97, 4.52), "positive number of volts"),
    (SupplyReadings(4.50, 4.80), "above its 4.5 V at rest"),
    (SupplyReadings(4.97, 4.52, -0.9), "positive number of amperes"),
    (SupplyReadings(4.97, math.nan), "positive number of volts"),
])
def test_bad_readings_are_refused(small, readings, match):
    with pytest.raises(MeasureError, match=match) as err:
        measure_supply(small, readings, VOLTS, AMPS)
    assert err.value.hint


def test_a_robot_file_that_disagrees_with_the_reading_is_refused(small):
    # a 0.6 A limit could not have let the servos draw 2 x 4.52 / 10 A
    with pytest.raises(MeasureError, match="current_limit_a = 0.6 A"):
        measure_supply(small.with_values({"power.current_limit_a": 0.6}), SupplyReadings(4.97, 4.52), VOLTS)
    # a 2 ohm source alone would sag the stalled plug below 3.8 V: at most 1.55 ohm
    with pytest.raises(MeasureError, match="at most 1.55 ohm"):
        measure_supply(small.with_values({"power.source_resistance_ohm": 2.0}), SupplyReadings(4.98, 3.80), VOLTS,
                       solve="limit")
    with pytest.raises(MeasureError, match="not a meter's accuracy"):
        MeterSpec.parse("0.5 %", 0.01)
    with pytest.raises(MeasureError, match="positive number"):
        MeterSpec.parse("0.5%+2", 0.0)


def test_a_perfect_meter_reads_the_circuit(small):
    exact = MeterSpec(0.0, 0.0, 1e-12)
    r = virtual_readings(small, exact, exact, seed=3)
    assert (r.rest_v, r.stall_v, r.stall_a) == pytest.approx((5.0, 50 / 11, 10 / 11), rel=1e-9)
    # a real one stays within its spec, and rounds to its last digit
    rng_readings = [virtual_readings(small, VOLTS, AMPS, seed=s) for s in range(50)]
    for r in rng_readings:
        assert abs(r.stall_v - 50 / 11) <= 0.005 * 50 / 11 + 0.02 + 1e-12
        assert r.stall_v == pytest.approx(round(r.stall_v, 2), abs=1e-12)


def hidden_supply(seed: int):
    """Small on a hidden current-limited source (0.7 A, 0.3 ohm), its servos' winding and its
    board's draw drawn about the robot file's own (10 ± 1.5 ohm, 0.05 ± 0.02 A), as a robot
    built from the file differs from it."""
    rng = np.random.default_rng(1000 + seed)
    return preset("small").with_values({
        "power.current_limit_a": 0.7, "power.source_resistance_ohm": 0.3, "power.brownout_v": 2.5,
        "servo.winding_resistance_ohm": 10.0 + 1.5 * rng.standard_normal(),
        "power.board_current_a": max(0.0, 0.05 + 0.02 * rng.standard_normal())})


@pytest.mark.parametrize("amps", [None, AMPS])
def test_a_hidden_current_limited_supply_is_recovered_within_its_interval(small, amps):
    """Ten seeds: the virtual meter's readings on the hidden supply, measured against the robot
    file (Small as built): the limit's 95 % interval holds the truth in at least 8 of 10 (with
    the current read too, without the winding's uncertainty)."""
    held, rest_held, widths = 0, 0, []
    for seed in range(10):
        truth = hidden_supply(seed)
        readings = virtual_readings(truth, VOLTS, amps, seed=seed)
        res = measure_supply(small, readings, VOLTS, amps, solve="limit")
        lo, hi = res.value.ci95
        held += lo <= 0.7 <= hi
        rest_held += res.rest.ci95[0] <= truth.power.supply_voltage_v <= res.rest.ci95[1]
        widths.append(hi - lo)
    assert held >= 8 and rest_held >= 8, (held, rest_held, widths)
    assert max(widths) < (0.5 if amps is None else 0.12)


def test_the_command_prints_writes_and_refuses(small, tmp_path):
    out = tmp_path / "robot.toml"
    runner = CliRunner()
    res = runner.invoke(cli, ["measure", "supply", "4.97", "4.52", "--preset", "small", "--write", str(out)])
    assert res.exit_code == 0, res.output
    assert "source resistance: 0.498 ± 0.077 Ω" in res.output and f"wrote {out}" in res.output
    written = load_robot(out)
    assert written.get("power.source_resistance_ohm") == pytest.approx(0.45 / 0.904, rel=1e-12)
    assert written.source_of("power.supply_voltage_v").source == "data:measure supply"
    again = runner.invoke(cli, ["measure", "supply", "4.97", "4.52", "--preset", "small", "--write", str(out)])
    assert again.exit_code == 2 and "exists" in again.output
    js = runner.invoke(cli, ["measure", "supply", "4.98", "3.8", "--source", "limit", "--preset", "small", "--json"])
    assert js.exit_code == 0, js.output
    assert json.loads(js.stdout)["power.current_limit_a"]["value"] == pytest.approx(0.81, rel=1e-12)
    for args, said in ((["4.97", "-4.52"], "leads reversed"), (["4.5", "4.8"], "above its 4.5 V at rest"),
                       (["4.97", "4.52", "--volts-accuracy", "half a percent"], "not a meter's accuracy")):
        bad = runner.invoke(cli, ["measure", "supply", *args, "--preset", "small"])
        assert bad.exit_code == 2 and "error:" in bad.output and said in bad.output, bad.output
