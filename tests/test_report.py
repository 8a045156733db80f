"""`locust report` on SYNTHETIC measured trials of known truth, a real sweep, and a browser.

The "measured" trials are the simulated nose of a true robot that differs from the model
(foot friction 1.2 instead of 1.7), sampled like a 30 frames/s camera with 0.5 mm noise and
lost frames (locust.report.synthetic); the model's predictions must be run()'s own numbers.
"""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.io.robot_toml import save_robot
from locust.params import Provenance, leg_set, preset
from locust.report.synthetic import simulated_nose, write_synthetic_trial
from locust.sim.run import run
from locust.sweep.design import Axis, parse_bound
from locust.sweep.optimize import run_optimize
from locust.sweep.run import run_sweep
from locust.trials.measure import measure_hops

CYCLES = 2
TRUE_HINGE_STIFFNESS = 0.02   # N*m/rad: a softer cardstock hinge than the model's 0.056
CAMERA_LEAD_S = 0.25


class Cells(HTMLParser):
    """Every <td data-config data-field> cell's text, and every <img>."""

    def __init__(self):
        super().__init__()
        self.cells: dict[tuple[str, str], str] = {}
        self.images: list[dict] = []
        self._key = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "td" and "data-field" in a:
            self._key = (a.get("data-config", ""), a["data-field"])
            self.cells[self._key] = ""
        if tag == "img":
            self.images.append(a)

    def handle_data(self, data):
        if self._key:
            self.cells[self._key] += data

    def handle_endtag(self, tag):
        if tag == "td":
            self._key = None


def parse(path: Path) -> Cells:
    p = Cells()
    p.feed(path.read_text(encoding="utf-8"))
    return p


def invoke(*args):
    return CliRunner().invoke(cli, ["report", *map(str, args)])


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    root = tmp_path_factory.mktemp("report")
    seed = preset("seed")
    truth = {}
    for name, trials in (("small", 2), ("medium", 1)):
        true_robot = leg_set(seed, name).with_values({"compliance.hinge_stiffness_nm_per_rad": TRUE_HINGE_STIFFNESS})
        sim = simulated_nose(true_robot, CYCLES)
        for k in range(1, trials + 1):
            truth[f"{name}-{k}"] = write_synthetic_trial(root / "hops" / f"{name}-{k}", true_robot, CYCLES,
                                                         seed=k, camera_lead_s=CAMERA_LEAD_S, truth=sim)
    sweep = run_sweep(seed, [Axis("scale", 0.0, 0.01, 2)], CYCLES, root / "sweep", jobs=1, plots=False)
    study = run_optimize(seed, [parse_bound("scale=0:0.01", seed)], 3, CYCLES, root / "study")
    res = invoke("--measured", root / "hops" / "small-1", "--measured", root / "hops" / "small-2",
                 "--measured", root / "hops" / "medium-1", "--preset", "seed", "--sweep", root / "sweep",
                 "--optimize", root / "study", "--out", root / "out")
    assert res.exit_code == 0, res.output
    html = Path(res.stdout.strip().splitlines()[-1])
    return {"root": root, "truth": truth, "html": html, "cells": parse(html), "sweep": sweep, "study": study}


def mm(value_m: float) -> str:
    return f"{value_m * 1000:.1f}"


def marker_apexes(robot, cycles, marker="nose"):
    """Highest point of the model's marker disc in each cycle, above where it stood after the
    settle phase: straight from MuJoCo, every physics step."""
    import mujoco
    import numpy as np

    from locust.sim.rollout import roll_out

    traj = roll_out(robot, cycles=cycles, keep_states=True)
    model, data = traj.built.model, mujoco.MjData(traj.built.model)
    gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"marker_{marker}")
    z = np.empty(len(traj.states))
    for i, state in enumerate(traj.states):
        mujoco.mj_setState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        mujoco.mj_kinematics(model, data)
        z[i] = data.geom_xpos[gid, 2]
    starts = traj.plan.cycle_start_steps
    stand = z[traj.plan.settle_steps - 1]
    return [float(z[starts[c]:starts[c + 1]].max() - stand) for c in range(cycles)]


