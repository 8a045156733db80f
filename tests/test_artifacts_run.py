"""``run.json`` has one owner: locust.io.run_record writes it and reads it back, equal."""

from __future__ import annotations

import html
import json

import click
import pytest

from locust.commands import hop as hop_command
from locust.errors import DeviceError, TrialError
from locust.firmware import protocol
from locust.io import run_record
from locust.report.compare import timing_rows, trial_cycles
from locust.report.page import timing_table
from locust.trials.measured import load_trial


def _record(status: str = run_record.COMPLETE) -> run_record.RunRecord:
    schedule = run_record.HopSchedule(cycles=2, push_deg=-25.5, push_ms=250, wait_ms=900, heartbeat_ms=400)
    rec = run_record.RunRecord(schedule=schedule, port="/dev/ttyUSB0", status=status, firmware_version="0.1.0",
                               firmware_status=run_record.COMPLETE, message=None, started_at="2026-01-01T12:00:00+0000")
    for cycle in (1, 2):
        t0 = (cycle - 1) * 1_150_000
        rec.add_phase(run_record.Phase(cycle, "push", t0, t0 + 37))
        rec.add_phase(run_record.Phase(cycle, "wait", t0 + 250_000, t0 + 250_412))
    return rec


def test_write_then_read_gives_the_same_record(tmp_path):
    rec = _record()
    path = run_record.write(rec, tmp_path)
    back = run_record.read_run_record(path)
    assert back == rec
    assert back.to_dict() == json.loads(path.read_text())


def test_a_partial_record_reads_back_equal_too(tmp_path):
    rec = run_record.RunRecord(schedule=run_record.HopSchedule(), port="sim", message="running")
    run_record.write(rec, tmp_path)
    assert run_record.read_run_record(tmp_path / run_record.RECORD_NAME) == rec
    rec.add_phase(run_record.Phase(1, "push", 0, 12))
    rec.status, rec.message = run_record.INCOMPLETE, "interrupted"
    run_record.write(rec, tmp_path)
    assert run_record.read_run_record(tmp_path / run_record.RECORD_NAME) == rec


def test_a_virtual_robots_host_stalls_read_back_equal(tmp_path):
    """Each phase's host stall (us) is data; the longest (s) and the note follow from it."""
    rec = _record()
    rec.phases[2] = run_record.Phase(2, "push", 1_150_000, 1_238_500)    # 88.5 ms late
    rec.set_host_stalls([0, 12, 88_400, 3])
    path = run_record.write(rec, tmp_path)
    doc = json.loads(path.read_text())
    back = run_record.read_run_record(path)
    assert back == rec and back.to_dict() == doc
    assert [p["host_stall_us"] for p in doc["phases"]] == [0, 12, 88_400, 3]
    assert doc["phases"][2]["host_stall_ms"] == 88.4
    assert doc["host_stall_max_s"] == 0.0884
    assert doc["timing_note"] == ("timing not representative: the host stalled 88.4 ms while cycle 2's push "
                                  "was due (it started 88.5 ms late)")
    doc["host_stall_max_s"], doc["timing_note"] = 1.0, "derived"     # derived: not read
    path.write_text(json.dumps(doc))
    assert run_record.read_run_record(path) == rec


def test_a_real_boards_record_has_no_host_stall(tmp_path):
    doc = run_record.write(_record(), tmp_path).read_text()
    assert '"host_stall_max_s": null' in doc and '"timing_note": null' in doc
    assert all(p.host_stall_us is None for p in run_record.read_run_record(tmp_path / run_record.RECORD_NAME).phases)


@pytest.mark.parametrize("error_us, stall_us, note", [
    (88_500, 88_400, "the host stalled 88.4 ms while cycle 1's push was due (it started 88.5 ms late)"),
    (3_000, 1_500, "the host stalled 1.5 ms"),     # 1.5 ms of 3 late: the firmware's own 1.5 is in the bound
    (1_500, 1_500, None),                          # within the bound, whoever caused it
    (50_000, 500, None),                           # 49.5 ms the firmware's own: its timing, shown as such
    (2_100, 2_050, "the host stalled 2.0 ms"),     # over the bound
    (4_100, 2_000, None),                          # the firmware's own 2.1 ms is over the bound
])
def test_the_timing_note_says_when_the_lateness_is_the_hosts(error_us, stall_us, note):
    phases = [run_record.Phase(1, "push", 0, error_us, stall_us), run_record.Phase(1, "wait", 300_000, 300_050, 0)]
    got = run_record.timing_note(phases)
    if note is None:
        assert got is None
    else:
        assert got.startswith("timing not representative: " + note), got


