"""``locust report --explain``: the tornado figure and each configuration's explanation, the
same as ``locust sim --explain`` gives for that configuration's robot (a SYNTHETIC trial of the
robot as built stands in for a filmed one)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

import locust
from locust.commands import cli
from locust.report.synthetic import write_synthetic_trial
from locust.sim.explain import explain

CYCLES = 1


@pytest.fixture(scope="module")
def explained_report(tmp_path_factory):
    root = tmp_path_factory.mktemp("report-explain")
    robot = locust.robot("small")
    write_synthetic_trial(root / "hops" / "small-1", robot, CYCLES, seed=1)
    res = CliRunner().invoke(cli, ["report", "--measured", str(root / "hops" / "small-1"), "--preset", "small",
                                   "--cycles", str(CYCLES), "--explain", "--out", str(root / "out")])
    assert res.exit_code == 0, res.output
    html = Path(res.stdout.strip().splitlines()[-1])
    return robot, html, json.loads((html.parent / "report.json").read_text())


def test_report_explains_each_configuration_as_sim_does(explained_report):
    robot, html, doc = explained_report
    (entry,) = doc["configurations"]
    ours = json.loads(json.dumps(explain(robot, cycles=CYCLES).to_json()))
    assert entry["explanation"]["words"] == ours["words"]
    assert entry["explanation"]["tornado"] == ours["tornado"]
    assert entry["explanation"]["tip_over"] == ours["tip_over"]


def test_report_page_has_the_tornado_figure(explained_report):
    robot, html, doc = explained_report
    text = html.read_text(encoding="utf-8")
    assert 'id="fig-tornado"' in text or "tornado" in text
    assert "What each uncertain value does to the prediction" in text
    assert "goes over in push 1" in text