def marker_distances(robot, cycles, marker="nose"):
    """Each hop's travel of the model's marker disc: the median of its x over the last 0.2 s
    of each cycle (the rest window a track's hops use) minus the same at the cycle's start."""
    import numpy as np

    from locust.report.synthetic import simulated_nose

    _, trace = simulated_nose(robot, cycles)
    period = robot.schedule.push_s + robot.schedule.wait_s
    rest = [0.0] + [float(np.median(trace.x_m[(trace.t_s > k * period - 0.2) & (trace.t_s <= k * period)]))
                    for k in range(1, cycles + 1)]
    return list(np.diff(rest))


def test_predictions_are_the_pipelines_own(world):
    """Distance: run()'s (locust sim's), to the printed 0.1 mm; marker travel: the simulated
    nose marker's, hop by hop. Apexes: the simulated nose marker's (what the camera follows),
    within 0.2 mm of MuJoCo's marker position at every step (the report thins the trace to
    240 Hz: about 0.02 mm lower at the top of the arc)."""
    cells = world["cells"].cells
    for name in ("small", "medium"):
        robot = leg_set(preset("seed"), name)
        r = run(robot, cycles=CYCLES)
        assert r.valid
        marker_hops = marker_distances(robot, CYCLES)
        assert cells[(name, "predicted_distance_mm")] == mm(r.distance_m)
        assert cells[(name, "predicted_marker_travel_mm")] == mm(sum(marker_hops))
        for k, d in enumerate(marker_hops, start=1):
            assert cells[(name, f"hop_predicted_marker_travel_mm:{name}-1#{k}")] == mm(d)
            # these robots stand on their feet after each hop: the nose marker travels as the chassis
            assert d == pytest.approx(r.hops[k - 1].distance_m, abs=0.0005)
        apexes = marker_apexes(robot, CYCLES)
        assert float(cells[(name, "predicted_jump_mm")]) == pytest.approx(max(apexes) * 1000, abs=0.2)
        for k, a in enumerate(apexes, start=1):
            assert float(cells[(name, f"hop_predicted_apex_mm:{name}-1#{k}")]) == pytest.approx(a * 1000, abs=0.2)
    # the sweep's designs at scale 0 and 0.01 are Small and Medium: every leg set converges at the
    # seed's own 1 ms (params.LEG_SETS), so the sweep's rows and the report's figures are one number
    rows = {round(r["scale"], 6): r for r in world["sweep"].rows}
    assert rows[0.0]["distance_m"] == pytest.approx(run(leg_set(preset("seed"), "small"), cycles=CYCLES).distance_m)
    assert rows[0.01]["distance_m"] == pytest.approx(run(leg_set(preset("seed"), "medium"), cycles=CYCLES).distance_m)


def test_measured_hops_match_the_synthetic_truth(world):
    """Hop distance within 1.5 mm of the true robot's (0.5 mm noise, median of ~6 rest frames);
    apex within 5 mm and never above truth + 1.5 mm: a 30 frames/s camera samples the peak
    up to 1/60 s away from it, which can only lower it (about 1-3 mm here)."""
    cells = world["cells"].cells
    for label, truth in world["truth"].items():
        name = label.split("-")[0]
        for k, (d_true, a_true) in enumerate(zip(truth.hop_distance_m, truth.hop_apex_m), start=1):
            d = float(cells[(name, f"hop_measured_marker_travel_mm:{label}#{k}")]) / 1000
            a = float(cells[(name, f"hop_measured_apex_mm:{label}#{k}")]) / 1000
            assert d == pytest.approx(d_true, abs=0.0015), (label, k)
            assert a == pytest.approx(a_true, abs=0.005), (label, k)
            assert a <= a_true + 0.0015
    # the true robot (softer hinges) hops 3.1 mm farther than the model over the two hops (2.8
    # mm before the loop fold had its spring): the report shows that error, to the
    # measurement's resolution
    err = float(cells[("small", "marker_travel_error_mm")])
    true_total = world["truth"]["small-1"].distance_m
    model_total = sum(marker_distances(leg_set(preset("seed"), "small"), CYCLES))
    assert (true_total - model_total) * 1000 == pytest.approx(3.08, abs=0.3)
    assert err == pytest.approx((true_total - model_total) * 1000, abs=0.6)


