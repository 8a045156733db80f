"""`locust demo` and `locust.run_demo` are one demo: both call `locust.demo.story.run_story`
(read from the source with ast), with the same options for the same arguments, and refuse the
same sizes (the API before it writes anything). The demo itself runs in tests/test_demo_fast.py."""

from __future__ import annotations

import ast
import inspect
import types
from pathlib import Path

import click
import pytest

import locust
from locust.api import demos
from locust.commands import demo as command
from locust.demo.options import RANGES, DemoOptions
from locust.errors import ReportError

ROOT = Path(locust.__file__).parent
STORY = "locust.demo.story.run_story"


def calls_of(path: Path, function: str) -> set[str]:
    """The absolute names of what ``function`` in ``path`` calls by a plain name, resolved
    through the module's imports (anywhere in it; relative ones too)."""
    tree = ast.parse(path.read_text(), str(path))
    package = ["locust", *path.relative_to(ROOT).parent.parts]
    names = {node.name: f"{'.'.join(package)}.{path.stem}.{node.name}" for node in tree.body
             if isinstance(node, ast.FunctionDef)}
    (body,) = [node for node in tree.body if isinstance(node, ast.FunctionDef) and node.name == function]
    for node in [*ast.walk(tree)]:
        if isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join([*base, *([node.module] if node.module else [])])
            names.update({alias.asname or alias.name: f"{module}.{alias.name}" for alias in node.names})
    called = set()
    for node in (n for statement in body.body for n in ast.walk(statement)):   # (not its decorators)
        if isinstance(node, ast.Call):
            if isinstance(node.func, ast.Name):
                called.add(names.get(node.func.id, node.func.id))
            elif isinstance(node.func, ast.Attribute) and isinstance(node.func.value, ast.Name):
                called.add(f"{node.func.value.id}.{node.func.attr}")
    return called


def test_the_call_reader_resolves_imports():
    # the check below is only as good as this: a known call of a module, found as written
    assert "locust.sweep.study.optimize_study" in calls_of(ROOT / "api" / "optimizing.py", "optimize")
    assert "locust.api.sweeps.vary_texts" in calls_of(ROOT / "api" / "optimizing.py", "optimize")   # a relative import


def test_the_command_and_the_api_call_the_same_demo():
    """The command parses, builds the options, calls the story and prints; the API builds
    the same options and calls the same story."""
    cmd = calls_of(ROOT / "commands" / "demo.py", "demo")
    api = calls_of(ROOT / "api" / "demos.py", "run_demo")
    assert cmd == {STORY, "locust.commands.demo.demo_options", "click.echo"}
    assert api == {STORY, "locust.api.demos.demo_options"}
    assert calls_of(ROOT / "commands" / "demo.py", "demo_options") == {"locust.demo.options.DemoOptions"}
    assert calls_of(ROOT / "api" / "demos.py", "demo_options") == {"locust.demo.options.DemoOptions", "pathlib.Path"}


def test_run_demo_is_at_the_package_top_beside_the_demo_package():
    import locust.demo.story  # binds the subpackage to locust.demo, as any use of the demo does

    assert "run_demo" in locust.__all__ and locust.run_demo is demos.run_demo
    assert isinstance(locust.demo, types.ModuleType)      # the API's name is not the package's


def options_of_the_command(args: list[str]) -> DemoOptions:
    """What ``locust demo ARGS`` hands the story: its options as click parses them, through
    the command's own builder."""
    with command.demo.make_context("demo", list(args)) as ctx:     # (click takes the list's items off it)
        return command.demo_options(**ctx.params)


def test_the_api_takes_every_option_of_the_command():
    options = {p.name for p in command.demo.params if p.name != "help"}
    assert options == {"out", "cycles", "trials", "designs", "jobs", "fit_hops"}
    assert set(inspect.signature(demos.run_demo).parameters) == options | {"stderr"}
    assert set(inspect.signature(demos.demo_options).parameters) == options


@pytest.mark.parametrize(("args", "kwargs"), [
    ([], {}),
    (["--out", "elsewhere", "--cycles", "2", "--trials", "4", "--designs", "9", "--jobs", "3", "--no-fit-hops"],
     {"out": "elsewhere", "cycles": 2, "trials": 4, "designs": 9, "jobs": 3, "fit_hops": False}),
    (["--cycles", "6", "--trials", "1", "--designs", "61", "--jobs", "64", "--fit-hops"],
     {"cycles": 6, "trials": 1, "designs": 61, "jobs": 64, "fit_hops": True}),
])
def test_the_api_builds_the_options_the_command_builds(args, kwargs):
    built = demos.demo_options(**kwargs)
    assert built == options_of_the_command(args)
    assert built == DemoOptions(**{**kwargs, **({"out": Path(kwargs["out"])} if "out" in kwargs else {})})
    if not args:    # the defaults, as `locust demo --help` states them
        assert built == DemoOptions(Path("demo-out"), 3, 2, 7, None, True)


@pytest.mark.parametrize("name", sorted(RANGES))
def test_both_doors_refuse_the_same_sizes(name, tmp_path):
    low, high = RANGES[name]
    for value in (low, high):
        assert getattr(options_of_the_command([f"--{name}", str(value)]), name) == value
        assert getattr(demos.demo_options(**{name: value}), name) == value
    for value in (low - 1, high + 1):
        with pytest.raises(click.BadParameter):
            options_of_the_command([f"--{name}", str(value)])
        with pytest.raises(ReportError, match=rf"{name}={value} is not a whole number from {low} to {high}") as err:
            demos.run_demo(tmp_path / "out", **{name: value})
        assert err.value.hint
    assert not (tmp_path / "out").exists()       # refused before anything is written


@pytest.mark.parametrize("kwargs", [{"cycles": 2.0}, {"trials": True}, {"designs": "7"}, {"fit_hops": "no"}])
def test_the_api_refuses_what_is_not_a_size(kwargs):
    with pytest.raises(ReportError, match=f"{next(iter(kwargs))}="):
        demos.demo_options(**kwargs)
