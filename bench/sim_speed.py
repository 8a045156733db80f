"""Single-design simulation speed: the notebook's own loop against locust's default, side by side.

The notebook's method is its Part 2 loop as written (per-step Python, ``data.site(name)``
lookups, Euler at dt = 1e-4 s, its own model). locust's is ``locust.sim.run.run`` on the
``seed`` preset (the hobby servo of docs/servo.md) at the package default, and a few other
routes on the same model so that what each choice buys, and costs in accuracy, is visible.
Every route runs the seed design for 3 hops on one core, and then each preset (seed, small,
medium, large) at its own default and on the refined route (rk4 at 5 ms, 1 ms for 10 ms after
each contact change and for 100 ms after each command change); all timings are taken in this one run, best of
``--repeat``. Accuracy: each route against itself with every step halved (the convergence
check ``locust sim --check-convergence`` makes) and against the converged reference (uniform
rk4 at 0.125 ms). The default and the other refined routes (``locust.sim.refine``: a coarse
step, taken again at a fine one where the floor contacts and the servo commands change) halve
both steps for their dt/2; each route's model steps are every step MuJoCo takes.

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
from locust.sim.rollout import roll_out
from locust.sim.run import run
from notebook_reference import notebook_run

CYCLES = 3
PRESETS = ("seed", "small", "medium", "large")
UNIFORM = {"solver.refine_timestep_s": 0.0}
REFINED = {"solver.timestep_s": 5e-3, "solver.refine_timestep_s": 1e-3, "solver.refine_window_s": 0.01,
           "solver.refine_command_window_s": 0.1}
ROUTES = [   # (name, solver values on the seed); the first is the package default
    ("locust default (rk4 1 ms, uniform)", {}),
    ("rk4 5 ms, 1 ms 10 ms / 100 ms at changes", REFINED),
    ("rk4 2 ms, uniform", {**UNIFORM, "solver.timestep_s": 2e-3}),
    ("implicitfast 1 ms, uniform", {**UNIFORM, "solver.timestep_s": 1e-3, "solver.integrator": "implicitfast"}),
    ("implicitfast 0.1 ms, uniform", {**UNIFORM, "solver.timestep_s": 1e-4, "solver.integrator": "implicitfast"}),
    ("rk4 4 ms, 0.5 ms for 40 ms at changes", {"solver.timestep_s": 4e-3, "solver.refine_timestep_s": 5e-4,
                                               "solver.refine_window_s": 0.04}),
    ("rk4 4 ms, 1 ms for 40 ms at changes", {"solver.timestep_s": 4e-3, "solver.refine_timestep_s": 1e-3,
                                             "solver.refine_window_s": 0.04}),
]


def halved(robot):
    """``robot`` with every step halved (``--check-convergence``'s dt/2)."""
    return robot.with_values(robot.solver.steps_scaled(0.5))


def model_steps(robot) -> int:
    """Every step MuJoCo takes in ``robot``'s run (coarse and fine)."""
    return roll_out(robot, cycles=CYCLES).model_steps


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
    ref = run(default.with_values({**UNIFORM, "solver.timestep_s": 1.25e-4}), cycles=CYCLES)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"reference: seed, rk4 at 0.125 ms, uniform: {ref.distance_m * 1000:.3f} mm "
          f"({ref.distance_m * 1000 / CYCLES:.3f} mm per hop), nose {ref.max_nose_height_m * 1000:.3f} mm")
    nb_t, _ = timed(lambda: notebook_run(dt=1e-4, num_hops=CYCLES), args.repeat)
    print(f"{'route':40s} {'dt_s':>8s} {'time_s':>7s} {'speedup':>7s} {'mm/hop':>7s} "
          f"{'dt/2 %':>7s} {'dt/2 mm/hop':>11s} {'ref %':>6s}")
    print(f"{'notebook loop (its model, euler)':40s} {1e-4:8.1e} {nb_t:7.3f} {1.0:7.2f}")
    rows = []
    for name, overrides in ROUTES:
        robot = default.with_values(overrides)
        t, r = timed(lambda robot=robot: run(robot, cycles=CYCLES), args.repeat)
        half = run(halved(robot), cycles=CYCLES)
        dev_half = abs(r.distance_m - half.distance_m) / abs(half.distance_m) * 100
        mm_half = abs(r.distance_m - half.distance_m) * 1000 / CYCLES
        dev_ref = abs(r.distance_m - ref.distance_m) / abs(ref.distance_m) * 100
        rows.append((name, nb_t / t, dev_half, mm_half))
        valid = "" if r.valid else "  INVALID: " + "; ".join(r.reasons)
        print(f"{name:40s} {robot.solver.timestep_s:8.1e} {t:7.3f} {nb_t / t:7.2f} {r.distance_m * 1000 / CYCLES:7.3f} "
              f"{dev_half:7.2f} {mm_half:11.3f} {dev_ref:6.2f}  ({model_steps(robot)} model steps){valid}", flush=True)
    # every preset at its own default and on the refined route, against the same notebook time
    print(f"{'preset (its default)':40s} {'dt_s':>8s} {'time_s':>7s} {'speedup':>7s} {'mm/hop':>7s} "
          f"{'dt/2 %':>7s} {'dt/2 mm/hop':>11s} {'nose dt/2 mm':>12s}")
    for name, (label, values) in ((n, r) for n in PRESETS for r in (("", {}), (", refined", REFINED))):
        robot = preset(name).with_values(values)
        t, r = timed(lambda robot=robot: run(robot, cycles=CYCLES), args.repeat)
        half = run(halved(robot), cycles=CYCLES)
        dev_half = abs(r.distance_m - half.distance_m) / abs(half.distance_m) * 100
        mm_half = abs(r.distance_m - half.distance_m) * 1000 / CYCLES
        nose_mm = abs(r.max_nose_height_m - half.max_nose_height_m) * 1000
        nose_pct = nose_mm / abs(half.max_nose_height_m * 1000) * 100
        print(f"{name + ' (' + robot.solver.integrator + label + ')':40s} {robot.solver.timestep_s:8.1e} {t:7.3f} "
              f"{nb_t / t:7.2f} {r.distance_m * 1000 / CYCLES:7.3f} {dev_half:7.2f} {mm_half:11.3f} "
              f"{nose_mm:12.3f} ({nose_pct:.2f} %)", flush=True)
    _, speedup, dev, mm = rows[0]
    print(f"sim speedup {speedup:.1f}x at deviation {dev:.2f}% ({mm:.3f} mm per hop) vs dt/2")


if __name__ == "__main__":
    main()
