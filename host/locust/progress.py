"""Progress on stderr for long work: a bar on a terminal, a plain line every ~10 s elsewhere
(logs, pipes, CI), so a long fit is never silent.

The time left is the work left at the rate measured from the first step finished (the setup
before it is no guide to the rest) to the latest, less the time since the latest: it counts
down through a long step instead of growing as if the work had slowed (a fit's last solver
iteration can take most of its run). It is shown only once that rate rests on at least
:data:`ETA_MIN_STEPS` steps and :data:`ETA_MIN_S` seconds.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any

ETA_MIN_STEPS = 3        # steps measured before a time left is shown
ETA_MIN_S = 2.0          # seconds measured before a time left is shown
PLAIN_EVERY_S = 10.0     # off a terminal: one line this often
BAR_EVERY_S = 0.2        # on a terminal: redraw at most this often
BAR_WIDTH = 30
_SILENT = [0]            # depth of silenced() blocks: while above 0 nothing is shown


def format_duration(seconds: float) -> str:
    """``1:05:09``, ``8:05``, ``0:42`` (hours only when there are some).

    Parameters
    ----------
    seconds : float

    Returns
    -------
    str
    """
    s = max(0, int(round(seconds)))
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    return f"{h}:{m:02d}:{s:02d}" if h else f"{m}:{s:02d}"


class Progress:
    """``length`` steps (or ``items``), reported on ``file`` as a bar (``tty``) or as plain lines.

    ``clock`` is the time source (seconds); tests give their own. ``rate_from_start``: the
    rate is measured from the start, and the time left shown from the first step on (steps
    that each carry their own setup: a demo stage's commands), not from the first step finished.
    """

    def __init__(self, items: Iterable | None = None, length: int | None = None, label: str = "",
                 file: Any = None, tty: bool | None = None, clock: Callable[[], float] = time.monotonic,
                 show_pos: bool = True, show_eta: bool = True, rate_from_start: bool = False, **_: Any):
        if length is None and items is not None:
            try:
                length = len(items)   # type: ignore[arg-type]
            except TypeError:
                length = None
        self.items, self.length, self.label = items, length, label
        self.file = file if file is not None else sys.stderr
        self.tty = self.file.isatty() if tty is None else tty
        self.clock, self.show_pos, self.show_eta = clock, show_pos, show_eta
        self.pos = 0
        self.start = clock()
        self._first: tuple[float, int] | None = (self.start, 0) if rate_from_start else None
        self._min_steps = 1 if rate_from_start else ETA_MIN_STEPS
        self._latest_s = self.start                      # when the latest step finished
        self._last_shown = self.start if not self.tty else -float("inf")
        self._drawn = False

    # -- what is shown -------------------------------------------------------------------
    def eta_s(self) -> float | None:
        """Seconds left at the rate measured from the first step to the latest, less the time
        since the latest; None until that rate means something.

        Returns
        -------
        float or None
            [s].
        """
        if self.length is None or self._first is None:
            return None
        t0, p0 = self._first
        steps, spent = self.pos - p0, self._latest_s - t0
        if steps < self._min_steps or spent < ETA_MIN_S:
            return None
        left = max(self.length - self.pos, 0) * spent / steps - (self.clock() - self._latest_s)
        return max(left, 0.0)

    def line(self) -> str:
        """The progress as shown: label, bar (on a terminal), percent or count, time elapsed and
        the time left once the rate is known.

        Returns
        -------
        str
        """
        parts = [self.label] if self.label else []
        if self.length:
            frac = min(self.pos / self.length, 1.0)
            if self.tty:
                filled = int(round(frac * BAR_WIDTH))
                parts.append("[" + "#" * filled + "-" * (BAR_WIDTH - filled) + "]")
            parts.append(f"{frac * 100:3.0f} %")
            if self.show_pos:
                parts.append(f"{self.pos}/{self.length}")
        elif self.show_pos:
            parts.append(str(self.pos))
        parts.append(f"{format_duration(self.clock() - self.start)} elapsed")
        eta = self.eta_s() if self.show_eta else None
        if eta is not None and self.pos < (self.length or 0):
            parts.append(f"about {format_duration(eta)} left")
        return "  ".join(parts)

    def _show(self, force: bool = False) -> None:
        if _SILENT[0]:
            return
        now = self.clock()
        if not force and now - self._last_shown < (BAR_EVERY_S if self.tty else PLAIN_EVERY_S):
            return
        self._last_shown = now
        if self.tty:
            self.file.write("\r\x1b[K" + self.line())
            self._drawn = True
        else:
            self.file.write(self.line() + "\n")
        self.file.flush()

    def tick(self) -> None:
        """Show the progress if it is due (a line every ~10 s off a terminal) though no step has
        ended: for a caller whose steps are long, from a thread of its own."""
        self._show()

    # -- the click.progressbar interface ------------------------------------------------
    def update(self, n_steps: int = 1, current_item: Any = None) -> None:
        """Count ``n_steps`` more steps done (``current_item`` is accepted as click's bar does,
        and ignored).

        Parameters
        ----------
        n_steps : int
        current_item : Any
        """
        self.pos += n_steps
        self._latest_s = self.clock()
        if self._first is None and self.pos > 0:
            self._first = (self._latest_s, self.pos)
        self._show()

    def __enter__(self) -> Progress:
        if self.tty:
            self._show(force=True)
        return self

    def __exit__(self, *exc: Any) -> bool:
        if self.tty and self._drawn:
            self._show(force=True)
            self.file.write("\n")
            self.file.flush()
        return False

    def __iter__(self):
        for item in self.items if self.items is not None else ():
            yield item
            self.update(1)


@contextlib.contextmanager
def silenced() -> Iterator[None]:
    """No progress shown inside the block (a notebook's cell output, where the result says enough)."""
    _SILENT[0] += 1
    try:
        yield
    finally:
        _SILENT[0] -= 1


def progress(items: Iterable | None = None, length: int | None = None, label: str = "", **options: Any) -> Progress:
    """Progress over ``items`` or ``length`` steps on stderr: a bar on a terminal, a plain line
    every ~10 s elsewhere.

    Use as ``with progress(length=n, label="x") as bar: ... bar.update(1)`` or
    ``with progress(items, label="x") as bar: for item in bar: ...``.

    Parameters
    ----------
    items : iterable, optional
        What is iterated (its length the steps, when it has one).
    length : int, optional
        The number of steps.
    label : str
        Shown before the bar.
    **options
        :class:`Progress`'s ``file``, ``tty``, ``clock``, ``show_pos``, ``show_eta``, ``rate_from_start``.

    Returns
    -------
    Progress
    """
    return Progress(items, length=length, label=label, **options)


__all__ = ["Progress", "format_duration", "progress", "silenced"]
