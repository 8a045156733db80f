"""Single-design simulation speed: the notebook's own loop against locust's default, side by side.

The notebook's method is its Part 2 loop as written (per-step Python, ``data.site(name)``
lookups, Euler at dt = 1e-4 s, its own model). locust's is ``locust.sim.run.run`` on the
``seed`` preset (the hobby servo of docs/servo.md) at the package default, and a few other
routes on the same model so that what each choice buys, and costs in accuracy, is visible.
Every route runs the seed design for 3 hops on one core, and then each preset (seed, small,
medium, large) at its own default; all timings are taken in this one run, best of
``--repeat``. Accuracy: each route against itself at half the step (the convergence check
``locust sim --check-convergence`` makes) and against the converged reference (rk4 at 1/8 of
the default step). The refined routes (``locust.sim.refine``: a coarse step, taken again at a
fine one where the floor contacts change) halve both steps for their dt/2.

Last line: ``sim speedup <N>x at deviation <D>% (<M> mm per hop) vs dt/2``: N is the
notebook loop's time over the package default's, D and M the default's distance change at
dt/2.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parent))

from locust.params import preset
from locust.sim.audit import audit
from locust.sim.hops import summarise
from locust.sim.rollout import roll_out
from locust.sim.run import run
from notebook_reference import notebook_run

CYCLES = 3
PRESETS = ("seed", "small", "medium", "large")
ROUTES = [   # (name, solver overrides); the first is the package default
    ("locust default (rk4)", {}),
    ("implicitfast, same step", {"solver.integrator": "implicitfast"}),
    ("implicitfast, step / 10", {"solver.integrator": "implicitfast", "solver.timestep_s": None}),
    ("rk4, step x 2", {"solver.timestep_s": None}),
]


def robot_for(overrides: dict, scale: float = 1.0):
    base = preset("seed")
    dt = base.solver.timestep_s
    values = dict(overrides)
    if "solver.timestep_s" in values:
        values["solver.timestep_s"] = dt / 10 if values.get("solver.integrator") == "implicitfast" else dt * 2
    values["solver.timestep_s"] = values.get("solver.timestep_s", dt) * scale
    return base.with_values(values)


REFINED = [(4e-3, 5e-4, 0.04), (4e-3, 1e-3, 0.04)]   # (step, fine step, window after a contact change) [s]


def refined_run(robot, coarse: float, fine: float, window: float):
    """Build, simulate refined, audit and summarise: what ``run`` does, on the refined route.
    Returns (the hop summary, model steps taken)."""
    traj = roll_out(robot.with_values({"solver.timestep_s": coarse, "solver.refine_timestep_s": fine,
                                       "solver.refine_window_s": window}), cycles=CYCLES)
    if not audit(traj).valid:
        raise SystemExit(f"the refined route {coarse:g}/{fine:g} s failed its audit")
    return summarise(traj), traj.model_steps


def timed(fn, repeat: int):
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5,
                    help="best of this many runs of each route (the machine is shared and noisy)")
    args = ap.parse_args()

    default = preset("seed")
    ref = run(default.with_values({"solver.timestep_s": default.solver.timestep_s / 8}), cycles=CYCLES)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"reference: seed, rk4 at {default.solver.timestep_s / 8:g} s: {ref.distance_m * 1000:.3f} mm "
          f"({ref.distance_m * 1000 / CYCLES:.3f} mm per hop), nose {ref.max_nose_height_m * 1000:.3f} mm")
    nb_t, _ = timed(lambda: notebook_run(dt=1e-4, num_hops=CYCLES), args.repeat)
    print(f"{'route':34s} {'dt_s':>8s} {'time_s':>7s} {'speedup':>7s} {'mm/hop':>7s} "
          f"{'dt/2 %':>7s} {'dt/2 mm/hop':>11s} {'ref %':>6s}")
    print(f"{'notebook loop (its model, euler)':34s} {1e-4:8.1e} {nb_t:7.3f} {1.0:7.2f}")
    rows = []
    for name, overrides in ROUTES:
        robot = robot_for(overrides)
        t, r = timed(lambda robot=robot: run(robot, cycles=CYCLES), args.repeat)
        half = run(robot_for(overrides, 0.5), cycles=CYCLES)
        dev_half = abs(r.distance_m - half.distance_m) / abs(half.distance_m) * 100
        mm_half = abs(r.distance_m - half.distance_m) * 1000 / CYCLES
        dev_ref = abs(r.distance_m - ref.distance_m) / abs(ref.distance_m) * 100
        rows.append((name, nb_t / t, dev_half, mm_half))
        valid = "" if r.valid else "  INVALID: " + "; ".join(r.reasons)
        print(f"{name:34s} {robot.solver.timestep_s:8.1e} {t:7.3f} {nb_t / t:7.2f} {r.distance_m * 1000 / CYCLES:7.3f} "
              f"{dev_half:7.2f} {mm_half:11.3f} {dev_ref:6.2f}{valid}", flush=True)
    # the step refined where the floor contacts and the commands change (solver.refine_timestep_s)
    for coarse, fine, window in REFINED:
        name = f"rk4 {coarse * 1e3:g} ms, {fine * 1e3:g} ms at contacts"
        t, (r, steps) = timed(lambda c=coarse, f=fine, w=window: refined_run(default, c, f, w), args.repeat)
        half, _ = refined_run(default, coarse / 2, fine / 2, window)
        dev_half = abs(r.distance_m - half.distance_m) / abs(half.distance_m) * 100
        mm_half = abs(r.distance_m - half.distance_m) * 1000 / CYCLES
        dev_ref = abs(r.distance_m - ref.distance_m) / abs(ref.distance_m) * 100
        print(f"{name:34s} {coarse:8.1e} {t:7.3f} {nb_t / t:7.2f} {r.distance_m * 1000 / CYCLES:7.3f} "
              f"{dev_half:7.2f} {mm_half:11.3f} {dev_ref:6.2f}  ({steps} model steps)", flush=True)
    # every preset at its own default (its leg set's step), against the same notebook time
    print(f"{'preset (its default)':34s} {'dt_s':>8s} {'time_s':>7s} {'speedup':>7s} {'mm/hop':>7s} "
          f"{'dt/2 %':>7s} {'dt/2 mm/hop':>11s} {'nose dt/2 mm':>12s}")
    for name in PRESETS:
        robot = preset(name)
        t, r = timed(lambda robot=robot: run(robot, cycles=CYCLES), args.repeat)
        half = run(robot, cycles=CYCLES, timestep_s=robot.solver.timestep_s / 2)
        dev_half = abs(r.distance_m - half.distance_m) / abs(half.distance_m) * 100
        mm_half = abs(r.distance_m - half.distance_m) * 1000 / CYCLES
        nose_mm = abs(r.max_nose_height_m - half.max_nose_height_m) * 1000
        print(f"{name + ' (' + robot.solver.integrator + ')':34s} {robot.solver.timestep_s:8.1e} {t:7.3f} "
              f"{nb_t / t:7.2f} {r.distance_m * 1000 / CYCLES:7.3f} {dev_half:7.2f} {mm_half:11.3f} "
              f"{nose_mm:12.3f}", flush=True)
    _, speedup, dev, mm = rows[0]
    print(f"sim speedup {speedup:.1f}x at deviation {dev:.2f}% ({mm:.3f} mm per hop) vs dt/2")


if __name__ == "__main__":
    main()
