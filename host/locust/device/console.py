"""The virtual robot's console: the bridge between the interpreter's pseudo-terminal and the
clients' one (``/dev/pts/N``), as a board's USB-serial bridge and console driver behave.

- bytes are copied both ways and dropped, like a UART's, when nobody reads;
- a bare LF the unix port writes reaches the client as the CR LF a board sends
  (:class:`ConsoleLines`);
- the REPL's mode (raw or friendly) is read off what the interpreter prints, so that a soft
  reset from the raw REPL comes back in it, as on a board;
- Ctrl-C raises KeyboardInterrupt wherever the program is while it has Ctrl-C on, not only
  in a read (a SIGINT, which the unix port turns into that).
"""

from __future__ import annotations

import errno
import fcntl
import os
import select
import signal
import subprocess
import threading
import time
from collections.abc import Callable

RAW_REPL_BANNER = b"raw REPL; CTRL-B to exit\r\n"
FRIENDLY_PROMPT = b"\n>>> "
CTRL_A = b"\x01"
CTRL_C = b"\x03"
SIGINT_BIT = 1 << (signal.SIGINT - 1)
READ_SYSCALL = {"x86_64": 0, "aarch64": 63}.get(os.uname().machine)  # read(2)'s number here


def set_nonblocking(fd: int) -> None:
    """Reads and writes on ``fd`` return at once.

    Parameters
    ----------
    fd : int
        A file descriptor.
    """
    fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) | os.O_NONBLOCK)


def _last_new(buf: bytes, marker: bytes, seen: int) -> int:
    """Where ``marker`` last occurs in ``buf`` ending past ``buf[:seen]`` (already searched), or -1."""
    i = buf.rfind(marker)
    return i if i >= 0 and i + len(marker) > seen else -1


class ConsoleLines:
    """A board's console line endings for what the unix port writes with a bare LF.

    On a board, MicroPython writes its text (the REPL's echo and prompt, ``print``, a
    traceback) through ``mp_hal_stdout_tx_strn_cooked``, which sends each LF as CR LF; the
    unix port leaves that to its terminal's ``onlcr``, which the virtual robot's raw
    pseudo-terminals do not do, so mpremote's REPL and a serial monitor showed a staircase.
    ``onlcr`` itself would be wrong: it doubles the CR of what a board sends as CR LF already
    (the raw REPL's banner, which mpremote waits for byte for byte). So only a bare LF becomes
    CR LF, and not at the end of a protocol frame (a line that starts with ``$``), which the
    firmware writes through ``sys.stdout.buffer``, raw on a board as well. Binary a program
    writes through ``sys.stdout.buffer`` (mpremote's ``mount``) gets a CR before each LF
    here, as under any terminal; a board sends it as it is.
    """

    def __init__(self):
        self._line = b""        # the current line's first byte (b"" at the start of a line)
        self._last = b"\n"      # the last byte passed on

    def feed(self, data: bytes) -> bytes:
        """What the client receives for ``data`` written by the interpreter.

        Parameters
        ----------
        data : bytes
            The next bytes of the interpreter's output.

        Returns
        -------
        bytes
            The same, each bare LF outside a frame written CR LF.
        """
        *lines, tail = data.split(b"\n")
        out = bytearray()
        for seg in lines:
            first = self._line or seg[:1]
            before = seg[-1:] or self._last
            out += seg + (b"\n" if first == b"$" or before == b"\r" else b"\r\n")
            self._line, self._last = b"", b"\n"
        if tail:
            self._line = self._line or tail[:1]
            self._last = tail[-1:]
            out += tail
        return bytes(out)


def _read_pty(fd: int) -> bytes:
    """What a pseudo-terminal's master holds now (b"" if nothing, or no process on the other side)."""
    try:
        return os.read(fd, 4096)
    except (BlockingIOError, InterruptedError):
        return b""
    except OSError as exc:
        if exc.errno == errno.EIO:
            return b""
        raise


