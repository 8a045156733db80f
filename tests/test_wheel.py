"""The toolkit as `pip install` gives it (tests/installed.py: the wheel of this checkout alone in
a fresh virtual environment outside it): the wheel carries every bundled recording and the
firmware, and the installed command and API find them from an empty folder. The notebook's
run in that environment is tests/test_notebook.py's ``wheel`` run; `locust demo` there is
slow (about 2 minutes)."""

from __future__ import annotations

import json
import subprocess
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RECORDINGS_HOME = ROOT / "calibration" / "recordings"     # their home in a checkout (the docs' paths)


def members(wheel: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(wheel) as z:
        return {name: z.read(name) for name in z.namelist()}


def test_the_wheel_carries_every_bundled_recording_and_the_firmware(wheel_venv):
    """Every file in calibration/recordings is in the wheel at locust/recordings/, byte for
    byte, and nothing else is there; so is every firmware file the board is flashed with."""
    files = members(wheel_venv.wheel)
    home = {p.name: p.read_bytes() for p in RECORDINGS_HOME.iterdir() if p.is_file() and not p.name.startswith(".")}
    assert len(home) >= 7
    shipped = {name.removeprefix("locust/recordings/"): data for name, data in files.items()
               if name.startswith("locust/recordings/")}
    assert shipped == home
    firmware = {p.name: p.read_bytes() for p in (ROOT / "firmware").iterdir() if p.suffix in (".py", ".json")}
    assert firmware and all(files.get(f"locust/firmware/{name}") == data for name, data in firmware.items())


def run_installed(venv, args: list, cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([str(a) for a in args], cwd=cwd, env=venv.env(), capture_output=True, text=True,
                          timeout=timeout, check=False)


def test_installed_command_fits_a_bundled_recording_from_an_empty_folder(wheel_venv, tmp_path):
    """From an empty folder outside the checkout, the installed package finds its recordings
    (in its own site-packages) and the installed `locust calibrate ramp` fits one: the same
    friction as the notebook's fit of that fixed file (tests/test_notebook.py)."""
    folder = tmp_path / "empty"
    folder.mkdir()
    where = run_installed(wheel_venv, [wheel_venv.python, "-c", "import locust; "
                                       "print(locust.bundled_recording('synthetic_ramp.csv'))"], folder)
    assert where.returncode == 0, where.stderr
    ramp = Path(where.stdout.strip())
    assert ramp.parent == wheel_venv.site_packages / "locust" / "recordings"
    assert ramp.read_bytes() == (RECORDINGS_HOME / "synthetic_ramp.csv").read_bytes()
    fit = run_installed(wheel_venv, [wheel_venv.bin / "locust", "calibrate", "ramp", ramp, "--json", "--no-plot"],
                        folder)
    assert fit.returncode == 0, fit.stderr
    assert json.loads(fit.stdout)["contact.foot_friction"]["value"] == pytest.approx(1.7112949, rel=1e-6)
    assert list(folder.iterdir()) == []       # --no-plot: nothing written where it ran


@pytest.mark.slow
def test_installed_demo_runs_from_an_empty_folder(wheel_venv, tmp_path):
    """`locust demo --out demo-out` of the installed wheel, from an empty folder outside the
    checkout: every one of its nine stages runs, its bench fits the SYNTHETIC recordings of the
    virtual robot (their names in the fitted values' sources), and its virtual robot is the
    draw of the robot as built that the checkout's own code makes."""
    from locust.demo.story import DemoOptions, stage_titles
    from locust.demo.virtual_robot import hidden_values, virtual_robot

    folder = tmp_path / "empty"
    folder.mkdir()
    proc = run_installed(wheel_venv, [wheel_venv.bin / "locust", "demo", "--out", "demo-out"], folder, timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    titles = stage_titles(DemoOptions())
    assert len(titles) == 9
    for n, title in enumerate(titles, 1):
        assert f"[{n}/9] {title}" in proc.stderr, title
    run = folder / "demo-out" / "run"
    report = Path(proc.stdout.strip().splitlines()[-1].removeprefix("report: "))
    assert (folder / report).resolve().is_file() and (folder / report).resolve().is_relative_to(run.resolve())
    bench = (run / "calibration" / "robot-bench.toml").read_text()
    for name in ("hinge_swing.csv", "servo_step.csv", "ramp.csv"):
        assert f"fit:{name}" in bench, name
    truth = json.loads((run / "virtual" / "truth.json").read_text())["values"]
    assert truth == hidden_values(virtual_robot())
