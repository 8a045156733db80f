"""Single-design simulation speed: the notebook's method against locust's routes, side by side.

The notebook's method is its Part 2 loop (per-step Python, ``data.site(name)`` lookups,
dt = 1e-4 s). The reference for accuracy is the same notebook model at half the step
(dt = 5e-5 s). Each locust route runs the same design (the ``seed-notebook`` physics) through
``mujoco.rollout`` with one change, so what each change buys is visible. All timings are
taken in this one run, interleaved, best of ``--repeat``.

Last line: ``sim speedup <R>x, deviation <D>% vs dt/2 reference`` for the fastest route whose
deviation is within 1 % (or, if none is, the most accurate route, said plainly).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from notebook_reference import notebook_run  # noqa: E402

from locust.params import preset  # noqa: E402
from locust.sim.model import build  # noqa: E402
from locust.sim.rollout import simulate_built  # noqa: E402
from locust.sim.schedule import control_plan  # noqa: E402

ROUTES = [
    ("rollout, notebook settings (euler, dt 1e-4)", {}),
    ("rollout + implicitfast", {"solver.integrator": "implicitfast"}),
    ("rollout + 5 solver iterations, tol 1e-6", {"solver.iterations": 5, "solver.tolerance": 1e-6}),
    ("rollout + no self-collision (contact geometry)", {"contact.self_collision": False}),
    ("rollout + implicitfast, dt 2e-4", {"solver.integrator": "implicitfast", "solver.timestep_s": 2e-4}),
    ("rollout + rk4, dt 2e-4", {"solver.integrator": "rk4", "solver.timestep_s": 2e-4}),
    ("rollout, dt 5e-5 (converged)", {"solver.timestep_s": 5e-5}),
]


def time_route(overrides: dict, repeat: int) -> tuple[float, float]:
    robot = preset("seed-notebook").with_values(overrides) if overrides else preset("seed-notebook")
    built = build(robot)
    plan = control_plan(robot.schedule, robot.solver)
    best, dist = float("inf"), float("nan")
    for _ in range(repeat):
        t0 = time.perf_counter()
        traj = simulate_built(built, plan)
        best = min(best, time.perf_counter() - t0)
        dist = float(traj.final_qpos[0] - traj.initial_sensordata[traj.built.sensors.chassis_pos][0])
    return best, dist


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()

    ref_dist, _ = notebook_run(dt=5e-5)
    print(f"reference: notebook model at dt 5e-5 s: {ref_dist * 100:.2f} cm")
    nb_best, nb_dist = float("inf"), float("nan")
    rows = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        nb_dist, _ = notebook_run(dt=1e-4)
        nb_best = min(nb_best, time.perf_counter() - t0)
    nb_dev = abs(nb_dist - ref_dist) / ref_dist * 100
    print(f"{'route':50s} {'time_s':>8s} {'speedup':>8s} {'dist_cm':>8s} {'dev_%':>6s}")
    print(f"{'notebook loop (python per step, dt 1e-4)':50s} {nb_best:8.3f} {1.0:8.2f} {nb_dist * 100:8.2f} {nb_dev:6.2f}")
    for name, overrides in ROUTES:
        t, dist = time_route(overrides, args.repeat)
        dev = abs(dist - ref_dist) / ref_dist * 100
        rows.append((name, t, nb_best / t, dist, dev))
        print(f"{name:50s} {t:8.3f} {nb_best / t:8.2f} {dist * 100:8.2f} {dev:6.2f}", flush=True)
    within = [r for r in rows if r[4] <= 1.0]
    if within:
        best = max(within, key=lambda r: r[2])
        print(f"best route within 1 %: {best[0]}")
    else:
        best = min(rows, key=lambda r: r[4])
        print(f"no route is within 1 % of the reference; most accurate: {best[0]}")
    print(f"sim speedup {best[2]:.2f}x, deviation {best[4]:.2f}% vs dt/2 reference")


if __name__ == "__main__":
    main()
