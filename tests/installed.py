"""The toolkit as a user installs it: a wheel built from this checkout, installed alone (with
the dependencies pip resolves from the index, and ipykernel) in a fresh virtual environment
outside the checkout, run with nothing of the checkout on its path.

The wheel is built from a copy of the files it is made of (pyproject.toml, README.md, host/ and
what its links point to), so the build leaves nothing in the checkout and no stale build/
folder there can slip a file into it. pip's cache is its usual one; byte-compiling on install
is left out (about 40 s of a minute's install here), as Python compiles what it imports.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# what the wheel is built from: the package (host/, whose links point into firmware/ and calibration/)
SOURCES = ("pyproject.toml", "README.md", "host", "firmware", "calibration/recordings")
IGNORE = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info", "build", ".*")
KERNEL = "locust-wheel"
# what would put the checkout, or another environment, on the installed toolkit's path
LEAKS = ("PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP", "VIRTUAL_ENV", "PYTHONUSERBASE")


@dataclass(frozen=True)
class Venv:
    """A virtual environment holding the wheel: its interpreter, its ``bin`` and where the
    package went (site-packages)."""

    folder: Path
    python: Path
    bin: Path
    site_packages: Path
    wheel: Path

    def env(self, **extra: str) -> dict[str, str]:
        """The environment a user's shell in it has: this machine's, its ``bin`` first on PATH,
        nothing that adds the checkout to the path."""
        env = {k: v for k, v in os.environ.items() if k not in LEAKS}
        env["PATH"] = os.pathsep.join([str(self.bin), env.get("PATH", "")])
        env["VIRTUAL_ENV"] = str(self.folder)
        return {**env, **extra}

    def kernels(self) -> Path:
        """A folder of Jupyter kernel specs holding one, :data:`KERNEL`: an IPython kernel on
        this environment's interpreter."""
        spec = self.folder / "kernels" / KERNEL
        spec.mkdir(parents=True, exist_ok=True)
        (spec / "kernel.json").write_text(json.dumps({
            "argv": [str(self.python), "-m", "ipykernel_launcher", "-f", "{connection_file}"],
            "display_name": "locust (installed wheel)", "language": "python"}))
        return spec.parent


def _run(cmd: list, what: str, timeout: float, **kw) -> subprocess.CompletedProcess:
    proc = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=timeout, check=False, **kw)
    if proc.returncode != 0:
        raise AssertionError(f"{what} failed (exit {proc.returncode}):\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return proc


def build_wheel(into: Path) -> Path:
    """The wheel of this checkout, built in ``into`` from a copy of its sources."""
    src = into / "src"
    for name in SOURCES:
        path = ROOT / name
        if path.is_dir():
            shutil.copytree(path, src / name, symlinks=True, ignore=IGNORE)
        else:
            (src / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(path, src / name)
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", into / "dist", src], "pip wheel", 600,
         cwd=into)
    (wheel,) = (into / "dist").glob("locust_hopper-*.whl")
    return wheel


def install(wheel: Path, folder: Path, *extras: str) -> Venv:
    """A fresh virtual environment in ``folder`` with only ``wheel`` (and ``extras``) installed,
    their dependencies as pip resolves them."""
    _run([sys.executable, "-m", "venv", folder], "python -m venv", 120, env={k: v for k, v in os.environ.items()
                                                                              if k not in LEAKS})
    python = folder / "bin" / "python"
    venv = Venv(folder, python, folder / "bin", Path(), wheel)
    _run([python, "-m", "pip", "install", "-q", "--no-compile", wheel, *extras], "pip install", 900,
         env=venv.env(), cwd=folder)
    purelib = _run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], "sysconfig", 60,
                   env=venv.env(), cwd=folder).stdout.strip()
    return Venv(folder, python, folder / "bin", Path(purelib), wheel)
