"""Delimited text of numbers: the one tokenizer under every table of samples locust reads.

The tracks CSV (:mod:`.tracks_csv`), Tracker's text export (:mod:`.tracker_text`) and the
calibration layer's plain CSV (:mod:`locust.calibrate.recordings`) are all lines of
delimited numbers under a header; this module splits them, and each format's own module
gives the columns their meaning.

- ``#`` lines are comments, kept in order (Tracker 6's ``#multi:`` line is a marker of its
  layout, not a comment); blank lines are skipped, but a line of tabs alone is a row of
  empty cells (Tracker's layout for a frame where no track has a step);
- the delimiter is a tab, ``;`` or ``,``: the first of these found in the first 20 lines;
- the header is the line above the first all-numeric row; the line above the header, if
  any, is Tracker's row of track names (or its title line);
- with a delimiter other than ``,``, a decimal comma reads as a decimal point (Tracker in
  such a locale); ``true``/``false`` (and ``yes``/``no``) read as 1/0 in a column whose
  name ends in ``_ok``; an empty cell is NaN.

Every problem is a :class:`~locust.errors.TrackError` naming the file, and the line or
column, with a hint.

A file read is a regular file of at most :data:`MAX_BYTES` and :data:`MAX_LINES` lines (``#``
comments aside), refused before it is read (its size) or split (its lines): a track of a clip
holds a line a frame, and beyond these it is no longer one experiment (nor would its rows fit a
laptop's memory: about 1.3 kB of Python objects a row while split). The writers of these
formats refuse what this reader would (:func:`check_text`).
"""

from __future__ import annotations

import csv
import io
import re
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import TrackError

# A track (a line a frame) of 14 minutes at 240 frames/s, or of nearly two hours at 30; a hop
# experiment is seconds to minutes.
MAX_LINES = 200_000
MAX_BYTES = 64 * 2**20
SIZE_HINT = ("cut the file to the experiment (keep its header and the rows you need, e.g. head -n 10000), or "
             "track a shorter part of the clip (--start, --end, --step)")

_TRUE = {"true", "yes", "1"}
_FALSE = {"false", "no", "0"}
_NUMERIC = re.compile(r"[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?|nan|NaN|true|false|True|False")


@dataclass(frozen=True)
class DelimitedText:
    """One file split into comments, header and data rows (each row with its line number)."""

    path: Path
    comments: tuple[str, ...]
    multi: bool                              # Tracker 6's ``#multi:`` line was there
    delimiter: str
    header: list[str]
    header_line: int
    names_row: list[str] | None              # the line above the header, if any
    rows: list[tuple[int, list[str]]]

    @property
    def tracker_layout(self) -> bool:
        """Laid out as Tracker exports: ``#multi:``, a names or title line, or a header ``t ...``."""
        return self.multi or self.names_row is not None or self.header[:1] == ["t"]

    def columns(self, names: list[str]) -> np.ndarray:
        """The data as floats, one column per name (``names`` label the header's columns in
        messages and decide where ``true``/``false`` is allowed); a short row is NaN-padded.

        Parameters
        ----------
        names : list of str
            The header's column names.

        Returns
        -------
        numpy.ndarray
            (rows, len(names)) floats.

        Raises
        ------
        locust.errors.TrackError
            A row with more fields than the header, or a field that is not a number.
        """
        data = np.full((len(self.rows), len(names)), np.nan)
        for k, (lineno, row) in enumerate(self.rows):
            if len(row) > len(names) and any(f.strip() for f in row[len(names):]):
                raise TrackError(f"{self.path}, line {lineno}: {len(row)} fields, header has {len(names)}",
                                 "every row needs the same columns as the header")
            for j, raw in enumerate(row[: len(names)]):
                data[k, j] = _number(raw, self.delimiter, self.path, lineno, names[j])
        return data


def read_text(path: str | Path) -> str:
    """The file's text (UTF-8, a byte-order mark dropped), or a TrackError naming it.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    str

    Raises
    ------
    locust.errors.TrackError
        No such file, not a regular file, over :data:`MAX_BYTES` (refused before it is read) or
        :data:`MAX_LINES` lines (before it is split), or not text.
    """
    path = Path(path)
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):   # a pipe blocks, a device never ends: not opened
            raise TrackError(f"{path}: not a regular file (a pipe, device or folder)",
                             "give the path of a recording file (a CSV or a Tracker text export)")
        check_size(path, info.st_size)
        with open(path, "rb") as fh:
            data = fh.read(MAX_BYTES + 1)   # (a file growing as it is read stops at the limit too)
        check_size(path, len(data), _lines(data))
        return data.decode("utf-8-sig")
    except FileNotFoundError:
        raise TrackError(f"{path}: no such file", "check the path of the recording") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise TrackError(f"{path}: cannot be read as text ({exc})", "give a CSV or a Tracker text export") from None


