"""Resolve --port for a command: a device path, autodetection, or ``sim`` (a virtual robot)."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

from ..tables import plant_lines
from .plant import make_plant
from .ports import SIM, autodetect, list_serial_ports


@contextlib.contextmanager
def open_port(port: str | None, plant: str = "auto", video: Path | None = None, robot=None,
              info=None, video_fps: int = 60) -> Iterator[str]:
    """Yields the device path to open. ``sim`` runs a virtual robot for the ``with`` block."""
    if port == SIM:
        from .virtual import VirtualRobot

        model = make_plant(plant, robot, video, video_fps)
        try:
            vr = VirtualRobot(plant=model).start()
        except BaseException:   # (a signal while it boots) the plant's video is dropped, not left half made
            abort = getattr(model, "abort", None)
            if abort is not None:
                abort()
            raise
        try:
            if info:
                info(f"virtual robot on {vr.device_path} (flash {vr.flash_dir}, {vr.scheduling} scheduling)")
            yield vr.device_path
        finally:
            summary = vr.stop()
            if info and summary.get("plant") == "mujoco":
                for line in plant_lines(summary):
                    info(line)
        return
    yield port or autodetect(list_serial_ports())

