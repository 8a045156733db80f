"""``run.json`` has one owner: locust.io.run_record writes it and reads it back, equal."""

from __future__ import annotations

import json

import click
import pytest

from locust.commands import hop as hop_command
from locust.errors import DeviceError, TrialError
from locust.firmware import protocol as P
from locust.io import run_record as R
from locust.report.compare import timing_rows, trial_cycles
from locust.trials.measured import load_trial


def _record(status: str = R.COMPLETE) -> R.RunRecord:
    rec = R.RunRecord(schedule=R.HopSchedule(cycles=2, push_deg=-25.5, push_ms=250, wait_ms=900, heartbeat_ms=400),
                      port="/dev/ttyUSB0", status=status, firmware_version="0.1.0", firmware_status=R.COMPLETE,
                      message=None, started_at="2026-01-01T12:00:00+0000")
    for cycle in (1, 2):
        t0 = (cycle - 1) * 1_150_000
        rec.add_phase(R.Phase(cycle, "push", t0, t0 + 37))
        rec.add_phase(R.Phase(cycle, "wait", t0 + 250_000, t0 + 250_412))
    return rec


def test_write_then_read_gives_the_same_record(tmp_path):
    rec = _record()
    path = R.write(rec, tmp_path)
    back = R.read_run_record(path)
    assert back == rec
    assert back.to_dict() == json.loads(path.read_text())


def test_a_partial_record_reads_back_equal_too(tmp_path):
    rec = R.RunRecord(schedule=R.HopSchedule(), port="sim", message="running")
    R.write(rec, tmp_path)
    assert R.read_run_record(tmp_path / R.RECORD_NAME) == rec
    rec.add_phase(R.Phase(1, "push", 0, 12))
    rec.status, rec.message = R.INCOMPLETE, "interrupted"
    R.write(rec, tmp_path)
    assert R.read_run_record(tmp_path / R.RECORD_NAME) == rec


def test_phase_times_stay_in_microseconds_and_convert_in_one_place():
    p = R.Phase(1, "wait", 300_000, 300_040)
    assert (p.commanded_ms, p.measured_ms, p.error_ms) == (300.0, 300.04, R.us_to_ms(40))
    d = p.to_dict()
    assert (d["commanded_us"], d["measured_us"], d["error_ms"]) == (300_000, 300_040, 0.04)


def test_derived_fields_are_not_read(tmp_path):
    doc = _record().to_dict()
    doc["jitter"] = {"n": 99}
    doc["phases_expected"] = 99
    doc["phases"][0]["commanded_ms"] = 12345.0       # the ms are for people; the us are the data
    (tmp_path / R.RECORD_NAME).write_text(json.dumps(doc))
    back = R.read_run_record(tmp_path / R.RECORD_NAME)
    assert back == _record()
    assert back.to_dict()["phases_expected"] == 4 and back.to_dict()["jitter"]["n"] == 4


@pytest.mark.parametrize("doc, message", [
    ("{not json", "not a readable JSON run record"),
    ({"status": "complete"}, "not a run record"),
    ({"schedule": {"cycles": 2, "push_ms": 300, "wait_ms": 1000}, "phases": []}, "schedule.push_deg"),
    ({"schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300.5, "wait_ms": 1000}, "phases": []}, "whole number"),
    ({"schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
      "phases": [{"cycle": 1, "phase": "push", "commanded_us": 0}]}, "phase 1"),
])
def test_bad_records_are_named(tmp_path, doc, message):
    path = tmp_path / R.RECORD_NAME
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    with pytest.raises(DeviceError, match=message) as info:
        R.read_run_record(path)
    assert str(path) in info.value.message and info.value.hint
    with pytest.raises(DeviceError, match="no such file"):
        R.read_run_record(tmp_path / "elsewhere.json")


def test_a_minimal_record_takes_the_protocol_defaults(tmp_path):
    path = tmp_path / R.RECORD_NAME
    path.write_text(json.dumps({"schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
                                "phases": []}))
    rec = R.read_run_record(path)
    assert rec.schedule.heartbeat_ms == P.COMMANDS["hop"]["heartbeat_ms"][3]
    assert (rec.status, rec.firmware_version, rec.phases) == (R.INCOMPLETE, None, [])


def test_the_report_reads_run_json_through_the_record(tmp_path):
    rec = _record()
    R.write(rec, tmp_path / "small-1")
    trial = load_trial(tmp_path / "small-1", "small")
    assert trial.record == rec and trial.run_path == tmp_path / "small-1" / R.RECORD_NAME
    assert trial.record.schedule.push_ms == 250 and trial.record.phases[1].measured_ms == 250.412
    assert trial_cycles(trial, 6) == 2
    (row,) = timing_rows("small", [trial])
    assert (row.status, row.phases, row.phases_expected, row.firmware) == ("complete", 4, 4, "0.1.0")
    assert row.jitter == R.jitter(rec.phases)
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / R.RECORD_NAME).write_text("[]")
    with pytest.raises(TrialError, match="not a run record"):
        load_trial(tmp_path / "bad", "small")


def test_schedule_limits_and_defaults_are_the_protocols():
    hop = P.COMMANDS["hop"]
    sched = R.HopSchedule()
    for name in ("cycles", "push_deg", "push_ms", "wait_ms", "heartbeat_ms"):
        assert getattr(sched, name) == hop[name][3]
        assert R.hop_range(name) == (hop[name][1], hop[name][2])
    options = {o.name: o for o in hop_command.hop.params}
    for name in ("cycles", "push_ms", "wait_ms", "heartbeat_ms"):
        kind = options[name].type
        assert isinstance(kind, click.IntRange) and (kind.min, kind.max) == R.hop_range(name)
    assert options["heartbeat_ms"].default == hop["heartbeat_ms"][3]