def check_size(path: str | Path, n_bytes: int, n_lines: int = 0, writing: bool = False) -> None:
    """Refuse a delimited file of more than :data:`MAX_BYTES` or :data:`MAX_LINES` lines, read or
    about to be written.

    Parameters
    ----------
    path : path-like
        For messages.
    n_bytes : int
        Its size [bytes].
    n_lines : int
        Its lines but its ``#`` comments, where known.
    writing : bool
        The file is about to be written (the message says so).

    Raises
    ------
    locust.errors.TrackError
        Over either limit.
    """
    what = "would be" if writing else "is"
    if n_bytes > MAX_BYTES:
        raise TrackError(f"{path} {what} {n_bytes / 2**20:,.0f} MB, over the {MAX_BYTES / 2**20:.0f} MB a track or "
                         f"recording file may hold ({MAX_LINES:,} lines: 14 minutes at 240 frames/s); "
                         f"{'nothing was written' if writing else 'not read'}", SIZE_HINT)
    if n_lines > MAX_LINES:
        raise TrackError(f"{path} {what} {n_lines:,} lines, over the {MAX_LINES:,} a track or recording file may "
                         f"hold (14 minutes at 240 frames/s); {'nothing was written' if writing else 'not read'}",
                         SIZE_HINT)


def check_text(path: str | Path, text: str) -> str:
    """``text``, to be written to ``path``, if this module would read it back (:func:`check_size`).

    Parameters
    ----------
    path : path-like
    text : str

    Returns
    -------
    str
        ``text``.

    Raises
    ------
    locust.errors.TrackError
        Over either limit.
    """
    data = text.encode("utf-8")
    check_size(path, len(data), _lines(data), writing=True)
    return text


def _lines(data: bytes) -> int:
    """The lines of ``data`` but its ``#`` comments (a converted file may say where it came from
    in more comments than its source had, and still be read back)."""
    return data.count(b"\n") - data.count(b"\n#") - data.startswith(b"#")


def split_text(text: str, path: str | Path) -> DelimitedText:
    """Split ``text`` (the contents of ``path``) into comments, header and data rows.

    Parameters
    ----------
    text : str
    path : path-like
        For messages.

    Returns
    -------
    DelimitedText

    Raises
    ------
    locust.errors.TrackError
        An empty file, no header, or no numeric rows.
    """
    path = Path(path)
    # a line of tabs alone is a row of empty cells (a frame no track has), not a blank line
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines()) if ln.strip() or "\t" in ln]
    comments = tuple(ln.lstrip("#").strip() for _, ln in lines if ln.startswith("#") and not _is_multi(ln))
    multi = any(_is_multi(ln) for _, ln in lines)
    body = [(n, ln) for n, ln in lines if not ln.startswith("#")]
    if not body:
        raise TrackError(f"{path}: empty recording (no header, no data)", "export the data again")
    delim = _delimiter([ln for _, ln in body[:20]])
    rows = [(n, next(csv.reader(io.StringIO(ln), delimiter=delim))) for n, ln in body]
    first_data = next((i for i, (_, r) in enumerate(rows) if _numeric_row(r)), None)
    if first_data is None:
        raise TrackError(f"{path}: no numeric rows under the header", "the file holds no samples")
    above = [i for i in range(first_data) if not _empty_row(rows[i][1])]
    if not above:
        raise TrackError(f"{path}: no header line", "the first line must name the columns, e.g. t_s,angle_deg")
    header_line, header = rows[above[-1]]
    return DelimitedText(path=path, comments=comments, multi=multi, delimiter=delim,
                         header=[h.strip() for h in header], header_line=header_line,
                         names_row=rows[above[-2]][1] if len(above) >= 2 else None,
                         rows=rows[above[-1] + 1:])


def check_names(names: list[str], path: Path, lineno: int) -> None:
    """Every column named, no name twice.

    Parameters
    ----------
    names : list of str
        The header's names.
    path : pathlib.Path
    lineno : int
        The header's line, for messages.

    Raises
    ------
    locust.errors.TrackError
        An empty name, or a name given twice.
    """
    seen: set[str] = set()
    for n in names:
        if not n:
            raise TrackError(f"{path}, line {lineno}: a column has no name", "name every column in the header")
        if n in seen:
            raise TrackError(f"{path}, line {lineno}: column {n!r} appears twice", "give each column one name")
        seen.add(n)


def _is_multi(line: str) -> bool:
    return line.strip().lower().startswith("#multi")


def _delimiter(lines: list[str]) -> str:
    sample = "\n".join(lines)
    for d in ("\t", ";", ","):
        if d in sample:
            return d
    return ","  # one column


def _empty_row(row: list[str]) -> bool:
    return not any(f.strip() for f in row)


def _numeric_row(row: list[str]) -> bool:
    fields = [f.strip() for f in row if f.strip()]
    return bool(fields) and all(_NUMERIC.fullmatch(f) is not None for f in fields)


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
        raise TrackError(f"{path}, line {lineno}: column {column!r} holds {raw!r}, not a number",
                         "fix or delete that line") from None
