"""How many virtual robots can hop at once and keep the firmware's clock within 2 ms?

``locust demo`` films several hops on the virtual robot at once (``HOP_JOBS``). Each hop is
the firmware under MicroPython timing its phases on this machine's clock, beside the MuJoCo
plant stepping the model and, with a video, rendering it on the CPU. A machine that does not
run the interpreter when a phase is due makes that phase late. This runs the demo's hops (the
same commands, a fresh virtual robot folder: Small, Medium and Large, ``--trials`` each) one at
a time and two at once, with and without video, one configuration after the other in one run,
and prints for each the worst phase start error over its hops, the worst host stall the run
records say (the time the host held the interpreter off while a phase was due,
``host_stall_max_s``), and how many hops had a phase more than 2 ms late:

    MUJOCO_GL=osmesa python bench/hop_timing.py [--trials 2] [--cycles 3] [--repeats 1]

The interpreter gets real-time scheduling where the host allows it (root or CAP_SYS_NICE) and
a normal one elsewhere; the scheduling the hops had is printed, with the load average. To see
a user's machine without that privilege, run it as one (e.g. ``capsh --drop=cap_sys_nice --
-c "python bench/hop_timing.py"`` as root). The last line:
``worst phase error: 1 at once <A> ms (<B> ms filmed), 2 at once <C> ms (<D> ms filmed)``.
"""

from __future__ import annotations

import argparse
import os
import re
import tempfile
from pathlib import Path

from locust.demo.runner import Demo
from locust.demo.virtual_robot import virtual_robot
from locust.io import run_record
from locust.io.robot_toml import save_robot
from locust.params import LEG_SETS
from locust.progress import progress

BOUND_MS = run_record.TIMING_BOUND_US / 1000
SCHEDULING = re.compile(r"(\w+) scheduling\)")


def hops(trials: int, cycles: int, jobs: int, video: bool) -> dict:
    """The demo's hops in a fresh virtual robot folder, ``jobs`` at once; their worst phase start
    error [ms], worst host stall [ms], the hops over the bound, and the scheduling they had."""
    with tempfile.TemporaryDirectory() as tmp, open(os.devnull, "w") as quiet:
        truth = save_robot(virtual_robot(), Path(tmp) / "truth.toml")     # the demo's virtual robot
        d = Demo(Path(tmp), quiet)
        d.call(["flash", "--port", "sim"])
        trials_dirs = [(name, Path(tmp) / f"{name}-{k}") for name in LEG_SETS for k in range(1, trials + 1)]
        calls = [(["hop", "--port", "sim", "--config", str(truth), "--leg-set", name, "--cycles", str(cycles),
                   "--out", str(trial), *(["--video", str(trial / "hop.mp4")] if video else ["--plant", "mujoco"])],
                  (trial / "run.json",)) for name, trial in trials_dirs]
        with progress(length=len(calls), file=quiet) as bar:
            d.call_side_by_side(calls, jobs, bar)
        scheduling = set()
        for log in sorted(d.logs.glob("*-hop.log")):
            scheduling.update(SCHEDULING.findall(log.read_text()))
        worst_err = worst_stall = 0.0
        over = 0
        for _, trial in trials_dirs:
            rec = run_record.read_run_record(trial / "run.json")
            err = max(abs(p.error_ms) for p in rec.phases)
            worst_err = max(worst_err, err)
            worst_stall = max(worst_stall, (run_record.host_stall_max_s(rec.phases) or 0.0) * 1000)
            over += err > BOUND_MS
    return {"error_ms": worst_err, "stall_ms": worst_stall, "over": over, "hops": len(calls),
            "scheduling": "/".join(sorted(scheduling))}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--trials", type=int, default=2, help="hops per leg set (the demo's default: 2)")
    ap.add_argument("--cycles", type=int, default=3, help="hop cycles (the demo's default: 3)")
    ap.add_argument("--repeats", type=int, default=1, help="times each configuration runs, alternately")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {len(LEG_SETS) * args.trials} hops of "
          f"{args.cycles} cycles a configuration, {args.repeats} time(s) each, alternately")
    configs = [(video, jobs) for video in (False, True) for jobs in (1, 2)]
    worst: dict = {}
    for r in range(args.repeats):
        for video, jobs in configs:
            got = hops(args.trials, args.cycles, jobs, video)
            key = (video, jobs)
            prev = worst.get(key)
            if prev is None:
                worst[key] = got
            else:
                prev["error_ms"] = max(prev["error_ms"], got["error_ms"])
                prev["stall_ms"] = max(prev["stall_ms"], got["stall_ms"])
                prev["over"] += got["over"]
                prev["hops"] += got["hops"]
            print(f"  repeat {r + 1}, {'filmed' if video else 'no video'}, {jobs} at once: worst phase error "
                  f"{got['error_ms']:.3f} ms, host stall {got['stall_ms']:.3f} ms, {got['over']}/{got['hops']} hops "
                  f"over {BOUND_MS:g} ms ({got['scheduling']} scheduling); load average {os.getloadavg()[0]:.2f}")
    print(f"{'':12} {'1 at once':>34} {'2 at once':>34}")
    for video in (False, True):
        cells = [f"{worst[(video, j)]['error_ms']:8.3f} ms (stall {worst[(video, j)]['stall_ms']:7.3f}) "
                 f"{worst[(video, j)]['over']:2d}/{worst[(video, j)]['hops']:<2d}" for j in (1, 2)]
        print(f"{'filmed' if video else 'no video':12} {cells[0]:>34} {cells[1]:>34}")
    print(f"worst phase error: 1 at once {worst[(False, 1)]['error_ms']:.3f} ms ({worst[(True, 1)]['error_ms']:.3f} ms "
          f"filmed), 2 at once {worst[(False, 2)]['error_ms']:.3f} ms ({worst[(True, 2)]['error_ms']:.3f} ms filmed)")


if __name__ == "__main__":
    main()
