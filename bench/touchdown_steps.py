"""A step refined only where a contact arrives or leaves: what it buys, measured.

    python bench/touchdown_steps.py [--preset seed] [--cycles 3] [--draws 32]

``locust.sim.refine``'s route (the coarse step, and where a step changes the number of floor
contacts, that step taken again from the state before it and the ``window`` after it at the
fine step) at several settings. Each route's figure is the chassis' forward position at the
end of the run (its free joint's x: what the distance is made of), against rk4 at 0.25 ms;
"its dt/2" halves both of the route's steps. Cost: model steps taken, against the uniform
1 ms run's (rk4 evaluates the model 4 times a step, whichever step it takes).
With ``--draws N`` the same on N draws of the preset's uncertain values: how many of them
each route converges by that figure.

Last line: ``touchdown steps: <preset> best <coarse>/<fine> ms: <E> mm off, <R>x fewer steps than 1 ms``:
the cheapest route converged by ``locust sim --check-convergence``'s rule (0.1 mm a hop or
1 %) both against the reference and at its dt/2.
"""

from __future__ import annotations

import argparse
import os

from locust.params import preset, problems
from locust.sim.rollout import roll_out
from locust.sim.run import CONVERGED_MM, CONVERGED_REL
from locust.sim.samples import draw

ROUTES = [  # (coarse step, fine step, window after a contact change) [s]
    (2e-3, 5e-4, 0.02), (2e-3, 5e-4, 0.04), (4e-3, 5e-4, 0.02), (4e-3, 5e-4, 0.04), (4e-3, 1e-3, 0.04),
]


def within(x_mm: float, other_mm: float, cycles: int) -> bool:
    """``locust sim --check-convergence``'s rule on the distance: 0.1 mm a hop or 1 %."""
    return abs(x_mm - other_mm) / cycles <= CONVERGED_MM or abs(x_mm - other_mm) <= CONVERGED_REL * abs(other_mm)


def uniform(robot, dt: float, cycles: int) -> tuple[float, int]:
    """Chassis x at the end [mm] and steps taken, of the package's own rollout at ``dt``."""
    traj = roll_out(robot.with_values({"solver.timestep_s": dt}), cycles=cycles)
    return float(traj.final_qpos[0]) * 1000, traj.sensordata.shape[0]



def refined(robot, coarse: float, fine: float, window: float, cycles: int) -> tuple[float, int]:
    """Chassis x at the end [mm] and model steps taken on ``locust.sim.refine``'s route."""
    traj = roll_out(robot.with_values({"solver.timestep_s": coarse, "solver.refine_timestep_s": fine,
                                       "solver.refine_window_s": window}), cycles=cycles)
    return float(traj.final_qpos[0]) * 1000, traj.model_steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", default="seed")
    ap.add_argument("--cycles", type=int, default=3)
    ap.add_argument("--draws", type=int, default=0,
                    help="also run the routes on this many draws of the preset's uncertain values")
    args = ap.parse_args()
    robot, cycles = preset(args.preset), args.cycles
    ref, _ = uniform(robot, 2.5e-4, cycles)
    print(f"{args.preset}, {cycles} hops, rk4; load average {os.getloadavg()[0]:.1f}; "
          f"reference (uniform 0.25 ms): chassis at {ref:.3f} mm")
    print(f"{'route':34s} {'mm off ref':>10s} {'dt/2 mm':>8s} {'steps':>6s} {'x fewer':>7s}")
    x1, n1 = uniform(robot, 1e-3, cycles)
    x1h, _ = uniform(robot, 5e-4, cycles)
    print(f"{'uniform 1 ms':34s} {x1 - ref:+10.3f} {x1 - x1h:+8.3f} {n1:6d} {1.0:7.2f}")
    best = None
    for coarse, fine, window in ROUTES:
        x, n = refined(robot, coarse, fine, window, cycles)
        xh, _ = refined(robot, coarse / 2, fine / 2, window, cycles)
        name = f"{coarse * 1e3:g} ms, {fine * 1e3:g} ms for {window * 1e3:g} ms"
        print(f"{name:34s} {x - ref:+10.3f} {x - xh:+8.3f} {n:6d} {n1 / n:7.2f}", flush=True)
        if within(x, ref, cycles) and within(x, xh, cycles) and (best is None or n < best[3]):
            best = (coarse, fine, x - ref, n)
    if args.draws:
        on_draws(robot, args.draws, cycles)
    if best:
        print(f"touchdown steps: {args.preset} best {best[0] * 1e3:g}/{best[1] * 1e3:g} ms: {best[2]:+.3f} mm off, "
              f"{n1 / best[3]:.2f}x fewer steps than 1 ms")
    else:
        print(f"touchdown steps: {args.preset} no route converged")


DRAW_ROUTES = [(4e-3, 5e-4, 0.04), (4e-3, 1e-3, 0.04)]


def on_draws(robot, n: int, cycles: int) -> None:
    """Uniform 1 ms and the refined routes on ``n`` draws of ``robot``'s uncertain values
    (``sim.samples.draw``, seed 0): how many draws each converges (at its own dt/2, and
    against uniform 0.25 ms), and its steps against uniform 1 ms's, summed over the draws."""
    robots = [r for r in draw(robot, n) if not problems(r, cycles)]
    routes = {"uniform 1 ms": (lambda r, h: uniform(r, 1e-3 * h, cycles))}
    for coarse, fine, window in DRAW_ROUTES:
        routes[f"{coarse * 1e3:g} ms, {fine * 1e3:g} ms for {window * 1e3:g} ms"] = (
            lambda r, h, c=coarse, f=fine, w=window: refined(r, c * h, f * h, w, cycles))
    tally = {name: [0, 0, 0] for name in routes}   # converged at dt/2, within the reference, steps
    for r in robots:
        ref, _ = uniform(r, 2.5e-4, cycles)
        for name, fn in routes.items():
            (x, steps), (xh, _) = fn(r, 1.0), fn(r, 0.5)
            tally[name][0] += within(x, xh, cycles)
            tally[name][1] += within(x, ref, cycles)
            tally[name][2] += steps
    print(f"{len(robots)} draws: {'route':34s} {'converged at dt/2':>17s} {'within 0.25 ms':>14s} {'x fewer':>7s}")
    uniform_steps = tally["uniform 1 ms"][2]
    for name, (conv, near, steps) in tally.items():
        print(f"{'':10s}{name:34s} {conv:11d}/{len(robots):<5d} {near:8d}/{len(robots):<5d} "
              f"{uniform_steps / steps:7.2f}", flush=True)


if __name__ == "__main__":
    main()
