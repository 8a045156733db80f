"""`select` whose poll timeouts end on a 10 ms tick, as on an ESP32 (MicroPython code).

MicroPython's ESP32 poll loop sleeps between checks with ulTaskNotifyTake(.., 1): one
FreeRTOS tick, 10 ms at CONFIG_FREERTOS_HZ=100. Input wakes it at once, but a timeout only
ends on the first tick at or after it: poll(3) can take 10 ms. The unix port's poll ends to
the millisecond. Here a timeout is stretched to the next multiple of TICK_MS of the
monotonic clock; ready input still returns at once. poll(0) and poll(-1) are unchanged.
"""
import uselect as _s
import utime as _t
from uselect import *  # noqa: F403

TICK_MS = 10


def _stretched(timeout):
    if timeout is None or timeout <= 0:
        return timeout
    now = _t.ticks_ms()
    end = now + timeout
    return end + (-end) % TICK_MS - now


class poll:
    """MicroPython's ``select.poll`` whose timeouts end on the next 10 ms tick."""

    def __init__(self):
        self._p = _s.poll()

    def register(self, obj, *mask):
        """Watch ``obj``.

        Parameters
        ----------
        obj : stream
            The object to watch.
        *mask : int
            The events to watch for (``POLLIN`` ...), as MicroPython's.
        """
        self._p.register(obj, *mask)

    def unregister(self, obj):
        """Stop watching ``obj``.

        Parameters
        ----------
        obj : stream
            The object watched.
        """
        self._p.unregister(obj)

    def modify(self, obj, mask):
        """Change the events watched for on ``obj``.

        Parameters
        ----------
        obj : stream
            The object watched.
        mask : int
            The events to watch for.
        """
        self._p.modify(obj, mask)

    def poll(self, timeout=-1, *flags):
        """Wait for events, a timeout stretched to the next 10 ms tick.

        Parameters
        ----------
        timeout : int, default -1
            Longest wait [ms]; -1 waits for ever, 0 not at all.
        *flags : int
            As MicroPython's.

        Returns
        -------
        list of tuple
            (object, event) for each ready object.
        """
        return self._p.poll(_stretched(timeout), *flags)

    def ipoll(self, timeout=-1, *flags):
        """Like :meth:`poll`, returning MicroPython's iterator.

        Parameters
        ----------
        timeout : int, default -1
            Longest wait [ms]; -1 waits for ever, 0 not at all.
        *flags : int
            As MicroPython's.

        Returns
        -------
        iterator of tuple
            (object, event) for each ready object.
        """
        return self._p.ipoll(_stretched(timeout), *flags)
