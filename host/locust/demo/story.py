"""The demo's story: the whole toolkit end to end on the virtual robot, as a student runs it.

:func:`run_story` is the demo, for ``locust demo`` and :func:`locust.run_demo` alike. The
virtual robot is the robot as built with its uncertain values drawn once
(:mod:`locust.demo.virtual_robot`: a draw whose Medium and Large rear and come back down, as
the filmed robots did), hidden from everything but the virtual board. Each stage runs the real
command (``python -m locust.commands ...``, one child process each, :mod:`locust.demo.runner`),
so the demo exercises the same code paths a user does:

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
   ``robot-bench.toml``); ``fit_hops=False`` (``--no-fit-hops``) leaves this stage out;
8. ``locust sweep``: a small ``scale`` sweep of the calibrated robot;
9. ``locust report``: the calibrated model against the measured hops, with bands from the
   fitted uncertainties and the bench robot's prediction before the fit beside it.

Every output stays under the options' ``out``: the virtual robot (``virtual/truth.toml``, what
it hides: ``virtual/truth.json``), its bench recordings, videos, run records, tracks, stills,
robot.toml, fit plots, the sweep, the report, each command's log (``logs/``) and the time each
stage took.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from ..fileio import atomic_write_json, atomic_write_text, unique_dir
from ..params import DEFAULT_PRESET, LEG_SETS
from .options import DemoOptions
from .runner import Demo

if TYPE_CHECKING:
    from .bench import BenchRecording

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
REPORT_STAGE_MARK = "report: "   # `locust report` says each of its stages so


def hop_jobs(cores: int) -> int:
    """Hops filmed at once on ``cores`` cores: up to HOP_JOBS where the virtual robot gets
    real-time scheduling, else one (a phase late only by the host is still not the firmware's).

    Parameters
    ----------
    cores : int
        The cores the demo may use.

    Returns
    -------
    int
    """
    from ..device.virtual import realtime_scheduling_allowed

    return max(1, min(HOP_JOBS, cores)) if realtime_scheduling_allowed() else 1


@dataclass(frozen=True)
class DemoResult:
    """What a demo made.

    Attributes
    ----------
    folder : pathlib.Path
        Its run folder (``run/``, ``run-2/``, ... under the options' ``out``).
    report : pathlib.Path
        The report's HTML page.
    stage_wall_s : dict of str to float
        Each stage's title -> its wall time [s] (also in ``timings.json``).
    total_s : float
        The whole demo's wall time [s].
    """

    folder: Path
    report: Path
    stage_wall_s: dict[str, float]
    total_s: float


class _Run:
    """One demo's folders and files, and the runner of its commands."""

    def __init__(self, options: DemoOptions, stderr: TextIO):
        self.options = options
        self.folder = unique_dir(options.out, "run")
        self.d = Demo(self.folder, stderr)
        self.hops_dir, self.cal_dir = self.folder / "hops", self.folder / "calibration"
        self.stills = self.folder / "stills"
        self.robot_toml, self.bench_toml = self.cal_dir / "robot.toml", self.cal_dir / "robot-bench.toml"
        self.trials_dirs = [(name, self.hops_dir / f"{name}-{k}") for name in LEG_SETS
                            for k in range(1, options.trials + 1)]
        self.truth_toml = Path()     # the virtual robot's file, and its bench: written as the story begins
        self.bench: list[BenchRecording] = []
        self.report = Path()         # the report's page, once its stage has run


def run_story(options: DemoOptions, stderr: TextIO | None = None) -> DemoResult:
    """Run the demo: every stage's command on the virtual robot, one after another.

    Parameters
    ----------
    options : DemoOptions
        Its folder and sizes.
    stderr : text stream, optional
        Where the stage lines and bars go (default: ``sys.stderr`` as the demo starts).

    Returns
    -------
    DemoResult

    Raises
    ------
    locust.errors.ReportError
        A command that failed or did not write what it should have (with its log's path), or
        the demo stopped by Ctrl-C, a TERM or a HUP (every command it ran ended).
    """
    from .bench import write_bench
    from .virtual_robot import write_truth

    t_start = time.perf_counter()
    run = _Run(options, sys.stderr if stderr is None else stderr)
    d = run.d
    d.say(f"demo: everything goes to {run.folder}")
    stages = _stages(options)
    with d.stoppable():
        run.truth_toml, hidden = write_truth(run.folder)
        d.say(f"demo: the virtual robot is a draw of the robot as built ({len(hidden)} uncertain values drawn, hidden "
              f"in {run.truth_toml}): one whose Medium and Large rear and come back down, as the filmed robots did")
        run.bench = write_bench(_load(run.truth_toml), run.folder / "virtual" / "bench")
        for number, (title, stage) in enumerate(stages, 1):
            with d.stage(number, len(stages), title):
                stage(run)
        wall = time.perf_counter() - t_start
        _timings(d, run.folder, wall, {"cycles": options.cycles, "trials": options.trials, "designs": options.designs})
    return DemoResult(run.folder, run.report, {s["stage"]: s["wall_s"] for s in d.stages}, round(wall, 2))


def _stages(options: DemoOptions) -> list[tuple[str, Callable[[_Run], None]]]:
    """Each stage's title and what runs in it, in order."""
    from .virtual_robot import HOP_FIT_SETS

    o = options
    stages = [("flash the firmware to the virtual robot", _flash),
              (f"hop Small, Medium, Large x {o.trials} on the virtual robot, {o.cycles} cycles, filmed", _hop),
              ("track nose and foot in the videos", _track),
              ("calibrate the hinge, the servo and the feet' friction on the bench (SYNTHETIC recordings)", _bench),
              ("measure the virtual robot: its plate on a kitchen scale, its stance from two side stills", _measure),
              (f"outcome shares of each leg set over {SHARE_DRAWS} draws of the calibrated robot", _shares)]
    if o.fit_hops:
        stages.append((f"fit the filmed hops of {' and '.join(HOP_FIT_SETS)}: what the bench cannot reach",
                       _fit_hops))
    return [*stages, (f"sweep the added link length over {o.designs} designs", _sweep),
            ("report: the calibrated model against the measured hops", _report)]


def stage_titles(options: DemoOptions) -> list[str]:
    """The stages the demo runs with ``options``, as it announces them (``[n/N] title``).

    Parameters
    ----------
    options : DemoOptions

    Returns
    -------
    list of str
        The stages' titles, in order.
    """
    return [title for title, _ in _stages(options)]


def _flash(run: _Run) -> None:
    run.d.call(["flash", "--port", "sim"])


def _hop(run: _Run) -> None:
    # each hop is its own virtual robot (the one flash folder, read only), the firmware paced
    # in real time while one core renders its video: hop_jobs() of them film at once
    o, d = run.options, run.d
    hops = [(["hop", "--port", "sim", "--config", str(run.truth_toml), "--leg-set", name, "--cycles", str(o.cycles),
              "--video", str(trial / "hop.mp4"), "--out", str(trial)],
             (trial / "hop.mp4", trial / "run.json")) for name, trial in run.trials_dirs]
    with d.bar(None, "hops", length=len(hops)) as bar:
        d.call_side_by_side(hops, hop_jobs(o.jobs or os.cpu_count() or 1), bar)


def _track(run: _Run) -> None:
    d = run.d
    with d.bar(run.trials_dirs, "tracks") as bar:
        for _, trial in bar:
            d.call(["track", str(trial / "hop.mp4")])
            d.expect(trial / "hop.tracks.csv")


def _bench(run: _Run) -> None:
    d = run.d
    with d.bar(run.bench, "fits") as bar:
        for k, rec in enumerate(bar):
            start = ["--preset", DEFAULT_PRESET] if k == 0 else []      # a new robot.toml: the robot as built
            d.call(["calibrate", rec.experiment, *map(str, rec.paths), *rec.options, *start,
                    "--write", str(run.robot_toml), "--out", str(run.cal_dir)])


def _measure(run: _Run) -> None:
    from .bench import plate_on_a_scale

    d, robot_toml, stills = run.d, run.robot_toml, run.stills
    plate_g = plate_on_a_scale(_load(run.truth_toml))
    d.call(["params", "--config", str(robot_toml), "--set", f"geometry.body_mass_kg={plate_g / 1000!r}",
            "--write", str(robot_toml), "--force"])
    d.call(["sim", "--config", str(run.truth_toml), "--cycles", "1", "--still", str(stills / "rest.png"),
            "--still-push", str(stills / "push.png")])
    d.call(["measure", "stance", str(stills / "rest.png"), str(stills / "push.png"),
            "--config", str(robot_toml), "--write", str(robot_toml), "--force"])
    atomic_write_text(run.bench_toml, robot_toml.read_text(encoding="utf-8"))


def _shares(run: _Run) -> None:
    d = run.d
    with d.bar(list(LEG_SETS), "leg sets") as bar:
        for name in bar:
            d.call(["sim", "--config", str(run.robot_toml), "--leg-set", name, "--cycles", str(run.options.cycles),
                    "--samples", str(SHARE_DRAWS), "--no-sensitivity"])


def _fit_hops(run: _Run) -> None:
    from .virtual_robot import HOP_FIT_SETS

    fitted = [f"{name}={run.hops_dir / f'{name}-1'}" for name in HOP_FIT_SETS]
    run.d.call(["calibrate", "hop", *fitted, "--write", str(run.robot_toml), "--out", str(run.cal_dir)])


def _sweep(run: _Run) -> None:
    o = run.options
    run.d.call(["sweep", "--config", str(run.robot_toml), "--vary", f"scale=0:0.03:{o.designs}", "--cycles",
                str(o.cycles), "--out", str(run.folder / "sweep"), *(["--jobs", str(o.jobs)] if o.jobs else [])])


def _report(run: _Run) -> None:
    d, fit_hops = run.d, run.options.fit_hops
    # each trial named by its leg set: the report need not guess it from the folder name
    measured = [arg for name, trial in run.trials_dirs for arg in ("--measured", f"{name}={trial}")]
    closing = ["--before", str(run.bench_toml), "--samples", str(REPORT_SAMPLES)] if fit_hops else []
    # its bar counts the report's own stage lines: per leg set its simulation (and its draws),
    # then the figures, worth REPORT_FIGURE_STEPS; each line ends the stage before it
    with d.bar(None, "report", length=len(LEG_SETS) * (2 if fit_hops else 1) + REPORT_FIGURE_STEPS) as bar:
        started = []

        def on_line(line: str) -> None:
            if line.startswith(REPORT_STAGE_MARK):
                if started:
                    bar.update(1)
                started.append(line)

        printed = d.call(["report", *measured, "--config", str(run.robot_toml), "--sweep", str(run.folder / "sweep"),
                          *closing, "--out", str(run.folder)], on_line=on_line)
        bar.update(max(bar.length - bar.pos, 0))
    run.report = Path(printed.strip().splitlines()[-1])


def _load(path: Path):
    from ..io.robot_toml import load_robot

    return load_robot(path)


def _timings(d: Demo, folder: Path, wall: float, sizes: dict[str, int]) -> None:
    """timings.json (each stage's wall time, the total, the demo's sizes) and the same printed."""
    atomic_write_json(folder / "timings.json", {"stages": d.stages, "total_s": round(wall, 2), **sizes})
    d.say("demo: time per stage")
    for s in d.stages:
        d.say(f"  {s['wall_s']:7.1f} s  {s['stage']}")
    d.say(f"  {wall:7.1f} s  total")
