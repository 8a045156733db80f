"""`locust demo` stopped in its hops stage by one TERM, one Ctrl-C or a kill -9: gone within
2 s (its children sent TERM, killed after half a second), no command of it left running,
nothing started after the signal, and (but for kill -9) `error:`/`hint:` with exit code 2."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from waiting import wait_for

GONE_S = 2.0      # the acceptance: gone within 2 s of one TERM or Ctrl-C


def descendants(pid: int) -> set[int]:
    """Every process below ``pid`` now (from /proc's children lists, one a thread: a command
    the demo runs side by side is started from a thread of its own)."""
    found, todo = set(), [pid]
    while todo:
        p = todo.pop()
        kids = []
        for task in Path(f"/proc/{p}/task").glob("*"):
            try:
                kids += (task / "children").read_text().split()
            except OSError:
                continue
        for k in map(int, kids):
            if k not in found:
                found.add(k)
                todo.append(k)
    return found


def alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def start_demo(out: Path) -> tuple[subprocess.Popen, list[str]]:
    """The demo in a session of its own (a terminal's process group), its stderr collected."""
    proc = subprocess.Popen([sys.executable, "-m", "locust.commands", "demo", "--out", str(out), "--cycles", "3",
                             "--trials", "2", "--no-fit-hops"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, cwd=out)
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(proc.stderr), daemon=True).start()
    return proc, lines


def in_hops_stage(proc: subprocess.Popen, lines: list[str], hops: Path) -> set[int]:
    """Wait until two `locust hop` children run, each with its virtual robot, and each has made
    its run folder in ``hops`` (a hop makes it after it starts: listing the folder before then
    would race it); their tree."""
    def hopping() -> bool:
        kids = [k for k in descendants(proc.pid) if b"hop" in Path(f"/proc/{k}/cmdline").read_bytes()]
        return (len(kids) >= 2 and len(descendants(proc.pid)) >= 4 and hops.is_dir()
                and len(list(hops.iterdir())) >= 2)
    wait_for(hopping, 120, "two filmed hops running, their folders made")
    return descendants(proc.pid)


@pytest.mark.parametrize("how", ["TERM", "Ctrl-C"])
def test_one_signal_ends_the_demo_and_its_commands_within_two_seconds(tmp_path, how):
    proc, lines = start_demo(tmp_path)
    tree = in_hops_stage(proc, lines, tmp_path / "run" / "hops")
    folders = set((tmp_path / "run" / "hops").iterdir())
    t0 = time.perf_counter()
    if how == "TERM":
        proc.send_signal(signal.SIGTERM)
    else:
        os.killpg(proc.pid, signal.SIGINT)      # what a terminal sends its foreground group
    rc = proc.wait(timeout=30)
    gone_s = time.perf_counter() - t0
    assert gone_s < GONE_S, gone_s
    assert rc == 2
    time.sleep(0.2)                           # (the stderr reader's last lines)
    text = "".join(lines)
    word = {"TERM": "a TERM signal", "Ctrl-C": "Ctrl-C"}[how]
    assert f"error: demo stopped by {word} during stage 2/8" in text and "hint:" in text, text[-2000:]
    assert "Traceback" not in text and "Aborted!" not in text
    assert not [p for p in tree if alive(p)]                  # no command of it left
    assert set((tmp_path / "run" / "hops").iterdir()) <= folders   # no hop started after it (empty ones go)


def test_a_kill_9_takes_its_commands_with_it(tmp_path):
    proc, lines = start_demo(tmp_path)
    tree = in_hops_stage(proc, lines, tmp_path / "run" / "hops")
    proc.kill()
    proc.wait(timeout=30)
    wait_for(lambda: not [p for p in tree if alive(p)], GONE_S, "the demo's commands ending with it")
