"""`locust calibrate hinge` refuses what no link can be and values its swing does not give,
says how far a long fit has gone, and ends cleanly on Ctrl-C; its Jacobian and its closed form
are the swing's own to the integrator's tolerance.

The real recording is ../shared's pendulum_transparency_film.csv (a link hanging on a film
hinge, swinging +-24 deg down to 4 deg over 52 s at about 31 frames/s, positions in mm);
the swings of known truth are SYNTHETIC (:mod:`locust.calibrate.synthetic`).
"""

from __future__ import annotations

import json
import math
import os
import pty
import re
import select
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from click.testing import CliRunner

from locust.calibrate import hinge, hingeswing, synthetic
from locust.commands import cli
from locust.errors import CalibrationError

FILM = ("hinge", "pendulum_transparency_film.csv")
# a link of 2 g with its centre of mass 80 mm from the hinge, so at least 1.28e-5 kg*m^2
MASS = ("--gravity", "in-plane", "--mass-kg", "0.002", "--com-m", "0.08")
K, B = "compliance.hinge_stiffness_nm_per_rad", "compliance.hinge_damping_nms_per_rad"   # the robot keys fitted


def run(*args):
    return CliRunner().invoke(cli, list(map(str, args)))


# -- the rig ------------------------------------------------------------------------------
def test_an_inertia_below_m_d_squared_is_refused_before_the_recording_is_read(tmp_path):
    """I >= M*D^2 (parallel axes): 1e-6 against 0.002 kg at 0.08 m (1.28e-5) is no link. The
    recording is not even opened (it does not exist here): no fit is tried."""
    res = run("calibrate", "hinge", tmp_path / "nowhere.csv", "--inertia-kgm2", "1e-6", *MASS, "--no-plot")
    assert res.exit_code == 2, res.output
    assert ("error: --inertia-kgm2 1e-06 is below --mass-kg x --com-m^2 = 0.002 x 0.08^2 = 1.28e-05 kg*m^2"
            in res.stderr)
    assert "I = M*L^2/3" in res.stderr and "nowhere" not in res.stderr
    with pytest.raises(CalibrationError, match="below --mass-kg"):
        hingeswing.check_rig(hingeswing.HingeRig(1.279e-5, "in-plane", 0.002, 0.08))
    hingeswing.check_rig(hingeswing.HingeRig(1.28e-5, "in-plane", 0.002, 0.08))      # a point mass: the least there is
    hingeswing.check_rig(hingeswing.HingeRig(1e-6, "out-of-plane"))   # no weight's moment, no M or D to check


def test_a_fit_that_does_not_follow_its_swing_writes_nothing(shared_data, tmp_path):
    """The 2 g link's rig at 1.5e-5 kg*m^2: allowed, yet gravity alone swings it faster than the
    film's 1.6 s period and a hinge cannot slow it, so the model does not follow the swing (its
    residual about the size of the swing): every value NOT IDENTIFIABLE (was: k 2.8e-24 +-
    7.7e21 % printed TOO NARROW), the note says why, --write writes nothing, exit 0 as the
    servo fit does. The first 20 s of the recording show it as the whole does."""
    robot = tmp_path / "robot.toml"
    args = ("calibrate", "hinge", shared_data.joinpath(*FILM), "--units", "mm", "--inertia-kgm2", "1.5e-5", *MASS,
            "--end-s", "20", "--no-plot")
    res = run(*args, "--write", robot)
    assert res.exit_code == 0, res.output
    lines = res.stdout.splitlines()
    for key in ("compliance.hinge_stiffness", "compliance.hinge_damping"):
        line = next(ln for ln in lines if ln.startswith(key + " "))
        assert line.endswith("NOT IDENTIFIABLE") and "TOO NARROW" not in line, line
    assert any(ln.startswith("note: the model does not follow pendulum_transparency_film.csv") for ln in lines)
    assert "nothing written" in res.stdout and not robot.exists()
    out = json.loads(run(*args, "--json").stdout)
    assert out[K]["identifiable"] is False
    assert out[B]["identifiable"] is False
    said = re.search(r"RMS (\S+) deg about a swing of (\S+) deg", out["notes"][0])
    residual, swing = float(said.group(1)), float(said.group(2))
    assert residual > hinge.FOLLOWS_SHARE * swing


