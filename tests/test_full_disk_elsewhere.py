"""A full disk (a real 64 kB tmpfs, tests/conftest.py) under `flash --port sim` and `sweep`:
an error that says the disk is full, the board's firmware files as they
were (no torn config.py), and a sweep folder its rerun resumes."""

from __future__ import annotations

import csv
import hashlib
import os
import subprocess
import sys

from click.testing import CliRunner

from locust.commands import cli

LOCUST = [sys.executable, "-c", "from locust.commands import main; main()"]


def digests(folder):
    return {p.name: hashlib.md5(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


def test_flash_onto_a_full_board_leaves_its_files_as_they_were(small_disk):
    disk, fill = small_disk
    env = dict(os.environ, LOCUST_VIRTUAL_DIR=str(disk / "virtual"))
    first = subprocess.run(LOCUST + ["flash", "--port", "sim"], env=env, capture_output=True, text=True, timeout=120)
    assert first.returncode == 0, first.stderr
    flash = disk / "virtual" / "flash"
    before = digests(flash)
    fill()
    again = subprocess.run(LOCUST + ["flash", "--port", "sim", "--servo", "left.trim_deg=1"], env=env,
                           capture_output=True, text=True, timeout=120)
    assert again.returncode == 2, again.stderr
    assert "cannot write config.py on the board (No space left on device)" in again.stderr, again.stderr
    assert "hint:" in again.stderr and "Traceback" not in again.stderr
    assert digests(flash) == before   # every file whole, as it was; no NAME.part left


def test_a_sweep_the_disk_stopped_at_once_is_resumed_not_refused(small_disk):
    disk, fill = small_disk
    fill()
    args = ["sweep", "--vary", "geometry.leg_m=0.05:0.07:2", "--cycles", "1", "--out", str(disk / "sw")]
    full = CliRunner().invoke(cli, args)
    assert full.exit_code == 2 and "the disk is full" in full.output and "hint:" in full.output, full.output
    (disk / "fill").unlink()
    again = CliRunner().invoke(cli, args)
    assert "not a sweep folder" not in again.output
    with open(disk / "sw" / "results.csv", newline="") as f:
        rows = list(csv.DictReader(f))     # (a refused design's reason spans lines, quoted)
    assert [row["design"] for row in rows] == ["0", "1"]   # both designs, once each
