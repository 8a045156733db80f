"""A kill (SIGTERM) or a closed terminal (SIGHUP) ends a command that talks to the robot as
Ctrl-C does: the robot goes to rest, the run record says so, a ``--port sim`` virtual robot
stops. Without this a TERM ends the process where it stands, the board's servos pushing."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

ENDING_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


def interrupt(signum, frame) -> None:
    """A signal handler that raises KeyboardInterrupt, so that Ctrl-C's handling takes over.

    Parameters
    ----------
    signum : int
        The signal.
    frame : frame or None
        Where it arrived.

    Raises
    ------
    KeyboardInterrupt
        Always.
    """
    raise KeyboardInterrupt


@contextlib.contextmanager
def signals_interrupt(signals: tuple[int, ...] = ENDING_SIGNALS) -> Iterator[None]:
    """Inside the block, each of ``signals`` raises KeyboardInterrupt; the handlers before it
    come back after. Only the main thread can set handlers: elsewhere (a notebook's worker
    thread) the block runs with the process's own.

    Parameters
    ----------
    signals : tuple of int, default (SIGTERM, SIGHUP)
        The signals that end the work as Ctrl-C does.

    Yields
    ------
    None
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, interrupt) for sig in signals}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
