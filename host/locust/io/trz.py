"""Reading a Tracker project zip (``.trz``) a user hands in, without trusting it.

Every member is checked when the zip is opened, before anything is read: its name must be a
relative path with no ``..`` (or drive) in it, it must be a plain file or folder (no symbolic
link, device or pipe), neither encrypted nor packed by a method Tracker does not write, and its
declared size within :data:`MAX_MEMBER_BYTES`; the zip holds at most :data:`MAX_MEMBERS`.
Members are read in pieces and counted as they come, so a member that inflates past its
bound stops there: a zip is read, never unpacked where its member names point.
"""

from __future__ import annotations

import stat
import zipfile
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path, PurePosixPath, PureWindowsPath

from ..errors import TrackError

# A Tracker project holds a .trk, a video or an image sequence, and a few thumbnails: a
# sequence of 10 000 frames is 5.5 min at 30 frames/s, beyond any hop experiment.
MAX_MEMBERS = 10_000
# A .trk is kB to a few MB (about 200 bytes per marked step: 150 000 steps are 30 MB).
MAX_TRK_BYTES = 32 * 2**20
# A video member is tens to hundreds of MB (a minute of 1080p H.264 at 30 frames/s ~ 100 MB).
MAX_MEMBER_BYTES = 2 * 2**30
# What one command unpacks of a project in all (the video's folder): a member's bound.
MAX_UNPACKED_BYTES = MAX_MEMBER_BYTES
# Tracker (java.util.zip) stores or deflates. Python inflates a deflated member in bounded
# pieces, but a bzip2 or lzma member's whole block at once (a 1 kB bzip2 stream is 45 MB), so
# only the two methods Tracker writes are read.
_METHODS = {zipfile.ZIP_STORED: "stored", zipfile.ZIP_DEFLATED: "deflate"}
_HINT = "this is not a project Tracker saved: open the .trk or the video itself, not this zip"
_CHUNK = 1 << 20


def _name_problem(name: str) -> str | None:
    """Why member ``name`` would land outside the folder it is unpacked into (None: it would not)."""
    if "\x00" in name:
        return "its name has a NUL character"
    posix, win = PurePosixPath(name), PureWindowsPath(name)
    if posix.is_absolute() or win.drive or win.root:
        return "its name is an absolute path"
    if ".." in posix.parts or ".." in win.parts:
        return "its name has a '..' component"
    return None


def _kind_problem(info: zipfile.ZipInfo) -> str | None:
    """Why member ``info`` is not a plain file or folder, or cannot be unpacked (None: it can)."""
    kind = stat.S_IFMT(info.external_attr >> 16)   # the Unix file type, where the zip records one
    if kind not in (0, stat.S_IFREG, stat.S_IFDIR):
        kind = "a symbolic link" if kind == stat.S_IFLNK else "a device, pipe or socket"
        return f"it is {kind}, not a plain file"
    if info.flag_bits & 0x1:
        return "it is encrypted (a password is needed)"
    if info.compress_type not in _METHODS:
        return (f"it is packed by compression method {info.compress_type}; Tracker stores or deflates (methods 0 "
                "and 8), and only those are read")
    if info.file_size > MAX_MEMBER_BYTES:
        return f"it unpacks to {info.file_size:,} bytes, over the limit of {MAX_MEMBER_BYTES:,} for one member"
    return None


def check_members(path: Path, z: zipfile.ZipFile) -> None:
    """:class:`TrackError` naming the first member of ``z`` that is not safe to read.

    Parameters
    ----------
    path : pathlib.Path
        The ``.trz``, for messages.
    z : zipfile.ZipFile

    Raises
    ------
    locust.errors.TrackError
        Too many members, or one that is not safe (an absolute or escaping name, a link, over
        the size limits).
    """
    infos = z.infolist()
    if len(infos) > MAX_MEMBERS:
        raise TrackError(f"{path}: a zip of {len(infos):,} members, over the limit of {MAX_MEMBERS:,} "
                         "(a Tracker project holds a .trk, a video and a few images)", _HINT)
    for info in infos:
        problem = _name_problem(info.filename) or _kind_problem(info)
        if problem:
            raise TrackError(f"{path}: member {info.filename!r}: {problem}; nothing was read from the zip",
                             _HINT)


