"""``locust demo``: the whole toolkit end to end on the virtual robot, as a student runs it.

The virtual robot is the robot as built with its uncertain values drawn once
(:mod:`locust.demo.virtual_robot`: a draw whose Medium and Large rear and come back down, as
the filmed robots did), hidden from everything but the virtual board. Each stage runs the real
command (``python -m locust.commands ...``, one child process each), so the demo exercises the
same code paths a user does:

1. ``locust flash --port sim``: the firmware into the demo's own virtual flash folder;
2. ``locust hop --port sim --leg-set NAME --video``: Small, Medium and Large hop on the virtual
   robot (the firmware under MicroPython driving the MuJoCo model), filmed;
3. ``locust track``: nose and foot tracks from those videos;
4. ``locust calibrate hinge|servo|ramp``: the virtual robot's parts on the bench
   (:mod:`locust.demo.bench`, SYNTHETIC recordings) into a new ``robot.toml``, which starts
   from the robot as built;
5. ``locust sim --still`` of the virtual robot, then ``locust measure stance``: the crank's
   angle at rest, the ground link's and the servo axis' place from two side stills;
6. ``locust sim --samples``: each leg set's outcome shares over the calibrated robot's
   uncertainties;
7. ``locust calibrate hop``: the filmed hops of ``HOP_FIT_SETS`` fitted for what the bench
   cannot reach, written over the bench values (the bench robot is kept as
   ``robot-bench.toml``); ``--no-fit-hops`` leaves this stage out;
8. ``locust sweep``: a small ``scale`` sweep of the calibrated robot;
9. ``locust report``: the calibrated model against the measured hops, with bands from the
   fitted uncertainties and the bench robot's prediction before the fit beside it.

Every output stays under ``--out``: the virtual robot (``virtual/truth.toml``, what it hides:
``virtual/truth.json``), its bench recordings, videos, run records, tracks, stills,
robot.toml, fit plots, the sweep, the report, each command's log (``logs/``) and the time each
stage took.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from contextlib import contextmanager
from pathlib import Path

import click

from ..errors import ReportError
from ..fileio import atomic_write_json, atomic_write_text, unique_dir
from ..orphans import die_with_parent
from ..params import DEFAULT_PRESET, LEG_SETS
from ..progress import progress

REPORT_SAMPLES = 8
SHARE_DRAWS = 16     # draws of each leg set's outcome shares (stage 6)
# the report's figures take about as long as three of its simulation stages with draws (4.4 s
# against 0.3 s and 2.9 s for a leg set's run and its draws, docs/performance.md): so many steps
# on its bar keep the time left within 2x from a quarter of the stage on
REPORT_FIGURE_STEPS = 3
# Hops filmed at once: each takes about one core (its video's rendering) while its firmware
# paces it in real time. With real-time scheduling the interpreters run ahead of the renders:
# two at once on 2 cores keep every phase within 0.12 ms, as one at a time does (12 hops
# each, bench/hop_timing.py). Without it the renders starve them: two filmed at once put
# phases 238 ms late, one at a time 59 ms (the run records say the host stalled that long).
HOP_JOBS = 2


def hop_jobs(cores: int) -> int:
    """Hops filmed at once on ``cores`` cores: up to HOP_JOBS where the virtual robot gets
    real-time scheduling, else one (a phase late only by the host is still not the firmware's)."""
    from ..device.virtual import realtime_scheduling_allowed

    return max(1, min(HOP_JOBS, cores)) if realtime_scheduling_allowed() else 1


# a progress line (locust.progress) always says how long it has run
PROGRESS_MARK = " elapsed"
REPORT_STAGE_MARK = "report: "   # `locust report` says each of its stages so


def relay_progress(lines, out, on_line=None) -> str:
    """All of a child command's output (``lines``), returned whole; its progress lines, which
    it prints every ~10 s off a terminal, shown on ``out`` as they come, indented under the
    stage (on a terminal, redrawn in place). ``on_line(line)`` sees every line as it comes."""
    tty = out.isatty()
    kept, shown = [], False
    for line in lines:
        kept.append(line)
        if on_line is not None:
            on_line(line)
        if PROGRESS_MARK in line:
            text = "      " + line.strip()
            with _OUT_LOCK:   # (commands run side by side each relay theirs)
                out.write("\r\x1b[K" + text if tty else text + "\n")
                out.flush()
            shown = True
    if tty and shown:
        with _OUT_LOCK:
            out.write("\n")
            out.flush()
    return "".join(kept)


_OUT_LOCK = threading.Lock()


class Demo:
    """Runs ``locust`` commands in this process, logging each and timing each stage."""

    def __init__(self, folder: Path, stderr):
        self.folder = folder
        self.stderr = stderr
        self.logs = folder / "logs"
        self.steps = 0
        self.stages: list[dict] = []
        self.env = {"LOCUST_VIRTUAL_DIR": str(folder / "virtual"), "PYTHONUNBUFFERED": "1"}
        self.running: set[subprocess.Popen] = set()   # the children now running (side by side: several)
        self.stopping = threading.Event()              # set once the demo is stopped: start nothing more
        self._lock = threading.Lock()
        self.stages_started: list[str] = []

    def call(self, args: list[str], step: int | None = None, on_line=None) -> str:
        """``locust ARGS`` in a child process; its output goes to logs/NN-verb.log; a failure stops the demo.

        A child per command: each starts clean, as a user's would (one process rendering many
        offscreen videos in turn is not what the commands are built for). ``step`` numbers its
        log (default: the next); ``on_line(line)`` sees its output as it comes.
        """
        if step is None:
            self.steps += 1
            step = self.steps
        log = self.logs / f"{step:02d}-{args[0]}{'-' + args[1] if args[0] == 'calibrate' else ''}.log"
        cmd = [sys.executable, "-m", "locust.commands", *args]
        if self.stopping.is_set():
            raise DemoStopped("the demo is stopping")
        parent = os.getpid()
        with subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              text=True, env={**os.environ, **self.env},
                              preexec_fn=lambda: die_with_parent(parent)) as proc:   # a kill -9 takes it too
            with self._lock:
                self.running.add(proc)
            try:
                output = relay_progress(proc.stdout, self.stderr, on_line)
            except BaseException:          # Ctrl-C or a TERM here: the command ends with the demo
                _end(proc)
                raise
            finally:
                if self.stopping.is_set():
                    _end(proc)
                proc.wait()
                with self._lock:
                    self.running.discard(proc)
        atomic_write_text(log, f"$ locust {' '.join(args)}\n{output}")   # (a stopped command's too)
        if self.stopping.is_set():
            raise DemoStopped(f"`locust {args[0]}` was stopped")
        if proc.returncode != 0:
            tail = "\n".join("    " + ln for ln in output.strip().splitlines()[-6:])
            raise ReportError(f"demo stopped: `locust {' '.join(args)}` failed (exit {proc.returncode}):\n{tail}",
                              f"its whole output is in {log}")
        return output

    def call_side_by_side(self, calls: list[tuple[list[str], tuple[Path, ...]]], jobs: int, bar) -> None:
        """Each ``(args, expected files)`` of ``calls`` as :meth:`call`, ``jobs`` at a time, each
        numbered in order; ``bar`` counts those done. The first failure (in order) stops the
        demo once the others running have ended."""
        first = self.steps
        self.steps += len(calls)

        def one(k: int) -> None:
            args, paths = calls[k]
            self.call(args, first + 1 + k)
            self.expect(*paths, step=first + 1 + k)

        pool = ThreadPoolExecutor(max_workers=max(1, min(jobs, len(calls))))
        try:
            futures = [pool.submit(one, k) for k in range(len(calls))]
            for future in as_completed(futures):
                if future.exception() is None:
                    bar.update(1)
        except BaseException:
            self.stop()       # the queued commands never start, the running ones end now
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        for future in futures:
            future.result()

    @contextmanager
    def stoppable(self):
        """Ctrl-C, a TERM or a HUP while the demo runs: no command more starts, the running ones
        end (:meth:`stop`), and the demo ends with an error saying where it stopped."""
        try:
            yield
        except (KeyboardInterrupt, SystemExit, DemoStopped) as exc:
            self.stop()
            what = {130: "Ctrl-C", 143: "a TERM signal", 129: "a HUP signal"}.get(
                getattr(exc, "code", 130) if not isinstance(exc, DemoStopped) else 0, "a signal")
            stage = self.stages_started[-1] if self.stages_started else "before its first stage"
            raise ReportError(f"demo stopped by {what} during {stage}; every command it ran has ended",
                              f"what it made so far is in {self.folder} (each command's output in "
                              f"{self.logs}); run `locust demo` again for a whole run") from None

    def stop(self) -> None:
        """Start no command more and end those running: each is sent TERM (it unwinds, leaving
        no temporary file), and killed if it has not ended within :data:`STOP_GRACE_S`."""
        self.stopping.set()
        with self._lock:
            running = list(self.running)
        _end(*running)

    def expect(self, *paths: Path, step: int | None = None) -> None:
        """The files the last command (or command ``step``) should have written; a command that
        exits 0 without them stops the demo here rather than at the next stage."""
        step = self.steps if step is None else step
        missing = [str(p) for p in paths if not p.is_file()]
        if missing:
            log = sorted(self.logs.glob(f"{step:02d}-*.log"))
            raise ReportError(f"demo stopped: step {step} exited 0 but did not write {', '.join(missing)}",
                              f"its output is in {log[0] if log else self.logs}")

    @contextmanager
    def stage(self, number: int, total: int, title: str):
        self.say(f"[{number}/{total}] {title}")
        self.stages_started.append(f"stage {number}/{total} ({title})")
        t0 = time.perf_counter()
        yield
        wall = time.perf_counter() - t0
        self.stages.append({"stage": title, "wall_s": round(wall, 2)})
        self.say(f"      {wall:.1f} s")

    @contextmanager
    def bar(self, items, label: str, length: int | None = None):
        """A stage's bar over its commands: each carries its own start-up, so the time left is
        measured from the start; shown every ~10 s off a terminal while a long command runs."""
        with progress(items, length=length, label=label, show_pos=True, rate_from_start=True,
                      file=self.stderr) as bar:
            done = threading.Event()
            ticker = threading.Thread(target=_tick, args=(bar, done), name="locust-demo-progress", daemon=True)
            ticker.start()
            try:
                yield bar
            finally:
                done.set()
                ticker.join()

    def say(self, msg: str) -> None:
        click.echo(msg, file=self.stderr)


