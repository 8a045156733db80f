"""Can the live simulation keep up with the virtual robot? Real-time factors, side by side.

For the seed robot (dt from its solver settings), the bang-bang schedule for ``--cycles``
cycles, driven at the 50 Hz control rate, timed alternately ``--repeats`` times each:

- rollout: ``locust sim``'s batch rollout (``mujoco.rollout``: no Python per step);
- live:    :class:`locust.sim.live.LiveSim`, ``mj_step`` one step at a time from Python;
- live+video: the same, rendering a 640x360 video at 30 fps (OSMesa, no shadows).

The real-time factor is simulated seconds per wall second (settle phase included); >= 1
keeps up with real time. The last line is ``realtime factor ...`` (best of the repeats)
with the ratios live/rollout and live+video/live.

    MUJOCO_GL=osmesa python bench/sim_live_speed.py [--cycles 2] [--repeats 3]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from locust.params import preset
from locust.sim.live import LiveSim  # importing locust.sim picks the offscreen GL backend
from locust.sim.rollout import roll_out


def drive(robot, cycles: int, video: Path | None) -> float:
    """Wall seconds for settle + ``cycles`` schedule cycles on a LiveSim."""
    sch, hz = robot.schedule, robot.solver.control_hz
    cycle_s = sch.push_s + sch.wait_s
    t = time.perf_counter()
    sim = LiveSim(robot, video_path=str(video) if video else None, fps=30, width=640, height=360, cycles=cycles)
    for i in range(int(cycles * cycle_s * hz + 1e-9)):
        angle = sch.push_deg if (i / hz) % cycle_s < sch.push_s else 0.0
        sim.set_servo_angles_deg(angle, angle)
        sim.advance_to((i + 1) / hz)
    out = sim.close()
    assert out["valid"], out["reasons"]
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cycles", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    robot = preset("seed")
    sim_s = robot.solver.settle_s + args.cycles * (robot.schedule.push_s + robot.schedule.wait_s)
    print(f"seed robot, dt {robot.solver.timestep_s:g} s, {sim_s:.2f} s simulated per run "
          f"({sim_s / robot.solver.timestep_s:.0f} steps)")
    best = {"rollout": float("inf"), "live": float("inf"), "live+video": float("inf")}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.repeats):
            t = time.perf_counter()
            roll_out(robot, cycles=args.cycles)
            best["rollout"] = min(best["rollout"], time.perf_counter() - t)
            best["live"] = min(best["live"], drive(robot, args.cycles, None))
            best["live+video"] = min(best["live+video"], drive(robot, args.cycles, Path(tmp) / f"live-{r}.mp4"))
    rtf = {k: sim_s / v for k, v in best.items()}
    for k, v in best.items():
        print(f"  {k:11s} {v:6.2f} s wall  real-time factor {rtf[k]:5.2f}")
    print(f"realtime factor rollout {rtf['rollout']:.2f} live {rtf['live']:.2f} live+video {rtf['live+video']:.2f}; "
          f"live/rollout {rtf['live'] / rtf['rollout']:.2f}, live+video/live {rtf['live+video'] / rtf['live']:.2f}")


if __name__ == "__main__":
    main()
