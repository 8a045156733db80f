"""Which measure of the host's stalls explains a virtual robot's late phases? Side by side.

One hop on a virtual robot run in this process (the real firmware under MicroPython), with
three watchers at once, each asked for every phase how much of its lateness the host caused:

- watch:    :class:`locust.device.stalls.StallWatch`, what ``locust hop`` records (the time the
            host held the interpreter off between the phase's commanded and measured start);
- runqueue: the interpreter's run-queue wait alone (``/proc/PID/schedstat``), added between the
            phase's commanded start and 2 ms after its measured start;
- sleeper:  a thread of this process that sleeps 1 ms and times how late it wakes, the latest
            wake from 15 ms before the phase's commanded start to 2 ms after its measured start.

A measure that explains the lateness gives the phase's lateness on a late phase and nothing
on one on time. Loads: ``--video`` (the MuJoCo plant renders, in this process), ``--hogs N``
CPU-bound processes, ``--stop MS`` (the interpreter stopped by SIGSTOP that long, from 20 ms
before cycle 2's wait is due). The interpreter has real-time scheduling where the host allows
it; run as a user without that privilege (``capsh --drop=cap_sys_nice -- -c "..."`` as root)
for a normal one.

    MUJOCO_GL=osmesa python bench/stall_measures.py [--cycles 4] [--video] [--hogs 2] [--stop 100]

The last line: ``largest |lateness - measure| over phases late by 1 ms or more: watch <W> ms,
runqueue <Q> ms, sleeper <S> ms; on time: watch <w> ms, runqueue <q> ms, sleeper <s> ms``.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from locust.device.flash import flash
from locust.device.hop import run_hop
from locust.device.link import Link
from locust.device.plant import RecordingPlant, make_plant
from locust.device.virtual import VirtualRobot
from locust.io import run_record
from locust.params import preset


class Sampler(threading.Thread):
    """Every millisecond: how late this thread woke, and the interpreter's run-queue wait [s]."""

    def __init__(self, vr: VirtualRobot):
        super().__init__(daemon=True)
        self.vr, self.rows, self.done = vr, [], threading.Event()

    def run(self) -> None:
        last = time.monotonic()
        while not self.done.is_set():
            time.sleep(0.001)
            now = time.monotonic()
            try:
                with open(f"/proc/{self.vr.interpreter_pid}/schedstat") as f:
                    wait_s = int(f.read().split()[1]) / 1e9
            except (OSError, ValueError, IndexError):
                wait_s = None
            self.rows.append((now, now - last - 0.001, wait_s))
            last = now

    def around(self, start_s: float, end_s: float) -> tuple[float, float]:
        """(run-queue wait added within [start, end + 2 ms], the latest wake from start - 15 ms to end + 2 ms) [s]."""
        waits = [w for t, _, w in self.rows if start_s <= t <= end_s + 0.002 and w is not None]
        late = [o for t, o, _ in self.rows if start_s - 0.015 <= t <= end_s + 0.002]
        return (max(waits) - min(waits) if waits else 0.0), max(late, default=0.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cycles", type=int, default=4)
    ap.add_argument("--video", action="store_true", help="the MuJoCo plant renders a video, in this process")
    ap.add_argument("--hogs", type=int, default=0, help="CPU-bound processes beside the hop")
    ap.add_argument("--stop", type=float, default=0.0, help="SIGSTOP the interpreter this long [ms]")
    args = ap.parse_args()
    schedule = run_record.HopSchedule(cycles=args.cycles, push_deg=-30.0, push_ms=300, wait_ms=1000, heartbeat_ms=2000)
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(args.hogs)]
    try:
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            with VirtualRobot(tmp / "flash", RecordingPlant()) as vr:
                flash(vr.device_path)
            plant = (make_plant("mujoco", preset("seed"), tmp / "hop.mp4" if args.video else None)
                     if args.video else RecordingPlant())
            with VirtualRobot(tmp / "flash", plant) as vr:
                sampler = Sampler(vr)
                sampler.start()

                def on_phase(p: run_record.Phase) -> None:
                    if args.stop and (p.cycle, p.phase) == (2, "push"):
                        start_s = time.monotonic() + (schedule.push_ms * 1000 - p.error_us) / 1e6 - 0.020

                        def stop() -> None:
                            time.sleep(max(0.0, start_s - time.monotonic()))
                            os.kill(vr.interpreter_pid, signal.SIGSTOP)
                            time.sleep(args.stop / 1000)
                            os.kill(vr.interpreter_pid, signal.SIGCONT)
                        threading.Thread(target=stop, daemon=True).start()

                with Link(vr.device_path) as link:
                    rec = run_hop(link, schedule, tmp / "run", on_phase=on_phase, stalls=vr.stalls)
                sampler.done.set()
                sampler.join()
                t0_s = vr.clock_of_ticks(rec.firmware_ticks_us[0])
                scheduling = vr.scheduling
    finally:
        for hog in hogs:
            hog.kill()
    print(f"{scheduling} scheduling, {'filmed' if args.video else 'no video'}, {args.hogs} CPU-bound processes"
          + (f", stopped {args.stop:g} ms" if args.stop else "") + f"; load average {os.getloadavg()[0]:.2f}")
    print(f"  {'phase':>10} {'late (ms)':>10} {'watch':>8} {'runqueue':>9} {'sleeper':>8}")
    worst = {"late": [0.0, 0.0, 0.0], "on time": [0.0, 0.0, 0.0]}
    for p in rec.phases:
        wait_s, late_s = sampler.around(t0_s + p.commanded_us / 1e6, t0_s + p.measured_us / 1e6)
        figures = [p.host_stall_us / 1000, wait_s * 1000, late_s * 1000]
        print(f"  {p.cycle:>4} {p.phase:>5} {p.error_ms:10.3f} {figures[0]:8.3f} {figures[1]:9.3f} {figures[2]:8.3f}")
        row = worst["late" if p.error_ms >= 1.0 else "on time"]
        for i, f in enumerate(figures):
            row[i] = max(row[i], abs(p.error_ms - f) if p.error_ms >= 1.0 else f)
    (lw, lq, ls), (ow, oq, os_) = worst["late"], worst["on time"]
    print(f"largest |lateness - measure| over phases late by 1 ms or more: watch {lw:.3f} ms, runqueue {lq:.3f} ms, "
          f"sleeper {ls:.3f} ms; on time: watch {ow:.3f} ms, runqueue {oq:.3f} ms, sleeper {os_:.3f} ms")


if __name__ == "__main__":
    main()
