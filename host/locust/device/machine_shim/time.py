"""`time` with a board's 30-bit ticks, for the virtual robot (MicroPython code).

The unix port is 64-bit: its ticks_us() wraps after 2**62 us, so code that mishandles the
wrap never fails there. On an ESP32 ticks_us(), ticks_ms() and ticks_cpu() wrap at 2**30
(MICROPY_PY_TIME_TICKS_PERIOD) and ticks_diff() is right only for |difference| < 2**29.
This module gives those ticks, offset by $LOCUST_TICKS_OFFSET_US so that they start a few
seconds before a wrap: every hop started soon after a boot crosses one. Everything else is
the built-in module's.
"""
import os

import utime as _t
from utime import *  # noqa: F403

_PERIOD = 1 << 30
_MASK = _PERIOD - 1
_HALF = _PERIOD >> 1
_off_us = int(os.getenv("LOCUST_TICKS_OFFSET_US") or 0)
_off_ms = _off_us // 1000


def ticks_us():
    """Microseconds, wrapping at 2**30 as on an ESP32, offset to start near a wrap.

    Returns
    -------
    int
        Ticks [us].
    """
    return (_t.ticks_us() + _off_us) & _MASK


def ticks_ms():
    """Milliseconds, wrapping at 2**30 as on an ESP32.

    Returns
    -------
    int
        Ticks [ms].
    """
    return (_t.ticks_ms() + _off_ms) & _MASK


def ticks_cpu():
    """The CPU ticks; here the same as :func:`ticks_us`.

    Returns
    -------
    int
        Ticks [us].
    """
    return ticks_us()


def ticks_add(ticks, delta):
    """A tick count moved by ``delta``, wrapped at 2**30.

    Parameters
    ----------
    ticks : int
        A tick count.
    delta : int
        Ticks to add (may be negative).

    Returns
    -------
    int
        The sum, wrapped.
    """
    return (ticks + delta) & _MASK


def ticks_diff(end, start):
    """``end - start`` across a wrap, right for differences under 2**29.

    Parameters
    ----------
    end, start : int
        Tick counts.

    Returns
    -------
    int
        The signed difference in ticks.
    """
    return ((end - start + _HALF) & _MASK) - _HALF
