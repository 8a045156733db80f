"""The firmware compiles with mpy-cross, and its unit tests pass under the MicroPython unix port."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from locust.device.flash import firmware_files, mpy_version
from locust.device.virtual import SHIM_DIR, _raise_priority, micropython_executable

ROOT = Path(__file__).resolve().parents[1]
UNIT_DIR = ROOT / "tests" / "firmware"
MODULES = ["test_protocol", "test_config", "test_schedule", "test_controller"]


@pytest.mark.parametrize("src", firmware_files(), ids=lambda p: p.name)
def test_compiles_with_mpy_cross(src, tmp_path):
    out = tmp_path / (src.stem + ".mpy")
    proc = subprocess.run([sys.executable, "-m", "mpy_cross", "-o", str(out), str(src)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert mpy_version(out.read_bytes()[:4]) == 6  # the format of MicroPython >= 1.22


def test_unit_tests_pass_under_micropython():
    expected = sum(len(re.findall(r"^def test_", (UNIT_DIR / f"{m}.py").read_text(), re.M)) for m in MODULES)
    env = dict(os.environ, MICROPYPATH=f"{ROOT / 'firmware'}:{UNIT_DIR}:{SHIM_DIR}")
    proc = subprocess.run([micropython_executable(), str(UNIT_DIR / "mp_run.py"), *MODULES],
                          capture_output=True, text=True, timeout=120, env=env, cwd=UNIT_DIR,
                          preexec_fn=_raise_priority)
    assert "MicroPython" in subprocess.run([micropython_executable(), "-c", "import sys; print(sys.version)"],
                                           capture_output=True, text=True).stdout
    last = proc.stdout.strip().splitlines()[-1]
    assert last == f"RESULT {expected} 0", proc.stdout[-3000:] + proc.stderr[-2000:]


def test_firmware_fallback_servo_config_is_the_robot_parameters():
    """The board's built-in config (used until config.json exists) keeps a copy of the pulse
    range and travel, as it cannot import the host; the host writes them from params.Servo."""
    from locust.device.flash import servo_config
    from locust.firmware import config as fw_config
    from locust.params import Servo

    keys = ("pulse_min_us", "pulse_max_us", "range_deg", "travel_deg")
    written = servo_config(Servo())
    assert fw_config.problems(written) == []
    for name in fw_config.SERVOS:
        assert {k: fw_config.default()[name][k] for k in keys} == {k: getattr(Servo(), k) for k in keys}
        assert {k: written[name][k] for k in keys} == {k: getattr(Servo(), k) for k in keys}
    narrow = servo_config(Servo(pulse_min_us=600.0, pulse_max_us=2400.0, travel_deg=40.0))
    assert narrow["right"]["pulse_min_us"] == 600.0 and narrow["left"]["travel_deg"] == 40.0
