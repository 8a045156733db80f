"""MUJOCO_GL that MuJoCo cannot render with: only rendering needs it (locust.sim.gl).

MuJoCo picks its OpenGL backend as it is imported and fails the import when it cannot:
`MUJOCO_GL=bogus locust params` (and `sim`, `hop --port sim`) ended in a RuntimeError
traceback, exit 1, and MUJOCO_GL=osmesa without the OSMesa library in an AttributeError from
PyOpenGL ('NoneType' object has no attribute 'glGetError'). Now a command that does not
render runs as it does with osmesa, and one that renders says what is wrong and what to install,
before it writes anything."""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import locust

LOCUST = [sys.executable, "-m", "locust.commands"]
OSMESA = "/lib/x86_64-linux-gnu/libOSMesa.so.8"


def run(args, cwd: Path, gl: str, env=None, wrap=()) -> subprocess.CompletedProcess:
    env = dict(env or os.environ, MUJOCO_GL=gl, PYOPENGL_PLATFORM="osmesa")
    return subprocess.run([*wrap, *LOCUST, *map(str, args)], cwd=cwd, env=env, capture_output=True, text=True,
                          timeout=240, check=False)


def assert_clean_error(proc, *words) -> None:
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr and "error:" in proc.stderr and "hint:" in proc.stderr, proc.stderr
    for w in words:
        assert w in proc.stderr, (w, proc.stderr)


@pytest.mark.parametrize("gl", ["bogus", "disable"])
def test_params_and_sim_run_without_a_renderer_and_a_render_says_why(tmp_path, gl):
    ref = run(["params", "--json"], tmp_path, "osmesa")
    assert ref.returncode == 0, ref.stderr
    proc = run(["params", "--json"], tmp_path, gl)
    assert proc.returncode == 0, proc.stderr
    # the same standing load as with a renderer (7.4 g of the small robot on its nose)
    assert json.loads(proc.stdout)["nose_load_kg"] == json.loads(ref.stdout)["nose_load_kg"]
    sim = run(["sim", "--cycles", "1", "--json"], tmp_path, gl)
    assert sim.returncode == 0 and json.loads(sim.stdout)["valid"] is True, sim.stderr
    video = run(["sim", "--cycles", "1", "--video", "v.mp4"], tmp_path, gl)
    assert_clean_error(video, f"MUJOCO_GL={gl}", "unset MUJOCO_GL", "sudo apt-get install -y libosmesa6")
    assert sorted(os.listdir(tmp_path)) == []                   # no video, no sidecar, no temporary


def test_hop_on_the_virtual_robot_runs_without_a_renderer_and_its_video_says_why(env, tmp_path):
    proc = run(["hop", "--port", "sim", "--cycles", "1", "--out", tmp_path / "run"], tmp_path, "bogus", env)
    assert proc.returncode == 0, proc.stderr
    record = json.loads((tmp_path / "run" / "run.json").read_text())
    assert record["status"] == "complete" and len(record["phases"]) == record["phases_expected"] == 2
    video = run(["hop", "--port", "sim", "--cycles", "1", "--out", tmp_path / "run2", "--video", tmp_path / "h.mp4"],
                tmp_path, "bogus", env)
    assert_clean_error(video, "MUJOCO_GL=bogus: not an OpenGL backend MuJoCo knows")
    assert not list(tmp_path.glob("*h.mp4*")) and not list(tmp_path.glob(".h.*"))


def _mujocos_own_values() -> dict[str, set[str]]:
    """The MUJOCO_GL values the installed MuJoCo accepts, by system, read from its own source
    (mujoco/rendering/classic/gl_context.py): the tuple every system takes, and each system's
    ``+=``; ``off`` the values that switch rendering off."""
    import importlib.util

    source = Path(importlib.util.find_spec("mujoco").submodule_search_locations[0]) / "rendering" / "classic" \
        / "gl_context.py"
    tree = ast.parse(source.read_text())
    values: dict[str, set[str]] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and isinstance(node.test, ast.Compare) \
                and isinstance(node.test.comparators[0], ast.Tuple) and isinstance(node.test.ops[0], ast.NotIn) \
                and getattr(node.test.left, "id", "") == "_MUJOCO_GL" and "off" not in values:
            values["off"] = {e.value for e in node.test.comparators[0].elts}
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "_VALID_MUJOCO_GL":
            values["any"] = {e.value for e in node.value.elts}
        if isinstance(node, ast.If) and isinstance(node.test, ast.Compare) \
                and getattr(node.test.left, "id", "") == "_SYSTEM" and isinstance(node.body[0], ast.AugAssign):
            values[node.test.comparators[0].value] = {e.value for e in node.body[0].value.elts}
    return values


