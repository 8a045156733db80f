"""How long the host kept the virtual robot's interpreter off the CPU while a phase was due.

The virtual robot's firmware times its phases on the host's clock: a host that does not run
the interpreter when a phase is due makes that phase late, and the run record would show it
as the firmware's lateness. :class:`StallWatch` samples the interpreter's own scheduling
accounting while a hop runs, every millisecond while it is awake (every 5 ms while it sleeps):

- ``/proc/PID/schedstat``: the time it has run on a CPU, the time it has waited on a run
  queue, and how many times it was put on a CPU;
- ``/proc/PID/stat``: its state, ``S`` when it sleeps of its own accord (``poll``, ``read``).

Between two samples at which it was awake, and between which it was not put on a CPU anew,
every microsecond it did not run is one the host held it off: waiting for a CPU behind other
work, stopped (SIGSTOP, a debugger), throttled as a real-time task, or its virtual CPU taken
by the hypervisor (the kernel leaves stolen time out of a task's run time). Otherwise (it
slept, or was put on a CPU again) only its run-queue wait counts, so a firmware that sleeps
when it should spin is not excused (:class:`HeldOff`).

A correct firmware runs from a phase's commanded start until it starts the phase (it spins the
last 12 ms), so the time it was held off between those two instants is the part of the
phase's lateness the host caused (:meth:`StallWatch.phase_stalls_us`); it is never more than
the lateness.

Neither the run-queue wait alone (it misses a stopped process, the hypervisor and real-time
throttling) nor a thread of the host that sleeps a millisecond and times how late it wakes
(it shares the host command's GIL with the video renderer, and may run on the other CPU)
measures this: docs/device.md has the measurements.
"""

from __future__ import annotations

import bisect
import itertools
import os
import threading
import time
from array import array
from collections.abc import Callable
from dataclasses import dataclass

SAMPLE_PERIOD_S = 0.001
# while it sleeps of its own accord it is held off by nothing, and the wait it has when woken
# is the kernel's figure whenever it is sampled: a slower pace there keeps the watch off the
# host command's GIL (the renderer's) most of the time
ASLEEP_PERIOD_S = 0.005
ASLEEP = "S"           # interruptible sleep: the firmware's own poll() or read()
STOPPED = ("T", "t")   # stopped by a signal, or by a debugger
MAX_RUN = 10_000       # samples of one stretch awake kept before it is counted (10 s at 1 ms)


@dataclass(frozen=True)
class Sample:
    """The interpreter's scheduling accounting at one instant.

    Attributes
    ----------
    t_s : float
        When it was read, ``time.monotonic()`` [s].
    cpu_s : float
        Time it has run on a CPU [s] (the kernel brings it up to date at each scheduler tick
        while the process runs, and when it leaves the CPU).
    wait_s : float
        Time it has waited on a run queue, ready to run [s] (added when it gets the CPU).
    arrivals : int
        How many times it was put on a CPU.
    state : str
        Its state letter (``R`` running or ready, ``S`` asleep, ``T`` stopped, ...).
    """

    t_s: float
    cpu_s: float
    wait_s: float
    arrivals: int
    state: str


