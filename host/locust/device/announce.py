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
    """Say that this process simulates ``source`` behind ``device_path``; returns the file."""
    path = _path(device_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return atomic_write_json(path, {"pid": os.getpid(), "device": device_path, "preset": source.preset,
                                    "robot_file": source.robot_file, "leg_set": source.leg_set})


def withdraw(device_path: str) -> None:
    _path(device_path).unlink(missing_ok=True)


def announced(device_path: str) -> RobotSource | None:
    """The robot a live ``locust virtual`` on ``device_path`` simulates, or None."""
    try:
        doc = json.loads(_path(device_path).read_text())
        os.kill(int(doc["pid"]), 0)
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if doc.get("device") != device_path:
        return None
    return RobotSource(preset=doc.get("preset"), robot_file=doc.get("robot_file"), leg_set=doc.get("leg_set"))
