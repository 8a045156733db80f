"""Progress on stderr: the time left from the measured rate, shown only once it means
something; plain lines every ~10 s off a terminal. A made-up clock drives it (no real time)."""

from __future__ import annotations

import contextlib
import io
import re

import pytest

from locust.progress import ETA_MIN_S, ETA_MIN_STEPS, PLAIN_EVERY_S, Progress, format_duration, silenced


class Clock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self) -> float:
        return self.t


def _run(steps_s: list[float], length: int, tty: bool) -> tuple[list[str], Progress]:
    clock, out = Clock(), io.StringIO()
    bar = Progress(length=length, label="fit", file=out, tty=tty, clock=clock)
    seen = []
    with bar:
        for dt in steps_s:
            clock.t += dt
            bar.update(1)
            seen.append(bar.eta_s())
    return out.getvalue().splitlines() if not tty else out.getvalue().split("\r\x1b[K"), seen


def test_the_time_left_ignores_the_setup_and_waits_for_a_real_rate():
    """The reported case: a 50-step fit at 1 s a step after 30 s of setup once said "10 %
    8:05" (the setup taken as the pace). From the measured rate it is 1 s per step left."""
    steps = [30.0] + [1.0] * 49
    _, seen = _run(steps, 50, tty=False)
    first_shown = next(k for k, eta in enumerate(seen) if eta is not None)
    # after the first step: ETA_MIN_STEPS more steps and ETA_MIN_S seconds of them
    assert first_shown == max(ETA_MIN_STEPS, int(ETA_MIN_S)) and all(e is None for e in seen[:first_shown])
    for k, eta in enumerate(seen[first_shown:], start=first_shown):
        assert eta == pytest.approx(50 - (k + 1), abs=1e-9)   # exactly the steps left at 1 s each


def test_an_uneven_pace_gives_the_mean_rate_not_the_last_step():
    steps = [5.0, 1.0, 3.0, 1.0, 3.0]          # after the first: 8 s over 4 steps
    _, seen = _run(steps, 20, tty=False)
    assert seen[-1] == pytest.approx(15 * 2.0)


def test_off_a_terminal_a_plain_line_every_ten_seconds():
    """A 117 s fit of 117 one-second steps: 11 lines, one per 10 s, none before the first 10 s."""
    lines, _ = _run([1.0] * 117, 117, tty=False)
    assert len(lines) == int(117 // PLAIN_EVERY_S)
    assert lines[0] == "fit    9 %  10/117  0:10 elapsed  about 1:47 left"
    assert lines[-1].startswith("fit   94 %  110/117  1:50 elapsed  about 0:07 left")
    assert all("\r" not in line and "[" not in line for line in lines)


def test_on_a_terminal_a_bar_redrawn_in_place():
    frames, _ = _run([0.5] * 10, 10, tty=True)
    assert frames[0] == ""
    assert re.fullmatch(r"fit  \[-{30}\]    0 %  0/10  0:00 elapsed", frames[1])
    assert frames[-1].rstrip("\n").startswith("fit  [" + "#" * 30 + "]  100 %  10/10  0:05 elapsed")
    assert "left" not in frames[-1]


def test_items_are_iterated_and_counted():
    out = io.StringIO()
    bar = Progress(["a", "b", "c"], label="x", file=out, tty=False, clock=Clock())
    with bar:
        assert list(bar) == ["a", "b", "c"]
    assert bar.pos == 3 and bar.length == 3 and out.getvalue() == ""


@pytest.mark.parametrize("seconds, text", [(0, "0:00"), (59.4, "0:59"), (485, "8:05"), (3600, "1:00:00"),
                                           (3725, "1:02:05"), (-3, "0:00")])
def test_durations(seconds, text):
    assert format_duration(seconds) == text


class _Out(io.StringIO):
    def __init__(self, tty: bool):
        super().__init__()
        self.tty = tty

    def isatty(self) -> bool:
        return self.tty


@pytest.mark.parametrize("tty", [False, True])
def test_the_demo_shows_a_childs_progress_and_keeps_all_its_output(tty):
    """A demo stage's command runs in a child whose output goes to a log: its progress lines
    (every ~10 s, a pipe being no terminal) are shown as they come, nothing else is."""
    from locust.demo.runner import relay_progress

    clock, child = Clock(), io.StringIO()
    with Progress(length=30, label="fitting hops", file=child, tty=False, clock=clock) as bar:
        for _ in range(30):
            clock.t += 1.0
            bar.update(1)
    lines = ["loading robot.toml\n", *child.getvalue().splitlines(keepends=True), "wrote robot.toml\n"]
    out = _Out(tty)
    assert relay_progress(iter(lines), out) == "".join(lines)
    shown = out.getvalue()
    assert "robot.toml" not in shown
    progress_lines = child.getvalue().splitlines()
    assert len(progress_lines) == 3          # at 10, 20 and 30 s
    if tty:
        assert shown == "".join("\r\x1b[K      " + p for p in progress_lines) + "\n"
    else:
        assert shown.splitlines() == ["      " + p for p in progress_lines]


@pytest.mark.parametrize("tty", [False, True])
def test_silenced_shows_nothing_and_ends_with_its_block(tty):
    """Inside silenced() (a notebook cell) neither lines nor a bar; after it, as before."""
    for quiet, expect_output in ((True, False), (False, True)):
        clock, out = Clock(), io.StringIO()
        with silenced() if quiet else contextlib.nullcontext():
            with Progress(length=5, label="rendering", file=out, tty=tty, clock=clock) as bar:
                for _ in range(5):
                    clock.t += PLAIN_EVERY_S + 1
                    bar.update(1)
        assert bool(out.getvalue()) == expect_output, (quiet, out.getvalue())


def test_a_stage_of_long_commands_says_its_time_left_from_a_quarter_on_and_a_line_every_ten_s():
    """The demo's hops stage: 6 commands, two at a time, each pair 20 s with its start-up. With
    the rate measured from the start, the time left is shown from the first pair on and is the
    true one (40 s, then 20 s); ticked every second, a line comes every 10 s between pairs."""
    clock, out = Clock(), io.StringIO()
    bar = Progress(length=6, label="hops", file=out, tty=False, clock=clock, rate_from_start=True)
    start, etas = clock.t, {}
    with bar:
        for _ in range(3):
            for _ in range(20):
                clock.t += 1.0
                bar.tick()
            bar.update(1)
            bar.update(1)
            etas[bar.pos] = bar.eta_s()
    assert etas[2] == pytest.approx(40.0) and etas[4] == pytest.approx(20.0)
    true_left = {2: 40.0, 4: 20.0}
    assert all(0.5 <= etas[k] / true_left[k] <= 2.0 for k in true_left)
    lines = out.getvalue().splitlines()
    assert len(lines) == int((clock.t - start) // PLAIN_EVERY_S)
    assert lines[1] == "hops    0 %  0/6  0:20 elapsed"              # (the tick just before the pair ended)
    assert lines[2] == "hops   33 %  2/6  0:30 elapsed  about 0:30 left"   # counting down through the next
