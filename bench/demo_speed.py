"""What the demo's hops stage costs against the hops' own real time, hop by hop.

``locust demo``'s stage 2 runs ``locust hop --port sim ... --video`` once per leg set and
trial: the firmware under MicroPython paces the hop in real time (its timing is the record)
while the MuJoCo plant steps the model and renders the video. A hop cannot take less than
the firmware's schedule; everything above it is start-up (the command's imports, the
interpreter's boot, the handshake) and the plant's rendering when it lags behind the clock.
This runs the stage exactly as the demo does (the same commands, a fresh virtual robot
folder) and prints, per hop, its wall time, the schedule's duration, the video's frames and
the share of those frames that film the hop (from the first push to the robot at rest):

    MUJOCO_GL=osmesa python bench/demo_speed.py [--trials 2] [--cycles 3] [--report DEMO_RUN]

``--report DEMO_RUN`` also times the demo's report stage again on a finished demo folder
(``demo-out/run``: its hops, calibration and sweep), as ``locust demo`` calls it.
The machine's load average is printed with the figures (timings move with it).
The last line: ``hops stage: <S> s for <N> hops, <R>x the hops' real time, <F> frames``.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import tempfile
import time
from pathlib import Path

from locust.commands.demo import (
    CALIBRATIONS,
    HOP_TRUTH,
    RECORDINGS,
    REPORT_SAMPLES,
    Demo,
    recording_truth,
    seed_leg_set_options,
)
from locust.params import LEG_SETS


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=2, help="hops per leg set (the demo's default: 2)")
    ap.add_argument("--cycles", type=int, default=3, help="hop cycles (the demo's default: 3)")
    ap.add_argument("--report", type=Path, default=None, help="a finished demo folder whose report stage to time")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    truth = {**recording_truth([RECORDINGS / rec for _, rec, _ in CALIBRATIONS]), **HOP_TRUTH}
    truth_sets = [arg for key, value in truth.items() for arg in ("--set", f"{key}={value!r}")]
    with tempfile.TemporaryDirectory() as tmp:
        d = Demo(Path(tmp), open(os.devnull, "w"))
        t = time.perf_counter()
        d.call(["flash", "--port", "sim"])
        print(f"flash: {time.perf_counter() - t:.1f} s")
        total, real, frames = 0.0, 0.0, 0
        print(f"{'hop':>12} {'wall s':>7} {'schedule s':>10} {'ratio':>6} {'frames':>7} {'filming the hop':>15}")
        for name in LEG_SETS:
            for k in range(1, args.trials + 1):
                trial = Path(tmp) / f"{name}-{k}"
                t = time.perf_counter()
                d.call(["hop", "--port", "sim", *seed_leg_set_options(name), "--leg-set", name, *truth_sets,
                        "--cycles", str(args.cycles), "--video", str(trial / "hop.mp4"), "--out", str(trial)])
                wall = time.perf_counter() - t
                sched = json.loads((trial / "run.json").read_text())["schedule"]
                duration = sched["cycles"] * (sched["push_ms"] + sched["wait_ms"]) / 1000
                n, moving = hop_frames(trial / "hop.truth.csv")
                total, real, frames = total + wall, real + duration, frames + n
                print(f"{name + '-' + str(k):>12} {wall:7.2f} {duration:10.2f} {wall / duration:6.2f} {n:7d} "
                      f"{moving / n:14.0%}")
    if args.report is not None:
        run = args.report
        measured = [arg for name in LEG_SETS for trial in sorted(run.glob(f"hops/{name}-*"))
                    for arg in ("--measured", f"{name}={trial}")]
        cal = run / "calibration"
        with tempfile.TemporaryDirectory() as tmp:
            d = Demo(Path(tmp), open(os.devnull, "w"))
            t = time.perf_counter()
            d.call(["report", *measured, "--config", str(cal / "robot.toml"), "--sweep", str(run / "sweep"),
                    "--before", str(cal / "robot-bench.toml"), "--samples", str(REPORT_SAMPLES), "--out", tmp])
            print(f"report stage: {time.perf_counter() - t:.1f} s")
    print(f"load average {os.getloadavg()[0]:.2f}")
    print(f"hops stage: {total:.1f} s for {len(LEG_SETS) * args.trials} hops, {total / real:.2f}x the hops' "
          f"real time, {frames} frames")


if __name__ == "__main__":
    main()
