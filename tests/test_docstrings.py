"""Docstrings of the API and of each job package, read from the source with ``ast``.

- every public function, class and method (no leading underscore, not nested in a function)
  of ``locust.api`` and of each job package has a docstring; the test prints any that lack one;
- every public function of ``locust.api`` (and ``bundled_recording``, which it exports from
  ``locust.bundled``) has the numpydoc sections ``Parameters`` and ``Returns``;
- each package's ``__init__`` docstring names its modules as ``:mod:`.name```: every name it
  gives exists, and every module of the package is named.

The packages and files whose docstrings are still being written are marked ``xfail(strict=True)``:
the mark turns into a failure the day they are done, and is removed then.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import locust

ROOT = Path(locust.__file__).parent
PACKAGES = ["api", "sim", "calibrate", "track", "sweep", "report", "fab", "device", "measure",
            "trials", "io", "params"]


def modules_of(package: str) -> list[Path]:
    """The package's own modules (``__init__`` and private ``_name`` modules left out)."""
    return sorted(p for p in (ROOT / package).glob("*.py") if not p.name.startswith("_"))


def undocumented(path: Path) -> list[str]:
    """``file:line name`` of each public function, class and method in ``path`` without a
    docstring (property setters and deleters share the getter's)."""
    missing = []

    def visit(body: list[ast.stmt], prefix: str) -> None:
        for node in body:
            if isinstance(node, (ast.If, ast.Try)):
                visit(node.body + node.orelse + getattr(node, "finalbody", []), prefix)
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                if node.name.startswith("_") or any(
                        isinstance(d, ast.Attribute) and d.attr in ("setter", "deleter")
                        for d in getattr(node, "decorator_list", [])):
                    continue
                if ast.get_docstring(node) is None:
                    missing.append(f"{path.relative_to(ROOT)}:{node.lineno} {prefix}{node.name}")
                if isinstance(node, ast.ClassDef):
                    visit(node.body, f"{prefix}{node.name}.")

    visit(ast.parse(path.read_text(), str(path)).body, "")
    return missing


@pytest.mark.parametrize("package", PACKAGES)
def test_public_definitions_have_docstrings(package):
    files = modules_of(package)
    assert files, f"no modules found in locust.{package}"
    missing = [m for path in files for m in undocumented(path)]
    print("\n".join(missing))
    assert missing == [], f"{len(missing)} public definitions without a docstring in locust.{package}"


# functions the API exports as they are from the shared module that owns them: file -> names
REEXPORTED = {"bundled.py": ("bundled_recording",)}


def api_functions():
    """Each public module-level function of ``locust.api``, and each it exports from a shared
    module (REEXPORTED): its docstring and its arguments."""
    for path in [*modules_of("api"), *(ROOT / name for name in REEXPORTED)]:
        for node in ast.parse(path.read_text(), str(path)).body:
            if isinstance(node, ast.FunctionDef) and not node.name.startswith("_") and (
                    path.parent.name == "api" or node.name in REEXPORTED[path.name]):
                a = node.args
                names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
                names += [x.arg for x in (a.vararg, a.kwarg) if x is not None]
                yield pytest.param(ast.get_docstring(node) or "", names, id=f"{path.stem}.{node.name}")


def documented_parameters(doc: str) -> set[str]:
    """The names a numpydoc ``Parameters`` section documents (``a, b : float`` names two)."""
    match = re.search(r"^Parameters\n-+\n(.*?)(?:^\w+\n-+$|\Z)", doc, re.M | re.S)
    if not match:
        return set()
    heads = [line.split(" : ")[0] for line in match.group(1).splitlines() if line and not line[0].isspace()]
    return {name.strip().lstrip("*") for head in heads for name in head.split(",")}


@pytest.mark.parametrize(("doc", "arguments"), list(api_functions()))
def test_api_functions_have_numpydoc_sections(doc, arguments):
    for section in ("Parameters", "Returns"):
        assert re.search(rf"^{section}\n-{{{len(section)}}}$", doc, re.M), f"no {section} section"
    assert sorted(set(arguments) - documented_parameters(doc)) == [], "arguments not in Parameters"


def test_documented_parameters_reads_numpydoc():
    doc = "Sum.\n\nParameters\n----------\na, b : float\n    Lengths [m].\n*rest\n\nReturns\n-------\nfloat\n"
    assert documented_parameters(doc) == {"a", "b", "rest"}
    assert documented_parameters("Sum.\n\nReturns\n-------\nfloat\n") == set()


def test_every_exported_api_function_is_checked():
    from locust.api import EXPORTS
    checked = {p.id.split(".")[1] for p in api_functions()}
    functions = {name for name in EXPORTS if name[0].islower()}
    assert len(functions) == 15
    assert sorted(functions - checked) == []


def named_modules(package: str) -> set[str]:
    """The modules the package's ``__init__`` docstring names with ``:mod:`.name```."""
    doc = ast.get_docstring(ast.parse((ROOT / package / "__init__.py").read_text())) or ""
    return set(re.findall(r":mod:`\.(\w+)`", doc))


@pytest.mark.parametrize("package", PACKAGES)
def test_package_docstring_names_its_modules(package):
    named = named_modules(package)
    present = {p.stem for p in modules_of(package)}
    assert sorted(named - present) == [], "named in the docstring but not in the package"
    assert sorted(present - named) == [], "in the package but not named in the docstring"


def test_package_docstring_check_can_fail(tmp_path, monkeypatch):
    # a package whose docstring names a module it lacks and omits one it has
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text('"""- :mod:`.gone`: was here."""\n')
    (tmp_path / "pkg" / "kept.py").write_text('"""Kept."""\n\ndef f():\n    pass\n')
    monkeypatch.setitem(globals(), "ROOT", tmp_path)
    assert named_modules("pkg") == {"gone"}
    assert {p.stem for p in modules_of("pkg")} == {"kept"}
    assert undocumented(tmp_path / "pkg" / "kept.py") == ["pkg/kept.py:3 f"]
