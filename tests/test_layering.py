"""The package layering (docs/architecture.md): the file layer ``locust.io`` imports no job
package, ``sim`` does not import ``track``, and ``calibrate`` does not import ``report``
(both build on ``locust.trials``). Every import is counted, at module level or inside a
function, read from the source with ``ast``."""

from __future__ import annotations

import ast
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


def offending(package: str, forbidden: tuple[str, ...]) -> dict[str, list[str]]:
    found = {}
    for path in sorted((ROOT / package).rglob("*.py")):
        bad = sorted(m for m in imports_of(path)
                     if any(m == f"locust.{f}" or m.startswith(f"locust.{f}.") for f in forbidden))
        if bad:
            found[str(path.relative_to(ROOT))] = bad
    return found


def test_the_import_reader_resolves_relative_imports():
    # the rule below is only as good as this: known imports of three modules, found as written
    assert "locust.io.camera_json" in imports_of(ROOT / "sim" / "clip.py")
    assert {"locust.trials.configs", "locust.trials.measured"} <= imports_of(ROOT / "calibrate" / "hop.py")
    assert {"locust.io", "locust.io.run_record"} <= imports_of(ROOT / "device" / "hop.py")


@pytest.mark.parametrize("package, forbidden", [
    ("sim", ("track",)),
    ("calibrate", ("report",)),
    ("trials", ("report", "calibrate", "track", "sim", "sweep", "device")),
    ("io", ("sim", "track", "report", "calibrate", "device", "sweep", "trials", "fab", "demo")),
])
def test_layering(package, forbidden):
    assert offending(package, forbidden) == {}
