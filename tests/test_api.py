"""The Python API at the package top (locust.robot, simulate, sweep, track, calibrate_*, report):
a notebook session with exactly those names, checked against the figures the toolkit computes."""

from __future__ import annotations

import importlib
import inspect
import json
import os
import re
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import locust
import locust.api
import locust.sweep.run
import locust.track.runner
from locust.api import EXPORTS, module_of
from locust.bundled import bundled_recording
from locust.errors import LocustError, ParamsError, SimError
from locust.params import Robot

ROOT = Path(__file__).resolve().parents[1]


def test_all_is_the_api_list():
    """locust.__all__ is locust.api.EXPORTS (the one list of the public names) and the version;
    every name is at the package top and in locust.api alike, callable."""
    assert locust.__all__ == [*EXPORTS, "__version__"]
    assert set(locust.__all__) <= set(dir(locust))
    assert {"Robot", "LocustError", "simulate", "calibrate_hops"} <= set(EXPORTS)
    for name in EXPORTS:
        value = getattr(locust, name)
        assert callable(value), name
        assert value is getattr(locust.api, name) is getattr(importlib.import_module(module_of(name)), name)
    assert (locust.Robot, locust.LocustError) == (Robot, LocustError)
    with pytest.raises(AttributeError, match="no attribute 'EXPORTS'"):
        locust.EXPORTS   # noqa: B018 (the list is locust.api's, not a name of the API)
    # the API's names are not the subpackages' (sweep, track, report, fab stay plain modules)
    for package in ("sweep", "track", "report", "fab"):
        assert isinstance(importlib.import_module(f"locust.{package}"), types.ModuleType)
        assert not callable(importlib.import_module(f"locust.{package}")), package
    assert "vary" in inspect.signature(locust.sweep_designs).parameters
    assert "Parameters" in locust.sweep_designs.__doc__


def called_names(text: str) -> set[str]:
    """The names ``text`` writes as calls between backquotes: ``simulate(robot)``, and
    ``calibrate_beam/hinge(...)`` for two (the names after the first take its prefix)."""
    names = set()
    for group in re.findall(r"`(\w+(?:/\w+)*)\(", text):
        first, *rest = group.split("/")
        names |= {first, *(f"{first.rpartition('_')[0]}_{name}" for name in rest)}
    return names


def test_called_names_reads_the_short_form():
    assert called_names("``calibrate_beam/hinge/hops(...)``, `robot(x)`, ``.plot()``, plain(x)") == {
        "calibrate_beam", "calibrate_hinge", "calibrate_hops", "robot"}


FUNCTIONS = {name for name in EXPORTS if name[0].islower()}
CLASSES = set(EXPORTS) - FUNCTIONS


def test_the_api_docstring_table_is_the_list():
    """locust.api's table has one row a name of EXPORTS, with the module EXPORTS gives it."""
    rows = re.findall(r"^``(\w+)``\s+:mod:`\.?([\w.]+)`", locust.api.__doc__, re.M)
    assert dict(rows) == EXPORTS
    assert len(rows) == len(EXPORTS)


def test_the_package_docstring_names_the_list():
    """``help(locust)``'s list of functions names exactly the functions of EXPORTS, and names
    each of its classes."""
    bullets = [line.partition("``:")[0] for line in locust.__doc__.splitlines() if line.startswith("- ``")]
    assert called_names("\n".join(bullets)) == FUNCTIONS
    assert sorted(c for c in CLASSES if not re.search(rf"\b{c}\b", locust.__doc__)) == []


