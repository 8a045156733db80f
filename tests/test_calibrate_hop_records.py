"""The hop fit takes only runs it can simulate truly: a run that did not finish its schedule,
one the board ran on its default config, and one whose measured phase starts contradict the
commanded order are refused before any simulation, naming the run and what to do.

Each run folder holds a ``run.json`` written by the run record's own writer (two cycles of the
protocol's default schedule, as ``locust hop`` records them) and a SYNTHETIC nose track written
by the tracks CSV writer: the nose stands 0.5 s, then rises 20 mm and back within each push.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from locust.calibrate.hopruns import load_run
from locust.commands import cli
from locust.errors import CalibrationError
from locust.io import run_record
from locust.io.tracks_csv import TracksCsv, write_tracks_csv
from locust.params import preset

SCHEDULE = run_record.HopSchedule(cycles=2)
ONSET_S = 0.5            # the nose's first motion on the camera's clock
FPS = 60.0


def _phases(late_push_us: int = 0) -> list[run_record.Phase]:
    """The schedule's phases as a board reports them (45 µs late), cycle 1's push ``late_push_us`` later."""
    period_us = 1000 * (SCHEDULE.push_ms + SCHEDULE.wait_ms)
    out = []
    for k in range(SCHEDULE.cycles):
        for name, at_us in (("push", k * period_us), ("wait", k * period_us + 1000 * SCHEDULE.push_ms)):
            late = late_push_us if (k, name) == (0, "push") else 0
            out.append(run_record.Phase(k + 1, name, at_us, at_us + 45 + late))
    return out


def run_folder(folder, status=run_record.COMPLETE, message=None, phases=None):
    """A run folder: its run.json (``status``, ``phases``) and a SYNTHETIC nose track."""
    folder.mkdir(parents=True)
    rec = run_record.RunRecord(schedule=SCHEDULE, port="/dev/ttyUSB0", status=status, message=message,
                               firmware_version="0.1.0",
                               firmware_status="complete" if status == run_record.COMPLETE else None,
                               robot=run_record.RobotSource(preset="small", leg_set="small"))
    for p in _phases() if phases is None else phases:
        rec.add_phase(p)
    run_record.write(rec, folder)
    t = np.arange(0.0, ONSET_S + SCHEDULE.duration_s + 0.5, 1 / FPS)
    period_s = (SCHEDULE.push_ms + SCHEDULE.wait_ms) / 1000
    into = t - ONSET_S
    lift = np.where((into >= 0) & (into % period_s < SCHEDULE.push_ms / 1000),
                    0.02 * np.sin(np.pi * (into % period_s) / (SCHEDULE.push_ms / 1000)), 0.0)
    n = t.size
    nose = {"px": np.full(n, 300.0), "py": 400.0 - 5000 * lift, "x_m": np.full(n, 0.046), "y_m": 0.02 + lift,
            "ok": np.ones(n, dtype=bool)}
    write_tracks_csv(folder / "hop.tracks.csv",
                     TracksCsv(frame=np.arange(n), t_s=t, **{kind: {"nose": c} for kind, c in nose.items()}))
    return folder


def test_a_complete_run_loads_on_its_measured_phase_times(tmp_path):
    """The control: the same folder with a complete record is a run of the fit, each phase
    starting at its measured time from the first push (45 µs late each, so 0 from the first)."""
    run = load_run(run_folder(tmp_path / "small-1"), "small", preset("small"))
    assert run.phase_s == pytest.approx([0.0, 0.3, 1.3, 1.6], abs=1e-9)
    assert run.pushing.tolist() == [True, False, True, False]
    assert run.onset_s == pytest.approx(ONSET_S, abs=1 / FPS)


@pytest.mark.parametrize("status, message, phases, said", [
    (run_record.INCOMPLETE, "lost the serial port", _phases()[:3],
     "the run is incomplete (lost the serial port), 3 of 4"),
    (run_record.ERROR, "bad_args: push_ms", [], "the run is error (bad_args: push_ms), 0 of 4"),
    (run_record.DEFAULT_CONFIG,
     "the board ran on its default config, not its config.json: config.json is not valid JSON",
     None, "the board ran this hop on its default config"),
])
def test_a_run_that_did_not_run_its_schedule_is_refused(tmp_path, status, message, phases, said):
    folder = run_folder(tmp_path / "small-1", status, message, phases)
    with pytest.raises(CalibrationError) as exc:
        load_run(folder, "small", preset("small"))
    assert exc.value.message.startswith(f"{folder / 'run.json'}: {said}")
    assert f"leave {folder} out of the fit" in exc.value.hint


def test_a_push_measured_after_its_wait_is_refused(tmp_path):
    """Cycle 1's push reported 305 ms into the hop, after its wait's 300 ms: no board ran that."""
    folder = run_folder(tmp_path / "small-1", phases=_phases(late_push_us=305_000))
    doc = json.loads((folder / "run.json").read_text())
    assert [p["phase"] for p in doc["phases"]][:2] == ["push", "wait"]      # the record keeps commanded order
    with pytest.raises(CalibrationError) as exc:
        load_run(folder, "small", preset("small"))
    assert exc.value.message == (f"{folder / 'run.json'}: cycle 1's wait is measured at 300.045 ms, not after "
                                 "cycle 1's push (commanded before it) at 305.045 ms: the record's phase times "
                                 "are not a hop's")
    assert run_record.read_run_record(folder / "run.json").order_problem() is not None
    assert run_record.read_run_record(run_folder(tmp_path / "sound") / "run.json").order_problem() is None


def test_calibrate_hop_refuses_an_incomplete_run_among_sound_ones(tmp_path):
    """Through the user's door: one bad run among good ones stops the fit before it starts,
    exit 2, the error naming that run."""
    good = run_folder(tmp_path / "small-1")
    bad = run_folder(tmp_path / "small-2", run_record.INCOMPLETE, "lost the serial port", _phases()[:2])
    res = CliRunner().invoke(cli, ["calibrate", "hop", f"small={good}", f"small={bad}", "--no-plot"])
    assert res.exit_code == 2, res.output
    assert f"error: {bad / 'run.json'}: the run is incomplete (lost the serial port), 2 of 4 phases" in res.stderr
    assert f"hint: rerun the hop, or leave {bad} out of the fit" in res.stderr
    assert "Traceback" not in res.output
