"""Sweep speed: the seed notebook's 30-design, 3-hop sweep against ``locust sweep``, side by side.

    python bench/sweep_speed.py [--grid-designs 1000] [--grid-cycles 1] [--skip-grid]

1. The notebook's way (``bench/notebook_sweep.py``): serial, a Python loop per step, its
   model as written (units bug, open linkage, no torque limit, dt 1e-4).
2. locust's way: ``run_sweep`` on the corrected seed model over the same 30 added lengths,
   3 cycles, every local core, each design checked and audited.
3. Equal work: the notebook's per-step loop and locust's ``mujoco.rollout`` on locust's own
   model for a few of the same designs, one core each, so the two methods are compared on
   identical physics (the notebook's model flies off after its blow-up and never touches the
   floor, which makes its steps cheap).
4. Throughput of a 4-parameter grid of at least 1,000 designs on every local core.

Last line: ``sweep speedup <R>x ...`` (R: notebook sweep wall time / locust sweep wall time).
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from locust.params import preset
from locust.sim.model import build
from locust.sim.rollout import initial_state, simulate_built
from locust.sim.schedule import control_plan
from locust.sweep.design import design_robot, parse_axis
from locust.sweep.execute import default_jobs
from locust.sweep.run import run_sweep
from notebook_sweep import notebook_sweep


def notebook_loop_on(built, plan) -> float:
    """The notebook's stepping style (Python loop, ``data.site`` every step) on a locust model."""
    model = built.model
    data = mujoco.MjData(model)
    state0, _ = initial_state(built)
    mujoco.mj_setState(model, data, state0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    t0 = time.perf_counter()
    max_h = 0.0
    for k in range(plan.nstep):
        data.ctrl[list(built.servo_actuators)] = plan.ctrl_rad[k]
        mujoco.mj_step(model, data)
        h = data.site("nose").xpos[2]
        if h > max_h:
            max_h = h
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--grid-designs", type=int, default=1000, help="designs in the 4-parameter grid (>= 1000)")
    ap.add_argument("--grid-cycles", type=int, default=1, help="hop cycles per grid design")
    ap.add_argument("--skip-grid", action="store_true")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                    help="a robot value, as locust's --set (e.g. solver.timestep_s=0.005 with "
                         "solver.refine_timestep_s=0.001: the refined route)")
    args = ap.parse_args()
    jobs = default_jobs()
    base = preset("seed")
    base = base.with_values(dict(kv.split("=", 1) for kv in args.sets))
    deltas = np.linspace(0.0, 0.05, 30)
    print(f"machine: {jobs} local cores; MuJoCo {mujoco.__version__}")

    t0 = time.perf_counter()
    nb = notebook_sweep(deltas)
    t_nb = time.perf_counter() - t0
    nb_best = max(nb, key=lambda r: r[1])
    print(f"notebook sweep   : {t_nb:7.1f} s for 30 designs, serial; its 'best' +{nb_best[0] * 100:.2f} cm, "
          f"{nb_best[1] * 100:.1f} cm, nose {nb_best[2] * 100:.1f} cm (blow-ups: its linkage is open)")

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        s = run_sweep(base, [parse_axis("scale=0:0.05:30", base)], cycles=3, out=Path(tmp) / "s", jobs=jobs,
                      plots=False)
        t_lo = time.perf_counter() - t0
    valid = [r for r in s.rows if r["valid"]]
    best = s.best
    print(f"locust sweep     : {t_lo:7.1f} s for 30 designs on {jobs} cores, dt {base.solver.timestep_s:g} s, "
          f"{len(valid)} valid; best +{best['scale'] * 100:.2f} cm, {best['distance_m'] * 100:.1f} cm, "
          f"nose {best['max_nose_height_m'] * 100:.1f} cm" if best else "no valid design")

    # equal work: the same designs and physics, one core, notebook loop vs rollout
    picks = [0.0, 0.01, 0.02]
    t_loop = t_roll = 0.0
    for d in picks:
        robot = design_robot(base, {"scale": d})
        built = build(robot)
        plan = control_plan(robot.schedule, robot.solver, 3)
        t_loop += notebook_loop_on(built, plan)
        t_roll += simulate_built(built, plan).wall_s
    print(f"equal work       : notebook loop {t_loop / len(picks):.2f} s/design, rollout {t_roll / len(picks):.2f} "
          f"s/design on one core ({t_loop / t_roll:.2f}x); with {jobs} cores "
          f"{t_loop / len(picks) * 30 / t_lo:.2f}x on the 30-design sweep")

    if not args.skip_grid:
        n = max(1000, args.grid_designs)
        k = math.ceil(n ** 0.25)
        axes = [parse_axis(f"scale=0:0.02:{k}", base), parse_axis(f"geometry.crank_start_deg=-100:-80:{k}", base),
                parse_axis(f"schedule.push_deg=-35:-25:{k}", base), parse_axis(f"schedule.push_s=0.2:0.4:{k}", base)]
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            g = run_sweep(base, axes, cycles=args.grid_cycles, out=Path(tmp) / "g", jobs=jobs, plots=False)
            t_g = time.perf_counter() - t0
        nv = sum(r["valid"] for r in g.rows)
        rate = len(g.rows) / t_g
        print(f"4-parameter grid : {len(g.rows)} designs ({nv} valid), {args.grid_cycles} cycle(s) each, "
              f"{t_g:.1f} s on {jobs} cores = {rate:.2f} designs/s; 10,000 designs would take "
              f"{10000 / rate / 60:.1f} min (goal < 10 min)")

    print(f"sweep speedup {t_nb / t_lo:.2f}x (notebook {t_nb:.1f} s serial vs locust {t_lo:.1f} s on {jobs} cores, "
          f"30 designs x 3 hops; goal 20x)")


if __name__ == "__main__":
    main()
