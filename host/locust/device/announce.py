"""Which robot a running ``locust virtual`` simulates, for the commands that talk to it.

``locust virtual --preset medium`` writes ``<virtual home>/robots/pts-N.json`` (its process
id and the robot: preset, robot file, leg set) while it runs; ``locust hop --port
/dev/pts/N`` records that robot in run.json, as ``hop --port sim`` records its own. A file
whose process is gone is ignored (a kill -9 leaves it behind; the next announcement on the
same pty replaces it).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ..fileio import atomic_write_json
from ..io.run_record import RobotSource
from .virtual import virtual_home


def _path(device_path: str) -> Path:
    return virtual_home() / "robots" / (Path(device_path).parent.name + "-" + Path(device_path).name + ".json")


def announce(device_path: str, source: RobotSource) -> Path:
    """Say that this process simulates ``source`` behind ``device_path``.

    Parameters
    ----------
    device_path : str
        The pseudo-terminal the virtual robot listens on, e.g. ``/dev/pts/3``.
    source : RobotSource
        The robot it simulates (preset, robot file, leg set).

    Returns
    -------
    Path
        The announcement file written under ``<virtual home>/robots/``.
    """
    path = _path(device_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return atomic_write_json(path, {"pid": os.getpid(), "device": device_path, "preset": source.preset,
                                    "robot_file": source.robot_file, "leg_set": source.leg_set})


def withdraw(device_path: str) -> None:
    """Remove the announcement for ``device_path`` (nothing happens if there is none).

    Parameters
    ----------
    device_path : str
        The pseudo-terminal the virtual robot listened on.
    """
    _path(device_path).unlink(missing_ok=True)


def announced(device_path: str) -> RobotSource | None:
    """The robot a live ``locust virtual`` on ``device_path`` simulates.

    Parameters
    ----------
    device_path : str
        The pseudo-terminal a command was given as ``--port``.

    Returns
    -------
    RobotSource or None
        The announced robot; None when no file names that device, it cannot be read, or the
        process that wrote it is gone.
    """
    try:
        doc = json.loads(_path(device_path).read_text())
        os.kill(int(doc["pid"]), 0)
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if doc.get("device") != device_path:
        return None
    return RobotSource(preset=doc.get("preset"), robot_file=doc.get("robot_file"), leg_set=doc.get("leg_set"))
