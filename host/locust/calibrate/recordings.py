"""Read calibration recordings: plain CSV, ``locust track`` CSV, or Tracker's text export.

All three become one :class:`Table` of numeric columns, with marker positions under the
``locust track`` names (``<marker>_x_m``, ``<marker>_y_m``) and time as ``t_s``:

- plain CSV (``t_s,angle_deg,command_deg`` or ``angle_deg``), ``#`` lines are comments;
- ``locust track`` CSV: ``frame,t_s,<m>_px,<m>_py,<m>_x_m,<m>_y_m,<m>_ok``; a row whose
  ``<m>_ok`` is false counts as *not found* (NaN), never as a position;
- Tracker (Open Source Physics) *File > Export > Data*: an optional title line (the track
  name) or Tracker 6's ``#multi:`` line followed by a row of track names, then a header
  (``t x y ...``), tab separated, possibly with decimal commas. Tracker writes positions
  in its calibration unit: calibrate Tracker in metres.

Every problem is a :class:`~locust.errors.CalibrationError` naming the file, and the line
or column, with a hint.
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import CalibrationError

_TRUE = {"true", "yes", "1"}
_FALSE = {"false", "no", "0"}


@dataclass(frozen=True)
class Table:
    """Numeric columns of one recording, by name, and the file they came from."""

    path: Path
    columns: dict[str, np.ndarray]
    kind: str = "csv"                        # csv | tracker
    comments: tuple[str, ...] = field(default=())

    @property
    def n_rows(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def has(self, *names: str) -> bool:
        return all(n in self.columns for n in names)

    def require(self, *names: str, purpose: str = "") -> list[np.ndarray]:
        missing = [n for n in names if n not in self.columns]
        if missing:
            what = f" for {purpose}" if purpose else ""
            raise CalibrationError(
                f"{self.path}: missing column{'s' if len(missing) > 1 else ''} "
                f"{', '.join(missing)}{what} (found: {', '.join(self.columns) or 'none'})",
                f"the file needs the columns {', '.join(names)}",
            )
        return [self.columns[n] for n in names]

    def markers(self) -> list[str]:
        return [c[:-4] for c in self.columns if c.endswith("_x_m") and c[:-4] + "_y_m" in self.columns]

    def marker(self, name: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Positions (x_m, y_m) of one marker; NaN where it was not found."""
        names = self.markers()
        if name is None:
            if len(names) != 1:
                raise CalibrationError(
                    f"{self.path}: {'no marker columns' if not names else 'several markers: ' + ', '.join(names)}",
                    "choose one with --marker NAME" if names else
                    "give a `locust track` CSV (<name>_x_m, <name>_y_m) or a Tracker export (t, x, y)",
                )
            name = names[0]
        if name not in names:
            raise CalibrationError(f"{self.path}: no marker {name!r} (markers: {', '.join(names) or 'none'})",
                                   "check the name given with --marker")
        x, y = self.columns[f"{name}_x_m"].copy(), self.columns[f"{name}_y_m"].copy()
        ok = self.columns.get(f"{name}_ok")
        if ok is not None:
            lost = ~(ok > 0.5)
            x[lost] = np.nan
            y[lost] = np.nan
        return x, y

    def time_s(self) -> np.ndarray:
        (t,) = self.require("t_s", purpose="time")
        return t


