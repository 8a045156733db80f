"""The modem lines the host moves when it opens and closes the port, against a model of the board.

A DevKit wires DTR and RTS to EN and GPIO0 through two transistors (the auto-reset circuit):
EN is pulled low, a reset, while RTS is asserted and DTR is not; GPIO0 is pulled low while DTR
is asserted and RTS is not (download mode if EN rises then). The C3/S3's USB-Serial-JTAG
controller acts on the same two lines the same way. The double below records every state the
lines pass through, from the kernel asserting both at open to the kernel dropping both
together at close, and the test asserts the host never passes through a reset state.
"""

from __future__ import annotations

import fcntl
import os
import pty
import struct
import termios

import pytest
import serial.serialposix as SP

from locust.device import link as L

DTR, RTS = termios.TIOCM_DTR, termios.TIOCM_RTS
REAL_IOCTL = fcntl.ioctl  # pyserial and this test share the one fcntl module


class AutoResetBoard:
    """The lines' states as the board sees them; ``resets`` counts EN pulses (RTS=1, DTR=0)."""

    def __init__(self):
        self.lines = DTR | RTS          # the kernel asserts both when the port opens
        self.states = [self.lines]
        self.calls: list[str] = []
        self.first_write_at: int | None = None

    def _enter(self, lines: int) -> None:
        self.lines = lines
        self.states.append(lines)

    def ioctl(self, fd, request, arg=0, *rest):
        names = {termios.TIOCMBIS: "TIOCMBIS", termios.TIOCMBIC: "TIOCMBIC", termios.TIOCMSET: "TIOCMSET"}
        if request in names:
            bits = struct.unpack("I", arg)[0]
            self.calls.append(names[request])
            if request == termios.TIOCMBIS:
                self._enter(self.lines | bits)
            elif request == termios.TIOCMBIC:
                self._enter(self.lines & ~bits)
            else:
                self._enter(bits)
            return arg
        if request == termios.TIOCMGET:
            return struct.pack("I", self.lines)
        return REAL_IOCTL(fd, request, arg, *rest)

    def closed(self) -> None:
        self._enter(0)  # HUPCL: the kernel drops both lines in one request

    @property
    def resets(self) -> int:
        return sum(1 for s in self.states if s & RTS and not s & DTR)


def test_auto_reset_model_flags_the_sequence_that_resets():
    """The model itself: pyserial's dtr=False, rts=False before open (applied DTR first) resets."""
    board = AutoResetBoard()
    board.ioctl(0, termios.TIOCMBIC, struct.pack("I", DTR))
    board.ioctl(0, termios.TIOCMBIC, struct.pack("I", RTS))
    assert board.resets == 1
    calm = AutoResetBoard()
    calm.ioctl(0, termios.TIOCMBIC, struct.pack("I", RTS))  # RTS first: GPIO0 low only, no reset
    calm.ioctl(0, termios.TIOCMBIC, struct.pack("I", DTR))
    assert calm.resets == 0


@pytest.fixture
def board(monkeypatch):
    model = AutoResetBoard()
    monkeypatch.setattr(SP.fcntl, "ioctl", model.ioctl)
    real_write = os.write

    def write(fd, data):
        if model.first_write_at is None and fd == getattr(model, "fd", None):
            model.first_write_at = len(model.calls)
        return real_write(fd, data)

    monkeypatch.setattr(SP.os, "write", write)
    return model


def test_link_open_and_close_make_no_reset_pulse(board):
    master, slave = pty.openpty()
    try:
        link = L.Link(os.ttyname(slave))
        board.fd = link.serial.fd
        before_write = list(board.calls)
        link.write(b"$x*00000000\n")
        assert board.first_write_at == len(before_write)
        link.close()
        board.closed()
    finally:
        os.close(master)
        os.close(slave)
    # before the first byte only re-assertions of what the kernel asserted: no line moves
    assert set(before_write) <= {"TIOCMBIS"} and before_write
    assert all(s == DTR | RTS for s in board.states[:len(before_write) + 1])
    assert board.resets == 0
    # at close RTS goes first: DTR=1/RTS=0 (GPIO0 low, ignored by a running chip), then both low
    assert board.states[-3:] == [DTR, 0, 0]