class HeldOff:
    """One process's samples, fed in order, turned into the spans in which the host held it off.

    Between consecutive samples:

    - awake at both and not put on a CPU in between: the time it did not run (wall time less
      CPU time), at the end of the interval (it can leave the CPU in it, not come back). Its
      CPU time lags by up to a scheduler tick while it runs and is exact once it leaves the
      CPU, so over each stretch awake the count is the least consistent with the later samples
      (a tick's lag paid back is not a stall);
    - stopped at the first and put on a CPU once (it resumed, and has not slept since: a sleep
      ends in another arrival): the time it did not run, at the start of the interval;
    - otherwise: its run-queue wait, which the kernel adds when it gets the CPU, as one span
      ending there (as late as the CPU time it ran after allows) and reaching back as far as
      the wait lasted, over what the samples before counted already.

    Spans that overlap are one: no time is counted twice.

    Attributes
    ----------
    starts, ends : array of float
        Each span in which it was held off [s, ``time.monotonic()``], in order, apart.
    """

    def __init__(self, max_run: int = MAX_RUN):
        self.max_run = max_run
        self.starts, self.ends = array("d"), array("d")
        self._last: Sample | None = None
        # the stretch awake: (start, end, wall - cpu, held at the start) per interval
        self._run: list[tuple[float, float, float, bool]] = []

    def feed(self, sample: Sample) -> None:
        """Take the next sample.

        Parameters
        ----------
        sample : Sample
        """
        last, self._last = self._last, sample
        if last is None:
            return
        not_run = (sample.t_s - last.t_s) - (sample.cpu_s - last.cpu_s)
        arrived = sample.arrivals - last.arrivals
        resumed = arrived == 1 and last.state in STOPPED
        if ASLEEP not in (last.state, sample.state) and (arrived == 0 or resumed):
            self._run.append((last.t_s, sample.t_s, not_run, resumed))
            if len(self._run) >= self.max_run:
                self._count_run(None)
            return
        self._count_run(not_run)
        got_cpu = max(last.t_s, sample.t_s - max(0.0, sample.cpu_s - last.cpu_s))
        self._add(got_cpu - (sample.wait_s - last.wait_s), got_cpu)

    def flush(self) -> None:
        """Count the stretch awake in progress (the samples end here)."""
        self._count_run(None)
        self._last = None

    def _count_run(self, closing: float | None) -> None:
        """Add the stretch awake's spans. ``closing``: wall less CPU time over the interval that
        ended it (it left the CPU there, so its CPU time is exact again)."""
        run, self._run = self._run, []
        if not run:
            return
        cum = list(itertools.accumulate(r[2] for r in run))
        low = cum[-1] if closing is None else min(cum[-1], cum[-1] + closing)
        floor = []
        for c in reversed(cum):   # the least held off by each sample that the later ones allow
            low = max(0.0, min(low, c))
            floor.append(low)
        floor.reverse()
        before = 0.0
        for (a, b, _, at_start), total in zip(run, floor):
            held = min(total - before, b - a)
            if at_start:
                self._add(a, a + held)
            else:
                self._add(b - held, b)
            before = total

    def _add(self, start_s: float, end_s: float) -> None:
        """Add a span, merged with those it overlaps (they all lie before its end)."""
        if end_s <= start_s:
            return
        while self.ends and self.ends[-1] >= start_s:
            start_s, end_s = min(start_s, self.starts.pop()), max(end_s, self.ends.pop())
        self.starts.append(start_s)
        self.ends.append(end_s)

    @property
    def total_s(self) -> float:
        """All the time it was held off [s]."""
        return sum(b - a for a, b in zip(self.starts, self.ends))

    def within_s(self, start_s: float, end_s: float) -> float:
        """The time held off within ``[start_s, end_s]``.

        Parameters
        ----------
        start_s, end_s : float
            The span [s, ``time.monotonic()``].

        Returns
        -------
        float
            [s].
        """
        total = 0.0
        for i in range(bisect.bisect_left(self.ends, start_s), len(self.starts)):
            a, b = self.starts[i], self.ends[i]
            if a >= end_s:
                break
            total += max(0.0, min(b, end_s) - max(a, start_s))
        return total


