"""docs/python-api.ipynb: run top to bottom in a real Jupyter kernel, in a temporary folder, and
its printed figures checked; the committed notebook carries no outputs."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "docs" / "python-api.ipynb"

nbformat = pytest.importorskip("nbformat", reason="nbformat is a test dependency (pip install -e '.[test]')")
nbclient = pytest.importorskip("nbclient", reason="nbclient is a test dependency (pip install -e '.[test]')")


def test_committed_notebook_has_no_outputs():
    nb = nbformat.read(NOTEBOOK, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert len(code) >= 10
    assert [c.outputs for c in code if c.outputs] == []
    assert [c.execution_count for c in code if c.execution_count is not None] == []


@pytest.fixture(scope="module")
def printed(tmp_path_factory) -> dict[str, dict]:
    """The JSON line each tagged cell prints, by tag, after running the notebook in a fresh kernel."""
    nb = nbformat.read(NOTEBOOK, as_version=4)
    folder = tmp_path_factory.mktemp("notebook")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "host"), os.environ.get("PYTHONPATH", "")]),
               MPLBACKEND="Agg")
    client = nbclient.NotebookClient(nb, timeout=240, kernel_name="python3",
                                     resources={"metadata": {"path": str(folder)}})
    client.execute(env=env, cwd=str(folder))
    out = {}
    for cell in nb.cells:
        for tag in cell.get("metadata", {}).get("tags", []):
            text = "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream")
            lines = [ln for ln in text.splitlines() if ln.startswith("{")]
            assert len(lines) == 1, (tag, text)
            out[tag] = json.loads(lines[0])
    assert (folder / "python-api-out" / "large.mp4").is_file()
    return out


def test_trace_gives_the_summary_figures(printed):
    c = printed["trace"]
    assert abs(c["distance_from_trace_m"] - c["distance_m"]) <= 1e-12
    assert c["max_nose_from_trace_m"] == c["max_nose_height_m"]


def test_sweep_rows_and_best(printed):
    import locust

    s = printed["sweep"]
    assert (s["designs"], s["valid"]) == (5, 5)
    assert s["distance_m"][s["best_design"]] == max(s["distance_m"])
    # design 0 adds nothing: the seed itself, simulated here in this process
    assert s["distance_m"][0] == locust.simulate(locust.robot("seed"), cycles=2).distance_m


def test_tracked_hop_against_the_rendered_truth(printed):
    t = printed["track"]
    assert t["frames"] == t["nose_found"] == 93          # 3.1 s of Large at 30 frames/s, the nose in every one
    assert t["compared"] >= 90
    # the colour centroid against the rendered truth at 480x270: 0.074 mm RMS, 0.23 mm at worst
    assert t["nose_rms_mm"] < 0.15
    assert t["nose_max_mm"] < 0.5


def test_calibrations_recover_the_synthetic_truth(printed):
    fits = printed["calibrate"]
    assert set(fits) == {"compliance.hinge_stiffness_nm_per_rad", "servo.noload_speed_rad_per_s",
                         "contact.foot_friction"}
    for key, f in fits.items():
        assert f["covered"], key
    # the bundled recordings are fixed files: their fits are fixed numbers
    assert fits["contact.foot_friction"]["value"] == pytest.approx(1.7112949, rel=1e-6)
    assert fits["compliance.hinge_stiffness_nm_per_rad"]["value"] == pytest.approx(0.0558676, rel=1e-4)
    assert fits["servo.noload_speed_rad_per_s"]["value"] == pytest.approx(10.2075, rel=1e-3)


def test_same_call_twice(printed):
    assert printed["repeat"] == {"same": True}
