"""A sweep's folder: ``sweep.json`` (what was asked) and ``results.csv`` (one row per design).

Rows are appended and flushed as designs finish, so an interrupted sweep keeps every finished
design; rerunning the same command in the same folder skips them. A folder that holds a
different sweep, or anything else, is refused rather than mixed or overwritten. When every
design is done the file is rewritten once, atomically, in design order, so the finished file is
the same whatever ran it. Floats are written with ``repr``: they read back bit for bit.
"""

from __future__ import annotations

import csv
import fcntl
import io
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import SweepError
from ..fileio import atomic_write_json, atomic_write_text, json_text, make_folder, try_lock

RESULTS = "results.csv"
META = "sweep.json"
LOCK = ".sweep.lock"
RESULT_FIELDS = ("valid", "reason", "outcome", "flip_share", "distance_m", "max_nose_height_m", "nose_apex_max_m",
                 "com_apex_max_m", "hops", "grashof", "transmission_deg")   # a design's result row
_FLOATS = {"flip_share", "distance_m", "max_nose_height_m", "nose_apex_max_m", "com_apex_max_m", "transmission_deg"}


def columns(axis_names: list[str]) -> list[str]:
    """``results.csv``'s header: ``design``, the varied names, then the result fields.

    Parameters
    ----------
    axis_names : list of str
        The varied parameters' dotted names, in order.

    Returns
    -------
    list of str
    """
    return ["design", *axis_names, *RESULT_FIELDS]


def _cell(value: Any) -> str:
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else "nan"
    return str(value)


def _parse(row: dict[str, str | None], axis_names: list[str]) -> dict[str, Any]:
    out: dict[str, Any] = {"design": int(row["design"])}
    for name in axis_names:
        out[name] = float(row[name])
    for name in RESULT_FIELDS:
        raw = row[name]
        if name == "valid":
            if raw not in ("True", "False"):
                raise ValueError(f"valid = {raw!r}")
            out[name] = raw == "True"
        elif name in _FLOATS:
            out[name] = float(raw)
        elif name == "hops":
            out[name] = int(raw)
        else:
            out[name] = raw
    return out


def read_rows(path: Path, axis_names: list[str]) -> list[dict[str, Any]]:
    """The rows of ``results.csv``, typed (``design`` int, axis values and figures float,
    ``valid`` bool, ``hops`` int), in file order.

    Only a torn last line is dropped: an interrupt can cut the row being appended, and a
    finished row always ends with a newline. Any other row that does not parse is an error
    naming its line, never skipped.

    Parameters
    ----------
    path : pathlib.Path
        A ``results.csv``.
    axis_names : list of str
        The varied names, in column order.

    Returns
    -------
    list of dict

    Raises
    ------
    locust.errors.SweepError
        Unreadable, other columns, or a malformed row other than a torn last one.
    """
    try:
        with open(path, encoding="utf-8", newline="") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        raise SweepError(f"{path}: unreadable ({exc})", "use a new --out folder") from None
    torn = bool(text) and not text.endswith("\n")
    reader = csv.DictReader(io.StringIO(text, newline=""))
    if reader.fieldnames != columns(axis_names):
        raise SweepError(f"{path}: unexpected columns {reader.fieldnames}",
                         f"expected {', '.join(columns(axis_names))}; use a new --out folder")
    raw = list(reader)
    rows = []
    for k, row in enumerate(raw):
        try:
            rows.append(_parse(row, axis_names))
        except (KeyError, TypeError, ValueError) as exc:
            if torn and k == len(raw) - 1:
                break
            raise SweepError(f"{path}, line {k + 2}: malformed row ({exc})",
                             "the file was edited or damaged: "
                             "restore it, or rerun the sweep in a new --out folder") from None
    return rows


