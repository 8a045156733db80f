r"""A `machine` module for the MicroPython unix port: the virtual robot's hardware.

MicroPython code (it runs inside the interpreter, not on the host). It shadows the unix
port's own `machine` (found first on MICROPYPATH) and offers what the firmware uses:
Pin, PWM at a period, reset, with the modelled chip's limits: a Pin that chip lacks raises
ValueError, PWM on an input-only pin too, PWM on a flash pin crashes (reboots) the board, and
a PWM used after deinit() raises RuntimeError. Every PWM change is written as one line
    P <pin> <duty_ns> <ticks_us>\n
to the FIFO named by $LOCUST_PWM_FIFO, where the host turns it back into a horn angle
and feeds the plant. `reset()` writes "R" and the host reboots the interpreter.
"""

import os
import time

_fifo = None


def _pins(name):
    text = os.getenv(name) or ""
    return [int(p) for p in text.split(",") if p]


# the modelled chip's pins (set by the host from locust.firmware.config.CHIPS): those that are
# not a machine.Pin there, those without an output driver, those wired to the flash
_INVALID = _pins("LOCUST_PINS_INVALID")
_INPUT_ONLY = _pins("LOCUST_PINS_INPUT")
_FLASH = _pins("LOCUST_PINS_FLASH")


def _emit(line):
    global _fifo
    if _fifo is None:
        path = os.getenv("LOCUST_PWM_FIFO")
        _fifo = open(path, "wb") if path else False
    if _fifo:
        _fifo.write(line.encode())


class Pin:
    """A GPIO pin of the modelled chip; nothing drives it, so a pulled-up input reads 1.

    Parameters
    ----------
    id : int
        The GPIO number (ValueError for a pin the chip lacks).
    mode, pull : int, optional
        ``Pin.IN``/``Pin.OUT``/... and ``Pin.PULL_UP``/``Pin.PULL_DOWN``, as MicroPython's.
    value : int, optional
        The initial level, 0 or 1.
    """

    IN = 1
    OUT = 3
    OPEN_DRAIN = 7
    PULL_UP = 2
    PULL_DOWN = 1

    def __init__(self, id, mode=-1, pull=-1, value=None, **kw):
        if id in _INVALID:
            raise ValueError("invalid pin")  # as the ESP32 port's machine.Pin says
        self.id = id
        # nothing drives the virtual board's pins: a pulled-up input (the BOOT button) reads 1
        self._value = value if value is not None else (1 if pull == Pin.PULL_UP else 0)

    def value(self, v=None):
        """Read the pin's level, or set it.

        Parameters
        ----------
        v : int or bool, optional
            The level to set; read when None.

        Returns
        -------
        int or None
            The level, 0 or 1, when read.
        """
        if v is None:
            return self._value
        self._value = 1 if v else 0

    def __repr__(self):
        return "Pin(%s)" % self.id


class PWM:
    """A PWM output whose every duty change is written to the host's FIFO with its ``ticks_us``.

    Parameters
    ----------
    pin : Pin or int
        The pin (ValueError for an input-only pin; a flash pin crashes the board).
    freq : int, default 50
        PWM frequency [Hz].
    duty_ns, duty_u16, duty : int, optional
        The initial duty: pulse width [ns], or a fraction of the period in 16 or 10 bits.
    """

    def __init__(self, pin, freq=50, duty_ns=None, duty_u16=None, duty=None, **kw):
        self.pin = pin.id if isinstance(pin, Pin) else Pin(int(pin)).id
        if self.pin in _INPUT_ONLY:
            raise ValueError("pin can only be input")
        if self.pin in _FLASH:
            # a board loses its flash (or PSRAM) mid-instruction fetch: a crash, then a reboot
            print("Guru Meditation Error: Core 0 panic'ed (the virtual robot: GPIO%d drives the flash)" % self.pin)
            reset()
        self._freq = freq
        self._ns = 0
        self._active = True
        if duty_ns is not None:
            self.duty_ns(duty_ns)
        elif duty_u16 is not None:
            self.duty_u16(duty_u16)
        elif duty is not None:
            self.duty(duty)

    def _period_ns(self):
        return 1000000000 // self._freq

    def _check(self):
        if not self._active:
            raise RuntimeError("PWM is inactive")  # the ESP32 port, after deinit()

    def freq(self, f=None):
        """Read the PWM frequency, or set it (keeping the pulse width).

        Parameters
        ----------
        f : int, optional
            The frequency to set [Hz]; read when None.

        Returns
        -------
        int or None
            The frequency [Hz] when read.
        """
        self._check()
        if f is None:
            return self._freq
        self._freq = int(f)
        self.duty_ns(self._ns)

    def duty_ns(self, ns=None):
        """Read the pulse width, or set it (clipped to 0..period) and tell the host.

        Parameters
        ----------
        ns : int, optional
            The pulse width to set [ns]; read when None.

        Returns
        -------
        int or None
            The pulse width [ns] when read.
        """
        self._check()
        if ns is None:
            return self._ns
        self._ns = max(0, min(int(ns), self._period_ns()))
        _emit("P %d %d %d\n" % (self.pin, self._ns, time.ticks_us()))

    def duty_u16(self, v=None):
        """Read or set the duty as a 16-bit fraction of the period.

        Parameters
        ----------
        v : int, optional
            The duty to set, 0..65535; read when None.

        Returns
        -------
        int or None
            The duty, 0..65535, when read.
        """
        if v is None:
            return self._ns * 65535 // self._period_ns()
        self.duty_ns(int(v) * self._period_ns() // 65535)

    def duty(self, v=None):  # the ESP32's 10-bit duty
        """Read or set the duty as the ESP32's 10-bit fraction of the period.

        Parameters
        ----------
        v : int, optional
            The duty to set, 0..1023; read when None.

        Returns
        -------
        int or None
            The duty, 0..1023, when read.
        """
        if v is None:
            return self._ns * 1023 // self._period_ns()
        self.duty_ns(int(v) * self._period_ns() // 1023)

    def deinit(self):
        """Stop the output (a zero pulse, told to the host); any later use raises RuntimeError."""
        if self._active:
            self._active = False
            self._ns = 0
            _emit("P %d 0 %d\n" % (self.pin, time.ticks_us()))


PWRON_RESET = 1
HARD_RESET = 2
WDT_RESET = 3
DEEPSLEEP_RESET = 4
SOFT_RESET = 5


def reset_cause():
    """How this boot came about, as the host says (``PWRON_RESET`` by default).

    Returns
    -------
    int
        ``PWRON_RESET``, ``HARD_RESET``, ``SOFT_RESET``, ...
    """
    return int(os.getenv("LOCUST_RESET_CAUSE") or PWRON_RESET)  # the host tells how it rebooted


def reset():
    """Ask the host for a hard reset (it reboots the interpreter) and wait for it."""
    _emit("R\n")
    time.sleep(1)


def soft_reset():
    """End the interpreter (``SystemExit``): the host starts it again, as a soft reset."""
    raise SystemExit


def unique_id():
    """The board's id.

    Returns
    -------
    bytes
        ``b"virtual0"``.
    """
    return b"virtual0"


def freq():
    """The CPU frequency.

    Returns
    -------
    int
        240000000 [Hz], a classic ESP32's.
    """
    return 240000000


def idle():
    """Sleep 1 ms, the unix port's stand-in for waiting on an interrupt."""
    time.sleep_ms(1)
