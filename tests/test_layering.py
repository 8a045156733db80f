"""The package layering (docs/architecture.md), from the bottom up:

- the shared modules at the root (errors, fileio, progress, tables, plotting, markers,
  arucoboard, orphans, version, bundled, derivatives) and ``params``, the robot's parameters;
- ``io``, the file formats, which imports no job package;
- the job packages (sim, calibrate, track, sweep, report, fab, device, measure, trials, demo);
- ``api``, the functions a notebook calls;
- ``commands``, the click commands, one module per verb;
- the package root, which only names the API.

Nothing imports upwards: no job package (nor io, params or a shared module) imports
``locust.api``, ``locust.commands`` or the root (``from locust import x``, ``from .. import
__version__``), and only ``commands`` uses click. Across the jobs, each package imports only the
job packages ARROWS allows it, every arrow there is one the code has (no stale permission), and
docs/architecture.md draws exactly that table. Every import is counted, at module level or
inside a function, read from the source with ``ast``."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import locust

ROOT = Path(locust.__file__).parent


def imports_of(path: Path) -> set[str]:
    """The absolute names of the modules ``path`` imports (relative imports resolved)."""
    package = ["locust", *path.relative_to(ROOT).parent.parts]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join([*base, *([node.module] if node.module else [])])
            out.add(module)
            out.update(f"{module}.{alias.name}" for alias in node.names)   # a name may be a module
    return out


# job package -> the job packages it may import, each arrow one the code has: the table
# docs/architecture.md draws
ARROWS = {
    "calibrate": ("sim", "track", "trials"),
    "demo": ("calibrate", "device", "sim"),
    "device": ("sim",),
    "fab": (),
    "measure": ("calibrate", "sim", "track"),
    "report": ("sim", "sweep", "track", "trials"),
    "sim": (),
    "sweep": ("sim",),
    "track": (),
    "trials": (),
}
JOBS = tuple(ARROWS)
BELOW_API = (*JOBS, "io", "params", "firmware")        # packages
SHARED = ("errors", "fileio", "progress", "tables", "plotting", "markers", "arucoboard", "orphans", "version",
          "bundled", "derivatives")
ROOT_NAMES = ("locust", "locust.__init__", "locust.__version__")


def modules_of(package: str) -> list[Path]:
    path = ROOT / package
    return sorted(path.rglob("*.py")) if path.is_dir() else [ROOT / f"{package}.py"]


def offending(package: str, forbidden: tuple[str, ...], root: bool = False) -> dict[str, list[str]]:
    """The modules of ``package`` that import one of ``forbidden`` (``locust.<name>`` or below
    it; ``root``: or the package root itself), with what they import."""
    found = {}
    for path in modules_of(package):
        bad = sorted(m for m in imports_of(path)
                     if any(m == f"locust.{f}" or m.startswith(f"locust.{f}.") for f in forbidden)
                     or (root and m in ROOT_NAMES))
        if bad:
            found[str(path.relative_to(ROOT))] = bad
    return found


def test_the_import_reader_resolves_relative_imports():
    # the rule below is only as good as this: known imports of three modules, found as written
    assert "locust.io.camera_json" in imports_of(ROOT / "sim" / "clip.py")
    assert {"locust.trials.configs", "locust.trials.measured"} <= imports_of(ROOT / "calibrate" / "hopruns.py")
    assert {"locust.io", "locust.io.run_record"} <= imports_of(ROOT / "device" / "hop.py")


def job_imports(package: str) -> dict[str, list[str]]:
    """The other job packages ``package``'s modules import, each with the modules that do."""
    found: dict[str, set[str]] = {}
    for path in modules_of(package):
        for module in imports_of(path):
            parts = module.split(".")
            if len(parts) > 1 and parts[0] == "locust" and parts[1] in JOBS and parts[1] != package:
                found.setdefault(parts[1], set()).add(str(path.relative_to(ROOT)))
    return {job: sorted(paths) for job, paths in sorted(found.items())}


def packages_on_disk() -> set[str]:
    """The subpackages of locust that hold Python modules (the firmware's link and the bundled
    recordings' left out: the board's code and data)."""
    return {p.name for p in ROOT.iterdir() if p.is_dir() and not p.is_symlink() and any(p.rglob("*.py"))}


def test_every_job_package_is_in_the_table():
    assert packages_on_disk() - set(JOBS) == {"api", "commands", "fileio", "io", "params"}


@pytest.mark.parametrize("package", JOBS)
def test_a_job_imports_only_its_arrows(package):
    """No import across the jobs that the table does not allow (the modules that make it named)."""
    imported = job_imports(package)
    assert {job: at for job, at in imported.items() if job not in ARROWS[package]} == {}


