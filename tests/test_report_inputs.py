"""Report inputs: hop measurement on traces of known truth, configuration names, sweep
folders (SYNTHETIC results.csv written here), and bad input turned into clear errors with
nothing written."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.errors import ReportError, TrialError
from locust.io.sweep_store import columns as sweep_columns
from locust.params import LEG_SETS, preset
from locust.report.landscape import design_value, read_landscape
from locust.trials.configs import configuration, name_from_path, parse_added
from locust.trials.measure import align, measure_hops, onset_time
from locust.trials.measured import parse_measured
from probing import assert_clear_error, invoke, tree


def staircase(fps=30.0, lead_s=0.4, period_s=1.3, hops=(0.20, 0.25, 0.15), apex=(0.05, 0.08, 0.03), noise=0.0, seed=0):
    """A SYNTHETIC nose: stands, then each cycle jumps forward by hops[k] along a parabola of
    height apex[k] during the first 0.4 s of the cycle, then rests. Camera clock starts lead_s early."""
    t = np.arange(0, lead_s + period_s * len(hops) + 0.3, 1 / fps)
    ts = t - lead_s
    x = np.zeros_like(t)
    y = np.zeros_like(t)
    done = 0.0
    for k, (d, a) in enumerate(zip(hops, apex)):
        u = np.clip((ts - k * period_s) / 0.4, 0, 1)
        active = (ts >= k * period_s) & (ts < (k + 1) * period_s)
        x[active] = done + d * u[active]
        y[active] = 4 * a * u[active] * (1 - u[active])
        done += d
    x[ts >= len(hops) * period_s] = done
    rng = np.random.default_rng(seed)
    return t, x + 0.3 + rng.normal(0, noise, t.size), y + 0.02 + rng.normal(0, noise, t.size)


def test_onset_and_hops_on_a_known_trace():
    t, x, y = staircase()
    onset, x0, y0 = onset_time(t, x, y)
    # the first 3 mm of travel: x = 0.2*u and y = 0.2*u(1-u) -> about u = 0.011, 4.4 ms after 0.4 s
    assert onset == pytest.approx(0.4 + 0.0044, abs=0.002)
    assert (x0, y0) == pytest.approx((0.3, 0.02))
    trace = align(t, x, y, onset_latency_s=0.0044)
    assert trace.start_s == pytest.approx(0.4, abs=0.002)
    hops = measure_hops(trace, 1.3, 3)
    assert [h.distance_m for h in hops] == pytest.approx([0.20, 0.25, 0.15], abs=1e-9)
    # apex sampled at 30 frames/s: the parabola's top is missed by at most a(1-(1-2*dt/0.4)^2)
    for h, a in zip(hops, (0.05, 0.08, 0.03)):
        assert a * (1 - 0.0278) - 1e-9 <= h.apex_m <= a + 1e-12


def test_noise_and_a_short_track():
    t, x, y = staircase(noise=0.0005, seed=3)
    trace = align(t, x, y, 0.0044)
    hops = measure_hops(trace, 1.3, 3)
    # median of the 6 frames of the last 0.2 s of a cycle: sd about 0.5 mm * 1.25 / sqrt(6) each end
    assert [h.distance_m for h in hops] == pytest.approx([0.20, 0.25, 0.15], abs=0.0015)
    cut = t < 0.4 + 3 * 1.3 - 0.5       # the clip stops half a second before hop 3 ends
    hops = measure_hops(align(t[cut], x[cut], y[cut], 0.0044), 1.3, 3)
    assert math.isfinite(hops[1].distance_m) and math.isnan(hops[2].distance_m) and math.isnan(hops[2].apex_m)


def test_takeoff_speed_is_the_fastest_before_the_apex():
    """SYNTHETIC nose at 240 frames/s: stands, pushed from rest at a constant 6 m/s² for 0.15 s
    to (0.4, 0.8) m/s (0.894 m/s), then flies a parabola under 9.81 m/s² and rests where it
    lands. Tracker's central difference is the mean velocity over two frames, so its highest
    value before the apex lies at most the push's gain over 1.5 frames below the take-off
    speed, turned by gravity over as long: 0.894 m/s down to 0.855 (measured: 0.876). A frame
    lost next to the fastest sample only blanks that sample's neighbours (Tracker's rule)."""
    from locust.trials.measure import Aligned, nose_speed

    g, push_s, v0 = 9.81, 0.15, np.array([0.4, 0.8])
    acc = v0 / push_s
    t = np.arange(-0.3, 1.0, 1 / 240) + 0.3 / 240          # the frames fall anywhere on the push
    tau = np.clip(t, 0, push_s)
    x, y = 0.5 * acc[0] * tau ** 2, 0.5 * acc[1] * tau ** 2
    flight = np.clip(t - push_s, 0, 2 * v0[1] / g)
    x, y = x + v0[0] * flight, y + v0[1] * flight - 0.5 * g * flight ** 2
    speed = float(np.hypot(*v0))
    (hop,) = measure_hops(Aligned(t, x, y, 0.0, 0.0), 1.0, 1)
    assert speed - 1.5 / 240 * float(np.hypot(*acc)) - speed * (1 - math.cos(1.5 / 240 * g / speed)) \
        <= hop.takeoff_speed_m_per_s <= speed
    before_apex = np.where(t < push_s + v0[1] / g, nose_speed(t, x, y), np.nan)
    fastest = int(np.nanargmax(before_apex))
    keep = np.arange(t.size) != fastest + 1
    sparse = nose_speed(t[keep], x[keep], y[keep])
    assert np.isnan(sparse[fastest]) and np.isnan(sparse[fastest + 1])    # beside the lost frame
    assert np.isfinite(sparse[fastest - 1]) and np.isfinite(sparse[fastest + 2])
    (lost,) = measure_hops(Aligned(t[keep], x[keep], y[keep], 0.0, 0.0), 1.0, 1)
    assert speed - 3 / 240 * float(np.hypot(*acc)) <= lost.takeoff_speed_m_per_s <= hop.takeoff_speed_m_per_s


def test_a_track_that_starts_moving_or_never_moves_is_refused():
    t, x, y = staircase(lead_s=0.0)
    with pytest.raises(TrialError, match="already moving"):
        onset_time(t, x, y)
    with pytest.raises(TrialError, match="never moves"):
        onset_time(t, np.full_like(t, 0.3), np.full_like(t, 0.02))


def test_configuration_names_and_added_lengths():
    seed = preset("seed")
    large = configuration(seed, "Large")
    assert large.name == "large" and large.label == "Large" and large.added_m == 0.02
    assert large.robot.link_lengths_m() == pytest.approx((0.06, 0.06, 0.04, 0.08))
    assert large.robot.source_of("geometry.leg_m").source == "leg-set:large"
    v2 = configuration(seed, "v2", 0.015)
    assert v2.robot.get("geometry.crank_m") == pytest.approx(0.055)
    assert configuration(seed, "other").robot.link_lengths_m() == seed.link_lengths_m()
    assert name_from_path(Path("runs/medium-2/run.json")) == "medium"
    assert name_from_path(Path("runs/small/trial-3/x.tracks.csv")) == "small"
    assert name_from_path(Path("runs/v2/x.csv")) == "v2"
    with pytest.raises(TrialError, match="cannot tell"):
        name_from_path(Path("data/runs/20260101-120000/run.json"))
    assert parse_added(["v2=0.015"]) == {"v2": 0.015}
    with pytest.raises(TrialError):
        parse_added(["v2"])


def test_a_leg_set_on_a_leg_set_robot_is_built_on_the_robot_as_built():
    """`report --preset large` with a `large` trial: the trial's leg set goes on the robot as
    built, not on top of Large's own +2 cm (it predicted 10.6 mm for a robot with 4 cm added,
    never built, against 17.7 mm filmed); a name that is no leg set keeps the base as given."""
    for base in LEG_SETS:
        for name in LEG_SETS:
            got = configuration(preset(base), name).robot
            assert got.link_lengths_m() == pytest.approx(preset(name).link_lengths_m(), abs=1e-9), (base, name)
            assert got.solver.timestep_s == preset(name).solver.timestep_s
    assert configuration(preset("large"), "mine").robot.link_lengths_m() == preset("large").link_lengths_m()
    v2 = configuration(preset("medium"), "v2", 0.015).robot        # an added length is on the base given
    assert v2.get("geometry.crank_m") == pytest.approx(preset("medium").get("geometry.crank_m") + 0.015)


def write_sweep(folder: Path, rows: list[str], vary="scale", cycles=3) -> Path:
    folder.mkdir(parents=True)
    (folder / "sweep.json").write_text(json.dumps({"request": {"base": "seed", "vary": [
        {"name": vary, "start": 0.0, "stop": 0.03, "n": len(rows)}], "cycles": cycles}, "finished": True}))
    head = ",".join(sweep_columns([vary])) + "\n"
    (folder / "results.csv").write_text(head + "".join(row + "\n" for row in rows))
    return folder


def test_sweep_landscape_reads_and_places_designs(tmp_path):
    # SYNTHETIC sweep results (numbers made up for the reader; not a simulation)
    folder = write_sweep(tmp_path / "synthetic-sweep", [
        "0,0.0,True,,stays_low,nan,0.60,0.1,0.09,0.05,3,crank-rocker,80.0",
        "1,0.01,True,,stays_low,nan,0.90,0.1,0.09,0.05,3,crank-rocker,80.0",
        "2,0.02,False,energy audit failed,,nan,nan,nan,nan,nan,0,crank-rocker,80.0",
    ])
    land = read_landscape(folder)
    assert land.names == ["scale"] and land.cycles == 3 and land.designs == 3
    assert list(land.valid) == [True, True, False]
    assert land.distance_per_hop_m[:2] == pytest.approx([0.20, 0.30])
    assert math.isnan(land.distance_per_hop_m[2])            # an invalid design is never a number
    seed = preset("seed")
    assert design_value(configuration(seed, "medium"), "scale") == 0.01
    assert design_value(configuration(seed, "large"), "geometry.leg_m") == pytest.approx(0.08)


@pytest.mark.parametrize("rows, message", [
    (["0,0.0,maybe,,,nan,0.6,0.1,0.09,0.05,3,crank-rocker,80.0"], "line 2: malformed row .valid = 'maybe'"),
    # a malformed row before the last is never skipped (only a torn last line is dropped)
    (["0,0.0,True,,stays_low,nan,0.6,0.1,0.09,0.05,3,crank-rocker,80.0",
      "1,0.01,True,,stays_low,nan,oops,0.1,0.09,0.05,3,crank-rocker,80.0",
      "2,0.02,True,,stays_low,nan,0.6,0.1,0.09,0.05,3,crank-rocker,80.0"], "line 3: malformed row"),
    ([], "no designs"),
])
def test_bad_sweep_folders(tmp_path, rows, message):
    folder = write_sweep(tmp_path / "s", rows)
    with pytest.raises(ReportError, match=message):
        read_landscape(folder)


def report(*args):
    return CliRunner().invoke(cli, ["report", *map(str, args)])


def make_trial(folder: Path, track: str | None = None, run: dict | None = None) -> Path:
    folder.mkdir(parents=True)
    if track is not None:
        (folder / "hop.tracks.csv").write_text(track)
    if run is not None:
        (folder / "run.json").write_text(json.dumps(run))
    return folder


PIXELS_ONLY = "frame,t_s,nose_px,nose_py,nose_x_m,nose_y_m,nose_ok\n" + "".join(
    f"{i},{i / 30:.6f},{100 + i},{200},nan,nan,1\n" for i in range(40))


@pytest.mark.parametrize("setup, message, hint", [
    (lambda d: d / "missing", "no such file or folder", "check the --measured path"),
    (lambda d: make_trial(d / "small", track=PIXELS_ONLY), "no nose position in metres", "--scale"),
    (lambda d: make_trial(d / "small", run={"status": "complete"}), "not a run record", "locust hop"),
    (lambda d: make_trial(d / "small", track="frame,t_s,nose_x_m,nose_y_m\n0,0.0,0.1,0.1\n1,0.03,abc,0.1\n"),
     "line 3", "fix or delete"),
    (lambda d: make_trial(d / "2026"), "no track", "locust track"),
])
def test_bad_measured_inputs_are_clear_errors_and_write_nothing(tmp_path, setup, message, hint):
    path = setup(tmp_path)
    out = tmp_path / "out"
    before = tree(tmp_path)
    assert_clear_error(invoke(["report", "--measured", path, "--out", out]), message, hint)
    assert tree(tmp_path) == before   # no --out made, every input as it was


def test_runs_with_different_schedules_are_refused_before_simulating(tmp_path):
    run = {"status": "complete", "schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
           "phases": []}
    a = make_trial(tmp_path / "small-1", run=run)
    b = make_trial(tmp_path / "small-2", run={**run, "schedule": {**run["schedule"], "push_ms": 250}})
    res = report("--measured", a, "--measured", b, "--out", tmp_path / "out")
    assert res.exit_code == 2 and "different schedules" in res.output
    assert not (tmp_path / "out").exists()


def test_a_missing_sweep_folder_fails_before_any_simulation(tmp_path):
    run = {"status": "complete", "schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
           "phases": []}
    trial = make_trial(tmp_path / "small-1", run=run)
    res = report("--measured", trial, "--sweep", tmp_path / "nowhere", "--out", tmp_path / "out")
    assert res.exit_code == 2 and "no sweep.json" in res.output
    assert not (tmp_path / "out").exists()


def test_measured_groups_by_name_and_folder(tmp_path):
    run = {"status": "complete", "schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
           "phases": [{"cycle": 1, "phase": "push", "commanded_us": 0, "measured_us": 200}]}
    a = make_trial(tmp_path / "large-1", run=run)
    b = make_trial(tmp_path / "x", run=run)
    groups = parse_measured([str(a), f"Medium={b}"])
    assert list(groups) == ["medium", "large"]            # leg-set order, not argument order
    assert groups["large"][0].label == "large-1" and groups["large"][0].track is None
    with pytest.raises(TrialError, match="given twice"):
        parse_measured([str(a), f"large={a}"])


