"""The host end of the serial protocol: framed requests with ids, replies, events, heartbeat.

The framing, message names and limits come from the firmware's own ``protocol.py``
(imported here as ``locust.firmware.protocol``), so the two ends cannot drift apart.
A reader thread splits the byte stream into frames: replies go to whoever waits on their
request id, events to a queue; anything else on the line (REPL text, noise) is counted
and dropped.
"""

from __future__ import annotations

import collections
import errno
import os
import queue
import threading
import time

import serial

from ..errors import DeviceError
from ..firmware import protocol as P
from .holders import check_free, in_use_error, port_holders
from .replies import check_hello

STOP_WAIT_S = 1.0               # closing waits this long for the heartbeat thread, then for a write
REPLY_LIMIT = 64 * 1024         # longest reply or event line read (requests are held to P.MAX_FRAME)
CLOSED = {"ev": "link_closed"}  # put on the event queue when the port goes away
REPL_PROMPT = b">>> "           # the friendly REPL echoing a frame: `>>> ${"id":...`
RAW_REPL = b"raw REPL; CTRL-B to exit"
MIN_MICROPYTHON = (1, 26)  # older ESP32 ports start a PWM at 50 % duty (a 10 ms pulse) before duty_ns applies
OLD_MICROPYTHON_HINT = ("install MicroPython 1.26 or newer (docs/hardware.md, \"Installing MicroPython\"): older "
                        "ESP32 releases start each servo's PWM at 50 % duty, a 10 ms pulse that throws the leg "
                        "to its end stop at every boot")


def raise_thread_priority(nice: int = -10) -> None:
    """Best effort: the calling thread ahead of the machine's other work (Linux threads have their
    own nice value; without the privilege, it stays as it is).

    Parameters
    ----------
    nice : int, default -10
        The nice value to set (lower runs first).
    """
    try:
        os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), nice)
    except (OSError, AttributeError):
        pass