class DemoStopped(Exception):
    """A command the demo ran was ended because the demo is being stopped."""


STOP_GRACE_S = 0.5   # a child sent TERM has this long to unwind before it is killed


def _end(*procs: subprocess.Popen) -> None:
    """End ``procs`` together: TERM to each, then KILL to those not ended within
    :data:`STOP_GRACE_S` of it (nothing to one that has ended)."""
    live = [p for p in procs if p.poll() is None]
    for p in live:
        p.terminate()
    deadline = time.monotonic() + STOP_GRACE_S
    for p in live:
        try:
            p.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def _tick(bar, done: threading.Event) -> None:
    while not done.wait(TICK_S):
        with _OUT_LOCK:
            bar.tick()


TICK_S = 1.0   # a stage's bar is looked at this often (it shows itself when due)


@click.command()
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=Path("demo-out"),
              show_default=True, help="Parent folder; each demo goes into a new run/ (run-2/, ...) inside.")
@click.option("--cycles", type=click.IntRange(1, 6), default=3, show_default=True, help="Hop cycles per trial.")
@click.option("--trials", type=click.IntRange(1, 5), default=2, show_default=True,
              help="Hops filmed per leg set (repeated trials give the report its error bars).")
@click.option("--designs", type=click.IntRange(2, 61), default=7, show_default=True,
              help="Designs in the sweep: scale from 0 to 30 mm added to every link.")
