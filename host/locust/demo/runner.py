"""The demo's commands, each run as a user runs it: a child process per command, logged, timed,
side by side where a stage allows it, and all ended together when the demo is stopped.

:class:`Demo` runs ``python -m locust.commands ARGS`` in a child (a kill -9 of the demo takes
it too, :func:`locust.orphans.die_with_parent`), keeps its output in ``logs/NN-verb.log`` and
relays its progress lines (:func:`relay_progress`); a command that fails, or exits 0 without
the files it should have written, stops the demo with its log's path. Ctrl-C, a TERM or a HUP
(:meth:`Demo.stoppable`) starts no command more and ends the running ones: TERM, then KILL
after :data:`STOP_GRACE_S`.
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

from ..errors import ReportError
from ..fileio import atomic_write_text
from ..orphans import die_with_parent
from ..progress import progress

# a progress line (locust.progress) always says how long it has run
PROGRESS_MARK = " elapsed"


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
    """Runs ``locust`` commands from this process, a child each, logging each and timing each stage."""

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
        """Stage ``number`` of ``total``: its title said as it starts, its wall time once it ends."""
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
        """``msg`` on its own line of the demo's stream, at once."""
        self.stderr.write(msg + "\n")
        self.stderr.flush()


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