def read_table(path: str | Path) -> Table:
    """Read a recording; see the module docstring for the formats understood."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise CalibrationError(f"{path}: no such file", "check the path of the recording") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise CalibrationError(f"{path}: cannot be read as text ({exc})",
                               "give a CSV or a Tracker text export") from None
    return parse_table(text, path)


def parse_table(text: str, path: Path) -> Table:
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines()) if ln.strip()]
    comments = tuple(ln.lstrip("#").strip() for _, ln in lines if ln.startswith("#") and not _is_multi(ln))
    multi = any(_is_multi(ln) for _, ln in lines)
    body = [(n, ln) for n, ln in lines if not ln.startswith("#")]
    if not body:
        raise CalibrationError(f"{path}: empty recording (no header, no data)", "export the data again")
    delim = _delimiter([ln for _, ln in body[:20]])
    rows = [(n, next(csv.reader(io.StringIO(ln), delimiter=delim))) for n, ln in body]

    first_data = next((i for i, (_, r) in enumerate(rows) if _numeric_row(r)), None)
    if first_data is None:
        raise CalibrationError(f"{path}: no numeric rows under the header", "the file holds no samples")
    if first_data == 0:
        raise CalibrationError(f"{path}: no header line", "the first line must name the columns, e.g. t_s,angle_deg")
    header = [h.strip() for h in rows[first_data - 1][1]]
    names_row = rows[first_data - 2][1] if first_data >= 2 else None
    tracker = multi or names_row is not None or (header[:1] == ["t"])
    names = _tracker_names(header, names_row) if tracker else header
    _check_names(names, path, rows[first_data - 1][0])

    data = np.full((len(rows) - first_data, len(names)), np.nan)
    for k, (lineno, row) in enumerate(rows[first_data:]):
        if len(row) > len(names) and any(f.strip() for f in row[len(names):]):
            raise CalibrationError(f"{path}, line {lineno}: {len(row)} fields, header has {len(names)}",
                                   "every row needs the same columns as the header")
        for j, raw in enumerate(row[: len(names)]):
            data[k, j] = _number(raw, delim, path, lineno, names[j])
    return Table(path=path, columns={n: data[:, j] for j, n in enumerate(names)},
                 kind="tracker" if tracker else "csv", comments=comments)


def _is_multi(line: str) -> bool:
    return line.strip().lower().startswith("#multi")


def _delimiter(lines: list[str]) -> str:
    sample = "\n".join(lines)
    for d in ("\t", ";", ","):
        if d in sample:
            return d
    return ","  # one column


def _numeric_row(row: list[str]) -> bool:
    fields = [f.strip() for f in row if f.strip()]
    return bool(fields) and all(_looks_numeric(f) for f in fields)


def _looks_numeric(f: str) -> bool:
    return re.fullmatch(r"[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?|nan|NaN|true|false|True|False", f) is not None


def _number(raw: str, delim: str, path: Path, lineno: int, column: str) -> float:
    f = raw.strip()
    if not f:
        return np.nan
    low = f.lower()
    if low in _TRUE and column.endswith("_ok"):
        return 1.0
    if low in _FALSE and column.endswith("_ok"):
        return 0.0
    if delim != ",":
        f = f.replace(",", ".")  # Tracker in a decimal-comma locale
    try:
        return float(f)
    except ValueError:
        raise CalibrationError(f"{path}, line {lineno}: column {column!r} holds {raw!r}, not a number",
                               "fix or delete that line") from None


def _slug(name: str) -> str:
    return re.sub(r"\W+", "_", name.strip()).strip("_") or "track"


def _tracker_names(header: list[str], names_row: list[str] | None) -> list[str]:
    """Tracker's ``t x y`` (+ track names above) -> ``t_s, <track>_x_m, <track>_y_m``."""
    owners: list[str] = []
    current = "track"
    if names_row is not None and len([f for f in names_row if f.strip()]) == 1 and len(names_row) == 1:
        current = _slug(names_row[0])  # a single title line: the track's name
        names_row = None
    for j in range(len(header)):
        if names_row is not None and j < len(names_row) and names_row[j].strip():
            current = _slug(names_row[j])
        owners.append(current)
    out = []
    for h, owner in zip(header, owners):
        if h == "t":
            out.append("t_s")
        elif h in ("x", "y"):
            out.append(f"{owner}_{h}_m")
        else:
            out.append(f"{owner}_{_slug(h)}")
    return out


def _check_names(names: list[str], path: Path, lineno: int) -> None:
    seen: set[str] = set()
    for n in names:
        if not n:
            raise CalibrationError(f"{path}, line {lineno}: a column has no name", "name every column in the header")
        if n in seen:
            raise CalibrationError(f"{path}, line {lineno}: column {n!r} appears twice", "give each column one name")
        seen.add(n)


def clean_samples(path: Path, what: str, t_s: np.ndarray, *series: np.ndarray,
                  min_samples: int) -> tuple[np.ndarray, ...]:
    """Rows where time and every series are finite, time increasing; enough of them."""
    t_s = np.asarray(t_s, dtype=float)
    keep = np.isfinite(t_s)
    for s in series:
        keep &= np.isfinite(s)
    out = [t_s[keep], *[np.asarray(s, dtype=float)[keep] for s in series]]
    n = len(out[0])
    if n < min_samples:
        raise CalibrationError(
            f"{path}: only {n} usable samples of {what} (need at least {min_samples}; "
            f"{len(t_s) - n} rows are empty or NaN)",
            "record longer or at a higher frame rate, or check that the marker was found",
        )
    if np.any(np.diff(out[0]) <= 0):
        bad = int(np.argmax(np.diff(out[0]) <= 0)) + 1
        raise CalibrationError(f"{path}: time does not increase at sample {bad} (t_s = {out[0][bad]:g})",
                               "sort the rows by time and remove duplicate frames")
    return tuple(out)
