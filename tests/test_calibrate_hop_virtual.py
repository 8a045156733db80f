"""`locust calibrate hop` on the virtual robot's filmed hops (slow): known truth end to end.

The virtual robot (firmware under MicroPython driving the MuJoCo plant, rendered video)
carries hidden values unlike any preset; Small and Medium (the seed robot with their links,
as the demo's virtual robot) each hop three cycles on it, filmed and tracked. The fit,
started from the seed's values, each leg set at its own converged step (params.LEG_SETS),
must recover each hidden value within 5 % (or its 95% interval must cover it and be narrower
than +-20 %); the written robot.toml must then give a prediction with a spread.

Friction is hidden at 2.2, above the ramp's 1.7 (each floor pair carries its part's friction
exactly).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
import tomllib

import pytest

from locust.params import LEG_SETS as LEG_SETS_STEP

pytestmark = pytest.mark.slow

HIDDEN = {"contact.foot_friction": 2.2, "compliance.hinge_stiffness_nm_per_rad": 0.040,
          "servo.noload_speed_rad_per_s": 8.5}
LEG_SETS = ("small", "medium")


def _locust(args, env, timeout=600):
    proc = subprocess.run([sys.executable, "-m", "locust.commands", *args], capture_output=True, text=True, env=env,
                          timeout=timeout, check=False)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return proc.stdout


@pytest.fixture(scope="module")
def fitted(env, tmp_path_factory):
    folder = tmp_path_factory.mktemp("hops")
    sets = [a for k, v in HIDDEN.items() for a in ("--set", f"{k}={v}")]
    for name in LEG_SETS:
        run = folder / f"{name}-1"
        _locust(["hop", "--port", "sim", "--preset", "seed", "--leg-set", name, *sets, "--cycles", "3",
                 "--video", str(run / "hop.mp4"),
                 "--out", str(run)], env)
        _locust(["track", str(run / "hop.mp4")], env)
    toml = folder / "fitted.toml"
    t0 = time.perf_counter()
    out = _locust(["calibrate", "hop", *(f"{n}={folder / f'{n}-1'}" for n in LEG_SETS), "--json",
                   "--write", str(toml), "--out", str(folder / "plots")], env, timeout=3000)
    return {"fit": json.loads(out), "wall_s": time.perf_counter() - t0, "toml": toml, "folder": folder, "env": env}


def test_fit_recovers_the_hidden_values(fitted):
    params = fitted["fit"]["parameters"]
    for key, truth in HIDDEN.items():
        p = params[key]
        lo, hi = p["ci95"]
        # each on its own: within 5 % (docs/calibrate.md: within 3 % on three truths), and an
        # interval that covers the truth (with the held values' part, as wide as +-22 %)
        assert abs(p["value"] - truth) <= 0.05 * truth, (key, p)
        assert lo is not None and lo <= truth <= hi, (key, p)
        # the intervals include the time step's part
        assert 0 < p["std_numerical"] <= p["std"], (key, p)
        # and the uncertainties of the values held fixed (the preset's SG90 fit, its stall torque)
        assert 0 < p["std_fixed"] <= p["std"], (key, p)
    for run in fitted["fit"]["runs"]:       # each leg set at its own converged step, or finer
        assert run["timestep_s"] <= LEG_SETS_STEP[run["config"]].timestep_s, run
        assert run["step_change_at_half_m"] <= 1e-4, run
    interval = fitted["fit"]["interval"]
    assert interval.startswith("cluster-robust over 6 hops (CR1), t(5)")
    assert "values held fixed" in interval and "servo.stall_torque_nm" in interval


def test_fit_leaves_little(fitted):
    for run in fitted["fit"]["runs"]:
        # absolute positions: the standing pose and where each marker's tracked face
        # sits on the robot stay in the residual; on one filming of Small and Medium (bench/hop_model_error.py
        # seed 100) the fit left
        # 0.17 and 0.13 mm (the foot 0.21 and 0.16 mm, the nose 0.11 and 0.10 mm; with each
        # marker taken from where it stood, 0.039 and 0.050 mm, docs/calibrate.md)
        assert run["rms_residual_m"] < 2.5e-4, run
    for name in LEG_SETS:
        assert (fitted["folder"] / "plots" / f"{name}-1-hops-fit.png").stat().st_size > 10_000
        assert not (fitted["folder"] / f"{name}-1" / "hops-fit.png").exists()   # nothing into a run's folder


def test_written_values_carry_their_provenance_and_spread(fitted):
    doc = tomllib.loads(fitted["toml"].read_text())
    for key in HIDDEN:
        section, name = key.split(".")
        entry = doc[section][name]
        assert entry["source"] == "fit:hops" and entry["uncertainty"] > 0
        assert entry["value"] == pytest.approx(fitted["fit"]["parameters"][key]["value"])
    out = json.loads(_locust(["sim", "--config", str(fitted["toml"]), "--samples", "16", "--json"], fitted["env"]))
    assert out["samples"]["distance_m_sd"] > 0 and out["samples"]["max_nose_height_m_sd"] > 0
