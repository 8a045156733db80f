"""locust optimize: objectives by name, the flip constraint, robust draws, the Pareto front."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import pytest

from locust.params import preset
from locust.sim.samples import draw, uncertain_values
from locust.sweep.design import design_robot, parse_bound
from locust.sweep.objectives import OBJECTIVES, DrawFigures, Judgement, judge_draws
from locust.sweep.optimize import run_optimize
from probing import invoke, signalled_in_design

LOCUST = [sys.executable, "-c", "from locust.commands import main; main()"]
TWO = [OBJECTIVES["distance_per_hop"], OBJECTIVES["nose_rise_per_hop"]]


def read_csv(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


# -- a cheap analytic stand-in (synthetic: no simulation) ------------------------------
# Two design variables x, y in [0, 1]; figures f1 = x and f2 = (1 - x^2)(1 - y), both
# maximised; a design with x above 0.8 "goes over" (flip share 1). The feasible Pareto front
# is y = 0, x in [0, 0.8]: f2 = 1 - f1^2, its hypervolume over (0, 0) 0.8 - 0.8^3 / 3.
FRONT_X_MAX = 0.8
TRUE_HYPERVOLUME = FRONT_X_MAX - FRONT_X_MAX ** 3 / 3


def standin(values: dict[str, float]) -> Judgement:
    x, y = values["scale"], values["schedule.push_s"]
    figures = {"distance_per_hop_m": x, "nose_rise_per_hop_m": (1 - x * x) * (1 - y)}
    flip = 1.0 if x > FRONT_X_MAX else 0.0
    return Judgement(True, "", figures, dict(figures), flip, {"goes_over": flip, "rears_and_returns": 0.0,
                                                             "stays_low": 1 - flip}, 1, 1)


def hypervolume_2d(points: list[tuple[float, float]]) -> float:
    """Area dominated by ``points`` (both maximised) above the origin."""
    area, top = 0.0, 0.0
    for f1, f2 in sorted(points, key=lambda p: -p[0]):
        if f2 > top:
            area += f1 * (f2 - top)
            top = f2
    return area


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_front_found_on_an_analytic_standin_is_the_known_front(tmp_path, seed):
    base = preset("seed")
    # scale 0:0.02 is a range the seed's links take; the stand-in reads it as x in [0, 1] / 50
    bounds = [parse_bound("scale=0:0.02", base), parse_bound("schedule.push_s=0.1:0.3", base)]

    def judge(values):
        return standin({"scale": values["scale"] / 0.02, "schedule.push_s": (values["schedule.push_s"] - 0.1) / 0.2})

    out = tmp_path / "o"
    summary = run_optimize(base, bounds, trials=80, cycles=1, folder=out, seed=seed, objectives=TWO,
                           judge=judge, max_flip=0.05)
    front = read_csv(out / "pareto.csv")
    trials = read_csv(out / "trials.csv")
    assert len(trials) == 80 and len(front) == len(summary.front) >= 5
    feasible = [t for t in trials if t["feasible"] == "True"]
    pts = [(float(r["distance_per_hop_m"]), float(r["nose_rise_per_hop_m"])) for r in front]
    for f1, f2 in pts:
        assert f1 <= FRONT_X_MAX                         # never a design that goes over
        assert f2 <= 1 - f1 * f1 + 1e-12                 # never better than the truth
        for t in feasible:                               # and no feasible trial dominates it
            g1, g2 = float(t["distance_per_hop_m"]), float(t["nose_rise_per_hop_m"])
            assert not (g1 >= f1 and g2 >= f2 and (g1 > f1 or g2 > f2))
    assert all(float(r["flip_share"]) <= 0.05 for r in front)
    # within 8 % of the true front's hypervolume (random search over 80 trials: 76-89 %, 20 seeds)
    assert hypervolume_2d(pts) == pytest.approx(TRUE_HYPERVOLUME, rel=0.08)
    # the ends and the knee are rows of the front
    picks = {p for r in front for p in r["pick"].split()}
    assert picks == {"best-distance_per_hop", "best-nose_rise_per_hop", "knee"}
    best_d = max(front, key=lambda r: float(r["distance_per_hop_m"]))
    assert "best-distance_per_hop" in best_d["pick"]


# -- the figures of one design ----------------------------------------------------------
def test_a_draw_that_goes_over_scores_zero_and_the_quantile_is_what_9_in_10_beat():
    # synthetic draws: seven on their feet at 2..8 cm a hop, one over (nose 12 cm on its back)
    draws = [DrawFigures("rears_and_returns", {"distance_per_hop_m": d / 100, "nose_rise_per_hop_m": 0.05})
             for d in range(2, 9)]
    draws.append(DrawFigures("goes_over", {"distance_per_hop_m": 0.0, "nose_rise_per_hop_m": 0.0}))
    j = judge_draws([*draws, None], TWO, quantile=0.1)
    assert j.valid and (j.draws, j.draws_valid) == (9, 8)
    assert j.flip_share == 1 / 8
    assert j.outcome_shares == {"goes_over": 1 / 8, "rears_and_returns": 7 / 8, "stays_low": 0.0}
    # sorted 0, 2, 3, ... 8 cm: the 0.1 quantile sits 0.7 of the way from 0 to 2 cm
    assert j.figures["distance_per_hop_m"] == pytest.approx(0.014, abs=1e-12)
    assert j.means["distance_per_hop_m"] == pytest.approx(0.35 / 8, abs=1e-12)
    assert j.figures["nose_rise_per_hop_m"] == pytest.approx(0.035, abs=1e-12)
    # more failed audits than valid draws: no verdict
    assert not judge_draws([draws[0], None, None], TWO, quantile=0.1).valid


def test_every_design_meets_the_same_draws():
    base = preset("medium")
    design = design_robot(base, {"scale": 0.01, "geometry.crank_start_deg": -108.0})
    # a value the design sets keeps the uncertainty it had, so the drawn keys are the same
    assert uncertain_values(design) == uncertain_values(base)
    for a, b in zip(draw(base, 4, seed=0), draw(design, 4, seed=0)):
        for key, sd in uncertain_values(base).items():
            za = (a.get(key) - base.get(key)) / sd
            zb = (b.get(key) - design.get(key)) / sd
            if base.get(key) > 0 and min(a.get(key) / base.get(key), b.get(key) / design.get(key)) <= 0.1:
                continue   # a positive value's draw held at a tenth of it
            assert za == pytest.approx(zb, abs=1e-9), key


# -- the command on the simulation -------------------------------------------------------
# Medium with gentle pushes on longer links: within the flip limit in every draw of the
# acceptance study (24 designs of 8 draws), so the front is not empty
OPT = ["optimize", "--preset", "medium", "--objective", "distance_per_hop", "--objective", "nose_rise_per_hop",
       "--vary", "scale=0.01:0.02", "--vary", "schedule.push_deg=-20:-15", "--robust", "2", "--max-flip", "0.05",
       "--cycles", "1"]

# The process kills itself (SIGKILL: no handler runs, as when a machine is lost) while judging
# its second design.
_KILLED_IN_SECOND_TRIAL = signalled_in_design("SIGKILL", 2)


@pytest.mark.slow
def test_optimize_writes_the_front_resumes_after_a_kill_and_refuses_other_objectives(tmp_path):
    out = tmp_path / "o"
    args = [*OPT, "--trials", "3", "--out", str(out)]
    killed = subprocess.run([sys.executable, "-c", _KILLED_IN_SECOND_TRIAL, *args], capture_output=True,
                            text=True, timeout=300)
    assert killed.returncode == -9
    rerun = subprocess.run(LOCUST + args, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    # trial 0 finished before the kill, trial 1 was under way: two computed now (trials 2, 3)
    assert "4 trials (2 computed now)" in rerun.stdout
    trials = read_csv(out / "trials.csv")
    assert [t["state"] for t in trials] == ["complete", "running", "complete", "complete"]
    names = ["scale", "schedule.push_deg"]
    objectives = ["distance_per_hop_m", "nose_rise_per_hop_m"]
    assert list(trials[0])[:2 + len(names)] == ["trial", "state", *names]
    for col in [*objectives, *(f"{c}_mean" for c in objectives), "flip_share", "share_goes_over",
                "share_rears_and_returns", "share_stays_low"]:
        assert col in trials[0]
    front = read_csv(out / "pareto.csv")
    assert 1 <= len(front) <= 3 and list(front[0]) == [*trials[0], "pick"]
    done = [t for t in trials if t["state"] == "complete"]
    for r in front:
        assert float(r["flip_share"]) <= 0.05 and r["draws"] == "2"
        for t in done:
            assert not all(float(t[c]) >= float(r[c]) for c in objectives) or \
                all(float(t[c]) == float(r[c]) for c in objectives)
    for pick in {p for r in front for p in r["pick"].split()}:
        assert (out / f"{pick}.toml").is_file()
    assert (out / "pareto.png").stat().st_size > 5_000
    # the same command again computes nothing; another objective is refused, the study untouched
    again = subprocess.run(LOCUST + args, capture_output=True, text=True, timeout=300)
    assert "4 trials (0 computed now)" in again.stdout
    journal = (out / "study.journal").read_bytes()
    other = invoke([*OPT[:3], "--objective", "flight_per_hop", *OPT[5:], "--trials", "3", "--out", out])
    assert other.exit_code == 2 and "other settings (objectives differ)" in other.output
    more = invoke([*OPT[:11], "--robust", "3", *OPT[13:], "--trials", "3", "--out", out])
    assert more.exit_code == 2 and "other settings (robust differ)" in more.output
    assert (out / "study.journal").read_bytes() == journal


@pytest.mark.slow
def test_trials_run_on_local_processes_and_on_a_dask_cluster_share_one_study(tmp_path):
    base = preset("seed")
    bounds = [parse_bound("scale=0:0.02", base)]
    out = tmp_path / "o"
    first = run_optimize(base, bounds, trials=4, cycles=1, folder=out, jobs=2)
    assert (first.trials, first.computed, first.complete + first.pruned) == (4, 4, 4)
    second = run_optimize(base, bounds, trials=6, cycles=1, folder=out, jobs=2, scheduler="dask-local")
    assert (second.trials, second.computed, second.complete + second.pruned) == (6, 2, 6)
    rows = read_csv(out / "trials.csv")
    assert [int(r["trial"]) for r in rows] == list(range(6))
    # each trial's figure is its design's, whichever process judged it
    from locust.sweep.robust import DesignJudge
    judge = DesignJudge(base, 1, (OBJECTIVES["distance_per_hop"],))
    for r in rows[::3]:
        if r["state"] == "complete":
            assert float(r["distance_per_hop_m"]) == judge({"scale": float(r["scale"])}).figures["distance_per_hop_m"]


@pytest.mark.parametrize("extra, words", [
    (["--objective", "height"], ("no such objective", "distance_per_hop, nose_rise_per_hop, flight_per_hop")),
    (["--objective", "distance"], ("each objective is a figure per hop", "--objective distance_per_hop")),
    (["--objective", "distance_per_hop", "--objective", "distance_per_hop"], ("given twice",)),
    (["--step", "geometry.crank_start_deg=18"], ("no --vary range of that name",)),
    (["--step", "scale=0.5"], ("a step must be above 0 and at most HIGH - LOW",)),
    (["--step", "scale"], ("not NAME=STEP",)),
    (["--vary", "geometry.leg_m=0.05,0.05"], ("given twice",)),
    (["--vary", "geometry.leg_m=0.05,9"], ("geometry.leg_m = 9",)),
])
def test_optimize_bad_input_is_refused_before_anything_runs(tmp_path, extra, words):
    res = invoke(["optimize", "--vary", "scale=0:0.02", *extra, "--out", tmp_path / "o"])
    assert res.exit_code == 2 and "error:" in res.output and "hint:" in res.output, res.output
    for w in words:
        assert w in res.output
    assert not (tmp_path / "o").exists()


def test_stepped_and_categorical_design_variables(tmp_path):
    base = preset("medium")
    horn = parse_bound("geometry.crank_start_deg=-136:-60", base, step=18.0)
    # the spline's steps from -136 up to the last one at or below -60: -136 + 4 x 18 = -64
    assert (horn.low, horn.high, horn.step) == (-136.0, -64.0, 18.0)
    legs = parse_bound("geometry.leg_m=0.06,0.07,0.08", base)
    assert legs.choices == (0.06, 0.07, 0.08) and (legs.low, legs.high) == (0.06, 0.08)
    # a study draws only those values (a synthetic judge: no simulation)
    run_optimize(base, [horn, legs], trials=12, cycles=1, folder=tmp_path / "o", seed=1,
                 judge=lambda v: standin({"scale": (v["geometry.crank_start_deg"] + 136) / 72,
                                          "schedule.push_s": (v["geometry.leg_m"] - 0.06) / 0.02}))
    rows = read_csv(tmp_path / "o" / "trials.csv")
    assert {float(r["geometry.crank_start_deg"]) for r in rows} <= {-136.0, -118.0, -100.0, -82.0, -64.0}
    assert {float(r["geometry.leg_m"]) for r in rows} <= {0.06, 0.07, 0.08}
    assert len({float(r["geometry.crank_start_deg"]) for r in rows}) >= 3


# -- one study job behind the command and the API ------------------------------------------
HOST = Path(__file__).resolve().parents[1] / "host" / "locust"


def called_names(path: Path) -> set[str]:
    """The names ``path``'s code calls (``f(...)`` and ``module.f(...)``)."""
    import ast

    calls = [n.func for n in ast.walk(ast.parse(path.read_text())) if isinstance(n, ast.Call)]
    return {c.id if isinstance(c, ast.Name) else c.attr for c in calls if isinstance(c, (ast.Name, ast.Attribute))}


