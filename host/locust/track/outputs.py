"""Where ``locust track``'s jobs write, and what they may never write over.

Every job writes into one output folder, named to the person first (``say``): ``--out`` (a
folder, or the tracks file's path), else the run folder the input sits in (``locust hop
--out`` made it: ``run.json`` beside the input), else the current folder; never beside an input
in a folder of its own. No output lands on an input or its sidecars, ``--force`` or not, and
an existing output is replaced only with ``--force``.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterator
from pathlib import Path

from ..errors import TrackError, WriteError
from ..fileio import make_folder, refuse_read_only_folder, write_target
from ..io import trk as trk_io
from ..io.camera_json import camera_json_beside
from ..io.importing import is_project
from ..io.run_record import RECORD_NAME
from ..io.tracks_csv import tracks_csv_in
from .video import VideoInfo, read_as_frame

Say = Callable[[str], None]   # a line for the person (the command's stderr), in order


def quiet(line: str) -> None:
    """A :data:`Say` that says nothing (the Python API's).

    Parameters
    ----------
    line : str
    """


def out_path(value: str | os.PathLike | None) -> Path | None:
    """``--out`` as given: a name ending in ``/`` is a folder, made if it is not there yet (a
    ``Path`` would drop the slash and name a file ``newdir.csv`` here instead).

    Parameters
    ----------
    value : str or path-like or None

    Returns
    -------
    pathlib.Path or None
    """
    if value is None:
        return None
    text = os.fspath(value)
    path = Path(text)
    if text.endswith(("/", os.sep)) and not path.exists():
        make_folder(path)
    return path


def named(video: Path) -> Path:
    """``.`` (an image sequence's folder, run from inside it) by its own name, which the
    outputs and sidecars are named after.

    Parameters
    ----------
    video : pathlib.Path

    Returns
    -------
    pathlib.Path
    """
    return video.resolve() if not video.name else video


@contextlib.contextmanager
def media(video: Path, project: trk_io.TrackerProject | None) -> Iterator[Path]:
    """The video to read: ``video`` itself, or the one the Tracker project ``video`` opens
    (unpacked from a ``.trz`` for the block).

    Parameters
    ----------
    video : pathlib.Path
    project : TrackerProject or None
        ``video``'s project when it is one (or the one its calibration comes from).

    Yields
    ------
    pathlib.Path
    """
    if project is not None and is_project(video):
        with trk_io.project_media(project) as path:
            yield path
    else:
        yield video


def stem(path: Path) -> str:
    """``hop.tracks.csv`` -> ``hop.tracks``: the name the outputs share (a .csv or .txt suffix off).

    Parameters
    ----------
    path : pathlib.Path

    Returns
    -------
    str
    """
    return path.name[: -len(path.suffix)] if path.suffix in (".csv", ".txt") else path.name


def outputs(base: Path, fmt: str, overlay_kind: str) -> dict[str, Path]:
    """The files a job writes beside the tracks file ``base``: the tracks (``.csv``, or ``.txt``
    in Tracker's layout), the sidecar ``.json`` and the overlay (``.png`` or ``.overlay.mp4``).

    Parameters
    ----------
    base : pathlib.Path
        The tracks file.
    fmt : {"csv", "tracker"}
    overlay_kind : {"png", "video", "none"}

    Returns
    -------
    dict of str to pathlib.Path
        ``tracks``, ``sidecar`` and maybe ``overlay``.
    """
    name = stem(base)
    folder = base.parent
    out = {"tracks": folder / f"{name}{'.txt' if fmt == 'tracker' else '.csv'}", "sidecar": folder / f"{name}.json"}
    if overlay_kind == "png":
        out["overlay"] = folder / f"{name}.png"
    elif overlay_kind == "video":
        out["overlay"] = folder / f"{name}.overlay.mp4"
    return out


def refuse_overwrite(paths: dict[str, Path], force: bool) -> None:
    """Refuse, before any work, what no write may replace (nor reach through a link), and an
    existing output without ``force``.

    Parameters
    ----------
    paths : dict of str to pathlib.Path
    force : bool

    Raises
    ------
    locust.errors.TrackError
        An output exists and ``force`` is False.
    locust.errors.WriteError
        A target no write may take.
    """
    for p in paths.values():
        write_target(p)
    taken = [str(p) for p in paths.values() if p.exists()]
    if taken and not force:
        raise TrackError(f"output exists: {', '.join(taken)}", "choose another --out, or add --force to replace it")


def refuse_inputs(paths: dict[str, Path], inputs: list[Path], info: VideoInfo | None = None) -> None:
    """No output may land on an input: the video, a Tracker project, or a sidecar beside them
    (``<video>.camera.json``, ``<video>.truth.csv``), ``--force`` or not; nor on any frame of an
    image sequence, nor where the next run would read it as one of its frames.

    Parameters
    ----------
    paths : dict of str to pathlib.Path
        The outputs.
    inputs : list of pathlib.Path
        What the job reads.
    info : VideoInfo, optional
        The video read, when it is an image sequence.

    Raises
    ------
    locust.errors.TrackError
        An output on an input.
    """
    guarded = set()
    for p in inputs:
        guarded |= {p.resolve(), camera_json_beside(p).resolve(), p.with_name(p.stem + ".truth.csv").resolve()}
    clash = [str(p) for p in paths.values() if p.resolve() in guarded]
    if clash:
        raise TrackError(f"--out would overwrite an input or its sidecar: {', '.join(clash)}",
                         "choose another --out (the default, <video>.tracks.csv, is always safe)")
    frames = [str(p) for p in paths.values() if info is not None and read_as_frame(info, p)]
    if frames:
        raise TrackError(f"--out would write {', '.join(frames)}, a frame of the image sequence {info.path} (or a "
                         "file the next run would read as one)", "choose an --out outside the sequence's folder")


def tracks_path(out: Path | None, source: Path, say: Say = quiet) -> Path:
    """The tracks file of ``source``: ``--out`` as given, or ``<stem>.tracks.csv`` in the ``--out``
    folder, else in :func:`default_folder`; its folder is said first.

    Parameters
    ----------
    out : pathlib.Path or None
        ``--out``.
    source : pathlib.Path
        What is tracked or converted.
    say : callable
        Told ``output folder: <absolute path>``.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.TrackError
        ``out`` is a device or a pipe.
    """
    if out is not None and not out.is_dir() and out.exists() and not out.is_file():
        raise TrackError(f"--out {out} is a device or pipe, not a folder or a file name",
                         "give a folder, or the path of the tracks file to write")
    path = out if out is not None and not out.is_dir() else tracks_csv_in(out or default_folder(source), source)
    say_folder(path, say)
    return path


def default_folder(source: Path) -> Path:
    """Without --out: the run folder ``source`` sits in (``locust hop --out`` made it; ``run.json``
    beside ``source``), where ``locust calibrate hop`` and ``locust report`` read its track, unless
    its mode says it is read-only (someone else's); else the current folder, as ``locust
    calibrate``'s plots, never a data folder beside the input.

    Parameters
    ----------
    source : pathlib.Path

    Returns
    -------
    pathlib.Path
    """
    folder = source.parent
    if (folder / RECORD_NAME).is_file():
        with contextlib.suppress(WriteError):
            refuse_read_only_folder(folder)
            return folder
    return Path(".")


def say_folder(path: Path, say: Say) -> None:
    """Say the output folder ``path`` lies in (absolute).

    Parameters
    ----------
    path : pathlib.Path
        An output.
    say : callable
    """
    say(f"output folder: {path.parent.resolve()}")