@pytest.mark.parametrize("package", JOBS)
def test_every_arrow_is_used(package):
    """The table allows nothing the code does not do: a permission no import uses is stale."""
    assert sorted(set(ARROWS[package]) - set(job_imports(package))) == []


def architecture_arrows(text: str) -> dict[str, tuple[str, ...]]:
    """The table of docs/architecture.md's Layers section: ``| `report` | `sim`, `sweep` |`` ->
    report: (sim, sweep); a dash for none."""
    section = text.split("\n## Layers\n", 1)[1].split("\n## ", 1)[0]
    rows = [line.split("|")[1:3] for line in section.splitlines() if line.startswith("| `")]
    return {package.strip().strip("`"): tuple(re.findall(r"`(\w+)`", may)) for package, may in rows}


def test_the_architecture_draws_the_table():
    text = (ROOT.parents[1] / "docs" / "architecture.md").read_text(encoding="utf-8")
    assert architecture_arrows(text) == ARROWS


def test_the_table_checks_can_fail(tmp_path, monkeypatch):
    """The rules are only as good as this: a job importing a job its row lacks is reported with
    the module that does, and a row's arrow no module uses is stale; the doc's table is read."""
    for job in ("report", "sim", "sweep"):
        (tmp_path / "locust" / job).mkdir(parents=True)
    (tmp_path / "locust" / "sim" / "bad.py").write_text("def f():\n    from ..report import build\n")
    (tmp_path / "locust" / "report" / "ok.py").write_text("from locust.sim import run\n")
    monkeypatch.setattr(__import__(__name__), "ROOT", tmp_path / "locust")
    assert job_imports("sim") == {"report": ["sim/bad.py"]}
    assert job_imports("report") == {"sim": ["report/ok.py"]}
    assert sorted(set(ARROWS["report"]) - set(job_imports("report"))) == ["sweep", "track", "trials"]
    assert architecture_arrows("# A\n\n## Layers\n\n| package | may import |\n|---|---|\n"
                               "| `report` | `sim`, `sweep` |\n| `sim` | - |\n\n## Next\n| `x` | `y` |\n") == {
        "report": ("sim", "sweep"), "sim": ()}


def test_io_imports_no_job_package():
    assert offending("io", JOBS) == {}


@pytest.mark.parametrize("package", [*BELOW_API, *SHARED])
def test_nothing_below_the_api_imports_upwards(package):
    assert offending(package, ("api", "commands"), root=True) == {}


def test_the_api_does_not_import_the_commands():
    assert offending("api", ("commands",), root=True) == {}


def test_params_and_io_stand_below_the_jobs():
    assert offending("params", (*JOBS, "io", "api", "commands")) == {}


def test_only_the_commands_use_click():
    users = {str(p.relative_to(ROOT)) for p in ROOT.rglob("*.py")
             if "click" in {m.split(".")[0] for m in imports_of(p)}}
    assert users and all(u.startswith("commands/") for u in users), sorted(users)


def test_the_rule_catches_an_upward_import(tmp_path, monkeypatch):
    """The rule is only as good as this: a job module importing the API, the commands, the
    version from the root, or ``import locust``, is each reported."""
    pkg = tmp_path / "locust" / "sim"
    pkg.mkdir(parents=True)
    (pkg / "bad.py").write_text("from ..api import simulate\nfrom .. import __version__\n"
                                "def f():\n    from locust.commands import main\n    import locust\n")
    monkeypatch.setattr(__import__(__name__), "ROOT", tmp_path / "locust")
    assert offending("sim", ("api", "commands"), root=True) == {
        "sim/bad.py": ["locust", "locust.__version__", "locust.api", "locust.api.simulate", "locust.commands",
                       "locust.commands.main"]}


def test_one_name_per_public_class_and_one_simulate():
    """No two public classes of the toolkit share a name, and only the API defines ``simulate``
    (module-level helpers such as ``build`` may repeat across modules)."""
    classes, simulates = {}, []
    for path in sorted(ROOT.rglob("*.py")):
        if "firmware" in path.relative_to(ROOT).parts:   # MicroPython, on the board
            continue
        for node in ast.parse(path.read_text(), str(path)).body:
            where = str(path.relative_to(ROOT))
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                classes.setdefault(node.name, []).append(where)
            elif isinstance(node, ast.FunctionDef) and node.name == "simulate":
                simulates.append(where)
    assert {name: at for name, at in classes.items() if len(at) > 1} == {}
    assert simulates == ["api/simulation.py"]
