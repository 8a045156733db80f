"""Locks a process holds while it updates a file or writes in a folder: ``flock``, which the
kernel releases when the process ends, however it ends."""

from __future__ import annotations

import fcntl
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ..errors import WriteError
from .writes import make_folder, write_error, write_target


@contextmanager
def locked(path: str | os.PathLike, wait_s: float = 60.0) -> Iterator[Path]:
    """Hold an exclusive lock for updating ``path`` (read, change, write back) while the block runs.

    The lock is ``fcntl.flock`` on ``.NAME.lock`` beside ``path`` (the file itself is replaced
    by every atomic write, so a lock on it would not outlive the first update). Another process
    (or another lock in this one) updating the same ``path`` waits until this block ends; after
    ``wait_s`` seconds of waiting it is :class:`WriteError`. What :func:`write_target` refuses
    is refused first, before any lock file is made. The lock file is removed as the lock is
    released; a waiter that then holds the removed file's lock sees so and locks the new one.

    Parameters
    ----------
    path : path-like
    wait_s : float
        How long to wait for another holder [s].

    Yields
    ------
    pathlib.Path
        The file a write to ``path`` lands on (:func:`write_target`).

    Raises
    ------
    locust.errors.WriteError
        Waited ``wait_s`` in vain, or a target :func:`write_target` refuses.
    """
    path = write_target(path)
    make_folder(path.parent)
    lock_path = path.parent / f".{path.name}.lock"
    deadline = time.monotonic() + wait_s
    while True:
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            raise write_error(lock_path, exc) from None
        try:
            _flock_until(fd, deadline, path, wait_s)
            held = os.fstat(fd)
            try:
                now = os.stat(lock_path)
            except FileNotFoundError:
                now = None
        except BaseException:
            os.close(fd)
            raise
        if now is not None and (now.st_dev, now.st_ino) == (held.st_dev, held.st_ino):
            break
        os.close(fd)   # its holder removed it as it let go: lock the one there now
    try:
        yield path
    finally:
        try:
            os.unlink(lock_path)   # (still held: no one can lock it between this and the close)
        except OSError:
            pass
        os.close(fd)


def _flock_until(fd: int, deadline: float, path: Path, wait_s: float) -> None:
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            if time.monotonic() > deadline:
                raise WriteError(f"{path} is being updated by another process (it holds .{path.name}.lock beside "
                                 f"it) and has been for over {wait_s:g} s",
                                 "wait for that command to finish, then run this one again") from None
            time.sleep(0.02)


def try_lock(path: str | os.PathLike) -> int | None:
    """An open descriptor of ``path`` (a folder, or a lock file made if missing) holding an
    exclusive ``flock`` on it; None at once when another process holds one. Close the
    descriptor to release it (a process that dies releases it too).

    Parameters
    ----------
    path : path-like

    Returns
    -------
    int or None
    """
    flags = os.O_RDONLY | os.O_DIRECTORY if os.path.isdir(path) else os.O_RDWR | os.O_CREAT
    fd = os.open(path, flags | os.O_CLOEXEC, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def claim_folder(folder: str | os.PathLike) -> int:
    """:func:`try_lock` of ``folder``, or :class:`WriteError` when another process writes there now.

    Parameters
    ----------
    folder : path-like

    Returns
    -------
    int
        The lock's descriptor.

    Raises
    ------
    locust.errors.WriteError
    """
    fd = try_lock(folder)
    if fd is None:
        raise WriteError(f"another process is writing in {folder} now; refusing to share it",
                         "give this command a folder of its own")
    return fd
