"""Waiting on another process: poll a condition until it holds or a deadline passes."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")


def wait_for(predicate: Callable[[], T], timeout_s: float, what: str, poll_s: float = 0.02) -> T:
    """Call ``predicate`` until it returns something true; return that.

    Parameters
    ----------
    predicate : callable
        Asked again every ``poll_s`` seconds; an ``OSError``, ``ValueError`` or ``KeyError`` it
        raises (a file not written yet, half written, or without that entry yet) counts as not yet.
    timeout_s : float
        The deadline [s] from the call; past it, ``AssertionError`` saying ``what`` was awaited.
    what : str
        The condition in words, for the failure's message.
    poll_s : float
        The pause between two tries [s].

    Returns
    -------
    object
        The predicate's first true value.
    """
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            value = predicate()
        except (OSError, ValueError, KeyError):
            value = None
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"waited {timeout_s:g} s for {what}; it did not happen")
        time.sleep(poll_s)