def test_the_architecture_table_names_the_list():
    """docs/architecture.md's table of the Python API names exactly the functions of EXPORTS."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text.split("## The Python API", 1)[1].split("\n## ", 1)[0]
    first_cells = [line.split("|")[1] for line in section.splitlines() if line.startswith("| `")]
    assert called_names("\n".join(first_cells)) == FUNCTIONS


def test_notebook_session(tmp_path):
    """A notebook session: robot, simulate, .trace(), .video(..., overwrite=True) twice,
    sweep .to_dataframe()."""
    robot = locust.robot("small", **{"servo.kp_nm_per_rad": 0.4})
    assert robot.get("servo.kp_nm_per_rad") == 0.4
    result = locust.simulate(robot, cycles=1)
    assert result.valid
    trace = result.trace()
    assert list(trace.columns[:3]) == ["t_s", "nose_x_m", "nose_z_m"]
    assert {"foot_x_m", "foot_z_m", "crank_left_deg", "crank_right_deg", "command_deg"} <= set(trace.columns)
    start = trace[trace.t_s < 0].iloc[-1]
    assert abs(trace.chassis_x_m.iloc[-1] - start.chassis_x_m - result.distance_m) <= 1e-12
    assert trace.nose_z_m[trace.t_s >= 0].max() == result.max_nose_height_m
    # the crank follows its command: at the end of the push it is within a few degrees of it
    push = trace[(trace.t_s >= 0) & (trace.t_s < robot.schedule.push_s)]
    assert np.allclose(push.command_deg, robot.schedule.push_deg, rtol=0, atol=1e-9)
    assert abs(push.crank_left_deg.iloc[-1] - robot.schedule.push_deg) < 1.0   # -29.67 deg

    again = locust.simulate(robot, cycles=1)
    assert (again.distance_m, again.max_nose_height_m, again.hops) == \
        (result.distance_m, result.max_nose_height_m, result.hops)
    pd.testing.assert_frame_equal(again.trace(), trace, check_exact=True)

    video = tmp_path / "hop.mp4"
    first = result.video(video, overwrite=True, width=160, height=120)
    inode, truth = video.stat().st_ino, first.truth_path.read_bytes()
    assert first.frames == round(result.duration_s * 30) and video.stat().st_size > 1000
    second = result.video(video, overwrite=True, width=160, height=120)
    assert second.video_path == video and second.frames == first.frames
    assert video.stat().st_ino != inode                         # rendered again, not left as it was
    assert second.truth_path.read_bytes() == truth              # the same rollout, the same truth
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hop.camera.json", "hop.mp4", "hop.truth.csv"]
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    with pytest.raises(SimError, match="exists already") as exc:
        result.video(video)
    assert exc.value.hint
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before

    table = locust.sweep_designs(locust.robot("seed"), vary={"scale": (0.0, 0.01, 2)}, cycles=1, jobs=1).to_dataframe()
    assert list(table.scale) == [0.0, 0.01] and table.valid.all()
    assert table.distance_m[0] == locust.simulate(locust.robot("seed"), cycles=1).distance_m


def test_repr_is_a_short_table_in_mm():
    r = locust.simulate(locust.robot("seed"), cycles=2)
    text = repr(r)
    assert f"{r.distance_m * 1000:.2f} mm" in text and f"{r.max_nose_height_m * 1000:.2f} mm" in text
    assert repr(r.distance_m) not in text and len(text.splitlines()) < 12
    assert "<table>" in r._repr_html_() and f"{r.hops[0].distance_m * 1000:.2f}" in r._repr_html_()
    # the CLI's JSON is the simulation's own figures and the standing load: nothing else of the facade
    facade = ("robot", "spread", "sensitivity", "nose_load_kg", "total_mass_kg")
    assert set(r.to_json()) == set(locust.sim.result.SimResult(**{k: v for k, v in vars(r).items()
                                                               if k not in facade}).to_json()) | set(facade[3:])
    assert f"nose load        {r.nose_load_kg * 1000:.1f} g" in text


def test_robot_from_a_file_and_bad_names(tmp_path):
    from locust.io.robot_toml import save_robot

    path = save_robot(locust.robot("medium", **{"geometry.leg_m": 0.075}), tmp_path / "mine.toml")
    mine = locust.robot(path)
    assert mine.geometry.leg_m == 0.075 and mine.geometry.crank_m == locust.robot("medium").geometry.crank_m
    assert locust.robot(str(path), **{"servo.kp_nm_per_rad": 0.3}).get("servo.kp_nm_per_rad") == 0.3
    for call in (lambda: locust.robot("tiny"), lambda: locust.robot("seed", **{"servo.kp": 1.0}),
                 lambda: locust.robot(tmp_path / "none.toml"), lambda: locust.robot("seed", **{"geometry.leg_m": -1})):
        with pytest.raises(ParamsError) as exc:
            call()
        assert isinstance(exc.value, LocustError) and exc.value.hint


def test_sweep_errors_are_the_library_s_own():
    with pytest.raises(LocustError, match="no such robot parameter"):
        locust.sweep_designs(locust.robot("seed"), vary={"geometry.nope_m": (0.0, 1.0, 2)})
    with pytest.raises(LocustError) as exc:
        locust.sweep_designs(locust.robot("seed"), vary={})
    assert exc.value.hint


def test_fit_matches_the_command_line_and_applies(tmp_path):
    data = bundled_recording("synthetic_ramp.csv")
    fit = locust.calibrate_ramp(data)
    proc = subprocess.run([sys.executable, "-m", "locust.commands", "calibrate", "ramp", str(data),
                           "--json", "--no-plot"],
                          capture_output=True, text=True, check=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=str(ROOT / "host")))
    cli = json.loads(proc.stdout)["contact.foot_friction"]
    est = fit.parameters["contact.foot_friction"]
    assert (est.value, est.std, list(est.ci95)) == (cli["value"], cli["std"], cli["ci95"])
    # the truth the synthetic file was made from (its header): mu 1.7
    assert est.ci95[0] <= 1.7 <= est.ci95[1]
    angles = pd.read_csv(data, comment="#").angle_deg.to_numpy()
    assert locust.calibrate_ramp(angles).parameters["contact.foot_friction"].value == est.value

    robot = fit.apply(locust.robot("seed"))
    prov = robot.source_of("contact.foot_friction")
    assert robot.contact.foot_friction == est.value
    assert (prov.source, prov.uncertainty) == ("fit:synthetic_ramp.csv", est.std)
    assert "95% CI" in prov.note and "Fit ramp" in repr(fit)
    fig = fit.plot()
    assert len(fig.axes) == 2
    # the residuals' axis says its unit (tan of an angle: none); ticks on whole trials only,
    # also for three trials (matplotlib's own ticks would be 1.00, 1.25, ...)
    trials = locust.calibrate_ramp([31.0, 30.2, 30.6]).plot().axes[1]
    trials.figure.canvas.draw()
    assert trials.get_ylabel() == "residual (no unit)" and trials.get_xlabel() == "trial"
    ticks = [t for t in trials.get_xticks() if trials.get_xlim()[0] <= t <= trials.get_xlim()[1]]
    assert ticks == [1, 2, 3], ticks


def test_fit_plots_residuals_in_the_datas_unit():
    """Beam: tip displacement [mm] above, residual [mm] below; servo: rad/s both."""
    beam = locust.calibrate_beam(bundled_recording("synthetic_beam.csv"), mass_kg=0.01, length_m=0.05)
    top, bottom = beam.plot().axes
    assert (top.get_ylabel(), bottom.get_ylabel()) == ("tip displacement [mm]", "residual [mm]")
    assert bottom.get_xlabel() == "t [s]"


def test_read_tracks_to_dataframe():
    tracks = locust.read_tracks(bundled_recording("synthetic_beam.csv"))
    df = tracks.to_dataframe()
    assert tracks.markers == ["tip"] and len(df) == 360
    # a file written before the tracks CSV had velocity columns: its own, then them, computed
    assert list(df.columns) == ["frame", "t_s", "tip_px", "tip_py", "tip_x_m", "tip_y_m", "tip_ok", "tip_vx_m_per_s",
                                "tip_vy_m_per_s", "tip_ax_m_per_s2", "tip_ay_m_per_s2"]
    # the file's header: frames 50 and 51 lost
    assert list(df.frame[~df.tip_ok]) == [50, 51] and df.tip_ok.dtype == bool
    # a lost frame has no position (NaN in pixels and metres), every other frame has one
    position = df[["tip_px", "tip_py", "tip_x_m", "tip_y_m"]]
    assert position[~df.tip_ok].isna().all(axis=None) and position[df.tip_ok].notna().all(axis=None)
    assert df.t_s.iloc[1] == pytest.approx(1 / 240, abs=1e-6)


def test_readme_python_api_runs_as_shown(tmp_path, monkeypatch, capsys):
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Python API", 1)[1]
    block = section.split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(tmp_path)      # "from any folder": the recording is the package's own
    scope: dict = {}
    exec(compile(block, "README.md", "exec"), scope)
    assert (tmp_path / "hop.mp4").is_file() and scope["result"].valid
    assert len(scope["swept"].to_dataframe()) == 6
    assert scope["calibrated"].contact.foot_friction == scope["fit"].parameters["contact.foot_friction"].value
    assert f"{scope['result'].distance_m * 1000:.2f} mm" in capsys.readouterr().out


def test_calibrate_hop_takes_its_runs_through_the_api(tmp_path, monkeypatch):
    """`locust calibrate hop` loads its runs through locust.calibrate_hops: an empty run folder is
    refused there, before any fit, and nothing is written."""
    from probing import assert_refused_and_unchanged

    (tmp_path / "small-1").mkdir()
    monkeypatch.chdir(tmp_path)
    assert_refused_and_unchanged(tmp_path, ["calibrate", "hop", "small=small-1", "--write", "robot.toml"],
                                 "small-1", "no run.json")
    with pytest.raises(LocustError, match="no run.json") as exc:
        locust.calibrate_hops(locust.robot("seed"), {"small": tmp_path / "small-1"})
    assert exc.value.hint


def test_a_result_without_states_says_how_to_keep_them():
    r = locust.simulate(locust.robot("seed"), cycles=1, keep_states=False)
    assert r.trajectory is None
    assert r.distance_m == locust.simulate(locust.robot("seed"), cycles=1).distance_m
    with pytest.raises(SimError, match="kept no rollout") as exc:
        r.trace()
    assert "keep_states=True" in exc.value.hint


def test_hop_fit_is_a_fit():
    """locust.calibrate_hops wraps calibrate.hop.fit_hops: its values, their provenance and the
    run's figure (a two-cycle SYNTHETIC run of Small, as tests/test_calibrate_hop.py makes them;
    coverage over seeds is that file's)."""
    from test_calibrate_hop import synthetic_run

    key = "servo.noload_speed_rad_per_s"
    run = synthetic_run("small", {key: 9.0}, cycles=2)
    fit = locust.calibrate_hops(run.robot, [run], [key], max_iter=3)
    assert fit.parameters == {key: fit.result.estimates[key]} and fit.result.identifiable[key]
    assert abs(fit.parameters[key].value - 9.0) < 1.0          # 9.30 here, from 9.0
    robot = fit.apply(locust.robot("seed"))
    prov = robot.source_of(key)
    assert (robot.get(key), prov.source, prov.uncertainty) == (fit.parameters[key].value, "fit:hops",
                                                               fit.parameters[key].std)
    assert "small:synthetic-small" in prov.note
    assert len(fit.plot().axes) == 4                             # nose and foot, x and y