def test_the_hop_table_gives_each_hops_takeoff_speed(world):
    """Take-off speed (the marker's fastest from a hop's start to its apex, Tracker's central
    difference; m/s): predicted, the model's simulated marker by the same rule, to the page's
    0.01 m/s; measured, the Medium trial's track (30 frames/s, 0.5 mm noise: 0.012 m/s a
    component, the fastest of a few frames) within 0.04 m/s of the same camera's noise-free
    view of the true nose (0.233 m/s; the true robot's 240 Hz figure is 0.264: a 30 frames/s
    camera blurs the push's peak). The Small true robot's hops rise 1.4 mm, three noise
    deviations: where their apex is, and so their take-off, is the noise's to say."""
    import numpy as np

    from locust.trials.measure import Aligned

    cells = world["cells"].cells
    seed = preset("seed")
    for name, trials in (("small", 2), ("medium", 1)):
        model = leg_set(seed, name)
        period = model.schedule.push_s + model.schedule.wait_s
        _, trace = simulated_nose(model, CYCLES)
        true_robot = model.with_values({"compliance.hinge_stiffness_nm_per_rad": TRUE_HINGE_STIFFNESS})
        _, true_trace = simulated_nose(true_robot, CYCLES)
        t = np.arange(-CAMERA_LEAD_S, true_trace.t_s[-1], 1 / 30)
        camera = Aligned(t, np.interp(t, true_trace.t_s, true_trace.x_m), np.interp(t, true_trace.t_s, true_trace.y_m),
                         0.0, 0.0)
        for k in range(1, trials + 1):
            label = f"{name}-{k}"
            for hop, predicted, seen in zip(range(1, CYCLES + 1), measure_hops(trace, period, CYCLES),
                                            measure_hops(camera, period, CYCLES)):
                shown = cells[(name, f"hop_predicted_takeoff_speed_m_per_s:{label}#{hop}")]
                assert shown == f"{predicted.takeoff_speed_m_per_s:.2f}", (label, hop)
                if name == "medium":
                    measured = float(cells[(name, f"hop_measured_takeoff_speed_m_per_s:{label}#{hop}")])
                    assert measured == pytest.approx(seen.takeoff_speed_m_per_s, abs=0.04), (label, hop)
                    assert seen.takeoff_speed_m_per_s == pytest.approx(0.233, abs=0.005)


def test_repeated_trials_have_error_bars_and_timing_is_the_records(world):
    cells = world["cells"].cells
    assert cells[("small", "trials")] == "2" and cells[("medium", "trials")] == "1"
    assert "±" in cells[("small", "measured_jump_mm")]          # two trials: mean ± sd
    assert "±" not in cells[("medium", "measured_jump_mm")]     # one trial: no error bar
    import json

    rec = json.loads((world["root"] / "hops" / "small-1" / "run.json").read_text())
    assert cells[("small", "jitter_mean_ms:small-1")] == f"{rec['jitter']['mean_ms']:.3f}"
    assert cells[("small", "jitter_max_abs_ms:small-1")] == f"{rec['jitter']['max_abs_ms']:.3f}"


def test_report_is_self_contained_with_named_figures(world):
    html_path = world["html"]
    text = html_path.read_text(encoding="utf-8")
    images = world["cells"].images
    assert len(images) >= 4                                   # overlay, jump, hops, landscape, timing
    for img in images:
        assert img["src"].startswith("data:image/png;base64,")
        png = base64.b64decode(img["src"].split(",", 1)[1])
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000
    named = [img["alt"] for img in images if "Small" in img["alt"] and "Medium" in img["alt"]]
    assert len(named) >= 3
    assert not re.search(r"(src|href)=\"(https?:|file:|//)", text)
    assert "<script" not in text
    assert (html_path.parent / "dashboard.png").stat().st_size > 50_000
    # parameter table with provenance
    assert world["cells"].cells[("", "param:contact.foot_friction")] == "1.7"
    assert "fig-landscape" in text


