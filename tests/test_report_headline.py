"""The report's headline compares like with like: the predicted and the measured distance are
the same marker's, from the same zero and cut into the same hops as the figure draws them.

On SYNTHETIC trials (locust.report.synthetic: the simulated nose of the very robot the model
is, sampled like a 60 frames/s camera without noise) of two robots: Large with its crank at
-88 deg, which rears (nose about 76 mm up) and returns, about 7 mm forward a hop (issue 33's
rear-and-return band, -90 to -86 deg with the presets' servo axis at 28 mm); and Small as
preset, which goes over onto its back in its first hop, where the chassis (-74 mm) and the
nose (about -127 mm) travel differently.
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
}


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def reported(request, tmp_path_factory):
    name = request.param
    root = tmp_path_factory.mktemp(name)
    robot = ROBOTS[name]()
    write_synthetic_trial(root / name, robot, CYCLES, fps=60.0, noise_m=0.0, lost_frames=0)
    config = root / "robot.toml"
    from locust.io.robot_toml import save_robot

    save_robot(robot, config)
    res = CliRunner().invoke(cli, ["report", "--measured", f"{name}={root / name}", "--config", str(config),
                                   "--out", str(root / "out")])
    assert res.exit_code == 0, res.output
    html = Path(res.stdout.strip().splitlines()[-1])
    doc = json.loads((html.parent / "report.json").read_text())
    return name, res.stderr, doc["configurations"][0]


def test_the_headline_is_the_figures_numbers(reported):
    """The printed line and report.json's summary within 1 % of the hops the figure draws
    (both sides), and the model against its own synthetic film within 1 %."""
    name, stderr, cfg = reported
    line = re.search(rf"^{name}\s+predicted (\S+) mm, measured (\S+) mm over 1 trial", stderr, re.M)
    assert line, stderr
    printed_pred, printed_meas = float(line.group(1)) / 1000, float(line.group(2)) / 1000
    figure_pred = sum(h["distance_m"] for h in cfg["predicted_marker_hops"])
    figure_meas = sum(h["measured_distance_m"] for h in cfg["hops"])
    assert [h["predicted_distance_m"] for h in cfg["hops"]] == pytest.approx(
        [h["distance_m"] for h in cfg["predicted_marker_hops"]], rel=1e-12)
    for value, truth in ((printed_pred, figure_pred), (cfg["predicted_distance_m"], figure_pred),
                         (printed_meas, figure_meas), (cfg["measured"]["distance_m"]["mean"], figure_meas)):
        assert value == pytest.approx(truth, rel=0.01, abs=0.00005), (name, value, truth)
    assert figure_meas == pytest.approx(figure_pred, rel=0.01), (name, figure_meas, figure_pred)


def test_the_robots_are_the_ones_named(reported):
    """The rearing robot returns (the nose rises over 3 cm a hop and it moves forward); the
    other ends on its back, its chassis travelling at least 20 mm less far back than its nose."""
    name, _, cfg = reported
    hops = cfg["predicted_marker_hops"]
    if name == "rearing":
        assert all(h["apex_m"] > 0.03 and h["distance_m"] > 0.003 for h in hops), hops
        assert cfg["predicted"]["distance_m"] == pytest.approx(cfg["predicted_distance_m"], rel=0.01)
    else:
        assert cfg["predicted"]["distance_m"] - cfg["predicted_distance_m"] > 0.02
