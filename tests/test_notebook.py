"""docs/python-api.ipynb: committed executed (figures, tables, an inline video, a first cell
that installs the toolkit in Colab), run again top to bottom in a real Jupyter kernel in a
temporary folder, and its printed figures checked against known truth and against the
figures the committed copy shows."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "docs" / "python-api.ipynb"

nbformat = pytest.importorskip("nbformat", reason="nbformat is a test dependency (pip install -e '.[test]')")
nbclient = pytest.importorskip("nbclient", reason="nbclient is a test dependency (pip install -e '.[test]')")


def tagged_lines(nb) -> dict[str, dict]:
    """The JSON line each tagged cell printed, by tag."""
    out = {}
    for cell in nb.cells:
        for tag in cell.get("metadata", {}).get("tags", []):
            if tag == "colab-install":
                continue
            text = "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream")
            lines = [ln for ln in text.splitlines() if ln.startswith("{")]
            assert len(lines) == 1, (tag, text)
            out[tag] = json.loads(lines[0])
    return out


def test_committed_notebook_shows_its_figures_tables_and_a_video():
    """What GitHub's viewer shows: every code cell run in order, at least three figures (PNG),
    tables (HTML), one inline HTML5 video, and the Colab install cell first."""
    nb = nbformat.read(NOTEBOOK, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert len(code) >= 10
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1))
    assert "google.colab" in code[0].source and "pip" in code[0].source
    data = [o.get("data", {}) for c in code for o in c.outputs]
    assert sum("image/png" in d for d in data) >= 3
    assert sum("<table" in d.get("text/html", "") for d in data) >= 3
    videos = [d["text/html"] for d in data if "<video" in d.get("text/html", "")]
    assert len(videos) == 1 and "data:video/mp4;base64," in videos[0] and len(videos[0]) > 20_000
    assert not [o for c in code for o in c.outputs if o.output_type == "error"]


def test_committed_notebook_is_quiet_and_shows_no_local_path():
    """Its outputs name files by name or by a path relative to the notebook (no /home/..., no
    folder of the machine that ran it) and hold no progress lines on stderr."""
    nb = nbformat.read(NOTEBOOK, as_version=4)
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.get("name") == "stderr"]
    texts = ["".join(o.get("text", "")) + "".join(v for k, v in o.get("data", {}).items() if k.startswith("text/"))
             for o in outputs]
    assert not [t for t in texts if str(ROOT) in t or "/home/" in t or "/tmp/" in t or "/work/" in t]
    assert any("Fit beam: synthetic_beam.csv" in t for t in texts)


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
    assert (folder / "python-api-out" / "large.mp4").is_file()
    return tagged_lines(nb)


def _close(a, b, rel: float) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k], rel) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(_close(x, y, rel) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        return math.isclose(a, b, rel_tol=rel, abs_tol=1e-12)
    return a == b


def test_printed_figures_still_match_the_committed_ones(printed):
    """Rerun, every figure the committed notebook shows is printed again: the simulations,
    sweep and fits to 1e-9; the tracked clip (rendered, then found by colour) to 2 %."""
    committed = tagged_lines(nbformat.read(NOTEBOOK, as_version=4))
    assert committed.keys() == printed.keys()
    for tag, values in printed.items():
        assert _close(values, committed[tag], 0.02 if tag == "track" else 1e-9), (tag, values, committed[tag])


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
