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
from ..fileio import atomic_write_json, atomic_write_text
from .design import RESULT_FIELDS

RESULTS = "results.csv"
META = "sweep.json"
LOCK = ".sweep.lock"
_FLOATS = {"distance_m", "max_nose_height_m", "nose_apex_max_m", "com_apex_max_m", "transmission_deg"}


def columns(axis_names: list[str]) -> list[str]:
    return ["design", *axis_names, *RESULT_FIELDS]


def _cell(value: Any) -> str:
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else "nan"
    return str(value)


def _parse(row: dict[str, str], axis_names: list[str]) -> dict[str, Any]:
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


@dataclass
class SweepStore:
    folder: Path
    meta: dict[str, Any]
    axis_names: list[str]
    done: dict[int, dict[str, Any]] = field(default_factory=dict)
    _fh: io.TextIOBase | None = None
    _lock_fd: int | None = None

    @property
    def results_path(self) -> Path:
        return self.folder / RESULTS

    @classmethod
    def open(cls, folder: Path, meta: dict[str, Any], axis_names: list[str]) -> "SweepStore":
        """Start a sweep in ``folder`` or resume the same sweep there."""
        folder = Path(folder)
        store = cls(folder, meta, axis_names)
        meta_path = folder / META
        if meta_path.exists():
            try:
                old = json.loads(meta_path.read_text())
            except (OSError, ValueError) as exc:
                raise SweepError(f"{meta_path}: unreadable ({exc})", "use a new --out folder") from None
            if old.get("request") != meta["request"]:
                raise SweepError(f"{folder} holds a different sweep (base, --vary, --cycles or parameters differ)",
                                 "use a new --out folder, or rerun the exact command that made it to resume")
            store.done = store._read_rows()
        elif folder.exists() and any(folder.iterdir()):
            raise SweepError(f"{folder} exists and is not a sweep folder; refusing to write into it",
                             "choose a new or empty --out folder")
        folder.mkdir(parents=True, exist_ok=True)
        store._lock()
        atomic_write_json(meta_path, meta)
        store._rewrite(sorted(store.done))
        return store

    def _lock(self) -> None:
        """One sweep at a time per folder: a second one would compute and append the same rows."""
        fd = os.open(self.folder / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise SweepError(f"another sweep is running in {self.folder}",
                             "wait for it to finish (or stop it), or use another --out folder") from None
        self._lock_fd = fd

    def _read_rows(self) -> dict[int, dict[str, Any]]:
        """Rows already finished; a line cut short by an interrupt is dropped."""
        done: dict[int, dict[str, Any]] = {}
        if not self.results_path.exists():
            return done
        with open(self.results_path, newline="") as fh:
            reader = csv.DictReader(fh)
            if reader.fieldnames != columns(self.axis_names):
                raise SweepError(f"{self.results_path}: unexpected columns {reader.fieldnames}",
                                 "use a new --out folder")
            for row in reader:
                try:
                    parsed = _parse(row, self.axis_names)
                except (KeyError, TypeError, ValueError):
                    continue
                done[parsed["design"]] = parsed
        return done

    def _rewrite(self, order: list[int]) -> None:
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        cols = columns(self.axis_names)
        writer.writerow(cols)
        for i in order:
            writer.writerow([_cell(self.done[i][c]) for c in cols])
        atomic_write_text(self.results_path, buf.getvalue())

    def append(self, row: dict[str, Any]) -> None:
        """Record one finished design now (flushed to disk before returning)."""
        self.done[row["design"]] = row
        if self._fh is None:
            self._fh = open(self.results_path, "a", newline="")
        line = io.StringIO()
        csv.writer(line, lineterminator="\n").writerow([_cell(row[c]) for c in columns(self.axis_names)])
        self._fh.write(line.getvalue())
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def close(self, complete: bool, **meta: Any) -> None:
        """Stop appending; when finished, rewrite the rows in design order; record ``meta``."""
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
        self.meta.update(extra)
        atomic_write_json(self.folder / META, self.meta)