def test_the_same_film_on_a_rig_that_swings_at_its_rate_is_fitted(shared_data):
    """The control: 1e-4 kg*m^2 (gravity's own period 1.6 s, the film's) follows the swing
    (1.1 deg RMS on a swing of 10 deg RMS) and both values are determined."""
    res = run("calibrate", "hinge", shared_data.joinpath(*FILM), "--units", "mm", "--inertia-kgm2", "1e-4", *MASS,
              "--end-s", "20", "--no-plot", "--json")
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    assert out[K]["identifiable"] and out[B]["identifiable"]
    assert out[K]["value"] == pytest.approx(1.255e-4, rel=0.01)
    assert out["rms_residual_deg"] < 1.5 and not out["notes"]


def test_a_value_run_to_its_bound_is_not_identifiable():
    """A swing with no viscous damping beside its Coulomb friction (SYNTHETIC: b 1e-12, tau_c
    1.5e-6) fitted with Coulomb friction: b runs to its bound, 0, and is not written; k is."""
    truth = synthetic.HingeTruth(hinge_damping_nms_per_rad=1e-12, coulomb_nm=1.5e-6)
    t, x, y = synthetic.hinge_swing_track(truth, np.random.default_rng(2))
    fit = hinge.fit_hinge(t, x, y, hingeswing.HingeRig(truth.inertia_kgm2), coulomb="on")
    assert fit.identifiable == {K: True, B: False}
    assert any(n.startswith(f"{B} ran to the edge of its range") for n in fit.notes)
    assert fit.estimates[K].value == pytest.approx(truth.hinge_stiffness_nm_per_rad, rel=0.02)


# -- the swing's derivatives and closed form ------------------------------------------------
def test_the_jacobian_is_the_swings_own_from_its_variational_equations():
    """The derivatives of an in-plane swing with Coulomb friction in its six values, from one
    integration, against central differences of 1e-3 at a tolerance 100 times tighter (their
    own error about 1e-6): within 2e-5 of each column's size. The forward differences of 3e-5
    they replace were 2e-4 off."""
    truth = synthetic.IN_PLANE_HINGE
    rig = hingeswing.HingeRig(truth.inertia_kgm2, truth.gravity, truth.mass_kg, truth.com_m)
    t = np.arange(0.0, 1.2, 1 / 240)
    p = np.array([9.9e-4, 8.2e-6, math.radians(-80.0), math.radians(-150.0), 0.0, 2e-6])
    width = 0.05
    theta, d = hingeswing.swing_sensitivities(t, p, rig, width)
    try:
        hingeswing.RTOL, hingeswing.ATOL = 1e-12, 1e-14
        ref = np.column_stack([(hingeswing.simulate_hinge(t, p + np.eye(6)[i] * h, rig, width)
                                - hingeswing.simulate_hinge(t, p - np.eye(6)[i] * h, rig, width)) / (2 * h)
                               for i, h in enumerate(1e-3 * np.maximum(np.abs(p), [0, 0, 1, 1, 1, 0]))])
        exact = hingeswing.simulate_hinge(t, p, rig, width)
    finally:
        hingeswing.RTOL, hingeswing.ATOL = 1e-10, 1e-12
    assert np.max(np.abs(theta - exact)) < 1e-8
    err = np.linalg.norm(d - ref, axis=0) / np.linalg.norm(ref, axis=0)
    assert np.all(err < 2e-5), err


@pytest.mark.parametrize("k, b", [(1.6e-4, 2.1e-6), (1.6e-4, 2 * math.sqrt(1.6e-4 * 8.5e-7)), (1.6e-4, 5e-5)],
                         ids=["under-damped", "critically damped", "over-damped"])