def test_the_command_and_the_api_run_one_study_job(tmp_path):
    """`locust optimize` and locust.optimize both call sweep.study.optimize_study, and the same
    study through each (three trials of a stepped push time on a Small that stays on its feet,
    seed 2) writes the same trials, figures and front, byte for byte."""
    import locust

    assert "optimize_study" in called_names(HOST / "commands" / "optimize.py")
    assert "optimize_study" in called_names(HOST / "api" / "optimizing.py")
    assert "run_optimize" not in called_names(HOST / "commands" / "optimize.py") | \
        called_names(HOST / "api" / "optimizing.py")
    res = invoke(["optimize", "--preset", "small", "--set", "geometry.crank_start_deg=-80", "--vary",
                  "schedule.push_s=0.15:0.4", "--step", "schedule.push_s=0.05", "--trials", "3", "--cycles", "1",
                  "--seed", "2", "--out", tmp_path / "cli"])
    assert res.exit_code == 0, res.output
    robot = locust.robot("small", **{"geometry.crank_start_deg": -80.0})
    api = locust.optimize(robot, {"schedule.push_s": (0.15, 0.4)}, steps={"schedule.push_s": 0.05}, trials=3,
                          cycles=1, seed=2, out=tmp_path / "api")
    for name in ("trials.csv", "pareto.csv"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "api" / name).read_bytes(), name
    trials = read_csv(tmp_path / "cli" / "trials.csv")
    assert [t["state"] for t in trials] == ["complete"] * 3
    # every value drawn is a step of the range: 0.15, 0.20, ... 0.40 s
    assert all(round((float(t["schedule.push_s"]) - 0.15) / 0.05, 9).is_integer() for t in trials)
    best = max(trials, key=lambda t: float(t["distance_per_hop_m"]))
    assert api.best["trial"] == int(best["trial"])
    assert api.best["distance_per_hop_m"] == float(best["distance_per_hop_m"])
    assert f"best-distance_per_hop: trial {best['trial']} " in res.output


def test_the_api_takes_every_option_of_the_command():
    """Each option of `locust optimize` (its robot aside: locust.robot makes it) is a parameter
    of locust.optimize, under the option's own name but for three the API has always spelt its way."""
    import inspect

    import locust
    from locust.commands.optimize import optimize

    api_name = {"varies": "vary", "objective_names": "objectives", "draws": "robust"}
    options = {p.name for p in optimize.params} - {"preset", "config", "sets"}
    assert set(inspect.signature(locust.optimize).parameters) >= {api_name.get(o, o) for o in options}
