"""Where a write lands and how: atomic writes through a temporary beside the file, folders
made and never reused, strict JSON; shared by every part."""

from __future__ import annotations

import errno
import json
import os
import re
import signal
import stat
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import WriteError

DISK_HINT = "check that the folder exists and is writable and that the disk has space, or write elsewhere"


def write_target(path: str | os.PathLike) -> Path:
    """The file a write to ``path`` lands on: a symlink's target (the link is kept), else ``path``.

    A write never leaves the folder it was given through a link: a symlink is followed only
    to a target in its own folder or below it (:func:`link_target`); one pointing anywhere
    else, there or not (a dangling link), is refused. Refuses too (:class:`WriteError`) what a
    write must never replace: a device, a folder, a pipe or any other non-regular file, and a
    file its owner made read-only.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
    """
    path = link_target(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return path
    except OSError as exc:
        raise WriteError(f"{path}: cannot inspect it ({exc.strerror})", DISK_HINT) from None
    if not stat.S_ISREG(st.st_mode):
        raise WriteError(f"{path} is not a regular file (a device, folder or pipe); refusing to replace it",
                         "write to a new file path")
    if not os.access(path, os.W_OK) or not st.st_mode & 0o222:  # (root may write anything: ask the mode)
        raise WriteError(f"{path} is read-only; refusing to replace it",
                         "write to another path, or make it writable (chmod u+w) if you mean to replace it")
    return path


def link_target(path: str | os.PathLike) -> Path:
    """``path``, or the file its symlink points to when that lies in the link's own folder or
    below it; :class:`WriteError` for a link pointing out of it.

    The folder a command is given (``--out``, the folder of a file named) is where its writes
    land: a link left there, by a person or a program, must not carry a write to a file
    elsewhere (``out/hop.tracks.csv -> ../../victim.csv``), whether that file exists or not.
    A link within the folder (``robot.toml -> robots/small.toml``) has its target updated.
    Only the last component is a link looked at: a folder named through a link is the folder
    chosen.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
    """
    path = Path(path)
    if not path.is_symlink():
        return path
    target = Path(os.path.realpath(path))
    folder = os.path.realpath(path.parent)
    if os.path.commonpath([folder, target]) != folder:
        there = "" if target.exists() else " (not there yet)"
        raise WriteError(f"{path} is a link to {target}{there}, outside the folder {folder}: a write never leaves "
                         "the folder it is given through a link; refusing to write it",
                         f"remove the link (rm {path}) or write to {target} itself")
    return target


def refuse_read_only_folder(folder: Path) -> None:
    """:class:`WriteError` when ``folder`` exists and its mode gives no one write access: someone
    else's data (as root the kernel would allow the write; the mode says what its owner meant).

    Parameters
    ----------
    folder : pathlib.Path

    Raises
    ------
    locust.errors.WriteError
    """
    try:
        mode = folder.stat().st_mode
    except OSError:
        return   # not there yet: making it reports its own error
    if not mode & 0o222:
        raise WriteError(f"cannot write in {folder}: the folder is read-only",
                         "write somewhere else (--out / a path in a folder of your own)")


def make_folder(folder: str | os.PathLike) -> Path:
    """``mkdir -p`` that says what went wrong (:class:`WriteError`) and writes into no read-only
    folder: the nearest existing ancestor's mode decides, as for files.

    Parameters
    ----------
    folder : path-like

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
        A file in the way, a read-only ancestor, or an OS error.
    """
    folder = Path(folder)
    check_can_make(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WriteError(f"cannot make the folder {folder} ({exc.strerror})", DISK_HINT) from None
    return folder


def check_can_make(folder: str | os.PathLike) -> None:
    """Refuse now, making nothing, what :func:`make_folder` would refuse: for a command that
    writes its folder only after minutes of work (a report), so that a path it cannot use
    fails before the work.

    Parameters
    ----------
    folder : path-like

    Raises
    ------
    locust.errors.WriteError
        A file in the way or a read-only ancestor (the nearest that exists decides).
    """
    folder = Path(folder)
    existing = folder
    while not existing.exists() and existing.parent != existing:
        existing = existing.parent
    if not existing.is_dir():
        raise WriteError(f"cannot make {folder}: {existing} is a file", "choose a folder path")
    refuse_read_only_folder(existing)


def temp_beside(path: str | os.PathLike, suffix: str = ".tmp") -> tuple[int, str]:
    """A new temporary file in ``path``'s folder (open fd, name), with ordinary permissions
    (an existing file's own mode, when it is replaced).

    Write it, then ``os.replace`` it onto ``path``: the rename is what makes a write atomic.
    Its name, ``.NAME.PID.XXXXXXXX<suffix>``, carries the writer's process id: temporaries of
    the same ``path`` left by a writer that no longer runs (killed with -9) are removed first.

    Parameters
    ----------
    path : path-like
        The file the temporary will replace.
    suffix : str

    Returns
    -------
    fd : int
    name : str

    Raises
    ------
    locust.errors.WriteError
    """
    path = Path(path)
    make_folder(path.parent)
    remove_stale_temporaries(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=suffix, dir=path.parent)
    except OSError as exc:
        raise WriteError(f"cannot write in {path.parent} ({exc.strerror})", DISK_HINT) from None
    try:
        mode = stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        mode = 0o666 & ~umask
    os.fchmod(fd, mode)  # mkstemp makes 0600
    return fd, tmp


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):   # another user's process: alive
        return pid > 0
    return True


def remove_stale_temporaries(path: str | os.PathLike) -> list[Path]:
    """Remove the temporaries :func:`temp_beside` made for ``path`` whose writer process is
    gone (a kill -9 leaves them; a rerun writing the same ``path`` clears them). Only names
    of exactly that form, regular files, are touched. Returns what was removed.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    list of pathlib.Path
    """
    path = Path(path)
    pattern = re.compile(rf"\.{re.escape(path.name)}\.(\d{{1,10}})\.[a-z0-9_]{{8}}(\.[A-Za-z0-9]{{1,8}})?")
    removed = []
    try:
        names = os.listdir(path.parent)
    except OSError:
        return removed
    for name in names:
        match = pattern.fullmatch(name)
        if not match or _pid_alive(int(match[1])):
            continue
        stale = path.parent / name
        try:
            if stat.S_ISREG(os.lstat(stale).st_mode):
                stale.unlink()
                removed.append(stale)
        except OSError:
            pass
    return removed


def unwind_on_termination() -> None:
    """Make SIGTERM and SIGHUP (a kill, a closed terminal) end this process as an exception
    does (``SystemExit`` with 128 + the signal's number): ``finally`` and ``except
    BaseException`` blocks run, so a writer removes its temporary file. Main thread only."""
    def unwind(signum, frame):
        raise SystemExit(128 + signum)

    for sig in (signal.SIGTERM, signal.SIGHUP):
        if signal.getsignal(sig) == signal.SIG_DFL:
            signal.signal(sig, unwind)


def storable(text: str) -> str:
    r"""``text`` as UTF-8 (and a font) can hold it: a lone surrogate (an undecodable byte of a
    file name, as Python keeps it) becomes its backslash escape, ``\udcff``; every other
    character is kept.

    Parameters
    ----------
    text : str

    Returns
    -------
    str
    """
    return text.encode("utf-8", "backslashreplace").decode("utf-8")


def write_error(path: str | os.PathLike, exc: OSError) -> WriteError:
    """The :class:`WriteError` for an ``OSError`` met writing ``path``; a full disk says so.

    Parameters
    ----------
    path : path-like
    exc : OSError

    Returns
    -------
    locust.errors.WriteError
    """
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return WriteError(f"{path}: the disk is full ({exc.strerror}); nothing was replaced",
                          "free some space on that disk (or write elsewhere) and run the command again")
    return WriteError(f"{path}: cannot write it ({exc.strerror or exc})", DISK_HINT)


def atomic_write_bytes(path: str | os.PathLike, data: bytes, *,
                       check: Callable[[Path], None] | None = None, exclusive: bool = False) -> Path:
    """Write ``data`` to ``path`` through a temporary file and a rename.

    A reader never sees a half-written file, and an interrupted or failed write (a full disk)
    leaves the old file (if any) untouched and no temporary file behind. A symlink is followed
    (its target is updated); what :func:`write_target` refuses is never replaced.

    Parameters
    ----------
    path : path-like
        The file to write.
    data : bytes
        Its whole new content.
    check : callable, optional
        Called with the written temporary file before it replaces ``path``: it reads the file
        back and raises (a :class:`~locust.errors.LocustError`) when it is not what was meant;
        ``path`` is then left as it was.
    exclusive : bool
        Create ``path``, never replace it: :class:`WriteError` when it exists, even when another
        process made it a moment ago (the temporary is hard-linked to its name, which the
        kernel refuses for a name taken).

    Returns
    -------
    Path
        The file written (a symlink's target).
    """
    path = Path(path) if exclusive else write_target(path)
    fd, tmp = temp_beside(path)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        if check is not None:
            check(Path(tmp))
        if exclusive:
            try:
                os.link(tmp, path)
            except FileExistsError:
                raise WriteError(f"{path} exists; refusing to replace it",
                                 "choose another path (or remove that file first)") from None
            os.unlink(tmp)
        else:
            os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        if isinstance(exc, OSError):
            raise write_error(path, exc) from None
        raise
    return path


def atomic_write_text(path: str | os.PathLike, text: str, **kwargs) -> Path:
    """:func:`atomic_write_bytes` of ``text`` in UTF-8 (``check``, ``exclusive`` as there).

    Parameters
    ----------
    path : path-like
    text : str
    **kwargs
        ``check``, ``exclusive``.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    locust.errors.WriteError
    """
    return atomic_write_bytes(path, text.encode("utf-8"), **kwargs)


def atomic_write_json(path: str | os.PathLike, obj: Any) -> Path:
    """Write ``obj`` as strict JSON (:func:`json_text`), atomically.

    Parameters
    ----------
    path : path-like
    obj : Any

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
    """
    return atomic_write_text(path, json_text(obj))


def json_text(obj: Any) -> str:
    """Strict JSON, indented, with a final newline: the one place where a number that JSON
    cannot hold (NaN, +-inf: an undetermined figure) becomes ``null``, numpy values become
    plain ones and paths strings. Every JSON file and every ``--json`` output goes through it.

    Parameters
    ----------
    obj : Any

    Returns
    -------
    str
    """
    return json.dumps(_strict(obj), indent=2, allow_nan=False) + "\n"


def _strict(obj: Any) -> Any:
    import math

    import numpy as np

    if isinstance(obj, dict):
        return {k: _strict(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_strict(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _strict(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Path):
        return str(obj)
    if obj is None or isinstance(obj, (str, int, bool)):
        return obj
    raise TypeError(f"not JSON serialisable: {type(obj).__name__}")


def unique_dir(parent: str | os.PathLike, stem: str) -> Path:
    """Create and return a new directory ``parent/stem`` (or ``stem-2``, ``stem-3``…).

    Never returns a directory that already existed: results are never overwritten.

    Parameters
    ----------
    parent : path-like
    stem : str

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
    FileExistsError
        Every suffixed name taken.
    """
    parent = make_folder(parent)
    try:
        for n in range(1, 10_000):
            candidate = parent / (stem if n == 1 else f"{stem}-{n}")
            try:
                candidate.mkdir()
                return candidate
            except FileExistsError:
                continue
    except OSError as exc:
        raise WriteError(f"cannot make a folder in {parent} ({exc.strerror})", DISK_HINT) from None
    raise FileExistsError(f"no free directory name for {stem!r} in {parent}")


def check_distinct(outputs: dict[str, str | os.PathLike | None],
                   inputs: list[str | os.PathLike] | tuple = ()) -> None:
    """Before anything is written: every output of one command is its own file, and none is
    one of its inputs (:class:`WriteError`). ``outputs``: by the option that names each
    (``--plot``, ``--write``; None: not written). Paths are compared resolved (links followed,
    ``./`` and ``..`` removed), so two spellings of one file are one file.

    Parameters
    ----------
    outputs : dict of str to path-like or None
    inputs : sequence of path-like

    Raises
    ------
    locust.errors.WriteError
    """
    read = {os.path.realpath(p): Path(p) for p in inputs}
    written: dict[str, str] = {}
    for option, path in outputs.items():
        if path is None:
            continue
        real = os.path.realpath(path)
        if real in read:
            raise WriteError(f"{option} {path} is {read[real]}, an input of this command; refusing to write it",
                             f"give {option} a new path of its own")
        if real in written:
            raise WriteError(f"{option} {path} and {written[real]} name the same file; refusing to write either",
                             "give every output its own path")
        written[real] = f"{option} {path}"
