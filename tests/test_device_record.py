"""Run-record arithmetic and port classification (pure functions, known values)."""

from __future__ import annotations

import json

import pytest

from locust.device import ports as PT
from locust.errors import DeviceError
from locust.io import run_record


def test_jitter_known_values():
    phases = [run_record.Phase(1, "push", 0, 500), run_record.Phase(1, "wait", 300_000, 298_500),
              run_record.Phase(2, "push", 1_300_000, 1_301_000)]
    j = run_record.jitter(phases)
    # errors 0.5, -1.5, 1.0 ms: mean 0, population sd sqrt((0.25+2.25+1)/3)
    assert j.mean_ms == pytest.approx(0.0, abs=1e-9)
    assert j.std_ms == pytest.approx((3.5 / 3) ** 0.5, abs=1e-4)
    assert (j.max_abs_ms, j.max_late_ms, j.max_early_ms) == (1.5, 1.0, 1.5)
    assert run_record.jitter([]) is None


def test_record_fields_and_never_overwrite(tmp_path):
    rec = run_record.RunRecord(schedule=run_record.HopSchedule(cycles=1), port="sim", firmware_version="0.1.0")
    rec.add_phase(run_record.Phase(1, "wait", 300_000, 300_040))
    rec.add_phase(run_record.Phase(1, "push", 0, 35))
    rec.add_phase(run_record.Phase(1, "push", 0, 99))  # a duplicate (event and report) counts once
    d = rec.to_dict()
    assert [p["phase"] for p in d["phases"]] == ["push", "wait"]
    assert d["phases"][1]["commanded_ms"] == 300.0 and d["phases"][1]["measured_ms"] == 300.04
    directory = run_record.run_dir(tmp_path / "run")
    run_record.write(rec, directory)
    assert json.loads((directory / "run.json").read_text())["schedule"]["push_ms"] == 300
    with pytest.raises(DeviceError, match="never overwritten"):
        run_record.run_dir(tmp_path / "run")
    a, b = run_record.run_dir(None, tmp_path / "runs"), run_record.run_dir(None, tmp_path / "runs")
    assert a != b


def test_esp32_hints_and_autodetect():
    assert "Espressif" in PT.esp32_hint(0x303A, 0x1001)
    assert "CP210x" in PT.esp32_hint(0x10C4, 0xEA60)
    assert PT.esp32_hint(0x046D, 0xC52B) is None and PT.esp32_hint(None, None) is None
    esp = PT.PortInfo("/dev/ttyUSB0", 0x10C4, 0xEA60, "0001", "CP2102", PT.esp32_hint(0x10C4, 0xEA60))
    mouse = PT.PortInfo("/dev/ttyACM0", 0x046D, 0xC52B, None, "receiver", None)
    assert esp.vid_pid == "10C4:EA60"
    assert PT.autodetect([mouse, esp]) == "/dev/ttyUSB0"
    with pytest.raises(DeviceError, match="no ESP32"):
        PT.autodetect([mouse])
    with pytest.raises(DeviceError, match="several"):
        PT.autodetect([esp, PT.PortInfo("/dev/ttyUSB1", 0x1A86, 0x7523, None, "CH340", "CH340")])