# -- tidy tracks, figures and tables on every result, help(locust) -----------------------------
def test_tidy_tracks_have_trackers_velocity_and_acceleration():
    """SYNTHETIC: a ball thrown at 1.5 m/s forward and 2 m/s up, 30 frames/s, one frame lost:
    one row per marker per frame; Tracker's rules are exact on a parabola, so vx = 1.5,
    vy = 2 - 9.81 t and ay = -9.81 m/s² to 1e-9 wherever every frame they read is seen, and
    NaN (Tracker's blank cell) wherever one is not: the lost frame itself has no velocity, and
    no acceleration within two frames of it."""
    from locust.api.tracking import Tracks
    from locust.io.tracks_csv import TracksCsv

    t = np.arange(20) / 30.0
    x, y = 0.1 + 1.5 * t, 0.2 + 2.0 * t - 9.81 / 2 * t ** 2
    ok = np.ones(20, dtype=bool)
    ok[10] = False
    nan = np.full(20, np.nan)
    tracks = Tracks(TracksCsv(
        frame=np.arange(20), t_s=t, px={"ball": nan, "still": nan}, py={"ball": nan, "still": nan},
        x_m={"ball": np.where(ok, x, np.nan), "still": np.zeros(20)},
        y_m={"ball": np.where(ok, y, np.nan), "still": np.zeros(20)},
        ok={"ball": ok, "still": np.ones(20, bool)}, comments=("synthetic",)))
    df = tracks.tidy()
    assert list(df.columns[:7]) == ["frame", "t_s", "marker", "x_px", "y_px", "x_m", "y_m"]
    assert len(df) == 40 and list(df.marker[:2]) == ["ball", "still"] and list(df.frame[:2]) == [0, 0]
    ball = df[df.marker == "ball"].set_index("frame")
    seen_v = [f for f in range(1, 19) if f not in (9, 10, 11)]
    seen_a = [f for f in range(2, 18) if f not in (8, 9, 10, 11, 12)]
    assert ball.vx_m_per_s[seen_v].to_numpy() == pytest.approx(np.full(len(seen_v), 1.5), abs=1e-9)
    assert ball.vy_m_per_s[seen_v].to_numpy() == pytest.approx(2.0 - 9.81 * t[seen_v], abs=1e-9)
    assert ball.ay_m_per_s2[seen_a].to_numpy() == pytest.approx(np.full(len(seen_a), -9.81), abs=1e-9)
    unseen_v = sorted(set(range(20)) - set(seen_v))
    unseen_a = sorted(set(range(20)) - set(seen_a))
    assert ball.vx_m_per_s[unseen_v].isna().all() and ball.ay_m_per_s2[unseen_a].isna().all()
    # the frame table has the same columns, marker by marker, as the tracks CSV
    wide = tracks.to_dataframe()
    assert wide.ball_ay_m_per_s2.to_numpy() == pytest.approx(ball.ay_m_per_s2.to_numpy(), nan_ok=True, abs=0)
    assert isinstance(df, pd.DataFrame) and len(tracks.plot().axes) == 2


