"""The report's headline cannot be misread: its distance is `locust sim`'s own figure for the
same robot and cycles (one name, one meaning), the marker's travel is compared like with like
under its own name, and a run that goes over onto its back is said to go over (at which hop,
resting where), never shown as a jump.

On SYNTHETIC trials (locust.report.synthetic: the simulated nose marker of the very robot the
model is, sampled like a 60 frames/s camera without noise) of three robots: Large with its
crank at -88 deg, which rears (nose about 76 mm up) and returns, about 7 mm forward a hop
(the rear-and-return band, -90 to -86 deg with the presets' servo axis at 28 mm); and Small
and Large as preset, which go over onto their backs in their first hop, where the chassis
(Small: -74 mm) and the nose marker (about -127 mm) travel differently and the marker then
rests 87 mm (Small) and 109 mm (Large) above where it stood.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.params import preset
from locust.report.synthetic import write_synthetic_trial

CYCLES = 2
ROBOTS = {
    "rearing": lambda: preset("large").with_values({"geometry.crank_start_deg": -88.0}),
    "over": lambda: preset("small"),
    "largeover": lambda: preset("large"),
}
OVER = ("over", "largeover")


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def reported(request, tmp_path_factory):
    from locust.io.robot_toml import save_robot

    name = request.param
    root = tmp_path_factory.mktemp(name)
    robot = ROBOTS[name]()
    write_synthetic_trial(root / name, robot, CYCLES, fps=60.0, noise_m=0.0, lost_frames=0)
    config = save_robot(robot, root / "robot.toml")
    res = CliRunner().invoke(cli, ["report", "--measured", f"{name}={root / name}", "--config", str(config),
                                   "--out", str(root / "out")])
    assert res.exit_code == 0, res.output
    html = Path(res.stdout.strip().splitlines()[-1])
    doc = json.loads((html.parent / "report.json").read_text())
    sim = CliRunner().invoke(cli, ["sim", "--config", str(config), "--cycles", str(CYCLES), "--json"])
    assert sim.exit_code == 0, sim.output
    sim_text = CliRunner().invoke(cli, ["sim", "--config", str(config), "--cycles", str(CYCLES)])
    return {"name": name, "stderr": res.stderr, "cfg": doc["configurations"][0], "html": html.read_text(),
            "sim": json.loads(sim.stdout), "sim_text": sim_text.stdout}


def cell(html: str, name: str, field: str) -> str:
    m = re.search(rf'data-config="{name}" data-field="{re.escape(field)}">([^<]*)<', html)
    assert m, field
    return m.group(1)


def printed(stderr: str, name: str, side: str) -> str:
    m = re.search(rf"^{name}\s+{side}[ :(].*$", stderr, re.M)
    assert m, stderr
    return m.group(0)


def test_the_predicted_distance_is_locust_sims(reported):
    """The same robot and cycles: `locust sim` prints a total distance, the report the same
    one, to 0.1 mm (report.json to the last digit; the page and the printed line to 0.1 mm)."""
    name, cfg, sim = reported["name"], reported["cfg"], reported["sim"]
    total = float(re.search(r"total distance (-?[\d.]+) mm", reported["sim_text"]).group(1)) / 1000
    assert cfg["predicted_distance_m"] == pytest.approx(sim["distance_m"], abs=1e-12)
    assert abs(cfg["predicted_distance_m"] - total) <= 0.00005
    assert float(cell(reported["html"], name, "predicted_distance_mm")) == pytest.approx(sim["distance_m"] * 1000,
                                                                                         abs=0.05)
    line = printed(reported["stderr"], name, "predicted")
    shown = float(re.search(r"distance (-?[\d.]+) mm \(locust sim's\)", line).group(1))
    assert shown == pytest.approx(sim["distance_m"] * 1000, abs=0.05), line


def test_the_marker_travel_is_like_with_like(reported):
    """The marker's travel, printed and in report.json, is the sum of the hops the figure draws
    on both sides, and the model against its own synthetic film agrees within 1 %; on a robot
    that ends on its back it differs from the distance by centimetres, under its own name."""
    name, cfg = reported["name"], reported["cfg"]
    figure_pred = sum(h["distance_m"] for h in cfg["predicted_marker_hops"])
    figure_meas = sum(h["measured_marker_travel_m"] for h in cfg["hops"])
    assert [h["predicted_marker_travel_m"] for h in cfg["hops"]] == pytest.approx(
        [h["distance_m"] for h in cfg["predicted_marker_hops"]], rel=1e-12)
    pred = printed(reported["stderr"], name, "predicted")
    meas = printed(reported["stderr"], name, "measured")
    printed_pred = float(re.search(r"marker travel (-?[\d.]+) mm", pred).group(1)) / 1000
    printed_meas = float(re.search(r"marker travel (-?[\d.]+) mm", meas).group(1)) / 1000
    for value, truth in ((printed_pred, figure_pred), (cfg["predicted_marker_travel_m"], figure_pred),
                         (printed_meas, figure_meas), (cfg["measured"]["marker_travel_m"]["mean"], figure_meas)):
        assert value == pytest.approx(truth, rel=0.01, abs=0.00005), (name, value, truth)
    assert figure_meas == pytest.approx(figure_pred, rel=0.01), (name, figure_meas, figure_pred)
    if name == "rearing":
        assert cfg["predicted_distance_m"] == pytest.approx(figure_pred, rel=0.01)
    else:
        assert cfg["predicted_distance_m"] - figure_pred > 0.02


def test_a_run_that_goes_over_is_said_to_and_is_no_jump(reported):
    """Small and Large as preset go over in their first hop: the summary, the printed lines and
    report.json say so, with the hop and where it rests (the robot: `locust sim`'s distance
    behind its start; the filmed marker: its rest height and travel), and show no jump; each hop
    row says how it ended and has no apex. The rearing robot's hops come back down, and its
    jump is its marker's highest apex."""
    name, cfg, html, sim = reported["name"], reported["cfg"], reported["html"], reported["sim"]
    pred, meas = printed(reported["stderr"], name, "predicted"), printed(reported["stderr"], name, "measured")
    marker_hops = cfg["predicted_marker_hops"]
    # the filmed marker's ending, read off the track alone, is the simulation's own (locust.sim.outcome)
    assert [o["outcome"] for o in cfg["measured"]["outcomes"]] == [sim["outcome"]]
    if name not in OVER:
        assert sim["outcome"] == "rears_and_returns"
        assert cfg["predicted_outcome"]["over_hop"] is None
        assert cfg["predicted_jump_m"] == pytest.approx(max(h["apex_m"] for h in marker_hops), abs=1e-12)
        assert float(cell(html, name, "measured_jump_mm")) == pytest.approx(cfg["predicted_jump_m"] * 1000, abs=1.0)
        assert {h["measured_state"] for h in cfg["hops"]} == {h["predicted_state"] for h in cfg["hops"]} \
            == {"on its feet"}
        assert "jump" in pred and "jump" in meas
        return
    assert sim["outcome"] == "goes_over"
    behind = f"{abs(sim['distance_m']) * 1000:.1f} mm behind its start"
    said = f"goes over at hop 1, rests on its back {behind}"
    assert cfg["predicted_outcome"]["over_hop"] == 1 and cfg["predicted_outcome"]["words"] == said
    assert cell(html, name, "predicted_outcome") == said and f"predicted: {said};" in pred
    rest = marker_hops[-1]["rest_height_m"]
    assert rest > 0.08                                             # lying on its back, not hopping
    measured = cell(html, name, "measured_outcome")
    assert measured.startswith("goes over at hop 1, its marker at rest ") and "behind where it stood" in measured
    assert float(re.search(r"at rest ([\d.]+) mm up", measured).group(1)) == pytest.approx(rest * 1000, abs=0.5)
    assert "goes over at hop 1" in meas
    for field in ("predicted_jump_mm", "measured_jump_mm", "jump_error_mm"):
        assert cell(html, name, field) == "—", field
    assert cfg["predicted_jump_m"] is None and cfg["measured"]["jump_m"]["n"] == 0
    assert "jump" not in pred and "jump" not in meas
    assert [h["predicted_state"] for h in cfg["hops"]] == [h["measured_state"] for h in cfg["hops"]] \
        == ["goes over", "on its back"]
    assert all(h["measured_apex_m"] is None and h["predicted_apex_m"] is None for h in cfg["hops"])


def test_the_jump_bars_say_a_run_went_over(tmp_path):
    """The jump figure draws no bar for a run that went over in its first hop (where its
    resting height, 87 mm on Small, stood before) and writes that it went over instead."""
    import locust
    from locust.plotting import pyplot
    from locust.report import figures

    robot = preset("small")
    write_synthetic_trial(tmp_path / "small-1", robot, CYCLES, fps=60.0, noise_m=0.0, lost_frames=0)
    res = locust.make_report(robot, {"over": [tmp_path / "small-1"]}, out=tmp_path / "out")
    (c,) = res.comparisons
    fig, ax = pyplot().subplots()
    figures.draw_bars(ax, [c], "jump")
    assert [p.get_height() for p in ax.patches] == [0.0, 0.0]
    texts = [t.get_text() for t in ax.texts]
    assert texts == ["measured: goes over at hop 1, no jump", "predicted: goes over at hop 1, no jump"]
