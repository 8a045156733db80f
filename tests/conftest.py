"""Shared test fixtures: paths to the project and to the public reference data."""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = ROOT.parent / "shared" / "data"

os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """``../shared/data``: real inputs from public projects (never copied into the repo)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"reference data not found at {SHARED_DATA} (clone with ../shared beside it)")
    return SHARED_DATA


@pytest.fixture(scope="session")
def tracker_example(shared_data, tmp_path_factory):
    """``tracker_example("BallToss.trz")``: one of Tracker's example zips, unpacked once a session
    into a temporary folder (returned); the files in it are not to be changed."""
    folders: dict[str, Path] = {}

    def unpacked(name: str) -> Path:
        if name not in folders:
            folders[name] = tmp_path_factory.mktemp(Path(name).stem)
            with zipfile.ZipFile(shared_data / "tracker" / name) as z:
                z.extractall(folders[name])
        return folders[name]

    return unpacked


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    """An environment whose virtual robot (``--port sim``) has the firmware flashed: one per
    test module, in its own folder."""
    import subprocess
    import sys

    env = dict(os.environ, LOCUST_VIRTUAL_DIR=str(tmp_path_factory.mktemp("virtual")))
    proc = subprocess.run([sys.executable, "-m", "locust.cli", "flash", "--port", "sim"],
                          capture_output=True, text=True, env=env, timeout=90, check=False)
    assert proc.returncode == 0, proc.stderr
    assert "files verified by SHA-256" in proc.stdout
    return env


@pytest.fixture()
def small_disk(tmp_path):
    """A real 64 kB disk (a tmpfs: mounting it needs root; skipped, saying so, where it is not
    allowed), and a function that fills it to ``free`` bytes left."""
    import subprocess

    disk = tmp_path / "disk"
    disk.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(disk)], capture_output=True)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here ({done.stderr.decode().strip()})")

    def fill(free: int = 0) -> None:
        st = os.statvfs(disk)
        (disk / "fill").write_bytes(b"x" * max(0, st.f_bavail * st.f_frsize - free))

    yield disk, fill
    subprocess.run(["umount", "-l", str(disk)], check=False)   # (lazy: a file still open does not keep it)