@click.option("--jobs", type=click.IntRange(1, 64), default=None,
              help="Sweep workers, and hops filmed at once up to 2 (1 where the virtual robot gets no "
                   "real-time scheduling: its phases would be late) [every local core].")
@click.option("--fit-hops/--no-fit-hops", default=True, show_default=True,
              help="Fit what the bench cannot reach from the filmed hops of Medium and Large.")
def demo(out, cycles, trials, designs, jobs, fit_hops):
    """Run the whole toolkit end to end on the virtual robot, then print where the report is.

    The virtual robot is the robot as built with its uncertain values drawn once (a draw whose
    Medium and Large rear and come back down, as the filmed robots did), hidden from every
    stage but the virtual board. Flash the firmware to it, hop Small, Medium and Large
    (filmed), track the videos, calibrate its parts from SYNTHETIC bench recordings of them,
    measure its stance from two side stills, say each leg set's outcome shares, fit what the
    bench cannot reach from the filmed hops, sweep the added link length, and compare the
    calibrated model with the measured hops in a report (the bench robot's prediction beside
    it). Everything it makes stays under --out; each command's output is in logs/.
    """
    from ..demo.bench import plate_on_a_scale, write_bench
    from ..demo.virtual_robot import HOP_FIT_SETS

    stderr = sys.stderr
    t_start = time.perf_counter()
    folder = unique_dir(out, "run")
    d = Demo(folder, stderr)
    d.say(f"demo: everything goes to {folder}")
    hops_dir, cal_dir, stills = folder / "hops", folder / "calibration", folder / "stills"
    robot_toml, bench_toml = cal_dir / "robot.toml", cal_dir / "robot-bench.toml"
    trials_dirs = [(name, hops_dir / f"{name}-{k}") for name in LEG_SETS for k in range(1, trials + 1)]
    total = 9 if fit_hops else 8
    stage = iter(range(1, total + 1))

    with d.stoppable():
        truth_toml, hidden = _virtual_robot(folder)
        d.say(f"demo: the virtual robot is a draw of the robot as built ({len(hidden)} uncertain values drawn, hidden "
              f"in {truth_toml}): one whose Medium and Large rear and come back down, as the filmed robots did")
        bench = write_bench(_load(truth_toml), folder / "virtual" / "bench")

        with d.stage(next(stage), total, "flash the firmware to the virtual robot"):
            d.call(["flash", "--port", "sim"])
        with d.stage(next(stage), total, f"hop Small, Medium, Large x {trials} on the virtual robot, {cycles} cycles, "
                                         "filmed"):
            # each hop is its own virtual robot (the one flash folder, read only), the firmware paced
            # in real time while one core renders its video: hop_jobs() of them film at once
            hops = [(["hop", "--port", "sim", "--config", str(truth_toml), "--leg-set", name, "--cycles", str(cycles),
                      "--video", str(trial / "hop.mp4"), "--out", str(trial)],
                     (trial / "hop.mp4", trial / "run.json")) for name, trial in trials_dirs]
            with d.bar(None, "hops", length=len(hops)) as bar:
                d.call_side_by_side(hops, hop_jobs(jobs or os.cpu_count() or 1), bar)
        with d.stage(next(stage), total, "track nose and foot in the videos"):
            with d.bar(trials_dirs, "tracks") as bar:
                for _, trial in bar:
                    d.call(["track", str(trial / "hop.mp4")])
                    d.expect(trial / "hop.tracks.csv")
        with d.stage(next(stage), total, "calibrate the hinge, the servo and the feet' friction on the bench "
                                         "(SYNTHETIC recordings)"):
            with d.bar(bench, "fits") as bar:
                for k, rec in enumerate(bar):
                    start = ["--preset", DEFAULT_PRESET] if k == 0 else []      # a new robot.toml: the robot as built
                    d.call(["calibrate", rec.experiment, *map(str, rec.paths), *rec.options, *start,
                            "--write", str(robot_toml), "--out", str(cal_dir)])
        with d.stage(next(stage), total, "measure the virtual robot: its plate on a kitchen scale, its stance from "
                                         "two side stills"):
            plate_g = plate_on_a_scale(_load(truth_toml))
            d.call(["params", "--config", str(robot_toml), "--set", f"geometry.body_mass_kg={plate_g / 1000!r}",
                    "--write", str(robot_toml), "--force"])
            d.call(["sim", "--config", str(truth_toml), "--cycles", "1", "--still", str(stills / "rest.png"),
                    "--still-push", str(stills / "push.png")])
            d.call(["measure", "stance", str(stills / "rest.png"), str(stills / "push.png"),
                    "--config", str(robot_toml), "--write", str(robot_toml), "--force"])
            atomic_write_text(bench_toml, robot_toml.read_text(encoding="utf-8"))
        with d.stage(next(stage), total, f"outcome shares of each leg set over {SHARE_DRAWS} draws of the calibrated "
                                         "robot"):
            with d.bar(list(LEG_SETS), "leg sets") as bar:
                for name in bar:
                    d.call(["sim", "--config", str(robot_toml), "--leg-set", name, "--cycles", str(cycles),
                            "--samples", str(SHARE_DRAWS), "--no-sensitivity"])
        if fit_hops:
            with d.stage(next(stage), total, f"fit the filmed hops of {' and '.join(HOP_FIT_SETS)}: what the bench "
                                             "cannot reach"):
                fitted = [f"{name}={hops_dir / f'{name}-1'}" for name in HOP_FIT_SETS]
                d.call(["calibrate", "hop", *fitted, "--write", str(robot_toml), "--out", str(cal_dir)])
        with d.stage(next(stage), total, f"sweep the added link length over {designs} designs"):
            d.call(["sweep", "--config", str(robot_toml), "--vary", f"scale=0:0.03:{designs}", "--cycles", str(cycles),
                    "--out", str(folder / "sweep"), *(["--jobs", str(jobs)] if jobs else [])])
        with d.stage(next(stage), total, "report: the calibrated model against the measured hops"):
            # each trial named by its leg set: the report need not guess it from the folder name
            measured = [arg for name, trial in trials_dirs for arg in ("--measured", f"{name}={trial}")]
            closing = ["--before", str(bench_toml), "--samples", str(REPORT_SAMPLES)] if fit_hops else []
            # its bar counts the report's own stage lines: per leg set its simulation (and its draws),
            # then the figures, worth REPORT_FIGURE_STEPS; each line ends the stage before it
            with d.bar(None, "report", length=len(LEG_SETS) * (2 if fit_hops else 1) + REPORT_FIGURE_STEPS) as bar:
                started = []

                def on_line(line: str) -> None:
                    if line.startswith(REPORT_STAGE_MARK):
                        if started:
                            bar.update(1)
                        started.append(line)

                printed = d.call(["report", *measured, "--config", str(robot_toml), "--sweep", str(folder / "sweep"),
                                  *closing, "--out", str(folder)], on_line=on_line)
                bar.update(max(bar.length - bar.pos, 0))
        report_path = Path(printed.strip().splitlines()[-1])
        _timings(d, folder, time.perf_counter() - t_start, {"cycles": cycles, "trials": trials, "designs": designs})
    click.echo(f"report: {report_path}")


