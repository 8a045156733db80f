"""Where a study lives: a journal file or an Optuna database, checked before Optuna touches it.

A storage file that is not an Optuna journal or database (a user's notes, a damaged journal)
is refused and left as it is; an output folder holding files ``locust optimize`` did not write
is refused.
"""

from __future__ import annotations

import json
import sqlite3
import time
from pathlib import Path

from ..errors import SweepError

RDB_PREFIXES = ("sqlite:", "postgresql", "mysql", "oracle", "mssql")
# what run_optimize writes in its folder; anything else there is someone else's
OWN_FILES = frozenset({"trials.csv", "pareto.csv", "optimize.json", "pareto.png", "study.html", "knee.toml",
                       "study.journal", "study.journal.lock"})
# and a robot file for each end of the front: best-<objective>.toml
OWN_PREFIX, OWN_SUFFIX = "best-", ".toml"
# a journal saved by --repair before its torn line was cut (sweep/journal.py)
TORN_PREFIX = "study.journal.torn-"
# the study's user attribute holding what it searches
SETTINGS_ATTR = "locust"
SQLITE_MAGIC = b"SQLite format 3\x00"
# pauses before reading a journal again when its last line is cut short (a process sharing the
# study may be writing it): 1.7 s in all before it is taken for a damaged one
JOURNAL_RECHECK_S = (0.0, 0.2, 0.5, 1.0)


def check_folder(folder: Path) -> None:
    """Refuse a folder holding files this command did not write (a user's ``trials.csv``
    included: a folder of ours always has ``optimize.json`` or the study's journal beside it).

    Parameters
    ----------
    folder : Path
        The ``--out`` folder (may not exist yet).

    Raises
    ------
    SweepError
        It is a file, or holds files ``locust optimize`` did not write.
    """
    if not folder.exists():
        return
    if not folder.is_dir():
        raise SweepError(f"--out {folder} is a file", "give a folder (new, or one `locust optimize` made)")
    names = {p.name for p in folder.iterdir() if not p.name.startswith(".")}
    foreign = sorted(n for n in names - OWN_FILES
                     if not (n.startswith(OWN_PREFIX) and n.endswith(OWN_SUFFIX)) and not n.startswith(TORN_PREFIX))
    ours = bool(names & {"optimize.json", "study.journal"})
    if foreign or (names and not ours):
        shown = ", ".join((foreign or sorted(names))[:5])
        raise SweepError(f"{folder} holds files `locust optimize` did not write ({shown}); refusing to write there",
                         "choose a new or empty --out folder")


def check_storage(url: str | None) -> None:
    """Refuse a ``--storage`` that is neither a database URL Optuna knows nor a journal file path
    in an existing folder, or a file there that is not an Optuna journal or database.

    Parameters
    ----------
    url : str or None
        The ``--storage`` given (None: the folder's own journal).

    Raises
    ------
    SweepError
        What is wrong with it; the file is left as it is.
    """
    if url is None or url.startswith(RDB_PREFIXES):
        if url is not None and url.startswith("sqlite:///"):
            check_sqlite_file(Path(url.removeprefix("sqlite:///")), url)
        return
    path = url.removeprefix("journal:")
    if "://" in path or not path.strip():
        raise SweepError(f"--storage {url}: not a journal file path nor a database URL Optuna knows",
                         "give a file path (e.g. opt/study.journal) or sqlite:///study.db, postgresql://..., mysql://...")
    parent = Path(path).parent
    if not parent.is_dir():
        raise SweepError(f"--storage {url}: the folder {parent} does not exist", "create it, or give another path")
    check_journal_file(Path(path))


