"""A sweep folder read while a sweep writes it, or after one was killed, is not finished.

The writer here is another process holding a real :class:`locust.io.sweep_store.SweepStore`
(29 SYNTHETIC rows of the 400 designs its sweep.json plans, made-up figures, not simulations),
as ``locust sweep`` holds it between its first row and its last; it says ``ready`` once its
rows are on disk and waits for its stdin, so nothing here waits on a clock.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap

import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.io.sweep_store import SweepStore, read_results
from locust.report.landscape import read_landscape

PLANNED = 400
WRITTEN = 29
REQUEST = {"base": "small", "vary": [{"name": "scale", "start": 0.0, "stop": 0.04, "n": PLANNED}], "cycles": 1}


def row(design: int) -> dict:
    """A SYNTHETIC result row of design ``design``."""
    return {"design": design, "scale": 0.0001 * design, "valid": True, "reason": "", "outcome": "stays_low",
            "flip_share": float("nan"), "distance_m": 0.001 * design, "max_nose_height_m": 0.03,
            "nose_apex_max_m": 0.02, "com_apex_max_m": 0.01, "hops": 1, "grashof": "crank-rocker",
            "transmission_deg": 80.0}


WRITER = textwrap.dedent(f"""
    import sys
    from locust.io.sweep_store import SweepStore
    sys.path.insert(0, {os.path.dirname(__file__)!r})
    from test_sweep_running import REQUEST, PLANNED, WRITTEN, row
    store = SweepStore.open(sys.argv[1], {{"request": REQUEST, "designs": PLANNED}}, ["scale"])
    for i in range(WRITTEN):
        store.append(row(i))
    print("ready", flush=True)
    if sys.stdin.readline().strip() == "finish":
        for i in range(WRITTEN, PLANNED):
            store.append(row(i))
        store.close(True, done=PLANNED, finished=True)
""")


@pytest.fixture()
def writer(tmp_path):
    """A process writing the sweep ``tmp_path / "sweep"``, its rows on disk."""
    folder = tmp_path / "sweep"
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(folder)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "ready"
    yield folder, proc
    if proc.poll() is None:
        proc.kill()
    proc.wait()


def test_a_sweep_being_written_reads_as_running_then_finished(writer):
    folder, proc = writer
    res = read_results(folder)
    assert (len(res.rows), res.planned, res.running, res.finished) == (WRITTEN, PLANNED, True, False)
    proc.stdin.write("finish\n")
    proc.stdin.close()
    assert proc.wait(timeout=60) == 0
    res = read_results(folder)
    assert (len(res.rows), res.planned, res.running, res.finished) == (PLANNED, PLANNED, False, True)


def test_a_killed_sweep_reads_as_unfinished(writer):
    """kill -9: no sweep.json 'finished' written, the lock gone with the process: 29 of 400 rows."""
    folder, proc = writer
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert "finished" not in json.loads((folder / "sweep.json").read_text())
    res = read_results(folder)
    assert (len(res.rows), res.planned, res.running, res.finished) == (WRITTEN, PLANNED, False, False)
    # rerunning the same sweep resumes it: its rows kept, the folder held again
    store = SweepStore.open(folder, {"request": REQUEST, "designs": PLANNED}, ["scale"])
    assert sorted(store.done) == list(range(WRITTEN)) and read_results(folder).running
    store.close(False, finished=False)
    assert not read_results(folder).running and not read_results(folder).finished


def test_report_says_the_sweep_is_still_running(writer, tmp_path):
    """Through ``locust report --sweep``: a warning printed and kept in report.json, naming the
    folder and how many designs of how many it shows."""
    folder, _ = writer
    trial = tmp_path / "small-1"
    trial.mkdir()
    (trial / "run.json").write_text(json.dumps({"status": "complete", "schedule": {
        "cycles": 1, "push_deg": -30, "push_ms": 300, "wait_ms": 1000}, "phases": []}))
    assert not read_landscape(folder).finished
    res = CliRunner().invoke(cli, ["report", "--measured", str(trial), "--sweep", str(folder),
                                   "--out", str(tmp_path / "out")])
    assert res.exit_code == 0, res.output
    said = (f"the sweep in {folder} is still running (read as it stood; report again when it ends): "
            f"the landscape shows only {WRITTEN} of the {PLANNED} designs it plans")
    assert f"warning: {said}" in res.stderr
    doc = json.loads((tmp_path / "out" / "report" / "report.json").read_text())
    assert [w["message"] for w in doc["warnings"] if w["kind"] == "sweep-unfinished"] == [said]
