"""The recordings the toolkit ships (SYNTHETIC, from ``calibration/make_synthetic.py``), found
where the package is: a source checkout or an installed wheel.

Their home is ``calibration/recordings`` (the paths the docs use, from a checkout's root);
``host/locust/recordings`` links to it, so the package carries them as data and the wheel
ships every file in that folder (pyproject's package-data). ``importlib.resources`` finds
them beside the package it imports, wherever that was installed: no path arithmetic on a
module's file, no reliance on the current folder.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from .errors import CalibrationError

FOLDER = "recordings"    # inside the package: host/locust/recordings, site-packages/locust/recordings


def _folder():
    return resources.files("locust") / FOLDER


def bundled_recordings() -> list[str]:
    """The names of the bundled recordings, sorted.

    Returns
    -------
    list of str
        Each file's name (``synthetic_beam.csv``, ...); empty where the package has none.
    """
    folder = _folder()
    if not folder.is_dir():
        return []
    return sorted(item.name for item in folder.iterdir() if item.is_file() and not item.name.startswith("."))


def bundled_recording(name: str) -> Path:
    """The path of a bundled recording, in a checkout (``calibration/recordings/NAME``, through
    the package's link) or in an installed wheel (``site-packages/locust/recordings/NAME``).

    Parameters
    ----------
    name : str
        The recording's file name, e.g. ``"synthetic_beam.csv"`` (:func:`bundled_recordings`
        lists them).

    Returns
    -------
    pathlib.Path
        The file, on disk.

    Raises
    ------
    CalibrationError
        No bundled recording has that name (a path or a name with a folder is not one); the
        hint lists those there are.

    Examples
    --------
    >>> import locust
    >>> locust.bundled_recording("synthetic_ramp.csv").name
    'synthetic_ramp.csv'
    """
    names = bundled_recordings()
    if name not in names:
        there = ", ".join(names) if names else "none: this installation of locust has lost its data files"
        raise CalibrationError(f"no bundled recording is named {name!r}",
                               f"the bundled recordings are: {there}")
    path = _folder() / name
    if not isinstance(path, Path):    # a package imported from a zip: its files are not on disk
        raise CalibrationError(f"the bundled recording {name!r} is inside a zip ({path}), not a file on disk",
                               "install locust with pip (it unpacks the package)")
    return path


__all__ = ["bundled_recording", "bundled_recordings"]
