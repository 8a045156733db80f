"""locust optimize's study.html (Optuna's own views: history, importances, interactive front)
in a headless browser, the study opened by optuna-dashboard's own storage loader, and the
importances on an analytic stand-in whose answer is known."""

from __future__ import annotations

import csv
import html
import io
import json
import re
import shutil
import subprocess
import warnings
from pathlib import Path

import pytest

from locust.params import preset
from locust.sweep.design import parse_bound
from locust.sweep.objectives import OBJECTIVES, Judgement
from locust.sweep.optimize import run_optimize
from locust.sweep.views import study_views
from probing import invoke

# the command as a user types it: two objectives on the simulation, a flip limit
TRIALS = 10
OPT = ["optimize", "--preset", "medium", "--objective", "distance_per_hop", "--objective", "nose_rise_per_hop",
       "--vary", "scale=0.01:0.02", "--vary", "schedule.push_deg=-20:-15", "--max-flip", "0.05",
       "--cycles", "1", "--trials", str(TRIALS)]


def read_csv(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("views") / "o"
    res = invoke([*OPT, "--out", out])
    assert res.exit_code == 0, res.output
    assert f"Optuna's views (history, importances, interactive front): {out / 'study.html'}" in res.output
    return out


PROBE = """<script>
window.__errors = [];
window.addEventListener('error', e => window.__errors.push(
  'error: ' + String(e.message || e.target.src || '?').slice(0, 80)), true);
document.addEventListener('securitypolicyviolation', e => window.__errors.push(
  'csp: ' + String(e.blockedURI).slice(0, 80)));
window.addEventListener('load', () => setTimeout(() => {
  const out = {errors: window.__errors};
  for (const key of ['history', 'importances', 'front']) {
    out[key] = Array.from(document.querySelectorAll('section#' + key + ' .js-plotly-plot')).map(gd => ({
      title: gd._fullLayout.title.text, svg: gd.querySelectorAll('svg.main-svg').length,
      traces: gd.data.map(t => ({name: t.name || '', x: Array.from(t.x || []), y: Array.from(t.y || [])}))}));
  }
  const pre = document.createElement('pre');
  pre.id = 'probe';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
}, 0));
</script>"""


def test_study_html_opens_offline_in_chromium_with_the_three_views(study, tmp_path):
    """study.html, plotly inlined and every outside resource forbidden by its policy, draws the
    history and importances of each objective and the front; the front's points are the
    complete trials' figures in mm, each trial once."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        pytest.skip("chromium not installed (Debian package `chromium`)")
    text = (study / "study.html").read_text(encoding="utf-8")
    assert "default-src 'none'" in text and "<script src" not in text     # nothing fetched
    page = tmp_path / "probe.html"
    page.write_text(text.replace("</body>", PROBE + "</body>"), encoding="utf-8")
    proc = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=10000",
                           "--dump-dom", page.as_uri()], capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stderr[-2000:]
    found = re.search(r'<pre id="probe">(.*?)</pre>', proc.stdout, re.S)
    assert found, proc.stdout[-2000:]
    views = json.loads(html.unescape(found.group(1)))
    assert views["errors"] == []
    labels = ["distance per hop (mm)", "nose rise per hop (mm)"]
    assert [v["title"] for v in views["history"]] == [f"Optimization history: {x}" for x in labels]
    assert [v["title"] for v in views["importances"]] == [f"Parameter importances for {x}" for x in labels]
    assert [v["title"] for v in views["front"]] == ["Pareto-front Plot"]
    assert all(v["svg"] >= 1 for key in ("history", "importances", "front") for v in views[key])
    # the importances rank the two design variables
    for v in views["importances"]:
        assert sorted(v["traces"][0]["y"]) == ["scale", "schedule.push_deg"]
    # every complete trial once on the front's plot, at its figures in mm
    rows = [r for r in read_csv(study / "trials.csv") if r["state"] == "complete"]
    drawn = sorted((round(x, 6), round(y, 6)) for t in views["front"][0]["traces"] for x, y in zip(t["x"], t["y"]))
    truth = sorted((round(float(r["distance_per_hop_m"]) * 1000, 6), round(float(r["nose_rise_per_hop_m"]) * 1000, 6))
                   for r in rows)
    assert drawn == truth and len(rows) >= TRIALS - 2
    # and the history of the first objective plots the same figures, trial by trial
    hist = {int(x): y for t in views["history"][0]["traces"] for x, y in zip(t["x"], t["y"]) if "Best" not in t["name"]}
    assert hist == pytest.approx({int(r["trial"]): float(r["distance_per_hop_m"]) * 1000 for r in rows}, abs=1e-9)


def _get(app, path: str):
    """One GET through the dashboard's WSGI app (no server, no socket)."""
    from wsgiref.util import setup_testing_defaults

    env = {"PATH_INFO": path, "REQUEST_METHOD": "GET", "wsgi.input": io.BytesIO()}
    setup_testing_defaults(env)
    status = []
    body = b"".join(app(env, lambda s, h, exc_info=None: status.append(s)))
    assert status[0].startswith("200"), (path, status, body[:300])
    return json.loads(body)


def test_the_dashboards_own_loader_opens_the_journal_and_lists_every_trial(study):
    """optuna-dashboard (`optuna-dashboard o/study.journal`, docs/sweep.md) reads the study
    through its own storage loader: every trial of trials.csv, in its state, with its figures,
    and the objectives named by their columns (units in the names)."""
    optuna_dashboard = pytest.importorskip("optuna_dashboard")   # the test extra installs it
    app = optuna_dashboard.wsgi(str(study / "study.journal"))
    studies = _get(app, "/api/studies")["study_summaries"]
    assert [s["study_name"] for s in studies] == ["locust"]
    detail = _get(app, f"/api/studies/{studies[0]['study_id']}")
    assert detail["name"] == "locust" and detail["directions"] == ["maximize", "maximize"]
    assert detail["objective_names"] == ["distance_per_hop_m", "nose_rise_per_hop_m"]
    rows = read_csv(study / "trials.csv")
    listed = {t["number"]: t for t in detail["trials"]}
    assert sorted(listed) == [int(r["trial"]) for r in rows] and len(rows) == TRIALS
    for r in rows:
        t = listed[int(r["trial"])]
        assert t["state"].lower() == r["state"]
        if r["state"] == "complete":
            assert t["values"] == [float(r["distance_per_hop_m"]), float(r["nose_rise_per_hop_m"])]


def _standin(values: dict) -> Judgement:
    """Synthetic: the distance per hop is the first variable where it is above 0.5 and half the
    second below: reaching a HIGH distance takes the first alone (a LOW one, the second)."""
    a = values["scale"] / 0.02
    b = (values["schedule.push_s"] - 0.1) / 0.2
    figures = {"distance_per_hop_m": a if a > 0.5 else 0.5 * b, "nose_rise_per_hop_m": 1.0 - a}
    return Judgement(True, "", figures, dict(figures), 0.0, {"goes_over": 0.0, "rears_and_returns": 1.0,
                                                            "stays_low": 0.0}, 1, 1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_importances_are_for_the_objectives_maximised(tmp_path, seed):
    """Optuna's default evaluator ranks for LOW targets: the views give it each objective
    negated, so the variable a high distance needs ranks first (0.94 to 0.99 on seeds 0-3 over
    40 trials; for a low distance, as the evaluator alone would rank, 0.2 to 0.5)."""
    import optuna

    base = preset("seed")
    bounds = [parse_bound("scale=0:0.02", base), parse_bound("schedule.push_s=0.1:0.3", base)]
    out = tmp_path / "o"
    objectives = [OBJECTIVES["distance_per_hop"], OBJECTIVES["nose_rise_per_hop"]]
    run_optimize(base, bounds, trials=40, cycles=1, folder=out, seed=seed, objectives=objectives, judge=_standin)
    journal = optuna.storages.journal.JournalFileBackend(str(out / "study.journal"))
    held = optuna.load_study(study_name="locust", storage=optuna.storages.JournalStorage(journal))
    with warnings.catch_warnings():
        warnings.simplefilter("error")       # the views raise no warning of their own
        views = {v.key: v for v in study_views(held, objectives)}
    bars = views["importances"].figures[0].data[0]
    importance = dict(zip(bars.y, bars.x))
    assert importance["scale"] >= 0.85, importance
    assert (out / "study.html").is_file()