def _catches_sigint(pid: int) -> bool:
    """Whether the process has a SIGINT handler: the unix port installs one exactly while
    Ctrl-C is on (``micropython.kbd_intr(3)``, and while the REPL runs code)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("SigCgt:"):
                    return bool(int(line.split()[1], 16) & SIGINT_BIT)
    except OSError:
        pass
    return False


def _in_readline(pid: int) -> bool:
    """Whether the process is blocked in read(2): the unix port's REPL waiting for a line (the
    firmware waits in poll(2)). A board's REPL takes Ctrl-C there as a character (it cancels
    the line); the unix port keeps its SIGINT handler installed at its prompt."""
    try:
        with open(f"/proc/{pid}/syscall") as fh:
            first = fh.read().split()[:1]
    except OSError:
        return True   # cannot tell: pass the byte on, as the pseudo-terminal would
    return READ_SYSCALL is None or first == [str(READ_SYSCALL)]


class ConsoleBridge:
    """The bridge between the interpreter's console and the clients' pseudo-terminal (see the
    module's description).

    Parameters
    ----------
    console_fd : int
        The master side of the interpreter's console (non-blocking).
    client_fd : int
        The master side of the clients' pseudo-terminal (non-blocking).
    interpreter : callable
        ``interpreter()``: the interpreter's process now (a reboot starts another), or None.
    """

    def __init__(self, console_fd: int, client_fd: int, interpreter: Callable[[], subprocess.Popen | None]):
        self._console_fd, self._client_fd = console_fd, client_fd
        self._interpreter = interpreter
        self.lock = threading.Lock()   # the bridge reads and watches the console under it
        self.raw_repl = False          # the console is in the raw REPL (read off its output)
        self.raw_boot_pending = False  # rebooted from the raw REPL: enter it again at the prompt
        self.bytes_sent = 0            # what reached the client
        self._tail = b""
        self._lines = ConsoleLines()   # a board's CR LF for the REPL's text
        self._sigint_at = 0.0

    def run(self, stopping: threading.Event) -> None:
        """The bridge's thread: pass bytes both ways until ``stopping`` is set.

        Parameters
        ----------
        stopping : threading.Event
            Set when the virtual robot stops (its descriptors are closed after).
        """
        from .link import raise_thread_priority

        raise_thread_priority()   # the host's heartbeat passes through here

        while not stopping.is_set():
            try:
                self._once()
            except (OSError, ValueError):   # a descriptor closed under it: only while stopping
                if stopping.is_set():
                    return
                raise

    def say(self, text: bytes) -> None:
        """Send ``text`` to the client as the interpreter's own output (a reboot's line).

        Parameters
        ----------
        text : bytes
            Its line endings as a board sends them.
        """
        with self.lock:   # (through the console's lines: the next line is a new one)
            self._to_client(self._lines.feed(text))

    def settle(self, timeout_s: float = 1.0) -> None:
        """Wait until the bridge has passed on (and read the REPL mode from) all the interpreter printed.

        Parameters
        ----------
        timeout_s : float, default 1.0
            The longest wait [s].
        """
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self.lock:  # the bridge reads and watches the console under it
                if not select.select([self._console_fd], [], [], 0)[0]:
                    return
            time.sleep(0.005)

    def _to_client(self, data: bytes) -> None:
        try:
            os.write(self._client_fd, data)
            self.bytes_sent += len(data)
        except (BlockingIOError, OSError):
            pass  # nobody reads: dropped, like a UART's output with no listener

    def _once(self) -> None:
        """One pass of the bridge: what the interpreter wrote to the client, what the client
        wrote to the interpreter (Ctrl-C as a board treats it)."""
        ready, _, _ = select.select([self._console_fd, self._client_fd], [], [], 0.2)
        if self._console_fd in ready:
            with self.lock:
                data = _read_pty(self._console_fd)
                if data:
                    self._watch(data)
                    self._to_client(self._lines.feed(data))
        if self._client_fd in ready:
            data = _read_pty(self._client_fd)
            if data:
                data = self._ctrl_c(data)
                try:
                    os.write(self._console_fd, data)
                except (BlockingIOError, OSError):
                    pass  # the interpreter is not reading: input overrun

    def _ctrl_c(self, data: bytes) -> bytes:
        """Ctrl-C as a board's console driver treats it: while the program has Ctrl-C on, the
        0x03 never reaches stdin; it raises KeyboardInterrupt wherever the program is (here: a
        SIGINT, which the unix port turns into that). With Ctrl-C off it is an ordinary byte."""
        if CTRL_C not in data:
            return data
        proc = self._interpreter()
        if proc is None or proc.poll() is not None or not _catches_sigint(proc.pid) or _in_readline(proc.pid):
            return data
        # one SIGINT per burst: the unix port exits on a second SIGINT before the first is handled
        if time.monotonic() - self._sigint_at > 0.1:
            self._sigint_at = time.monotonic()
            proc.send_signal(signal.SIGINT)
        return data.replace(CTRL_C, b"")

    def _watch(self, data: bytes) -> None:
        """Follow the console's REPL mode in the interpreter's output (the last marker wins)."""
        buf = self._tail + data
        seen = len(self._tail)
        raw, friendly = _last_new(buf, RAW_REPL_BANNER, seen), _last_new(buf, FRIENDLY_PROMPT, seen)
        if raw >= 0 or friendly >= 0:
            self.raw_repl = raw > friendly
        self._tail = buf[-(max(len(RAW_REPL_BANNER), len(FRIENDLY_PROMPT)) - 1):]
        if self.raw_boot_pending and friendly >= 0:
            self.raw_boot_pending = False
            try:
                os.write(self._console_fd, CTRL_A)  # back into the raw REPL, as the board stays there
            except OSError:
                pass