def test_fit_and_sweep_have_tables_and_figures(tmp_path):
    fit = locust.calibrate_ramp(bundled_recording("synthetic_ramp.csv"))
    table = fit.to_dataframe()
    est = fit.parameters["contact.foot_friction"]
    assert table.loc["contact.foot_friction", "value"] == est.value
    assert (table.loc["contact.foot_friction", "ci95_low"], table.loc["contact.foot_friction", "ci95_high"]) == est.ci95
    swept = locust.sweep_designs(locust.robot("seed"), vary={"scale": (0.0, 0.01, 2)}, cycles=1, jobs=1)
    fig = swept.plot()
    (ax,) = fig.axes
    assert list(ax.lines[0].get_ydata()) == pytest.approx([r["distance_m"] * 1000 for r in swept.rows if r["valid"]])
    # the added length in mm, as locust sweep draws and prints it (it was drawn in m)
    assert list(ax.lines[0].get_xdata()) == pytest.approx([r["scale"] * 1000 for r in swept.rows if r["valid"]])
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("added length on every link (mm)", "distance (mm)")
    m = re.search(r"\(scale (-?[\d.]+) mm\): distance (-?[\d.]+) mm over the run", repr(swept))
    assert m, repr(swept)
    best = swept.best
    assert [float(v) for v in m.groups()] == pytest.approx([best["scale"] * 1000, best["distance_m"] * 1000], abs=0.005)


