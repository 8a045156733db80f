"""Firmware unit tests: plain functions that run under CPython (pytest) and MicroPython.

``tests/test_device_firmware.py`` runs every module here under the MicroPython unix port
through ``mp_run.py``; pytest runs the ones that need no MicroPython-only API as well.
"""

import sys
from pathlib import Path

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
if str(FIRMWARE) not in sys.path:
    sys.path.insert(0, str(FIRMWARE))

# need time.ticks_us and the machine shim: MicroPython only
collect_ignore = ["test_controller.py", "mp_run.py"]