def test_the_values_checked_are_the_ones_the_installed_mujoco_takes():
    from locust.sim.gl import backend_problem

    own = _mujocos_own_values()
    assert set(own) == {"off", "any", "Linux", "Windows", "Darwin"} and "osmesa" in own["Linux"], own
    for system in ("Linux", "Windows", "Darwin"):
        for value in own["any"] | own[system]:
            problem = backend_problem(value, system)
            assert problem is None or "OSMesa library" in problem[0], (system, value, problem)
        others = set().union(*(own[s] for s in ("Linux", "Windows", "Darwin") if s != system)) - own[system]
        for value in others | {"bogus"}:
            assert "not an OpenGL backend MuJoCo knows" in backend_problem(value, system)[0], (system, value)
        for value in own["off"]:
            assert "rendering is switched off" in backend_problem(value, system)[0]


def test_no_module_imports_mujoco_but_through_locust_sim():
    """The check runs before MuJoCo is first imported only if every module outside locust.sim
    takes MuJoCo from locust.sim.gl (one that imported it first would fail on MUJOCO_GL=bogus
    again: `locust calibrate servo` did)."""
    root = Path(locust.__file__).parent
    direct = []
    for path in root.rglob("*.py"):
        if "sim" in path.relative_to(root).parts[:1]:
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) and node.level == 0 else []
            direct += [f"{path.relative_to(root)}: {n}" for n in names if n.split(".")[0] == "mujoco"]
    assert direct == []


def test_calibrate_servo_runs_with_a_value_mujoco_does_not_know(tmp_path):
    rec = locust.bundled_recording("synthetic_servo.csv")
    proc = run(["calibrate", "servo", rec, "--inertia-kgm2", "1.5e-5", "--stall-torque-nm", "0.15", "--no-plot",
                "--json"], tmp_path, "bogus")
    assert proc.returncode == 0, proc.stderr
    fit = json.loads(proc.stdout)
    # header truth: the AA swing's SG90 (noload 10.2 rad/s, armature 3.1e-4 kg*m^2, kp 0.26 N*m/rad)
    assert fit["servo.noload_speed_rad_per_s"]["value"] == pytest.approx(10.2, rel=0.01)
    assert fit["servo.armature_kgm2"]["value"] == pytest.approx(3.1e-4, rel=0.05)
    assert fit["servo.kp_nm_per_rad"]["value"] == pytest.approx(0.26, rel=0.05)


@pytest.fixture()
def without_osmesa():
    """A private mount namespace where the OSMesa library is an empty file, as on a machine
    without libosmesa6 (mounting needs root: skipped, saying so, where it is not allowed)."""
    if not (shutil.which("unshare") and os.path.exists(OSMESA)):
        pytest.skip(f"needs unshare and {OSMESA}")
    probe = subprocess.run(["unshare", "-m", "sh", "-c", f"mount --bind /dev/null {OSMESA}"], capture_output=True,
                           text=True, check=False)
    if probe.returncode != 0:
        pytest.skip(f"cannot hide the OSMesa library here ({probe.stderr.strip()})")
    return ["unshare", "-m", "sh", "-c", f'mount --bind /dev/null {OSMESA} && exec "$@"', "sh"]


def test_osmesa_missing_is_named_with_the_package_to_install(tmp_path, without_osmesa):
    proc = run(["params", "--json"], tmp_path, "osmesa", wrap=without_osmesa)
    assert proc.returncode == 0 and json.loads(proc.stdout)["nose_load_kg"] > 0, proc.stderr
    video = run(["sim", "--cycles", "1", "--video", "v.mp4"], tmp_path, "osmesa", wrap=without_osmesa)
    assert_clean_error(video, "the OSMesa library", "sudo apt-get install -y libosmesa6")
    assert os.listdir(tmp_path) == []
