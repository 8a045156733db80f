"""The coarse step refined where the floor contacts and the servo commands change
(``solver.refine_timestep_s``, locust.sim.refine)."""

import numpy as np
import pytest

from locust.errors import ParamsError
from locust.params import preset
from locust.sim.model import build
from locust.sim.rollout import roll_out, simulate_batch
from locust.sim.run import check_convergence, run
from locust.sim.samples import draw
from locust.sim.schedule import control_plan

REFINED = {"solver.timestep_s": 4e-3, "solver.refine_timestep_s": 5e-4, "solver.refine_window_s": 0.04}


def test_the_seed_at_4_ms_refined_lands_nearer_rk4_at_a_quarter_ms_than_uniform_4_ms():
    """Seed, its loop fold unsprung, 3 hops (docs/performance.md): 4 ms refined to 0.5 ms for
    40 ms lands 0.015 mm a hop and 0.005 mm of nose from rk4 at 0.25 ms; uniform 4 ms lands
    0.080 mm a hop and 0.026 mm off, uniform 1 ms 0.072 and 0.057."""
    seed = preset("seed").with_values({"folds.loop_stiffness_nm_per_rad": 0.0, "folds.loop_damping_nms_per_rad": 0.0})
    truth = run(seed.with_values({"solver.timestep_s": 2.5e-4}), cycles=3)
    robot = seed.with_values(REFINED)
    got = run(robot, cycles=3, keep_states=True)
    assert got.valid
    assert abs(got.distance_m - truth.distance_m) / 3 < 0.03e-3      # refining nothing: 0.080 mm
    assert abs(got.max_nose_height_m - truth.max_nose_height_m) < 0.015e-3   # 0.026 mm
    traj = got.trajectory
    plan = control_plan(robot.schedule, robot.solver, 3)
    assert plan.refined and traj.sensordata.shape[0] == plan.nstep     # the record on the 4 ms grid
    # fine windows taken, at under half the steps of uniform 0.5 ms (8 a row)
    assert plan.nstep < traj.model_steps < plan.nstep * 8 / 2


def test_each_model_of_a_batch_is_refined_at_its_own_contact_changes():
    """Three draws of medium in one batch on every core: each record is the draw's run alone,
    number for number (each model's windows are its own)."""
    robot = preset("medium").with_values(REFINED)
    draws = draw(robot, 3, seed=4)
    plan = control_plan(robot.schedule, robot.solver, 1)
    builts = [build(d) for d in draws]
    together = simulate_batch(builts, plan, threads=2)
    for b, t in zip(builts, together):
        alone = simulate_batch([b], plan, threads=1)[0]
        assert np.array_equal(alone.sensordata, t.sensordata)
        assert alone.model_steps == t.model_steps
    assert len({t.model_steps for t in together}) > 1      # the draws touch down at steps of their own


def test_check_convergence_halves_the_step_and_the_fine_step():
    robot = preset("small").with_values(REFINED)
    result = run(robot, cycles=1)
    conv = check_convergence(robot, result, cycles=1)
    half = run(robot.with_values({"solver.timestep_s": 2e-3, "solver.refine_timestep_s": 2.5e-4}), cycles=1)
    assert conv["half_timestep_s"] == 2e-3
    assert conv["half_distance_m"] == half.distance_m
    assert robot.solver.steps_scaled(0.5) == {"solver.timestep_s": 2e-3, "solver.refine_timestep_s": 2.5e-4}
    assert preset("small").solver.steps_scaled(0.5) == {"solver.timestep_s": 5e-4}   # uniform: its one step


def test_a_fine_step_that_does_not_divide_the_step_is_refused():
    robot = preset("seed").with_values({"solver.timestep_s": 1e-3, "solver.refine_timestep_s": 3e-4})
    with pytest.raises(ParamsError, match="does not divide"):
        run(robot, cycles=1)


def test_a_supply_that_limits_the_servos_is_stepped_uniformly_at_the_fine_step():
    """The supply is solved step by step in Python, not refined: a refined plan's record is
    the uniform fine run's, every eighth row, number for number."""
    limited = preset("small").with_values({"power.current_limit_a": 0.8})
    robot = limited.with_values(REFINED)
    coarse = roll_out(robot, cycles=1)
    assert coarse.built.supply is not None
    fine = roll_out(limited.with_values({"solver.timestep_s": 5e-4}), cycles=1)
    assert np.array_equal(coarse.sensordata, fine.sensordata[::8])
    assert coarse.model_steps == fine.sensordata.shape[0]
