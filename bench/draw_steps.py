"""Which time step a design's draws need: each step's time, and how many draws it converges.

    python bench/draw_steps.py [--preset medium] [--draws 32] [--cycles 3] [--steps 4e-3,2e-3,1e-3,5e-4,2.5e-4]
                               [--refined 4e-3,5e-4,0.04]

The same draws of the preset's uncertain values (``locust.sim.samples.sample``, seed 0) at
each step, in one batched call each. For every step against the next finer one (its dt/2
when the steps halve): how many draws are converged by ``locust sim --check-convergence``'s
rule (distance within 1 % or 0.1 mm a hop, highest nose point within 1 % or 0.1 mm), the
worst change, and how many draws keep their outcome class (goes over / rears and returns /
stays low) against the finest step's. A draw that is not converged at any step (a rearing
robot whose highest nose point moves by millimetres each time the step is halved, a robot
whose tumble after going over ends somewhere else) is listed with its figures. With
``--refined``, the same draws on ``locust.sim.refine``'s route (a coarse step taken again at a
fine one where the floor contacts change), against itself with both steps halved and against
the finest step.

Last line: ``draw steps: <preset> <N> draws: <dt> s <k>/<N> converged, <c>/<N> same class, ...``.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from types import SimpleNamespace

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

from locust.errors import GeometryError
from locust.params import preset, problems
from locust.sim.audit import audit
from locust.sim.hops import summarise
from locust.sim.outcome import classify
from locust.sim.rollout import roll_out
from locust.sim.run import CONVERGED_MM, CONVERGED_REL
from locust.sim.samples import draw, sample


def converged(coarse, fine, cycles: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per draw: converged by the dt/2 rule, distance change [mm per hop], nose change [mm]."""
    d_c, d_f = np.array(coarse.distance_m), np.array(fine.distance_m)
    n_c, n_f = np.array(coarse.max_nose_height_m), np.array(fine.max_nose_height_m)
    dist_mm, nose_mm = np.abs(d_c - d_f) * 1000 / cycles, np.abs(n_c - n_f) * 1000
    dist_rel, nose_rel = np.abs(d_c - d_f) / np.abs(d_f), np.abs(n_c - n_f) / np.abs(n_f)
    ok = (((dist_rel <= CONVERGED_REL) | (dist_mm <= CONVERGED_MM))
          & ((nose_rel <= CONVERGED_REL) | (nose_mm <= CONVERGED_MM)))
    return ok, dist_mm, nose_mm


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", default="medium")
    ap.add_argument("--draws", type=int, default=32)
    ap.add_argument("--cycles", type=int, default=3)
    ap.add_argument("--steps", default="4e-3,2e-3,1e-3,5e-4,2.5e-4",
                    help="time steps [s], coarse to fine; the last is the reference for the classes")
    ap.add_argument("--refined", metavar="STEP,FINE,WINDOW",
                    help="also the same draws on locust.sim.refine's route, e.g. 4e-3,5e-4,0.04 [s]")
    args = ap.parse_args()
    steps = sorted((float(s) for s in args.steps.split(",")), reverse=True)
    robot, n, cycles = preset(args.preset), args.draws, args.cycles
    print(f"{args.preset}: {n} draws, {cycles} hops, {robot.solver.integrator}, its own step "
          f"{robot.solver.timestep_s:g} s; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    spreads, walls = {}, {}
    for dt in steps:
        t0 = time.perf_counter()
        spreads[dt] = sample(robot.with_values({"solver.timestep_s": dt}), n, cycles=cycles)
        walls[dt] = time.perf_counter() - t0
    finest = spreads[steps[-1]]
    print(f"{'step_s':>8s} {'wall_s':>7s} {'valid':>5s} {'vs':>8s} {'converged':>9s} {'worst mm/hop':>12s} "
          f"{'worst nose mm':>13s} {'same class':>10s}")
    summary = []
    for coarse, fine in zip(steps[:-1], steps[1:]):
        s = spreads[coarse]
        ok, dist_mm, nose_mm = converged(s, spreads[fine], cycles)
        same = sum(a == b for a, b in zip(s.outcome, finest.outcome))
        print(f"{coarse:8.1e} {walls[coarse]:7.2f} {s.n_valid:5d} {fine:8.1e} {int(ok.sum()):6d}/{n:<2d} "
              f"{np.nanmax(dist_mm):12.3f} {np.nanmax(nose_mm):13.3f} {same:7d}/{n:<2d}")
        for k in np.flatnonzero(~ok):
            print(f"         draw {k:2d}: {s.outcome[k]} / {spreads[fine].outcome[k]}; distance "
                  f"{s.distance_m[k] * 1000:.2f} / {spreads[fine].distance_m[k] * 1000:.2f} mm, highest nose "
                  f"{s.max_nose_height_m[k] * 1000:.2f} / {spreads[fine].max_nose_height_m[k] * 1000:.2f} mm")
        summary.append(f"{coarse:g} s {int(ok.sum())}/{n} converged, {same}/{n} same class")
    print(f"{steps[-1]:8.1e} {walls[steps[-1]]:7.2f} {finest.n_valid:5d}")
    if args.refined:
        coarse, fine, window = (float(v) for v in args.refined.split(","))
        t0 = time.perf_counter()
        route = refined_spread(robot, n, cycles, coarse, fine, window)
        wall = time.perf_counter() - t0
        half = refined_spread(robot, n, cycles, coarse / 2, fine / 2, window)
        ok, dist_mm, nose_mm = converged(route, half, cycles)
        near, _, _ = converged(route, finest, cycles)
        same = sum(a == b for a, b in zip(route.outcome, finest.outcome))
        print(f"refined {coarse:g} s, {fine:g} s for {window:g} s (one draw at a time, {wall:.2f} s): converged at "
              f"dt/2 {int(ok.sum())}/{n} (worst {np.nanmax(dist_mm):.3f} mm/hop, nose {np.nanmax(nose_mm):.3f} mm), "
              f"within the rule of {steps[-1]:g} s {int(near.sum())}/{n}, same class {same}/{n}")
        for k in np.flatnonzero(~ok | ~near):
            print(f"         draw {k:2d}: {route.outcome[k]} / {half.outcome[k]} / {finest.outcome[k]}; distance "
                  f"{route.distance_m[k] * 1000:.2f} / {half.distance_m[k] * 1000:.2f} / "
                  f"{finest.distance_m[k] * 1000:.2f} mm, highest nose {route.max_nose_height_m[k] * 1000:.2f} / "
                  f"{half.max_nose_height_m[k] * 1000:.2f} / {finest.max_nose_height_m[k] * 1000:.2f} mm "
                  f"(refined / its dt/2 / {steps[-1]:g} s)")
        summary.append(f"refined {coarse:g}/{fine:g} s {int(ok.sum())}/{n} converged, {same}/{n} same class")
    print(f"draw steps: {args.preset} {n} draws: " + ", ".join(summary))


def refined_spread(robot, n: int, cycles: int, coarse: float, fine: float, window: float) -> SimpleNamespace:
    """The draws of ``sample`` (seed 0) on the refined route (``locust.sim.refine``), one at a
    time: distance, highest nose and outcome of each (nan / None: outside the limits, a
    linkage that cannot close, or an audit failed)."""
    out = SimpleNamespace(distance_m=[], max_nose_height_m=[], outcome=[])
    for r in draw(robot, n):
        r = r.with_values({"solver.timestep_s": coarse, "solver.refine_timestep_s": fine,
                           "solver.refine_window_s": window})
        summary = None
        if not problems(r, cycles):
            try:
                traj = roll_out(r, cycles=cycles)
                summary = summarise(traj) if audit(traj).valid else None
            except GeometryError:
                pass
        out.distance_m.append(summary.distance_m if summary else math.nan)
        out.max_nose_height_m.append(summary.max_nose_height_m if summary else math.nan)
        out.outcome.append(classify(summary.hops) if summary else None)
    return out


if __name__ == "__main__":
    main()
