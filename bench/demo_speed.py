"""What the demo's hops stage costs against the hops' own real time, one hop at a time and side by side.

``locust demo``'s stage 2 runs ``locust hop --port sim ... --video`` once per leg set and
trial: the firmware under MicroPython paces the hop in real time (its timing is the record)
while the MuJoCo plant steps the model and renders the video. A hop cannot take less than
the firmware's schedule; everything above it is start-up (the command's imports, the
interpreter's boot, the handshake) and the plant's rendering when it lags behind the clock.
This runs the stage as the demo does (the same commands, a fresh virtual robot folder), once
with one hop at a time and once with as many at once as the demo films (``hop_jobs``), and prints per hop the
video's frames, the share of them that film the hop (the foot away from where it stood and
from where it comes to rest), the firmware's worst phase start error, and the stage's wall
time against the hops' real time:

    MUJOCO_GL=osmesa python bench/demo_speed.py [--trials 2] [--cycles 3] [--report DEMO_RUN]

``--report DEMO_RUN`` also times the demo's report stage again on a finished demo folder
(``demo-out/run``: its hops, calibration and sweep), as ``locust demo`` calls it.
The machine's load average is printed with the figures (timings move with it).
The last line: ``hops stage: <S1> s one at a time, <S2> s <J> at once (<R>x); <T> s of hops``.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import tempfile
import time
from pathlib import Path

from locust.demo.runner import Demo
from locust.demo.story import REPORT_SAMPLES, hop_jobs
from locust.demo.virtual_robot import virtual_robot
from locust.io.robot_toml import save_robot
from locust.params import LEG_SETS
from locust.progress import progress


def hop_frames(truth_csv: Path) -> tuple[int, int]:
    """Frames in a video (its truth sidecar's rows), and those from the first in which the foot
    marker is more than 0.1 mm from where it stood to the last in which it is more than 0.1 mm
    from where it comes to rest."""
    with open(truth_csv) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    foot = [(float(r["foot_x_m"]), float(r["foot_z_m"])) for r in rows]

    def off(p, q):
        return abs(p[0] - q[0]) > 1e-4 or abs(p[1] - q[1]) > 1e-4

    first = next((i for i, p in enumerate(foot) if off(p, foot[0])), None)
    last = next((i for i in range(len(foot) - 1, -1, -1) if off(foot[i], foot[-1])), None)
    return len(rows), 0 if first is None or last is None else last - first + 1


def hops_stage(trials: int, cycles: int, jobs: int) -> tuple[float, float]:
    """The demo's flash and hops stages in a fresh folder, ``jobs`` hops at once; prints a row
    per hop. Returns the hops stage's wall time and the hops' real time [s]."""
    with tempfile.TemporaryDirectory() as tmp, open(os.devnull, "w") as quiet:
        truth = save_robot(virtual_robot(), Path(tmp) / "truth.toml")     # the demo's virtual robot
        d = Demo(Path(tmp), quiet)
        d.call(["flash", "--port", "sim"])
        trials_dirs = [(name, Path(tmp) / f"{name}-{k}") for name in LEG_SETS for k in range(1, trials + 1)]
        calls = [(["hop", "--port", "sim", "--config", str(truth), "--leg-set", name,
                   "--cycles", str(cycles), "--video", str(trial / "hop.mp4"), "--out", str(trial)],
                  (trial / "hop.mp4", trial / "run.json")) for name, trial in trials_dirs]
        t = time.perf_counter()
        with progress(length=len(calls), file=quiet) as bar:
            d.call_side_by_side(calls, jobs, bar)
        wall = time.perf_counter() - t
        real = 0.0
        print(f"  {'hop':>10} {'frames':>7} {'filming the hop':>15} {'worst start error':>18}")
        for _, trial in trials_dirs:
            run = json.loads((trial / "run.json").read_text())
            sched = run["schedule"]
            real += sched["cycles"] * (sched["push_ms"] + sched["wait_ms"]) / 1000
            n, moving = hop_frames(trial / "hop.truth.csv")
            print(f"  {trial.name:>10} {n:7d} {moving / n:15.0%} {run['jitter']['max_abs_ms']:15.3f} ms")
    return wall, real


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=2, help="hops per leg set (the demo's default: 2)")
    ap.add_argument("--cycles", type=int, default=3, help="hop cycles (the demo's default: 3)")
    ap.add_argument("--report", type=Path, default=None, help="a finished demo folder whose report stage to time")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    walls = {}
    at_once = hop_jobs(os.cpu_count() or 1)
    for jobs in (1, at_once):
        print(f"hops stage, {jobs} at a time:")
        walls[jobs], real = hops_stage(args.trials, args.cycles, jobs)
        print(f"  {walls[jobs]:.1f} s, {walls[jobs] / real:.2f}x the hops' real time ({real:.1f} s); "
              f"load average {os.getloadavg()[0]:.2f}")
    if args.report is not None:
        run = args.report
        measured = [arg for name in LEG_SETS for trial in sorted(run.glob(f"hops/{name}-*"))
                    for arg in ("--measured", f"{name}={trial}")]
        cal = run / "calibration"
        with tempfile.TemporaryDirectory() as tmp, open(os.devnull, "w") as quiet:
            t = time.perf_counter()
            Demo(Path(tmp), quiet).call(["report", *measured, "--config", str(cal / "robot.toml"),
                                         "--sweep", str(run / "sweep"), "--before", str(cal / "robot-bench.toml"),
                                         "--samples", str(REPORT_SAMPLES), "--out", tmp])
            print(f"report stage: {time.perf_counter() - t:.1f} s; load average {os.getloadavg()[0]:.2f}")
    print(f"hops stage: {walls[1]:.1f} s one at a time, {walls[at_once]:.1f} s {at_once} at once "
          f"({walls[1] / walls[at_once]:.2f}x); {real:.1f} s of hops")


if __name__ == "__main__":
    main()
