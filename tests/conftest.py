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


@pytest.fixture(scope="session")
def wheel_venv(tmp_path_factory):
    """This checkout as a user installs it (tests/installed.py): its wheel alone, with
    ipykernel, in a fresh virtual environment outside the checkout; built once a session
    (about 35 s on a quiet 2-core machine: the wheel 5 s, the environment 30 s)."""
    import installed

    folder = tmp_path_factory.mktemp("wheel")
    assert ROOT not in folder.resolve().parents, folder
    wheel = installed.build_wheel(folder / "build")
    return installed.install(wheel, folder / "venv", "ipykernel")     # 0.9 GB, left to pytest's tmp_path cleanup


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    """An environment whose virtual robot (``--port sim``) has the firmware flashed: one per
    test module, in its own folder."""
    import subprocess
    import sys

    env = dict(os.environ, LOCUST_VIRTUAL_DIR=str(tmp_path_factory.mktemp("virtual")))
    proc = subprocess.run([sys.executable, "-m", "locust.commands", "flash", "--port", "sim"],
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


from host_probe import STALL_LIMIT_US, STALL_PROBE_S, spin_probe_us  # noqa: E402


@pytest.fixture(scope="session")
def host_stall_us() -> float:
    """The longest this machine stopped a spinning process over STALL_PROBE_S (microseconds)."""
    return spin_probe_us()


@pytest.fixture()
def board_timing(host_stall_us):
    """``board_timing(errors_us)`` asserts every phase error within the board's 2 ms, or skips
    (after the test's other checks) on a host measured to stall longer than STALL_LIMIT_US, in
    the session's probe or, where the bound is broken, in a second probe then."""
    def check(errors_us, bound_us: float = 2000.0, what: str = "phase start error") -> None:
        errors_us = list(errors_us)
        if host_stall_us > STALL_LIMIT_US:
            pytest.skip(f"this host stopped a spinning process for {host_stall_us / 1000:.2f} ms (over "
                        f"{STALL_LIMIT_US / 1000:g} ms in a {STALL_PROBE_S:g} s probe): a {bound_us / 1000:g} ms "
                        f"timing bound cannot be tested here (worst {what} {max(map(abs, errors_us)) / 1000:.2f} ms)")
        worst = max(map(abs, errors_us))
        if worst > bound_us:
            # the hypervisor's stalls come in spells: one may start after the session's probe.
            # Probed again now: a host stalling over STALL_LIMIT_US cannot judge the bound; one
            # that does not, can, and the firmware was late.
            again_us = spin_probe_us()
            if again_us > STALL_LIMIT_US:
                pytest.skip(f"worst {what} {worst / 1000:.2f} ms over {bound_us / 1000:g} ms, and the host, probed "
                            f"again, stopped a spinning process for {again_us / 1000:.2f} ms (over "
                            f"{STALL_LIMIT_US / 1000:g} ms): the bound cannot be tested here")
        for e in errors_us:
            assert abs(e) <= bound_us, (what, e, errors_us)
    return check