def _load(path: Path):
    from ..io.robot_toml import load_robot

    return load_robot(path)


def _virtual_robot(folder: Path) -> tuple[Path, dict[str, float]]:
    """The virtual robot written to virtual/truth.toml, and the values it hides (also written,
    with a note, to virtual/truth.json)."""
    from ..demo.virtual_robot import DRAW_INDEX, DRAW_SEED, HOP_FIT_SETS, hidden_values, virtual_robot
    from ..io.robot_toml import save_robot

    robot = virtual_robot()
    path = save_robot(robot, folder / "virtual" / "truth.toml")
    hidden = hidden_values(robot)
    note = (f"the virtual robot: the robot as built with each uncertain value drawn (draw {DRAW_INDEX} of seed "
            f"{DRAW_SEED}), chosen as one whose {' and '.join(HOP_FIT_SETS)} rear and come back down; hidden from "
            "every stage but the virtual board")
    atomic_write_json(folder / "virtual" / "truth.json", {"note": note, "values": hidden,
                                                          "hop_fit_sets": list(HOP_FIT_SETS)})
    return path, hidden


def _timings(d: Demo, folder: Path, wall: float, sizes: dict[str, int]) -> None:
    """timings.json (each stage's wall time, the total, the demo's sizes) and the same printed."""
    atomic_write_json(folder / "timings.json", {"stages": d.stages, "total_s": round(wall, 2), **sizes})
    d.say("demo: time per stage")
    for s in d.stages:
        d.say(f"  {s['wall_s']:7.1f} s  {s['stage']}")
    d.say(f"  {wall:7.1f} s  total")
