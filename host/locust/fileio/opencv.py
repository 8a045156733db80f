"""OpenCV's files: a name it can open whatever bytes the file's name holds, and a video it
wrote read back (its writer reports no failed write)."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

from ..errors import WriteError
from .writes import DISK_HINT


@contextmanager
def opencv_path(path: str | os.PathLike) -> Iterator[str]:
    """A name OpenCV can open ``path`` by, for the duration of the ``with``: ``path`` itself, or,
    where it is not UTF-8 text, a link to it in a private temporary folder.

    OpenCV takes a file name as UTF-8 text; a name with bytes that are not UTF-8 (a folder
    copied from an old camera or another system: Python keeps those bytes as lone
    surrogates) crashes it with a segmentation fault, in its reader and its writer alike. The
    link (``media`` plus the name's suffix, which OpenCV's writer chooses the container by)
    reaches the same file, to read or to write through. A capture or writer opens its file as
    it is made, so the link may go once it is.

    Parameters
    ----------
    path : path-like
        The file to read or write (a writer's file may not exist yet).

    Yields
    ------
    str
        A UTF-8 name of the same file.

    Raises
    ------
    locust.errors.WriteError
        No private folder can be made for the link.
    """
    name = os.fspath(path)
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        pass
    else:
        yield name
        return
    suffix = Path(name).suffix
    try:
        suffix.encode("utf-8")
    except UnicodeEncodeError:
        suffix = ""
    try:
        folder = tempfile.mkdtemp(prefix="locust-name-")
    except OSError as exc:
        raise WriteError(f"cannot make a temporary folder ({exc.strerror})", DISK_HINT) from None
    link = os.path.join(folder, "media" + suffix)
    try:
        os.symlink(os.path.abspath(name), link)
        yield link
    finally:
        with suppress(OSError):
            os.unlink(link)
        with suppress(OSError):
            os.rmdir(folder)


def check_encoded(tmp: str | os.PathLike, frames: int, path: Path) -> None:
    """Raise :class:`WriteError` unless the video just encoded at ``tmp`` (for ``path``) reads
    back with its ``frames`` frames: OpenCV's writer ignores a failed write (a full disk) and
    leaves a truncated file no player opens.

    Parameters
    ----------
    tmp : path-like
        The encoded video.
    frames : int
        The frames written.
    path : pathlib.Path
        The video's final path, for the message.

    Raises
    ------
    locust.errors.WriteError
    """
    if frames == 0:
        return
    import cv2

    with opencv_path(tmp) as name:
        cap = cv2.VideoCapture(name)
        try:
            count = int(cap.get(cv2.CAP_PROP_FRAME_COUNT)) if cap.isOpened() else 0
        finally:
            cap.release()
    if count != frames:
        raise WriteError(f"{path}: the video could not be written completely ({count} of {frames} frames read "
                         "back); the disk may be full", DISK_HINT)