def test_the_linear_swing_in_closed_form_is_the_integrated_one(k, b):
    """Out of plane and without Coulomb friction the swing is linear: its closed form agrees with
    LSODA at a relative tolerance of 1e-12 within 1e-9 rad, whatever its damping."""
    rig = hingeswing.HingeRig(8.5e-7)
    t = np.linspace(0.0, 8.0, 481)
    p = np.array([k, b, math.radians(95.0), math.radians(130.0), -0.3])
    assert hingeswing.is_linear(p, rig)
    try:
        hingeswing.RTOL, hingeswing.ATOL = 1e-12, 1e-14
        integrated = hingeswing._integrate(t, p, rig, 0.0, sensitivities=False)[:, 0]
    finally:
        hingeswing.RTOL, hingeswing.ATOL = 1e-10, 1e-12
    assert np.max(np.abs(hingeswing.linear_swing(t, p, rig.inertia_kgm2) - integrated)) < 1e-9


def test_a_jacobian_of_the_integrated_swing_is_one_integration(monkeypatch):
    """A Jacobian of the integrated swing (in plane: the weight's moment makes it nonlinear) is
    one integration, its variational equations; the forward differences it replaced took one
    per dynamic value and one more (6)."""
    truth = synthetic.IN_PLANE_HINGE
    t, x, y = synthetic.hinge_swing_track(truth, np.random.default_rng(0))
    solved = []
    solve = hinge._Swing.solve
    monkeypatch.setattr(hinge._Swing, "solve", lambda self, q0: solved.append((self, q0)) or solve(self, q0))
    hinge.fit_hinge(t, x, y, hingeswing.HingeRig(truth.inertia_kgm2, truth.gravity, truth.mass_kg, truth.com_m),
                    coulomb="off")
    problem, q0 = solved[0]
    calls = []
    odeint = hingeswing.integrate.odeint
    monkeypatch.setattr(hingeswing.integrate, "odeint", lambda *a, **k: calls.append(a[1].size) or odeint(*a, **k))
    jac = problem.jacobian(q0)
    assert calls == [2 + 2 * 5]               # the swing and its derivatives in k, b, theta0, start angle, rate
    assert jac.shape == (2 * len(problem.t), len(q0)) and np.all(np.isfinite(jac))


# -- a long fit on a terminal -------------------------------------------------------------------
def _on_a_terminal(args: list[str]):
    """``locust ARGS`` with its stderr on a pseudo-terminal (progress draws a bar there), stdout a pipe."""
    primary, secondary = pty.openpty()
    env = {**os.environ, "COLUMNS": "200"}
    proc = subprocess.Popen([sys.executable, "-m", "locust.commands", *args], stdout=subprocess.PIPE,
                            stderr=secondary, env=env)
    os.close(secondary)
    return proc, primary


def _read_until(fd: int, pattern: str, limit_s: float = 120.0) -> str:
    """What the terminal shows until ``pattern`` appears (or the process closes it)."""
    seen, deadline = "", time.monotonic() + limit_s
    while not re.search(pattern, seen) and time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 1.0)
        if ready:
            try:
                chunk = os.read(fd, 4096)
            except OSError:
                break
            if not chunk:
                break
            seen += chunk.decode(errors="replace")
    return seen


def test_a_long_fit_shows_its_progress_and_ctrl_c_ends_it_with_an_error(shared_data, tmp_path):
    """The whole 52 s film (1573 samples): the bar names the stage and counts the swing's
    evaluations while the fit runs (it stood at 0/1 through all of it); Ctrl-C then gives one
    `error:` and exit 2 (was: `Aborted!`, exit 1), nothing written."""
    robot = tmp_path / "robot.toml"
    proc, fd = _on_a_terminal(["calibrate", "hinge", str(shared_data.joinpath(*FILM)), "--units", "mm",
                               "--inertia-kgm2", "1e-4", *MASS, "--no-plot", "--write", str(robot)])
    try:
        shown = _read_until(fd, r"fitting hinge swing \(viscous fit\): evaluations of the swing\s+\d+\s+0:\d\d elapsed")
        assert re.search(r"\(viscous fit\): evaluations of the swing\s+[1-9]\d*\s", shown), shown
        proc.send_signal(signal.SIGINT)
        shown += _read_until(fd, r"hint:.*\n")
        assert proc.wait(timeout=60) == 2
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(fd)
    assert re.search(r"error: interrupted: the hinge fit stopped after 0:\d\d; nothing was fitted or written", shown)
    assert "hint: run it again; a long recording fits sooner in a window of it (--start-s, --end-s)" in shown
    assert "Aborted" not in shown and "Traceback" not in shown
    assert not robot.exists()
