# `time` with a board's 30-bit ticks, for the virtual robot (MicroPython code).
#
# The unix port is 64-bit: its ticks_us() wraps after 2**62 us, so code that mishandles the
# wrap never fails there. On an ESP32 ticks_us(), ticks_ms() and ticks_cpu() wrap at 2**30
# (MICROPY_PY_TIME_TICKS_PERIOD) and ticks_diff() is right only for |difference| < 2**29.
# This module gives those ticks, offset by $LOCUST_TICKS_OFFSET_US so that they start a few
# seconds before a wrap: every hop started soon after a boot crosses one. Everything else is
# the built-in module's.
import os

import utime as _t
from utime import *  # noqa: F403

_PERIOD = 1 << 30
_MASK = _PERIOD - 1
_HALF = _PERIOD >> 1
_off_us = int(os.getenv("LOCUST_TICKS_OFFSET_US") or 0)
_off_ms = _off_us // 1000


def ticks_us():
    return (_t.ticks_us() + _off_us) & _MASK


def ticks_ms():
    return (_t.ticks_ms() + _off_ms) & _MASK


def ticks_cpu():
    return ticks_us()


def ticks_add(ticks, delta):
    return (ticks + delta) & _MASK


def ticks_diff(end, start):
    return ((end - start + _HALF) & _MASK) - _HALF