@dataclass(frozen=True)
class StoredSweep:
    """A sweep folder read back: what was asked and every finished row."""

    folder: Path
    base: str                          # the base robot's name
    axis_names: list[str]              # varied names, in order
    cycles: int
    rows: list[dict[str, Any]]         # typed rows (see :func:`read_rows`), in file order
    finished: bool                     # False: still running, or interrupted with designs missing
    planned: int | None = None         # the designs the sweep plans (None: a folder that does not say)
    running: bool = False              # another process holds the folder's lock: it is writing it now

    def column(self, name: str) -> list[Any]:
        """One column's values over the rows, in file order.

        Parameters
        ----------
        name : str

        Returns
        -------
        list
        """
        return [row[name] for row in self.rows]


def read_results(folder: Path) -> StoredSweep:
    """Read a ``locust sweep --out`` folder (``sweep.json`` and ``results.csv``).

    It is finished only when no sweep holds its lock now (one being written holds it until
    its last row), its ``sweep.json`` does not say it stopped short, and its rows cover every
    design it plans (a sweep killed outright says nothing more than that).

    Parameters
    ----------
    folder : pathlib.Path

    Returns
    -------
    StoredSweep

    Raises
    ------
    locust.errors.SweepError
        A file missing, a ``sweep.json`` that does not describe a sweep, or a bad row.
    """
    folder = Path(folder)
    meta_path, csv_path = folder / META, folder / RESULTS
    hint = "give the --out folder of a `locust sweep`"
    for p in (meta_path, csv_path):
        if not p.is_file():
            raise SweepError(f"{folder}: no {p.name}", hint)
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
        req = meta.get("request", meta)   # what was asked; older folders keep it at the top
        names = [str(v["name"]) for v in req["vary"]]
        cycles = int(req["cycles"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        raise SweepError(f"{meta_path}: not a sweep description ({exc})", hint) from None
    if not names or cycles < 1:
        raise SweepError(f"{meta_path}: no varied parameter or no cycles", hint)
    planned = meta.get("designs")
    if planned is not None and (not isinstance(planned, int) or isinstance(planned, bool) or planned < 1):
        raise SweepError(f"{meta_path}: designs = {planned!r} is not a count of designs", hint)
    running = is_running(folder)
    rows = read_rows(csv_path, names)
    finished = (not running and meta.get("finished", True) is True
                and (planned is None or len({row["design"] for row in rows}) >= planned))
    return StoredSweep(folder=folder, base=str(req.get("base", "?")), axis_names=names, cycles=cycles,
                        rows=rows, finished=finished, planned=planned, running=running)


def is_running(folder: Path) -> bool:
    """Whether a sweep is writing ``folder`` now: another open description holds its lock
    (:meth:`SweepStore.open` takes it before its first row and keeps it to the last; a process
    that dies lets go of it). Reading makes no file: a folder without the lock file is not
    being written.

    Parameters
    ----------
    folder : pathlib.Path

    Returns
    -------
    bool
    """
    try:
        fd = os.open(Path(folder) / LOCK, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    finally:
        os.close(fd)
    return False


@dataclass
class SweepStore:
    """A sweep being written: its folder held under a lock, each finished design's row
    appended to ``results.csv`` as it arrives, ``sweep.json`` rewritten atomically.

    Attributes
    ----------
    folder : pathlib.Path
    meta : dict
        ``sweep.json``'s content.
    axis_names : list of str
        The varied names, in column order.
    done : dict of int to dict
        Design number -> its row, for the designs already written.
    """

    folder: Path
    meta: dict[str, Any]
    axis_names: list[str]
    done: dict[int, dict[str, Any]] = field(default_factory=dict)
    _fh: io.TextIOBase | None = None
    _lock_fd: int | None = None

    @property
    def results_path(self) -> Path:
        """The folder's ``results.csv``."""
        return self.folder / RESULTS

    @classmethod
    def open(cls, folder: Path, meta: dict[str, Any], axis_names: list[str]) -> SweepStore:
        """Start a sweep in ``folder`` or resume the same sweep there.

        Parameters
        ----------
        folder : pathlib.Path
        meta : dict
            ``sweep.json``'s content: the request (base, varied axes, cycles) and the robot.
        axis_names : list of str

        Returns
        -------
        SweepStore
            Holding the folder's lock, with the rows already written in :attr:`done`.

        Raises
        ------
        locust.errors.SweepError
            The folder holds another sweep or other files, or another sweep is running there.
        """
        folder = Path(folder)
        store = cls(folder, meta, axis_names)
        meta_path = folder / META
        if meta_path.exists():
            try:
                old = json.loads(meta_path.read_text())
            except (OSError, ValueError) as exc:
                raise SweepError(f"{meta_path}: unreadable ({exc})", "use a new --out folder") from None
            # compared as stored: strict JSON has no inf (a supply without a current limit), it is null there
            if old.get("request") != json.loads(json_text(meta["request"])):
                raise SweepError(f"{folder} holds a different sweep (base, --vary, --cycles or parameters differ)",
                                 "use a new --out folder, or rerun the exact command that made it to resume")
            store.done = store._read_rows()
        elif folder.exists() and any(p.name != LOCK for p in folder.iterdir()):   # (a sweep that failed before
            # its sweep.json was written, a full disk, leaves only its lock: it is started again)
            raise SweepError(f"{folder} exists and is not a sweep folder; refusing to write into it",
                             "choose a new or empty --out folder")
        make_folder(folder)
        store._lock()
        try:
            atomic_write_json(meta_path, meta)
            store._rewrite(sorted(store.done))
        except BaseException:   # (a full disk) the lock goes with the failed start
            os.close(store._lock_fd)
            store._lock_fd = None
            raise
        return store

    def _lock(self) -> None:
        """One sweep at a time per folder: a second one would compute and append the same rows."""
        fd = try_lock(self.folder / LOCK)
        if fd is None:
            raise SweepError(f"another sweep is running in {self.folder}",
                             "wait for it to finish (or stop it), or use another --out folder") from None
        self._lock_fd = fd
        # a worker forked from here must not hold the lock: when this process dies (kill -9),
        # the lock goes with it, and rerunning resumes
        os.register_at_fork(after_in_child=self._forget_lock)

    def _forget_lock(self) -> None:
        if self._lock_fd is not None:
            try:
                os.close(self._lock_fd)
            except OSError:
                pass
            self._lock_fd = None

    def _read_rows(self) -> dict[int, dict[str, Any]]:
        """Rows already finished (a last line cut short by an interrupt is dropped)."""
        if not self.results_path.exists():
            return {}
        return {row["design"]: row for row in read_rows(self.results_path, self.axis_names)}

    def _rewrite(self, order: list[int]) -> None:
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        cols = columns(self.axis_names)
        writer.writerow(cols)
        for i in order:
            writer.writerow([_cell(self.done[i][c]) for c in cols])
        atomic_write_text(self.results_path, buf.getvalue())

    def append(self, row: dict[str, Any]) -> None:
        """Record one finished design now (flushed to disk before returning).

        Parameters
        ----------
        row : dict
            ``design``, the varied values and the result fields.
        """
        self.done[row["design"]] = row
        if self._fh is None:
            self._fh = open(self.results_path, "a", newline="")
        line = io.StringIO()
        csv.writer(line, lineterminator="\n").writerow([_cell(row[c]) for c in columns(self.axis_names)])
        self._fh.write(line.getvalue())
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self, complete: bool, **meta: Any) -> None:
        """Stop appending; when finished, rewrite the rows in design order; record ``meta``.

        Parameters
        ----------
        complete : bool
            Every design done.
        **meta
            Added to ``sweep.json``.
        """
        if self._fh is not None:
            self._fh.close()
            self._fh = None
        if complete:
            self._rewrite(sorted(self.done))
        self.write_meta(**meta)
        if self._lock_fd is not None:
            os.close(self._lock_fd)   # releases the lock
            self._lock_fd = None

    def write_meta(self, **extra: Any) -> None:
        """Update ``sweep.json`` with ``extra`` and write it atomically."""
        self.meta.update(extra)
        atomic_write_json(self.folder / META, self.meta)
