"""Robust evaluation speed: one design's draws of its uncertain values in one batched call,
against the same draws simulated one at a time.

    python bench/robust_speed.py [--draws 32] [--cycles 3] [--preset medium] [--repeat 3]

1. ``locust.sim.samples.sample``: every draw built, simulated in one ``mujoco.rollout`` call
   on every core, audited and summarised (what ``locust sim --samples`` runs).
2. The same call for one draw: what a draw costs alone, batched or not.
3. ``locust.simulate`` on each drawn robot in turn: the same draws one at a time (one core).

The draws' figures must agree between 1 and 3 (the same physics, batched or not); timings are
best of ``--repeat``, taken in this one run, interleaved. Last line:
``robust: <N> draws in <S> s, <R>x the draws one at a time`` (R: time of 3 over time of 1).
"""

from __future__ import annotations

import argparse
import math
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import locust
from locust.errors import GeometryError
from locust.params import preset
from locust.sim.rollout import available_cores
from locust.sim.samples import draw, sample, uncertain_values


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def one_at_a_time(robots, cycles: int) -> list:
    """``locust.simulate`` on each robot; None for one whose linkage cannot close."""
    out = []
    for r in robots:
        try:
            out.append(locust.simulate(r, cycles=cycles))
        except GeometryError:
            out.append(None)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--draws", type=int, default=32)
    ap.add_argument("--cycles", type=int, default=3)
    ap.add_argument("--preset", default="medium")
    ap.add_argument("--repeat", type=int, default=3, help="best of this many (the machine is shared and noisy)")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                    help="a robot value, as locust's --set (e.g. solver.timestep_s=0.005 with "
                         "solver.refine_timestep_s=0.001: the refined route)")
    args = ap.parse_args()
    robot = preset(args.preset)
    robot = robot.with_values(dict(kv.split("=", 1) for kv in args.sets))
    n, cycles = args.draws, args.cycles
    print(f"{args.preset}: {n} draws of its {len(uncertain_values(robot))} uncertain values, "
          f"{cycles} hops, {robot.solver.integrator} at {robot.solver.timestep_s:g} s; "
          f"{available_cores()} cores; load average {os.getloadavg()[0]:.1f}")

    best = {"batch": math.inf, "one": math.inf, "serial": math.inf}
    spread = serial = None
    for _ in range(args.repeat):
        t, spread = timed(lambda: sample(robot, n, cycles=cycles))
        best["batch"] = min(best["batch"], t)
        t, _ = timed(lambda: sample(robot, 1, cycles=cycles))
        best["one"] = min(best["one"], t)
        t, serial = timed(lambda: one_at_a_time(draw(robot, n), cycles))
        best["serial"] = min(best["serial"], t)

    same = all((math.isnan(a) and (s is None or not s.valid)) or (s is not None and s.valid and a == s.distance_m)
               for a, s in zip(spread.distance_m, serial))
    print(f"{'evaluation':44s} {'time_s':>7s} {'per draw_s':>10s}")
    print(f"{f'{n} draws, one batched call (all cores)':44s} {best['batch']:7.3f} {best['batch'] / n:10.4f}")
    print(f"{'1 draw, the same call':44s} {best['one']:7.3f} {best['one']:10.4f}")
    print(f"{f'{n} draws, locust.simulate one at a time':44s} {best['serial']:7.3f} {best['serial'] / n:10.4f}")
    print(f"{spread.n_valid} of {n} draws valid; distance {spread.distance_m_mean * 1000:.2f} +- "
          f"{spread.distance_m_sd * 1000:.2f} mm; batched and one-at-a-time figures "
          f"{'identical' if same else 'DIFFER'}")
    print(f"batch of {n} against one draw: {best['batch'] / best['one']:.1f}x the time of one")
    print(f"robust: {n} draws in {best['batch']:.2f} s, {best['serial'] / best['batch']:.1f}x the draws one at a time")


if __name__ == "__main__":
    main()