def test_the_page_gives_every_length_in_mm(world):
    """docs/report.md: every length on the page in mm, each with its unit (the added length was
    in cm, the parameters' lengths in m): no header in cm or m, the links and added lengths
    the robots', and every parameter in mm, g or deg, its dotted name that of --set."""
    text = world["html"].read_text(encoding="utf-8")
    headers = re.findall(r"<th[^>]*>([^<]*)</th>", text)
    assert headers and not [h for h in headers if re.search(r"\((c?m)\)", h)], headers
    assert "added (mm)" in headers
    cells = world["cells"].cells
    seed = preset("seed")
    assert cells[("", "param:geometry.crank_m")] == f"{seed.geometry.crank_m * 1000:.6g} mm"
    assert cells[("", "param:geometry.body_mass_kg")] == f"{seed.geometry.body_mass_kg * 1000:.6g} g"
    assert cells[("", "param:geometry.crank_start_deg")] == f"{seed.geometry.crank_start_deg:.6g} deg"
    added = re.search(r'<td class="l">Medium</td><td>([^<]*)</td>', text)
    assert added and added.group(1) == "+10"


def test_report_draws_an_optimize_study_s_front_and_names_its_pick(world):
    text = world["html"].read_text(encoding="utf-8")
    assert "fig-pareto" in text
    best = world["study"].best     # one objective: the front is the farthest design
    scale = f"{best['scale'] * 1000:#.4g}".rstrip(".")
    assert f"best-distance_per_hop: trial {best['trial']} (scale {scale} mm): distance per hop " in text
    doc = json.loads((world["html"].parent / "report.json").read_text())
    assert [r["trial"] for r in doc["optimize"]["front"]] == [best["trial"]]
    assert doc["optimize"]["front"][0]["distance_per_hop_m"] == best["distance_per_hop_m"]


def test_report_writes_optuna_s_views_of_the_study_beside_the_page(world):
    """--optimize: study.html beside report.html, drawn from the study's journal (its three
    trials), linked from the front's caption; one objective, so a history and importances and a
    note in place of a front."""
    folder = world["html"].parent
    text = world["html"].read_text(encoding="utf-8")
    assert '<a href="study.html">Optuna&#x27;s own views of the study' in text
    views = (folder / "study.html").read_text(encoding="utf-8")
    assert "3 trials in " in views and str(world["root"] / "study" / "study.journal") in views
    assert views.count('data-view="history"') == 1 and views.count('data-view="front"') == 0
    assert "one objective: the study has no front" in views
    doc = json.loads((folder / "report.json").read_text())
    assert doc["optimize"]["views"] == "study.html"


def test_a_study_made_under_the_old_objective_names_is_refused_with_the_new_ones(world, tmp_path):
    """A study whose optimize.json maximises `distance` (the name before it said per hop) is not
    drawn as if its figures were this locust's: error and hint, nothing simulated or written."""
    old = tmp_path / "old-study"
    shutil.copytree(world["root"] / "study", old)
    meta = json.loads((old / "optimize.json").read_text())
    meta["settings"]["objectives"] = ["distance"]
    (old / "optimize.json").write_text(json.dumps(meta))
    res = invoke("--measured", world["root"] / "hops" / "small-1", "--preset", "seed", "--optimize", old,
                 "--out", tmp_path / "out")
    assert res.exit_code == 2, res.output
    assert "its study maximises distance, which is no objective of this locust" in res.output
    assert "hint: rerun the study into a new --out with --objective distance_per_hop" in res.output
    assert not (tmp_path / "out").exists()


