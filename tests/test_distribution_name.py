"""The distribution is locust-hopper: "locust" on PyPI is an unrelated load-testing tool with the
same package and command name. An environment holding that tool is refused, loudly, by the
install (scripts/check_shadowing.py, run by `make install`) and by the command itself."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from locust import commands as C

ROOT = Path(__file__).resolve().parents[1]


def _fake_distribution(site: Path, summary: str, version: str = "2.32.0") -> Path:
    """A SYNTHETIC dist-info for a distribution named "locust" (metadata only, no code)."""
    info = site / f"locust-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: locust\nVersion: {version}\nSummary: {summary}\n")
    return site


def test_the_distribution_is_not_named_locust():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert meta["name"] == "locust-hopper"
    assert meta["scripts"]["locust"] == "locust.commands:main"        # the command stays `locust`
    assert meta["description"].startswith(C.OUR_SUMMARY)


def test_the_load_testing_tool_beside_it_is_refused(tmp_path, monkeypatch, capsys):
    site = _fake_distribution(tmp_path / "site", "Developer-friendly load testing framework")
    monkeypatch.syspath_prepend(str(site))
    assert C.shadowing_install() == "2.32.0"
    with pytest.raises(SystemExit) as exc:
        C.main()
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "error: the load-testing tool 'locust' 2.32.0 is installed" in err and "hint:" in err
    proc = subprocess.run([sys.executable, str(ROOT / "scripts" / "check_shadowing.py"), "the test venv"],
                          capture_output=True, text=True, check=False, env={"PYTHONPATH": str(site)})
    assert proc.returncode == 1 and "would shadow it" in proc.stderr


def test_an_old_install_of_this_toolkit_under_the_old_name_is_not_the_load_tester(tmp_path, monkeypatch):
    site = _fake_distribution(tmp_path / "site", C.OUR_SUMMARY + ": flash, hop, ...", version="0.0.9")
    monkeypatch.syspath_prepend(str(site))
    assert C.shadowing_install() is None