def check_journal_file(path: Path) -> None:
    """Refuse an existing file that is not a whole Optuna journal: one JSON operation per line,
    the first creating a study, the last ending with its newline. Optuna would append to
    anything (a user's notes) and cannot read a damaged one back. A last line cut short is
    read again for up to 1.7 s (``JOURNAL_RECHECK_S``): a process sharing the study may be
    writing it.

    Parameters
    ----------
    path : Path
        The journal file (missing or empty is fine).

    Raises
    ------
    SweepError
        Not a file, not UTF-8, a torn last line (``--repair`` mends it), or a line that is not
        an Optuna operation.
    """
    if not path.exists() or (path.is_file() and path.stat().st_size == 0):
        return
    hint = "give --storage a new file path (or a new --out folder); this file is left as it is"
    if not path.is_file():
        raise SweepError(f"{path} is not a file; refusing it as an Optuna journal", hint)
    for wait_s in JOURNAL_RECHECK_S:   # another process sharing the study may be appending a line
        time.sleep(wait_s)
        try:
            text = path.read_bytes().decode("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise SweepError(f"{path}: not an Optuna journal (not UTF-8 text: {exc})", hint) from None
        lines = text.split("\n")
        if not lines[-1]:
            break
    if lines[-1]:
        raise SweepError(f"{path}: a damaged Optuna journal (its last line is cut short, as a full disk leaves it)",
                         "rerun the same command with --repair: it saves the file beside it and cuts the torn "
                         "line, keeping every whole trial; or " + hint)
    for k, line in enumerate(lines[:-1]):
        try:
            op = json.loads(line)
        except ValueError:
            op = None
        if not isinstance(op, dict) or not isinstance(op.get("op_code"), int) or (k == 0 and op["op_code"] != 0):
            what = "a damaged Optuna journal" if k else "not an Optuna journal"
            raise SweepError(f"{path}, line {k + 1}: {what} (each line must be one Optuna operation in JSON)",
                             hint)


def check_sqlite_file(path: Path, url: str) -> None:
    """Refuse an existing file that is not an SQLite database holding Optuna's tables (or none):
    Optuna would add its tables to someone else's database, or fail on a text file.

    Parameters
    ----------
    path : Path
        The database file (missing or empty is fine).
    url : str
        The ``--storage`` URL, for the message.

    Raises
    ------
    SweepError
        The file cannot be read, is not SQLite, or holds other tables and not Optuna's.
    """
    if not path.exists():
        return
    hint = "give a new database file (sqlite:///new.db); this file is left as it is"
    try:
        with open(path, "rb") as fh:
            magic = fh.read(len(SQLITE_MAGIC))
    except OSError as exc:
        raise SweepError(f"--storage {url}: cannot read {path} ({exc.strerror})", hint) from None
    if path.stat().st_size == 0:
        return
    if magic != SQLITE_MAGIC:
        raise SweepError(f"--storage {url}: {path} is not an SQLite database", hint)
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        finally:
            con.close()
    except sqlite3.Error as exc:
        raise SweepError(f"--storage {url}: {path} cannot be read as a database ({exc})", hint) from None
    if tables and "studies" not in tables:
        raise SweepError(f"--storage {url}: {path} is a database without Optuna's tables "
                         f"({', '.join(sorted(tables)[:4])})", hint)


def open_storage(url: str | None, folder: Path):
    """The Optuna storage a study lives in.

    Parameters
    ----------
    url : str or None
        A database URL, a journal file path (``journal:`` prefix optional), or None for
        ``study.journal`` in ``folder``.
    folder : Path
        The optimisation's folder.

    Returns
    -------
    optuna.storages.BaseStorage
        A ``JournalStorage`` or an ``RDBStorage``.

    Raises
    ------
    SweepError
        The database cannot be opened.
    """
    import optuna
    from optuna.storages import JournalStorage
    from optuna.storages.journal import JournalFileBackend

    if url is None:
        return JournalStorage(JournalFileBackend(str(folder / "study.journal")))
    if url.startswith(RDB_PREFIXES):
        try:
            return optuna.storages.RDBStorage(url)
        except Exception as exc:  # sqlalchemy raises many kinds
            raise SweepError(f"--storage {url}: cannot open ({exc.__class__.__name__}: {exc})",
                             "check the URL, e.g. sqlite:///study.db; the database driver must be installed") from None
    path = url.removeprefix("journal:")
    return JournalStorage(JournalFileBackend(path))
