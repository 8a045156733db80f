"""An Optuna journal torn by a full disk: what it holds, and its repair.

Optuna appends one JSON operation per line. A write that fails part way (the disk filled up
during a trial) leaves the last line cut short, and Optuna cannot read the journal back:
every trial it holds would be locked away. :func:`repair` keeps the whole lines (every
operation that was written in full: the finished trials), after saving the file as it was
beside it; ``locust optimize --repair`` runs it.
"""

from __future__ import annotations

import errno
import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import SweepError
from ..fileio import atomic_write_bytes

FULL_DISK = (errno.ENOSPC, errno.EDQUOT)


@dataclass(frozen=True)
class Repair:
    """What :func:`repair` did to a journal.

    Attributes
    ----------
    path : Path
        The journal.
    records : int
        Whole operations kept.
    cut_bytes : int
        The torn last line's bytes removed (0: the journal was whole).
    backup : Path or None
        The journal as it was (None: nothing was changed).
    """

    path: Path
    records: int              # whole operations kept
    cut_bytes: int            # the torn last line's bytes removed (0: the journal was whole)
    backup: Path | None       # the journal as it was (None: nothing was changed)

    def line(self) -> str:
        """One line for the user.

        Returns
        -------
        str
            What was cut and kept, and where the backup is; or that the journal is whole.
        """
        if not self.cut_bytes:
            return f"{self.path}: the journal is whole ({self.records} operations); nothing to repair"
        return (f"repaired {self.path}: cut its torn last line ({self.cut_bytes} bytes), kept its "
                f"{self.records} whole operations; the journal as it was is saved as {self.backup}")


def repair(path: str | os.PathLike) -> Repair:
    """Cut a journal's torn last line, after saving the whole file as ``NAME.torn-N`` beside it.

    Parameters
    ----------
    path : path-like
        The Optuna journal. Run this only while no process appends to it.

    Returns
    -------
    Repair
        What was kept and where the backup is. A whole journal is left untouched.

    Raises
    ------
    SweepError
        The journal cannot be read or cut, or 999 backups of it exist already.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise SweepError(f"--repair: cannot read {path} ({exc.strerror})",
                         "give the journal of the study (OUT/study.journal or --storage)") from None
    whole = data.rfind(b"\n") + 1
    records = data[:whole].count(b"\n")
    if whole == len(data):
        return Repair(path, records, 0, None)
    backup = _backup_path(path)
    atomic_write_bytes(backup, data, exclusive=True)   # (a full disk: WriteError, the journal untouched)
    try:
        os.truncate(path, whole)   # in place: Optuna's lock file and any reader keep the same file
    except OSError as exc:
        raise SweepError(f"--repair: cannot cut {path} ({exc.strerror}); it is as it was, and saved as {backup}",
                         "check that the file is writable") from None
    return Repair(path, records, len(data) - whole, backup)


def _backup_path(path: Path) -> Path:
    for n in range(1, 1000):
        candidate = path.with_name(f"{path.name}.torn-{n}")
        if not candidate.exists():
            return candidate
    raise SweepError(f"{path}: 999 backups of it are there already", "remove the old NAME.torn-N files")


def full_disk(exc: BaseException) -> OSError | None:
    """The full-disk ``OSError`` behind ``exc`` (itself, or what it was raised while handling:
    Optuna fails a second time, ``AssertionError: Should not reach.``, after its write failed).

    Parameters
    ----------
    exc : BaseException
        The exception caught.

    Returns
    -------
    OSError or None
        The ``ENOSPC`` or ``EDQUOT`` error in its chain, None when there is none.
    """
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno in FULL_DISK:
            return exc
        exc = exc.__cause__ or exc.__context__
    return None
