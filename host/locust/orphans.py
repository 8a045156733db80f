"""No orphans: a child process that dies with the process that started it (Linux)."""

from __future__ import annotations

import os
import signal


def _libc_prctl():
    try:
        import ctypes

        return ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):  # not Linux
        return None


# looked up at import: a child between fork and exec only calls it
_PRCTL = _libc_prctl()
_PR_SET_PDEATHSIG = 1


def die_with_parent(parent_pid: int) -> None:
    """In a child: be killed when ``parent_pid`` dies, however it dies (kill -9, out of memory).

    Elsewhere than Linux nothing happens (the parent's own shutdown then has to do it).

    Parameters
    ----------
    parent_pid : int
    """
    if _PRCTL is None:
        return
    _PRCTL(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent_pid:   # the parent died before the line above
        os._exit(1)
