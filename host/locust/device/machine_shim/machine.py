# A `machine` module for the MicroPython unix port: the virtual robot's hardware.
#
# MicroPython code (it runs inside the interpreter, not on the host). It shadows the unix
# port's own `machine` (found first on MICROPYPATH) and offers what the firmware uses:
# Pin, PWM at a period, reset, with the modelled chip's limits: a Pin that chip lacks raises
# ValueError, PWM on an input-only pin too, PWM on a flash pin crashes (reboots) the board, and
# a PWM used after deinit() raises RuntimeError. Every PWM change is written as one line
#     P <pin> <duty_ns> <ticks_us>\n
# to the FIFO named by $LOCUST_PWM_FIFO, where the host turns it back into a horn angle
# and feeds the plant. `reset()` writes "R" and the host reboots the interpreter.

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
        if v is None:
            return self._value
        self._value = 1 if v else 0

    def __repr__(self):
        return "Pin(%s)" % self.id


class PWM:
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
        self._check()
        if f is None:
            return self._freq
        self._freq = int(f)
        self.duty_ns(self._ns)

    def duty_ns(self, ns=None):
        self._check()
        if ns is None:
            return self._ns
        self._ns = max(0, min(int(ns), self._period_ns()))
        _emit("P %d %d %d\n" % (self.pin, self._ns, time.ticks_us()))

    def duty_u16(self, v=None):
        if v is None:
            return self._ns * 65535 // self._period_ns()
        self.duty_ns(int(v) * self._period_ns() // 65535)

    def duty(self, v=None):  # the ESP32's 10-bit duty
        if v is None:
            return self._ns * 1023 // self._period_ns()
        self.duty_ns(int(v) * self._period_ns() // 1023)

    def deinit(self):
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
    return int(os.getenv("LOCUST_RESET_CAUSE") or PWRON_RESET)  # the host tells how it rebooted


def reset():
    _emit("R\n")
    time.sleep(1)


def soft_reset():
    raise SystemExit


def unique_id():
    return b"virtual0"


def freq():
    return 240000000


def idle():
    time.sleep_ms(1)