def test_changing_a_calibrated_stiffness_changes_the_predictions(world, tmp_path):
    """Hinge stiffness 0.056 -> 0.02 N*m/rad (as if refitted from a beam drop): run() moves Small
    by about 2 mm over two hops; the simulation is deterministic, so any difference above the
    printed 0.1 mm is the input's. The report must print the new run()'s number and the new
    provenance."""
    changed = preset("seed").with_values({"compliance.hinge_stiffness_nm_per_rad": 0.02},
                                         Provenance(source="fit:beam-test", uncertainty=0.002, date="2026-01-01"))
    toml = save_robot(changed, tmp_path / "robot.toml")
    res = invoke("--measured", f"small={world['root'] / 'hops' / 'small-1'}", "--config", toml,
                 "--out", tmp_path / "out")
    assert res.exit_code == 0, res.output
    cells = parse(Path(res.stdout.strip().splitlines()[-1])).cells
    before = float(world["cells"].cells[("small", "predicted_distance_mm")])
    after = float(cells[("small", "predicted_distance_mm")])
    assert abs(after - before) >= 1.5
    assert cells[("small", "predicted_distance_mm")] == mm(run(leg_set(changed, "small"), cycles=CYCLES).distance_m)
    assert cells[("small", "predicted_marker_travel_mm")] == mm(sum(marker_distances(leg_set(changed, "small"),
                                                                                       CYCLES)))
    assert cells[("", "param:compliance.hinge_stiffness_nm_per_rad")] == "0.02 N·m/rad"
    # the measured side moves only with the hop windows, which the model's onset latency places
    # on the track's clock (a softer hinge starts the push later): by at most 0.3 mm here
    a = float(cells[("small", "hop_measured_marker_travel_mm:small-1#1")])
    b = float(world["cells"].cells[("small", "hop_measured_marker_travel_mm:small-1#1")])
    assert a == pytest.approx(b, abs=0.3)


PROBE = """<script>
window.__errors = [];
window.addEventListener('error', e => window.__errors.push(
  'error: ' + String(e.message || e.target.src || '?').slice(0, 80)), true);
document.addEventListener('securitypolicyviolation', e => window.__errors.push(
  'csp: ' + String(e.blockedURI).slice(0, 80)));
window.addEventListener('load', () => {
  const imgs = Array.from(document.images);
  const drawn = imgs.filter(i => i.complete && i.naturalWidth > 0 && i.naturalHeight > 0);
  document.body.setAttribute('data-images', imgs.length);
  document.body.setAttribute('data-drawn', drawn.length);
  document.body.setAttribute('data-min-width', Math.min(...imgs.map(i => i.naturalWidth)));
  document.body.setAttribute('data-errors', window.__errors.join(' | '));
});
</script>"""


def test_report_loads_in_headless_chromium(world, tmp_path):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        pytest.skip("chromium not installed (Debian package `chromium`)")
    text = world["html"].read_text(encoding="utf-8")
    # the probe is added to this copy only; its CSP allows inline script, nothing else changes
    probe = text.replace("style-src 'unsafe-inline'", "style-src 'unsafe-inline'; script-src 'unsafe-inline'")
    probe = probe.replace("</body>", PROBE + "</body>")
    page = tmp_path / "probe.html"
    page.write_text(probe, encoding="utf-8")
    proc = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr",
                           "--v=0", "--virtual-time-budget=5000", "--dump-dom", page.as_uri()],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    body = re.search(r"<body([^>]*)>", proc.stdout).group(1)
    attrs = dict(re.findall(r'(data-[\w-]+)="([^"]*)"', body))
    n_images = len(world["cells"].images)
    assert int(attrs["data-images"]) == n_images
    assert int(attrs["data-drawn"]) == n_images, attrs
    assert int(attrs["data-min-width"]) > 300
    assert attrs["data-errors"] == ""
    console = [ln for ln in proc.stderr.splitlines() if "CONSOLE" in ln or "Refused" in ln]
    assert console == []


def test_a_full_disk_leaves_no_half_report(world, small_disk):
    """A report onto a real full disk (a 64 kB tmpfs): error:/hint:, and no report/ folder left
    (an earlier version left an empty one)."""
    disk, fill = small_disk
    fill(free=8192)
    res = invoke("--measured", world["root"] / "hops" / "small-1", "--preset", "seed", "--out", disk / "out")
    assert res.exit_code == 2 and "the disk is full" in res.output and "hint:" in res.output, res.output
    assert not (disk / "out").exists() or list((disk / "out").iterdir()) == []
