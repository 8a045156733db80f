"""What the folds and sides cost a simulation: the default robot against the same robot with its
loop fold's spring off, with no loop tendon at all (the model before the folds were springs of
their own), and with one crank a tooth off (the two legs no longer alike), side by side.

Each leg set (small, medium, large) at its own default, the schedule's 6 hops, on one core;
the variants are timed in turn, round after round, each round starting one variant later (so
none is always first after a pause), best of ``--repeat`` (the machine is shared and noisy):
a drift in the machine's load reaches every variant alike. Timed: the rollout of a built
model (``locust.sim.rollout.simulate_built``), and apart from it the build.

Last line: ``fold speed: default <R>x the model without the loop tendon, <T>x with a crank a
tooth off`` (R, T: the worst ratio of rollout times over the leg sets; above 1 is slower).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

from locust.params import preset
from locust.sim.model import build, build_spec, compile_spec
from locust.sim.rollout import simulate_built
from locust.sim.schedule import control_plan

LEG_SETS = ("small", "medium", "large")
LOOP_OFF = {"folds.loop_stiffness_nm_per_rad": 0.0, "folds.loop_damping_nms_per_rad": 0.0}


def without_loop_tendon(robot):
    """The model as it was before the loop fold had a spring: no tendon at all."""
    spec, asms = build_spec(robot)
    for tendon in list(spec.tendons):
        spec.delete(tendon)
    return compile_spec(spec, asms, robot)


def variants(name: str) -> dict:
    robot = preset(name)
    return {
        "default": (robot, lambda: build(robot)),
        "loop spring off": (robot.with_values(LOOP_OFF), lambda: build(robot.with_values(LOOP_OFF))),
        "no loop tendon": (robot.with_values(LOOP_OFF), lambda: without_loop_tendon(robot.with_values(LOOP_OFF))),
        "left crank a tooth off": (robot.with_values({"left.crank_tooth": 1}),
                                   lambda: build(robot.with_values({"left.crank_tooth": 1}))),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=12, help="rounds; each variant's best is kept")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'leg set':8s} {'variant':24s} {'build_s':>8s} {'rollout_s':>9s} {'vs no tendon':>12s} {'vs default':>10s}")
    worst = {"default": 0.0, "left crank a tooth off": 0.0}
    for name in LEG_SETS:
        cases = variants(name)
        builts = {v: make() for v, (_, make) in cases.items()}
        plans = {v: control_plan(r.schedule, r.solver) for v, (r, _) in cases.items()}
        best_run = dict.fromkeys(cases, float("inf"))
        best_build = dict.fromkeys(cases, float("inf"))
        names = list(cases)
        for round_ in range(args.repeat):
            for v in names[round_ % len(names):] + names[:round_ % len(names)]:
                make = cases[v][1]
                t0 = time.perf_counter()
                make()
                t1 = time.perf_counter()
                simulate_built(builts[v], plans[v])
                t2 = time.perf_counter()
                best_build[v] = min(best_build[v], t1 - t0)
                best_run[v] = min(best_run[v], t2 - t1)
        base, default = best_run["no loop tendon"], best_run["default"]
        for v in cases:
            print(f"{name:8s} {v:24s} {best_build[v]:8.4f} {best_run[v]:9.4f} {best_run[v] / base:12.3f} "
                  f"{best_run[v] / default:10.3f}", flush=True)
        worst["default"] = max(worst["default"], default / base)
        tooth = "left crank a tooth off"
        worst[tooth] = max(worst[tooth], best_run[tooth] / base)
    print(f"fold speed: default {worst['default']:.3f}x the model without the loop tendon, "
          f"{worst['left crank a tooth off']:.3f}x with a crank a tooth off")


if __name__ == "__main__":
    main()