@contextmanager
def open_trz(path: str | Path) -> Iterator[zipfile.ZipFile]:
    """The zip at ``path``, every member checked (:func:`check_members`); a damaged zip is a
    :class:`TrackError`.

    Parameters
    ----------
    path : path-like

    Yields
    ------
    zipfile.ZipFile

    Raises
    ------
    locust.errors.TrackError
        Not a readable zip, or a member not safe to read.
    """
    path = Path(path)
    try:
        z = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, EOFError, ValueError) as exc:
        raise _damaged(path, exc) from None
    with z:
        check_members(path, z)
        yield z


def _damaged(path: Path, exc: Exception) -> TrackError:
    return TrackError(f"{path}: cannot read the zip ({exc})", "check the file is a complete Tracker project")


def _chunks(path: Path, z: zipfile.ZipFile, name: str, limit: int) -> Iterator[bytes]:
    """Member ``name``'s bytes in pieces; :class:`TrackError` once they pass ``limit``."""
    total = 0
    try:
        with z.open(name) as f:
            while chunk := f.read(_CHUNK):
                total += len(chunk)
                if total > limit:
                    raise TrackError(f"{path}: member {name!r} unpacks to over {limit:,} bytes, the limit; "
                                     "stopped reading it", _HINT)
                yield chunk
    except (zipfile.BadZipFile, EOFError, ValueError, NotImplementedError, RuntimeError, OSError, zlib.error) as exc:
        raise _damaged(path, exc) from None


def read_member(path: Path, z: zipfile.ZipFile, name: str, limit: int = MAX_TRK_BYTES) -> bytes:
    """Member ``name`` of ``z`` (opened by :func:`open_trz`) in memory, at most ``limit`` bytes.

    Parameters
    ----------
    path : pathlib.Path
        The ``.trz``, for messages.
    z : zipfile.ZipFile
    name : str
        The member.
    limit : int
        The most bytes read.

    Returns
    -------
    bytes

    Raises
    ------
    locust.errors.TrackError
        The member unpacks to more than ``limit`` bytes, or is damaged.
    """
    info = z.getinfo(name)
    if info.file_size > limit:
        raise TrackError(f"{path}: member {name!r} says it unpacks to {info.file_size:,} bytes, over the "
                         f"limit of {limit:,}", _HINT)
    return b"".join(_chunks(path, z, name, limit))


def unpack_members(path: Path, z: zipfile.ZipFile, names: list[str], folder: Path) -> None:
    """Copy members ``names`` of ``z`` (opened by :func:`open_trz`, so every name is relative
    and plain) under ``folder``, a fresh temporary folder; at most :data:`MAX_UNPACKED_BYTES` in all.

    Parameters
    ----------
    path : pathlib.Path
        The ``.trz``, for messages.
    z : zipfile.ZipFile
    names : list of str
        The members copied.
    folder : pathlib.Path
        Where they go.

    Raises
    ------
    locust.errors.TrackError
        A member that would land outside ``folder``, more than the limit in all, or damaged.
    """
    root = folder.resolve()
    left = MAX_UNPACKED_BYTES
    for name in names:
        target = root.joinpath(*PurePosixPath(name).parts)
        if not target.resolve().is_relative_to(root):   # checked names cannot; kept as the last guard
            raise TrackError(f"{path}: member {name!r} would be written outside the folder it is unpacked into",
                             _HINT)
        target.parent.mkdir(parents=True, exist_ok=True)
        with open(target, "xb") as out:
            for chunk in _chunks(path, z, name, left):
                out.write(chunk)
            left -= out.tell()
