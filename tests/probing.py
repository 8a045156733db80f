"""What every bad-input probe asserts: a clear ``error:``/``hint:``, exit 2, no traceback, and
no file under the probe's folder changed (bytes and mode), lost or left behind.

The commands run in this process through the ``locust`` click group, as the console script
runs them. Each test file that probes a class of bad input imports these.
"""

from __future__ import annotations

import os
import stat
import traceback as _traceback
from pathlib import Path

from click.testing import CliRunner

from locust.commands import cli


def tree(folder: Path) -> dict[str, tuple[bytes, int]]:
    """Every file under ``folder``: its bytes and mode (symlinks by their target's name)."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = str(p.relative_to(folder))
        if p.is_symlink():
            out[rel] = (os.readlink(p).encode(), 0)
        elif p.is_file():
            out[rel] = (p.read_bytes(), stat.S_IMODE(p.stat().st_mode))
        elif p.is_dir():
            out[rel + "/"] = (b"", stat.S_IMODE(p.stat().st_mode))
        else:   # a pipe, a device: its type and mode
            out[rel + "|"] = (b"", p.stat().st_mode)
    return out


def invoke(args: list[str]):
    return CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=True)


def assert_clear_error(res, *words: str) -> None:
    traceback = "".join(_traceback.format_exception(res.exception)) if res.exception else ""
    # click ends a refused command with SystemExit(2); any other exception is a crash
    assert res.exception is None or isinstance(res.exception, SystemExit), traceback
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.output
    assert "error:" in res.stderr and "hint:" in res.stderr, res.stderr
    for w in words:
        assert w in res.stderr, (w, res.stderr)


def assert_refused_and_unchanged(folder: Path, args: list, *words: str) -> None:
    """Run ``args`` in ``folder``; it must be a clear error and leave every file as it was."""
    before = tree(folder)
    res = invoke(args)
    assert_clear_error(res, *words)
    assert tree(folder) == before


def signalled_in_design(signal_name: str, call: int) -> str:
    """A Python script running the ``locust`` command line that sends itself ``signal_name``
    (SIGINT: Ctrl-C; SIGKILL: a lost machine) as it starts judging its ``call``-th design of
    ``locust optimize``: a point that does not depend on the machine's speed."""
    return f"""
import os, signal, sys
from locust.sweep import robust
judge = robust.DesignJudge.__call__
calls = []
def judge_or_signal(self, values):
    calls.append(1)
    if len(calls) == {call}:
        os.kill(os.getpid(), signal.{signal_name})
    return judge(self, values)
robust.DesignJudge.__call__ = judge_or_signal
from locust.commands import main
sys.argv[0] = "locust"
main()
"""
