"""The supply's two models side by side: the static one (every default run) against the stepped
one (only where the supply limits the servos), their time and their figures.

For each leg set as built (its supply 5 V, 0.5 ohm, 1.5 A: not limiting) it times, best of
``--repeat``, in this one run:

- ``static``: ``locust.sim.run.run`` as every default run takes it (``mujoco.rollout``, the
  servos' numbers folded in once, ``sim/servo.py at_supply``);
- ``stepped``: the same robot forced through the stepped circuit (``sim/supply_rollout.py``,
  the rail solved before each physics step), the route a limiting supply takes; its figures
  against the static run's are what the static model leaves out on a supply that does not
  limit (the source's sag in the proportional band, where the duty is below 1);
- ``limited`` and ``browned out``: the same robot on a 0.8 A source (the limit binds) and on a
  0.7 A one (stalled, the plug falls below the servos' 3.5 V), each stepped.

It also times the check every build now makes (``supply_limits``) against the build itself,
and with ``--against DIR`` (another checkout's ``host`` folder: main's, before the supply was
modelled) the same default runs on that code in a subprocess, alternating with this one's.

Last line: ``supply: static <t> s, stepped <r>x, check <c> % of a build``.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from locust.params import preset
from locust.sim.audit import audit
from locust.sim.hops import summarise
from locust.sim.model import build
from locust.sim.rollout import simulate_built
from locust.sim.run import run
from locust.sim.schedule import control_plan
from locust.sim.supply import ServoSupply, supply_limits

CYCLES = 3
LEG_SETS = ("small", "medium", "large")


def timed(fn, repeat: int):
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def forced_stepped(robot):
    """``run``'s figures with the model stepped on its supply, whether it limits or not."""
    built = dataclasses.replace(build(robot), supply=ServoSupply((robot.servo,) * 2, robot.power))
    traj = simulate_built(built, control_plan(robot.schedule, robot.solver, CYCLES))
    if not audit(traj).valid:
        raise SystemExit(f"{robot.name}: the stepped run failed its audit")
    return summarise(traj)


TIME_DEFAULT = """
import time
from locust.params import preset
from locust.sim.run import run
best = {}
for name in %r:
    robot = preset(name)
    run(robot, cycles=%d)
    t0 = time.perf_counter()
    run(robot, cycles=%d)
    best[name] = time.perf_counter() - t0
print(repr(best))
"""


def default_times(host: Path) -> dict[str, float]:
    """One timed default run of each leg set on the code under ``host`` (a subprocess)."""
    code = TIME_DEFAULT % (LEG_SETS, CYCLES, CYCLES)
    env = {**os.environ, "PYTHONPATH": str(host)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return eval(out.stdout.strip().splitlines()[-1])   # our own repr of a dict of floats


def against(other: Path, repeat: int) -> None:
    """This code's default runs and ``other``'s, alternating, best of ``repeat`` each."""
    here = Path(__file__).resolve().parents[1] / "host"
    best = {"this": {}, "other": {}}
    for _ in range(repeat):
        for key, host in (("this", here), ("other", other)):
            for name, t in default_times(host).items():
                best[key][name] = min(best[key].get(name, float("inf")), t)
    for name in LEG_SETS:
        print(f"{name:8s} default run: this code {best['this'][name]:.3f} s, {other} {best['other'][name]:.3f} s: "
              f"{best['this'][name] / best['other'][name]:.3f}x")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3, help="best of this many runs of each (the machine is shared)")
    ap.add_argument("--against", type=Path, default=None, metavar="DIR",
                    help="another checkout's host folder: its default runs timed beside this one's")
    args = ap.parse_args()
    if args.against is not None:
        against(args.against, args.repeat)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; {CYCLES} hops a run")
    print(f"{'leg set':8s} {'route':12s} {'time_s':>7s} {'x static':>8s} {'nose mm':>8s} {'distance mm':>11s} "
          f"{'outcome':>18s}")
    ratios = []
    for name in LEG_SETS:
        robot = preset(name)
        t_static, r = timed(lambda robot=robot: run(robot, cycles=CYCLES), args.repeat)
        print(f"{name:8s} {'static':12s} {t_static:7.3f} {1.0:8.2f} {r.hops[0].nose_apex_m * 1e3:8.2f} "
              f"{r.distance_m * 1e3:11.2f} {r.outcome:>18s}")
        t, s = timed(lambda robot=robot: forced_stepped(robot), args.repeat)
        ratios.append(t / t_static)
        nose_mm = (r.hops[0].nose_apex_m - s.hops[0].nose_apex_m) * 1e3
        print(f"{'':8s} {'stepped':12s} {t:7.3f} {t / t_static:8.2f} {s.hops[0].nose_apex_m * 1e3:8.2f} "
              f"{s.distance_m * 1e3:11.2f}   (static - stepped: nose {nose_mm:+.2f} mm, "
              f"distance {(r.distance_m - s.distance_m) * 1e3:+.2f} mm)")
        for label, limit in (("limited", 0.8), ("browned out", 0.7)):
            weak = robot.with_values({"power.current_limit_a": limit})
            t, w = timed(lambda weak=weak: run(weak, cycles=CYCLES), args.repeat)
            print(f"{'':8s} {label:12s} {t:7.3f} {t / t_static:8.2f} {w.hops[0].nose_apex_m * 1e3:8.2f} "
                  f"{w.distance_m * 1e3:11.2f} {w.outcome:>18s}", flush=True)
    robot = preset("small")
    n = 20000
    t0 = time.perf_counter()
    for _ in range(n):
        supply_limits(robot.servo, robot.power)
    check = (time.perf_counter() - t0) / n
    t_build, _ = timed(lambda: build(robot), args.repeat)
    print(f"supply_limits: {check * 1e6:.2f} us a call; a build {t_build * 1e3:.1f} ms")
    print(f"supply: static {t_static:.3f} s, stepped {max(ratios):.2f}x, "
          f"check {check / t_build * 100:.4f} % of a build")


if __name__ == "__main__":
    main()
