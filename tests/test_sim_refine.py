"""The coarse step refined where the floor contacts change (locust.sim.refine)."""

import numpy as np
import pytest

from locust.errors import SimError
from locust.params import preset
from locust.sim.audit import audit
from locust.sim.hops import summarise
from locust.sim.model import build
from locust.sim.refine import simulate_refined
from locust.sim.rollout import roll_out
from locust.sim.schedule import control_plan


def _refined(robot, dt, fine_s, window_s, cycles):
    robot = robot.with_values({"solver.timestep_s": dt})
    built = build(robot)
    return simulate_refined(built, control_plan(robot.schedule, robot.solver, cycles), fine_s, window_s)


def test_the_seed_at_4_ms_refined_is_converged_at_fewer_steps_than_1_ms():
    """Seed, 3 hops: 4 ms refined to 0.5 ms for 40 ms after each contact change lands within
    0.016 mm a hop of rk4 at 0.25 ms (uniform 1 ms: 0.072 mm; uniform 2 ms: 0.215) in 2,318
    model steps against uniform 1 ms's 4,400 (docs/performance.md: the seed as it was measured,
    its loop fold unsprung; sprung as stiff as its beam-stiff hinges, the refined route lands
    0.051 mm a hop off and uniform 1 ms 0.036 mm)."""
    seed = preset("seed").with_values({"folds.loop_stiffness_nm_per_rad": 0.0, "folds.loop_damping_nms_per_rad": 0.0})
    truth = summarise(roll_out(seed.with_values({"solver.timestep_s": 2.5e-4}), cycles=3))
    out = _refined(seed, 4e-3, 5e-4, 0.04, cycles=3)
    assert audit(out.trajectory).valid
    got = summarise(out.trajectory)
    assert abs(got.distance_m - truth.distance_m) / 3 < 0.03e-3          # a refinement that did nothing: > 0.2 mm
    assert abs(got.max_nose_height_m - truth.max_nose_height_m) < 0.02e-3
    assert out.model_steps < 2500 and out.fine_steps > 0
    assert out.trajectory.sensordata.shape[0] == control_plan(seed.schedule, seed.solver, 3).nstep // 4   # 4 ms rows


def test_refined_at_its_own_step_is_the_plain_run():
    """A fine step equal to the step: the same positions as ``simulate`` (each refinement
    restarts the solver's warm start, so they agree to the solver's tolerance, not bit for bit)."""
    seed = preset("seed")
    built = build(seed)
    plain = roll_out(seed, cycles=1, built=built)
    out = simulate_refined(built, plain.plan, seed.solver.timestep_s, 0.04)
    s = built.sensors
    for cols in (s.chassis_pos, s.nose_pos, s.foot_pos):
        # within 0.1 um (the solver's tolerance); a row out of place would be millimetres off
        assert np.abs(out.trajectory.sensordata[:, cols] - plain.sensordata[:, cols]).max() < 1e-7
    # (1.4e-7 rad on the knee and ankle, the loop fold's spring coupling them to the servo)
    assert out.trajectory.final_qpos == pytest.approx(plain.final_qpos, abs=1e-6)
    assert out.fine_steps > 0      # the settle's touchdown was taken again


def test_a_fine_step_that_does_not_divide_the_step_is_refused():
    seed = preset("seed")
    with pytest.raises(SimError, match="does not divide"):
        _refined(seed, 1e-3, 3e-4, 0.04, cycles=1)