def test_phase_times_stay_in_microseconds_and_convert_in_one_place():
    p = run_record.Phase(1, "wait", 300_000, 300_040)
    assert (p.commanded_ms, p.measured_ms, p.error_ms) == (300.0, 300.04, run_record.us_to_ms(40))
    d = p.to_dict()
    assert (d["commanded_us"], d["measured_us"], d["error_ms"]) == (300_000, 300_040, 0.04)


def test_derived_fields_are_not_read(tmp_path):
    doc = _record().to_dict()
    doc["jitter"] = {"n": 99}
    doc["phases_expected"] = 99
    doc["phases"][0]["commanded_ms"] = 12345.0       # the ms are for people; the us are the data
    (tmp_path / run_record.RECORD_NAME).write_text(json.dumps(doc))
    back = run_record.read_run_record(tmp_path / run_record.RECORD_NAME)
    assert back == _record()
    assert back.to_dict()["phases_expected"] == 4 and back.to_dict()["jitter"]["n"] == 4


@pytest.mark.parametrize("doc, message", [
    ("{not json", "not a readable JSON run record"),
    ({"status": "complete"}, "not a run record"),
    ({"schedule": {"cycles": 2, "push_ms": 300, "wait_ms": 1000}, "phases": []}, "schedule.push_deg"),
    ({"schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300.5, "wait_ms": 1000}, "phases": []}, "whole number"),
    ({"schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
      "phases": [{"cycle": 1, "phase": "push", "commanded_us": 0}]}, "phase 1"),
    ({"schedule": {"cycles": 1, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
      "phases": [{"cycle": 1, "phase": "push", "commanded_us": 0, "measured_us": 9, "host_stall_us": -5}]},
     "phase 1's host_stall_us"),
])
def test_bad_records_are_named(tmp_path, doc, message):
    path = tmp_path / run_record.RECORD_NAME
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    with pytest.raises(DeviceError, match=message) as info:
        run_record.read_run_record(path)
    assert str(path) in info.value.message and info.value.hint
    with pytest.raises(DeviceError, match="no such file"):
        run_record.read_run_record(tmp_path / "elsewhere.json")


def test_a_minimal_record_takes_the_protocol_defaults(tmp_path):
    path = tmp_path / run_record.RECORD_NAME
    path.write_text(json.dumps({"schedule": {"cycles": 2, "push_deg": -30, "push_ms": 300, "wait_ms": 1000},
                                "phases": []}))
    rec = run_record.read_run_record(path)
    assert rec.schedule.heartbeat_ms == protocol.COMMANDS["hop"]["heartbeat_ms"][3]
    assert (rec.status, rec.firmware_version, rec.phases) == (run_record.INCOMPLETE, None, [])


def test_the_report_reads_run_json_through_the_record(tmp_path):
    rec = _record()
    run_record.write(rec, tmp_path / "small-1")
    trial = load_trial(tmp_path / "small-1", "small")
    assert trial.record == rec and trial.run_path == tmp_path / "small-1" / run_record.RECORD_NAME
    assert trial.record.schedule.push_ms == 250 and trial.record.phases[1].measured_ms == 250.412
    assert trial_cycles(trial, 6) == 2
    (row,) = timing_rows("small", [trial])
    assert (row.status, row.phases, row.phases_expected, row.firmware) == ("complete", 4, 4, "0.1.0")
    assert row.jitter == run_record.jitter(rec.phases) and row.timing_note is None
    rec.set_host_stalls([0, 0, 25_000, 0])
    run_record.write(rec, tmp_path / "small-2")
    (row,) = timing_rows("small", [load_trial(tmp_path / "small-2", "small")])
    assert row.timing_note == run_record.timing_note(rec.phases) and "stalled 25.0 ms" in row.timing_note
    status = f'data-config="small" data-field="status:small-2">complete; {html.escape(row.timing_note)}</td>'
    assert status in timing_table([row], {"small": "Small"})     # where the report shows the firmware's timing
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / run_record.RECORD_NAME).write_text("[]")
    with pytest.raises(TrialError, match="not a run record"):
        load_trial(tmp_path / "bad", "small")


def test_schedule_limits_and_defaults_are_the_protocols():
    hop = protocol.COMMANDS["hop"]
    sched = run_record.HopSchedule()
    for name in ("cycles", "push_deg", "push_ms", "wait_ms", "heartbeat_ms"):
        assert getattr(sched, name) == hop[name][3]
        assert run_record.hop_range(name) == (hop[name][1], hop[name][2])
    options = {o.name: o for o in hop_command.hop.params}
    for name in ("cycles", "push_ms", "wait_ms", "heartbeat_ms"):
        kind = options[name].type
        assert isinstance(kind, click.IntRange) and (kind.min, kind.max) == run_record.hop_range(name)
    assert options["heartbeat_ms"].default == hop["heartbeat_ms"][3]
