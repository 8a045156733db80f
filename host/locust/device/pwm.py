"""The virtual robot's servos: each PWM write of the firmware turned back into a horn angle and
handed to the plant, on the plant's own thread.

Each pulse becomes a horn angle with the firmware's own ``config.py`` and ``config.json``
(pins, pulse range, trim, direction) and reaches the plant at the start of the next 20 ms PWM
period, as the ESP32's PWM hardware does. Both servos share the period (one timer, as on the
board): the firmware's two writes of one command reach the legs at the same instant, a
period apart only if a period starts between them.
"""

from __future__ import annotations

import collections
import math
import queue
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..firmware import config as fw_config
from .plant import Plant

PWM_PERIOD_S = 0.020
LOG_HEADER = ("# virtual robot PWM writes: horn angles recovered from the firmware's pulses\n"
              "t_written_s,t_effect_s,pin,servo,pulse_us,horn_deg\n")


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


class PlantFeed:
    """The plant's thread and what it keeps (see the module's description).

    Parameters
    ----------
    plant : Plant
        What the servos drive.
    flash_dir : Path
        The virtual robot's flash folder, whose ``config.json`` maps pins and pulses to horns.
    chip : str
        The chip the firmware reads its config as.
    clock_s : callable
        ``clock_s()``: the virtual robot's clock [s], where the plant ends when it is closed.
    """

    def __init__(self, plant: Plant, flash_dir: Path, chip: str, clock_s: Callable[[], float]):
        self.plant = plant
        self.queue: queue.Queue = queue.Queue()   # (t_s, pin, pulse_us) each write; None: stop
        self.writes: collections.deque[PwmWrite] = collections.deque(maxlen=100_000)
        # set by the plant thread as it ends: waited on instead of Thread.join, which a signal
        # interrupting it (Python 3.11) leaves saying the thread ended while it still runs
        self.done = threading.Event()
        self.summary: dict | None = None         # the plant's, once closed
        self.error: BaseException | None = None  # the plant's (its video onto a full disk)
        self.log = None                          # the CSV of every write (open_log)
        self._flash_dir, self._chip, self._clock_s = flash_dir, chip, clock_s
        self._config_cache: tuple[float, dict] | None = None
        # one PWM timer for both servos (they run at the same 50 Hz: MicroPython's ESP32 PWM
        # gives channels of one frequency one LEDC timer), so their periods start together
        self._period_anchor_s: float | None = None
        self._last_angle = {"left": 0.0, "right": 0.0}

    def open_log(self, path: Path) -> None:
        """Log every write to ``path``, a new CSV file (never overwritten).

        Parameters
        ----------
        path : Path
            The log's path; it must not exist.
        """
        self.log = open(path, "x", buffering=1)  # never overwrite a log
        self.log.write(LOG_HEADER)

    def restart_timer(self) -> None:
        """A boot starts the PWM timer again: the next write begins a period."""
        self._period_anchor_s = None

    def run(self) -> None:
        """The plant thread: an error of the plant (its video onto a full disk) is kept in
        :attr:`error` for the virtual robot to raise in the caller's thread, and the plant is aborted."""
        try:
            self._run_guarded()
        finally:
            self.done.set()

    def _run_guarded(self) -> None:
        stopped = []
        try:
            self._run_until_stopped(stopped)
        except BaseException as exc:   # handed to the main thread
            self.error = exc
            abort = getattr(self.plant, "abort", None)
            if abort is not None:
                try:
                    abort()
                except Exception:   # the first error is the one reported
                    pass
            while not stopped and self.queue.get() is not None:   # until stop() says so
                pass

    def _run_until_stopped(self, stopped: list) -> None:
        idle = getattr(self.plant, "idle", None)
        while True:
            try:
                item = self.queue.get(timeout=0.1 if idle else None)
            except queue.Empty:
                idle(self._clock_s())    # nothing written for 0.1 s: the plant may go on (a live model)
                continue
            if item is None:
                stopped.append(True)
                break
            self._command(*item)
        self.summary = self.plant.close(self._clock_s())

    def _command(self, t_s: float, pin: int, pulse_us: float) -> None:
        """One write: kept, logged, and the horns it commands handed to the plant."""
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
        self.writes.append(PwmWrite(t_s, t_effect, pin, pulse_us, servo, horn))
        if self.log:
            self.log.write(f"{t_s:.6f},{t_effect:.6f},{pin},{servo or ''},{pulse_us:.3f},"
                           f"{'' if horn is None else format(horn, '.4f')}\n")
        if horn is not None:
            self.plant.command(t_effect, self._last_angle["left"], self._last_angle["right"])

    def _config(self) -> dict:
        path = self._flash_dir / fw_config.FILE
        try:
            mtime = path.stat().st_mtime
        except OSError:
            mtime = -1.0
        if self._config_cache is None or self._config_cache[0] != mtime:
            cfg, _ = fw_config.load(str(path), self._chip)  # as the firmware reads it on this chip
            self._config_cache = (mtime, cfg)
        return self._config_cache[1]