def read_sample(schedstat_fd: int, stat_fd: int) -> Sample | None:
    """A :class:`Sample` from a process's open ``schedstat`` and ``stat`` files, None if it is gone.

    Parameters
    ----------
    schedstat_fd, stat_fd : int
        ``/proc/PID/schedstat`` and ``/proc/PID/stat``, opened for reading.

    Returns
    -------
    Sample or None
    """
    t = time.monotonic()
    try:
        run_ns, wait_ns, arrivals = (int(v) for v in os.pread(schedstat_fd, 128, 0).split())
        stat = os.pread(stat_fd, 1024, 0)
    except (OSError, ValueError):
        return None
    state = stat[stat.rfind(b")") + 2:][:1].decode("ascii", "replace")   # after "PID (comm) "
    if not state or state in "ZX":
        return None
    return Sample(t, run_ns / 1e9, wait_ns / 1e9, arrivals, state)


class StallWatch:
    """Samples the virtual robot's interpreter during a hop, and says how long the host held it off.

    Parameters
    ----------
    pid_of : callable
        ``pid_of()``: the process to watch now (a reboot changes it), or None when there is none.
    clock_of_ticks : callable
        ``clock_of_ticks(ticks_us)``: the ``time.monotonic()`` second at which the process's
        30-bit ``ticks_us`` last read ``ticks_us`` (the virtual robot knows their offset).
    period_s : float
        Time between two samples while the process is awake [s].
    asleep_period_s : float
        Time between two samples while it sleeps of its own accord [s].
    """

    def __init__(self, pid_of: Callable[[], int | None], clock_of_ticks: Callable[[int], float],
                 period_s: float = SAMPLE_PERIOD_S, asleep_period_s: float = ASLEEP_PERIOD_S):
        self._pid_of = pid_of
        self._clock_of_ticks = clock_of_ticks
        self.period_s = period_s
        self.asleep_period_s = asleep_period_s
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.held_off = HeldOff()
        self.samples = 0

    def start(self) -> None:
        """Forget what was seen and sample from now on (a new hop)."""
        self.stop()
        self.held_off, self.samples = HeldOff(), 0
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="locust-virtual-stalls", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop sampling; what was seen is kept."""
        if self._thread is not None:
            self._stop.set()
            self._thread.join(timeout=5)
            self._thread = None

    def _run(self) -> None:
        from .link import raise_thread_priority

        raise_thread_priority()
        pid, fds, period = None, None, self.period_s
        try:
            while not self._stop.wait(period):
                now_pid = self._pid_of()
                if now_pid != pid:     # a reboot: a new process, a new baseline
                    _close(fds)
                    self.held_off.flush()
                    pid, fds = now_pid, _open(now_pid)
                sample = read_sample(*fds) if fds is not None else None
                if sample is None:
                    continue
                self.held_off.feed(sample)
                self.samples += 1
                period = self.asleep_period_s if sample.state == ASLEEP else self.period_s
        finally:
            _close(fds)
            self.held_off.flush()

    def phase_stalls_us(self, end_ticks_us: int, end_us: int, phases) -> list[int]:
        """Each phase's host stall: the time the interpreter was held off between the phase's
        commanded and measured start. Call it after :meth:`stop`.

        Parameters
        ----------
        end_ticks_us : int
            The firmware's ``ticks_us`` at the end of the hop (its ``done`` event).
        end_us : int
            The hop's length on the firmware's clock at that instant [us].
        phases : list of Phase
            The hop's phases (commanded and measured start from the hop's start [us]).

        Returns
        -------
        list of int
            [us], one per phase.
        """
        t0_s = self._clock_of_ticks(end_ticks_us) - end_us / 1e6
        return [round(1e6 * self.held_off.within_s(t0_s + p.commanded_us / 1e6, t0_s + p.measured_us / 1e6))
                for p in phases]


def _open(pid: int | None) -> tuple[int, int] | None:
    if pid is None:
        return None
    try:
        sched = os.open(f"/proc/{pid}/schedstat", os.O_RDONLY)
    except OSError:
        return None
    try:
        return sched, os.open(f"/proc/{pid}/stat", os.O_RDONLY)
    except OSError:
        os.close(sched)
        return None


def _close(fds: tuple[int, int] | None) -> None:
    for fd in fds or ():
        os.close(fd)