class Link:
    """The host end of one serial port speaking the locust protocol.

    Opening it opens the port (keeping DTR and RTS asserted, so that the board is not reset)
    and starts a reader thread: replies go to the request waiting on their id, events to
    :attr:`events`, anything else is counted in :attr:`noise_lines`. Use it as a context
    manager, or call :meth:`close`.

    Parameters
    ----------
    port : str
        The serial port, e.g. ``/dev/ttyUSB0`` or a virtual robot's ``/dev/pts/N``.
    baud : int, default 115200
        Baud rate [bit/s].
    timeout_s : float, default 1.0
        How long a request waits for its reply unless told otherwise [s].

    Raises
    ------
    DeviceError
        The port cannot be opened.
    """

    def __init__(self, port: str, baud: int = 115200, timeout_s: float = 1.0):
        self.port = port
        self.timeout_s = timeout_s
        self.events: queue.Queue = queue.Queue()
        self.unsolicited: collections.deque = collections.deque(maxlen=200)  # replies with no waiter
        self.noise_lines = 0
        self.repl_seen = False  # a MicroPython REPL prompt was among the noise: no command loop
        self.error: Exception | None = None
        self._pending: dict[int, queue.Queue] = {}
        self._lock = threading.Lock()
        self._write_lock = threading.Lock()
        self._next_id = 1
        self._heartbeat: tuple[threading.Event, threading.Thread] | None = None
        ser = serial.Serial()
        ser.port = port
        ser.baudrate = baud
        ser.timeout = 0.05
        # DTR and RTS drive EN and GPIO0 through a DevKit's auto-reset circuit (EN is pulled low
        # while RTS is asserted and DTR is not), and a C3/S3's USB-Serial-JTAG resets the chip on
        # the same combination. The kernel asserts both lines when the port opens; pyserial then
        # applies its own dtr/rts settings one at a time, DTR first. Clearing them (dtr=False,
        # rts=False) passes through DTR=0/RTS=1 and resets the board at every open, and on S2/S3
        # MicroPython sends nothing (or drops bursts) while DTR is low. So keep pyserial's
        # default, both asserted, as mpremote does on POSIX: open() re-asserts what the kernel
        # already asserted (TIOCMBIS only) and the lines never move.
        # Two readers of one port split the board's bytes between them (holders.py): the port is
        # locked (pyserial's flock, which mpremote takes too) and refused while another program
        # has it open, rather than a hop losing its replies to it.
        ser.exclusive = True
        try:
            ser.open()
        except (serial.SerialException, OSError) as exc:
            if exc.errno in (errno.EAGAIN, errno.EWOULDBLOCK):   # the flock: another locust or mpremote
                raise in_use_error(port, port_holders(port)) from None
            raise DeviceError(f"cannot open serial port {port}: {exc}",
                              "check the cable and the port name (`locust ports`)") from None
        try:
            check_free(port)
        except DeviceError:
            ser.close()
            raise
        ser.reset_input_buffer()
        self.serial = ser
        self._reader = threading.Thread(target=self._read_loop, name="locust-link-reader", daemon=True)
        self._reader.start()

    # -- reading ---------------------------------------------------------------------
    def _read_loop(self) -> None:
        lines = P.LineReader(limit=REPLY_LIMIT)
        while self.error is None:
            try:
                data = self.serial.read(max(1, self.serial.in_waiting))
            except (serial.SerialException, OSError, TypeError, AttributeError) as exc:
                if self.serial.is_open:  # not a close() of ours: the cable went away
                    self.error = exc
                break
            for line in lines.feed(data):
                self._dispatch(line)
        self.events.put(CLOSED)
        with self._lock:
            for waiter in self._pending.values():
                waiter.put(CLOSED)

    def _dispatch(self, line: bytes | None) -> None:
        try:
            msg = P.decode(line, REPLY_LIMIT) if line is not None else None
        except P.ProtocolError:
            msg = None
        if msg is None or ("ev" not in msg and "ok" not in msg):  # noise, or a REPL echoing our request
            self.noise_lines += 1
            if line is not None and (REPL_PROMPT in line or RAW_REPL in line):
                self.repl_seen = True
        elif "ev" in msg:
            if msg["ev"] == P.EV_BOOT:
                self.repl_seen = False  # the command loop (re)started
            self.events.put(msg)
        else:
            rid = msg.get("id")   # a reply to none of ours (an id of another type too) is kept aside
            with self._lock:
                waiter = self._pending.pop(rid, None) if type(rid) is int else None
            (waiter.put(msg) if waiter else self.unsolicited.append(msg))

    # -- writing -------------------------------------------------------------------
    def write(self, data: bytes) -> None:
        """Write raw bytes to the port (whole frames come from :meth:`request`).

        Parameters
        ----------
        data : bytes
            The bytes to send.

        Raises
        ------
        DeviceError
            The port is lost.
        """
        with self._write_lock:
            if not self.serial.is_open:   # close() ran: nothing more goes out
                raise DeviceError(f"the serial port {self.port} is closed", "open a new Link") from None
            try:
                self.serial.write(data)
            except (serial.SerialException, OSError) as exc:
                self.error = self.error or exc
                raise self.lost_error() from None
            except (TypeError, AttributeError, ValueError):   # closed under it (close() gave up waiting)
                raise DeviceError(f"the serial port {self.port} is closed", "open a new Link") from None

    def _new_id(self) -> int:
        with self._lock:
            req_id = self._next_id
            self._next_id = self._next_id % P.MAX_ID + 1
            return req_id

    def request(self, cmd: str, timeout_s: float | None = None, **args) -> dict:
        """Send ``cmd`` and wait for its reply (ok or not).

        Parameters
        ----------
        cmd : str
            The protocol command, e.g. ``hello`` or ``hop``.
        timeout_s : float, optional
            How long to wait for the reply [s]; the link's ``timeout_s`` when None.
        **args
            The command's arguments, sent in the request frame.

        Returns
        -------
        dict
            The reply, with ``ok`` true or an ``error`` and ``detail``.

        Raises
        ------
        DeviceError
            No reply in time, or the port is lost.
        """
        if self.error is not None:
            raise self.lost_error()
        req_id = self._new_id()
        waiter: queue.Queue = queue.Queue(maxsize=1)
        with self._lock:
            self._pending[req_id] = waiter
        self.write(P.encode({"id": req_id, "cmd": cmd, **args}))
        try:
            msg = waiter.get(timeout=self.timeout_s if timeout_s is None else timeout_s)
        except queue.Empty:
            with self._lock:
                self._pending.pop(req_id, None)
            other = self.other_program_error()
            if other is not None:
                raise other from None
            raise DeviceError(f"no reply to {cmd!r} from {self.port} within "
                              f"{self.timeout_s if timeout_s is None else timeout_s:g} s",
                              "is the locust firmware running? run `locust flash --port "
                              f"{self.port}` (or reset the board)") from None
        if msg is CLOSED:
            raise self.lost_error()
        return msg

    def call(self, cmd: str, timeout_s: float | None = None, **args) -> dict:
        """Like :meth:`request`, but an error reply raises.

        Parameters
        ----------
        cmd : str
            The protocol command.
        timeout_s : float, optional
            How long to wait for the reply [s]; the link's ``timeout_s`` when None.
        **args
            The command's arguments.

        Returns
        -------
        dict
            The reply, ``ok`` true.

        Raises
        ------
        DeviceError
            An error reply, no reply in time, or the port is lost.
        """
        msg = self.request(cmd, timeout_s, **args)
        if not msg.get("ok"):
            raise DeviceError(f"the robot refused {cmd!r}: {msg.get('error')}: {msg.get('detail')}",
                              "see docs/protocol.md for the limits of each command")
        return msg

    def lost_error(self) -> DeviceError:
        """The error that says the port went away, with the reason, and what the robot does now.

        Returns
        -------
        DeviceError
            The error to raise: "port in use by another program" when another program has
            opened the port since (its reads take the board's bytes away from this one).
        """
        other = self.other_program_error()
        if other is not None:
            return other
        if self._heartbeat is not None:   # the robot's own watch on the host's pings is armed
            after = "the robot returns to rest on its own once the host has been silent for the hop's heartbeat timeout"
        else:   # pose, config, hello: nothing on the robot notices that the host went away
            after = ("nothing tells the robot to rest: the servos keep the last pose they were given until the "
                     "board is reset or powered off")
        return DeviceError(f"lost the serial port {self.port}: {self.error}",
                           f"check the USB cable and the port (`locust ports`), re-plug the board and run the "
                           f"command again; {after}")

    def other_program_error(self) -> DeviceError | None:
        """The "port in use" error when another program has the port open now (one that opened
        it after this link did, without a lock: a serial monitor), else None.

        Returns
        -------
        DeviceError or None
        """
        holders = port_holders(self.port)
        return in_use_error(self.port, holders) if holders else None

    # -- handshake and heartbeat -----------------------------------------------------
    def hello(self, wait_s: float = 3.0, soft_reset: bool = False) -> dict:
        """The identity/version handshake, retried for ``wait_s`` (a board may be booting).

        Parameters
        ----------
        wait_s : float, default 3.0
            How long to keep asking [s].
        soft_reset : bool, default False
            A board found at the MicroPython REPL (mpremote leaves it there) is soft-reset once, as
            mpremote itself does, and gets ``wait_s`` more to start main.py.

        Returns
        -------
        dict
            The ``hello`` reply, checked by :func:`check_hello`.

        Raises
        ------
        DeviceError
            Nothing answers, the board is at the REPL, the answer is not the locust firmware, its
            MicroPython is older than 1.26, or it speaks another protocol version.
        """
        deadline = time.monotonic() + wait_s
        reset_sent = False
        while True:
            try:
                msg = self.request("hello", timeout_s=min(0.5, max(0.05, deadline - time.monotonic())))
                break
            except DeviceError:
                if soft_reset and not reset_sent and self.error is None and self.repl_seen:
                    self.soft_reset()
                    reset_sent = True
                    deadline = time.monotonic() + wait_s
                    continue
                if self.error is None and time.monotonic() >= deadline and self.repl_seen:
                    port = self.port
                    what = "a soft reset did not start it: " if reset_sent else ""
                    raise DeviceError(f"no locust firmware answered on {port}: it is at the MicroPython REPL "
                                      f"({what}after Ctrl-C, mpremote or `locust repl`, or with no main.py)",
                                      f"restart the firmware: Ctrl-D at the >>> prompt of `locust repl --port {port}` "
                                      f"(a soft reset runs main.py), `mpremote connect {port} reset`, "
                                      f"or `locust flash --port {port}` (which also installs it)") from None
                if self.error is not None:
                    raise self.lost_error() from None
                if time.monotonic() >= deadline:
                    other = self.other_program_error()
                    if other is not None:
                        raise other from None
                    raise DeviceError(f"no locust firmware answered on {self.port}",
                                      "flash it with `locust flash --port "
                                      f"{self.port}` (a board without MicroPython needs that first: see "
                                      "`locust flash --help`)") from None
        if not msg.get("ok") or msg.get("name") != P.NAME:
            raise DeviceError(f"{self.port} answered but is not the locust firmware: {msg}",
                              f"flash it with `locust flash --port {self.port}`")
        version = check_hello(msg, self.port).get("micropython")
        if version is not None and tuple(version[:2]) < MIN_MICROPYTHON:  # older firmware does not say
            shown = ".".join(str(v) for v in version)
            raise DeviceError(f"the robot runs MicroPython {shown}; locust needs 1.26 or newer", OLD_MICROPYTHON_HINT)
        if msg.get("protocol") != P.PROTOCOL:
            raise DeviceError(f"firmware {msg.get('version')} speaks protocol {msg.get('protocol')}, "
                              f"this host speaks {P.PROTOCOL}",
                              f"flash the matching firmware with `locust flash --port {self.port}`")
        return msg

    def soft_reset(self) -> None:
        """From the MicroPython REPL back to main.py: Ctrl-C clears the line typed so far,
        Ctrl-B leaves the raw REPL (whose own soft reset skips main.py), Ctrl-D soft-resets.

        Raises
        ------
        DeviceError
            The port is lost.
        """
        self.write(b"\r\x03\x02")
        time.sleep(0.05)    # the REPL redraws its prompt before the reset byte
        self.write(b"\x04")

    def start_heartbeat(self, interval_s: float) -> None:
        """Ping every ``interval_s`` until :meth:`stop_heartbeat`: the robot's proof the host is alive.

        The pings come from a thread of their own, on a fixed clock (a late beat does not push
        the next one later), at a raised priority where the system allows it, so that a busy
        machine or a busy main thread does not silence the host.

        Parameters
        ----------
        interval_s : float
            Time between pings [s].
        """
        self.stop_heartbeat()
        stop = threading.Event()
        frame = P.encode({"id": 0, "cmd": "ping"})

        def beat() -> None:
            raise_thread_priority()
            due = time.monotonic()
            while self.error is None:
                due += interval_s
                if stop.wait(max(0.0, due - time.monotonic())):
                    return
                due = max(due, time.monotonic() - interval_s)   # after a long stall, beat on from now
                try:
                    self.write(frame)
                except DeviceError:
                    return

        thread = threading.Thread(target=beat, name="locust-link-heartbeat", daemon=True)
        self._heartbeat = (stop, thread)
        thread.start()

    def stop_heartbeat(self) -> None:
        """Stop the pings of :meth:`start_heartbeat` and wait for their thread to end (up to
        ``STOP_WAIT_S``): no ping is sent after this returns (nothing happens if none run)."""
        if self._heartbeat is not None:
            stop, thread = self._heartbeat
            self._heartbeat = None
            stop.set()
            if thread is not threading.current_thread():
                thread.join(timeout=STOP_WAIT_S)

    def close(self) -> None:
        """Stop the heartbeat (its thread ended first: a ping written while the port closes
        under it fails inside pyserial), release RTS then DTR (as mpremote does, so that the
        board is not reset), close the port once no write is in progress, and wait up to 1 s
        for the reader thread.
        """
        self.stop_heartbeat()
        try:
            # Release RTS before DTR (as mpremote does): DTR=1/RTS=0 only holds GPIO0 low, which a
            # running chip ignores; DTR first would pass through DTR=0/RTS=1, a reset. Closing then
            # drops the last line.
            self.serial.rts = False
            self.serial.dtr = False
        except (serial.SerialException, OSError):
            pass  # a pseudo-terminal (the virtual robot) has no modem lines
        # a write still in progress (one blocked on a port that stopped draining) is given
        # STOP_WAIT_S, then the port closes anyway: a hung board must not hang the host
        locked = self._write_lock.acquire(timeout=STOP_WAIT_S)
        try:
            self.serial.close()
        except (serial.SerialException, OSError):
            pass
        finally:
            if locked:
                self._write_lock.release()
        self._reader.join(timeout=1.0)

    def __enter__(self) -> Link:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