def test_help_locust_lists_every_function():
    import pydoc

    text = pydoc.render_doc(locust, renderer=pydoc.plaintext)
    for name in ("robot(", "simulate(", "sweep_designs(", "track_markers(", "read_tracks(", "calibrate_beam",
                 "calibrate_hops", "make_report(", "make_cut_files(", ".tidy()", ".to_dataframe()", ".plot()"):
        assert name in text, name


def test_optimize_is_the_commands_search(tmp_path):
    """locust.optimize over run_optimize: three trials of the push time of a Small whose crank
    sits at -80 deg (it stays on its feet); the best trial's distance per hop is what simulating
    that design gives over its one cycle (to 1e-12), and best-distance_per_hop.toml holds the value."""
    base = locust.robot("small", **{"geometry.crank_start_deg": -80.0})
    res = locust.optimize(base, {"schedule.push_s": (0.15, 0.4)}, trials=3, cycles=1, out=tmp_path / "opt")
    assert (res.trials, res.complete + res.pruned) == (3, 3)
    assert res.best is not None and 0.15 <= res.best["schedule.push_s"] <= 0.4
    again = locust.simulate(base.with_values({"schedule.push_s": res.best["schedule.push_s"]}), cycles=1)
    assert again.outcome != "goes_over"
    assert res.best["distance_per_hop_m"] == pytest.approx(again.distance_m, abs=1e-12)
    assert locust.robot(res.robots["best-distance_per_hop"]).schedule.push_s == res.best["schedule.push_s"]
    assert (tmp_path / "opt" / "trials.csv").is_file()
    with pytest.raises(LocustError, match="twice"):
        locust.optimize(base, ["scale=0:0.01", "scale=0:0.02"], trials=1, out=tmp_path / "x")
    assert "Parameters" in locust.optimize.__doc__


def test_fab_is_the_commands_summary(tmp_path):
    """locust.make_cut_files(robot) gives `locust fab --from-robot seed --json`'s summary; with out it
    writes the cut files the summary lists, and the subpackage stays importable as before."""
    from click.testing import CliRunner

    from locust.commands import cli

    mine = locust.make_cut_files(locust.robot("seed"))
    theirs = json.loads(CliRunner().invoke(cli, ["fab", "--from-robot", "seed", "--json"]).stdout)
    assert mine == theirs
    written = locust.make_cut_files(locust.robot("seed"), out=tmp_path / "cut", previews=False)
    assert sorted(p.name for p in (tmp_path / "cut").iterdir()) == sorted(written["files"])
    assert "rigid_top.dxf" in written["files"] and "flat_pattern.dxf" in written["files"]
    assert locust.fab.laminate.SEED_STACK and "Parameters" in locust.make_cut_files.__doc__
