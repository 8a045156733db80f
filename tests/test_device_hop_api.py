"""`locust hop` and `locust.hop` are one job: both call `locust.device.hop_job.run_hop_job`,
the API takes every option the command has, and the two write the same run.json."""

from __future__ import annotations

import ast
import inspect
import json
import subprocess
import sys

import click
import pytest

import locust
from locust.commands import hop as hop_command
from locust.device.hop_job import run_hop_job
from locust.errors import DeviceError
from locust.io import run_record as R

LOCUST = [sys.executable, "-m", "locust.commands"]
JOB = "locust.device.hop_job"
# the keys of run.json that one schedule on one robot fixes, whoever asked for the hop
SAME_KEYS = ("status", "message", "firmware_version", "firmware_status", "robot", "board", "schedule",
             "phases_expected")


def calls_from(module, module_name: str) -> set[str]:
    """The names ``module`` imports from ``module_name`` and calls, read from its source."""
    tree = ast.parse(inspect.getsource(module))
    package = module.__name__.rsplit(".", 1)[0].split(".")
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            if ".".join([*base, *([node.module] if node.module else [])]) == module_name:
                imported |= {alias.asname or alias.name for alias in node.names}
    called = {node.func.id for node in ast.walk(tree) if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)}
    return imported & called


def test_the_command_and_the_api_call_the_same_job():
    import locust.api.hopping as api_hopping

    assert calls_from(hop_command, JOB) == {"HopOptions", "run_hop_job"}
    assert calls_from(api_hopping, JOB) == {"HopOptions", "run_hop_job"}
    assert api_hopping.run_hop_job is run_hop_job
    assert locust.hop is api_hopping.hop and "hop" in locust.__all__


def test_the_api_takes_every_option_of_the_command_with_its_default():
    """Each option of `locust hop --help` is a parameter of `locust.hop` named after it
    (`--leg-set`: leg_set; a repeatable one in the plural, `--set`: sets), with the command's
    default; `--json` is the record returned."""
    api = inspect.signature(locust.hop).parameters
    defaults = hop_command.hop.make_context("hop", [], resilient_parsing=True).params
    options = {max(p.opts, key=len).lstrip("-").replace("-", "_") + ("s" if p.multiple else ""): p
               for p in hop_command.hop.params if isinstance(p, click.Option)}
    assert set(options) - set(api) == {"json"}
    assert set(api) - set(options) == {"say"}    # (told the lines the command prints)
    for name in set(options) & set(api):
        assert api[name].default == defaults[options[name].name], name
    assert len(options) == 15


def test_a_hop_through_the_api_writes_the_commands_record(env, tmp_path, monkeypatch):
    """One cycle of 50 ms push and wait on the virtual robot, once by the command and once by
    `locust.hop` with the same options: run.json has the same keys, the same schedule, robot,
    board and verdict, the same phases at the same commanded times, each measured (the jitter
    over both); the API returns the record it wrote and says the command's first line."""
    options = {"cycles": 1, "push_ms": 50, "wait_ms": 50, "plant": "record", "preset": "small"}
    cli_out, api_out = tmp_path / "cli", tmp_path / "api"
    proc = subprocess.run(LOCUST + ["hop", "--port", "sim", "--cycles", "1", "--push-ms", "50", "--wait-ms", "50",
                                    "--plant", "record", "--preset", "small", "--out", str(cli_out)],
                          capture_output=True, text=True, env=env, timeout=90)
    assert proc.returncode == 0, proc.stderr
    monkeypatch.setenv("LOCUST_VIRTUAL_DIR", env["LOCUST_VIRTUAL_DIR"])
    said: list[str] = []
    rec = locust.hop(port="sim", out=api_out, say=said.append, **options)
    by_cli = json.loads((cli_out / "run.json").read_text())
    by_api = json.loads((api_out / "run.json").read_text())
    assert rec.to_dict() == by_api
    assert set(by_api) == set(by_cli)
    assert {k: by_api[k] for k in SAME_KEYS} == {k: by_cli[k] for k in SAME_KEYS}
    assert by_api["status"] == "complete" and by_api["schedule"]["push_ms"] == 50
    assert by_api["robot"] == {"preset": "small", "robot_file": None, "leg_set": "small"}

    def phases(doc):
        return [(p["cycle"], p["phase"], p["commanded_ms"], sorted(p)) for p in doc["phases"]]

    assert phases(by_api) == phases(by_cli) == [(1, "push", 0, sorted(by_cli["phases"][0])),
                                                (1, "wait", 50, sorted(by_cli["phases"][1]))]
    assert by_api["jitter"]["n"] == by_cli["jitter"]["n"] == 2
    assert said[0] == f"output folder: {api_out}" and proc.stderr.splitlines()[0] == f"output folder: {cli_out}"


def test_the_api_refuses_what_the_command_line_refuses(tmp_path):
    """A value the command's option types refuse is refused by the API before any folder is
    made: an error naming the value and its limits (the firmware's, as the command's), nothing
    written."""
    assert [(p.type.min, p.type.max) for p in hop_command.hop.params if p.name in ("cycles", "push_ms")] == \
        [R.hop_range("cycles"), R.hop_range("push_ms")] == [(1, 1000), (20, 10000)]
    for bad, said in (({"cycles": 0}, "cycles 0 is not a whole number within 1..1000"),
                      ({"cycles": 1001}, "cycles 1001 is not a whole number within 1..1000"),
                      ({"push_ms": 60.5}, "push_ms 60.5 is not a whole number within 20..10000"),
                      ({"push_deg": float("nan")}, "push_deg nan is not a number within -90..90"),
                      ({"push_deg": -90.5}, "push_deg -90.5 is not a number within -90..90"),
                      ({"fps": 0}, "video_fps 0 is not a whole number within 1..1000"),
                      ({"plant": "wood"}, "unknown plant 'wood'")):
        with pytest.raises(DeviceError) as caught:
            locust.hop(port="sim", out=tmp_path / "run", **bad)
        assert caught.value.message == said and caught.value.hint
        assert not (tmp_path / "run").exists()
