"""What the report's figures and warnings show: each warning shared by several trials once,
with its count; legends outside the axes (never over data); captions that name only what
is drawn; lengths in millimetres on every axis, the sweep's heat maps included, and never a
key in metres beside a value in mm.

The trials are synthetic (locust.report.synthetic: the seed's leg sets simulated, with
camera noise), written into folders whose names give their leg set."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from locust.params import leg_set, preset
from locust.report import figures
from locust.report.checks import Notice, collapsed
from locust.report.landscape import Landscape
from locust.report.synthetic import simulated_nose, write_synthetic_trial
from locust.sweep import plot as sweep_plot
from locust.sweep.design import Axis
from locust.sweep.run import run_sweep
from probing import invoke

CYCLES = 2
LENGTH_WORDS = ("distance", "height", "forward", "displacement", "travel", "apex", "above standing", "added length",
                "_m (", "geometry.")


class Captured:
    """Every figure the report draws, kept open instead of written (png_bytes patched)."""

    def __init__(self):
        self.figures = []

    def __call__(self, fig, dpi=110):
        self.figures.append(fig)
        return b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    root = tmp_path_factory.mktemp("figures")
    seed = preset("seed")
    for name, trials in (("small", 2), ("medium", 1)):
        robot = leg_set(seed, name)
        sim = simulated_nose(robot, CYCLES)
        for k in range(1, trials + 1):
            write_synthetic_trial(root / "hops" / f"{name}-{k}", robot, CYCLES, seed=k, camera_lead_s=0.25, truth=sim)
    run_sweep(seed, [Axis("scale", 0.0, 0.01, 2)], CYCLES, root / "sweep", jobs=1, plots=False)
    captured = Captured()
    mp = pytest.MonkeyPatch()
    mp.setattr(figures, "png_bytes", captured)
    try:
        trials = [a for t in ("small-1", "small-2", "medium-1") for a in ("--measured", root / "hops" / t)]
        res = invoke(["report", *trials, "--preset", "seed", "--sweep", root / "sweep", "--out", root / "out"])
    finally:
        mp.undo()
    assert res.exit_code == 0, res.output
    return {"res": res, "figures": captured.figures, "html": Path(res.stdout.strip().splitlines()[-1]).read_text()}


def test_a_warning_shared_by_several_trials_is_one_line_with_its_count(report):
    lines = [ln for ln in report["res"].stderr.splitlines() if ln.startswith("warning:")]
    assert lines == ["warning: 3 trials (small-1, small-2, medium-1): the leg set was guessed from the folder name, "
                     "not given: say which leg set was filmed with --measured NAME=PATH, or record it with "
                     "`locust hop --leg-set NAME`"]
    assert report["html"].count('data-kind="configuration-guessed"') == 1
    # six virtual-robot trials, as the demo hops them: one line; a lone notice keeps its own words
    six = [Notice("virtual-robot", c, f"{c}-{k}", f"{c}-{k}: from the virtual robot", "from the virtual robot")
           for c in ("small", "medium", "large") for k in (1, 2)]
    lone = Notice("units", "small", "small-1", "small-1: 600 m in one hop", "")
    shown = collapsed([*six, lone])
    assert [n.message for n in shown] == [
        "6 trials (small-1, small-2, medium-1, medium-2, large-1, large-2): from the virtual robot",
        "small-1: 600 m in one hop"]
    assert shown[0].config == "small, medium, large"


def _drawn(fig):
    fig.canvas.draw()
    return fig.canvas.get_renderer()


def test_every_legend_stands_outside_its_axes(report):
    legends = 0
    for fig in report["figures"]:
        renderer = _drawn(fig)
        for ax in fig.axes:
            legend = ax.get_legend()
            if legend is None:
                continue
            legends += 1
            box, area = legend.get_window_extent(renderer), ax.get_window_extent(renderer)
            overlap_w = min(box.x1, area.x1) - max(box.x0, area.x0)
            overlap_h = min(box.y1, area.y1) - max(box.y0, area.y0)
            assert overlap_w <= 0 or overlap_h <= 0, (ax.get_title(), box, area)
    # overlay (2 columns), jump, hops, landscape, timing, and the dashboard's four panels
    assert legends == 2 + 1 + 1 + 1 + 1 + 4


def test_every_length_on_every_axis_is_in_mm(report):
    """Hop figures (forward, height, apex, marker travel, distance) and a design's added length
    in mm, as every table and every command prints them (the design in cm before)."""
    labels = [lab for fig in report["figures"] for ax in fig.axes for lab in (ax.get_xlabel(), ax.get_ylabel())
              if lab]
    lengths = [lab for lab in labels if any(w in lab for w in LENGTH_WORDS)]
    # overlay 2, jump 1, hops 2, landscape 2, dashboard 1 + 1 + 2 (its landscape)
    assert len(lengths) == 11, lengths
    assert all(lab.endswith("(mm)") for lab in lengths), lengths
    assert "added length on every link (mm)" in lengths
    assert not [lab for lab in labels if re.search(r"\((c?m)\)$", lab) or "_m (" in lab]


def _landscape(valid):
    values = np.array([0.0, 0.01, 0.02])
    return Landscape(folder=Path("sweep"), base="seed", names=["scale"], cycles=2, values={"scale": values},
                     valid=np.array(valid), distance_m=np.where(valid, [0.010, 0.008, 0.006], np.nan),
                     reason=["" if v else "energy audit" for v in valid])


def test_the_landscape_caption_names_only_what_is_drawn(report, monkeypatch):
    caption = re.search(r'<figure id="fig-landscape">.*?<figcaption>(.*?)</figcaption>', report["html"], re.S)
    assert caption and "every design valid" in caption.group(1) and "cross" not in caption.group(1)
    captured = Captured()
    monkeypatch.setattr(figures, "png_bytes", captured)
    for valid, crosses in (([True, True, True], 0), ([True, False, False], 2)):
        land = _landscape(valid)
        figures.landscape_figure(land, [], {})
        drawn = [line for line in captured.figures[-1].axes[0].lines if line.get_marker() == "x"]
        assert sum(len(line.get_xdata()) for line in drawn) == crosses
        assert all(np.all(line.get_ydata() == 0) for line in drawn)
        text = figures.landscape_caption(land, [])
        assert ("2 invalid designs, failed audit: red crosses at zero" in text) == bool(crosses)
        assert ("cross" in text) == bool(crosses)
        assert "open circle" not in text and "square" not in text      # no design was predicted or measured


def test_the_sweep_heat_map_draws_lengths_in_mm(tmp_path, monkeypatch):
    shown = []
    monkeypatch.setattr(sweep_plot, "save_png", lambda fig, path: shown.append(fig) or Path(path))
    a, b = Axis("geometry.leg_m", 0.02, 0.04, 3), Axis("servo.kp_nm_per_rad", 1.0, 2.0, 2)
    rows = [{"geometry.leg_m": x, "servo.kp_nm_per_rad": k, "valid": True, "outcome": "stays_low",
             "distance_m": 0.01, "max_nose_height_m": 0.002} for x in a.values() for k in b.values()]
    sweep_plot._heatmap(rows, a, b, tmp_path / "h.png")
    ax = shown[0].axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("geometry.leg (mm)", "servo.kp (N·m/rad)")
    assert ax.get_xlim() == pytest.approx((15.0, 45.0))        # 20..40 mm, half a step either side
