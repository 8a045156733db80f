"""Resolve --port for a command: a device path, autodetection, or ``sim`` (a virtual robot)."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path

from ..errors import DeviceError
from ..tables import plant_lines
from .plant import make_plant
from .ports import SIM, autodetect, list_serial_ports


@contextlib.contextmanager
def open_port(port: str | None, plant: str = "auto", video: Path | None = None, robot=None,
              info=None, video_fps: int = 60, firmware: bool = True,
              on_close: Callable[[dict], None] | None = None,
              on_open: Callable[[object], None] | None = None) -> Iterator[str]:
    """Resolve ``--port`` for the ``with`` block: a device path, autodetection, or ``sim``.

    ``sim`` runs a virtual robot for the ``with`` block; with ``firmware`` (a command that talks
    to the firmware) its flash must hold one. ``on_close`` gets the virtual robot's plant
    summary (its simulated hops) when it stops.

    Parameters
    ----------
    port : str or None
        A device path, ``sim``, or None to autodetect the one ESP32.
    plant : str, default "auto"
        The virtual robot's plant (``auto``, ``mujoco`` or ``record``, :func:`make_plant`).
    video : Path, optional
        A video the virtual robot's MuJoCo plant renders.
    robot : Robot, optional
        The robot the virtual robot simulates (the seed preset when None).
    info : callable, optional
        ``info(line)`` for what the virtual robot is and, at the end, its simulated hops.
    video_fps : int, default 60
        Frame rate of ``video`` [frames/s].
    firmware : bool, default True
        Require firmware in the virtual robot's flash folder.
    on_close : callable, optional
        ``on_close(summary)`` with the virtual robot's plant summary when it stops.
    on_open : callable, optional
        ``on_open(robot)`` with the :class:`VirtualRobot` once it runs (not called for a real port).

    Yields
    ------
    str
        The device path to open.

    Raises
    ------
    DeviceError
        Nothing flashed on the virtual robot, an unknown plant, or no single ESP32 found.
    """
    if port == SIM:
        from .virtual import VirtualRobot, default_flash_dir

        flash = default_flash_dir()
        if firmware and not (flash / "main.py").exists():
            raise DeviceError(f"nothing flashed: run `locust flash --port sim` (the virtual robot's flash "
                              f"folder {flash} has no firmware)",
                              "flash it once: it stays flashed for every later --port sim command")

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
            if on_open is not None:
                on_open(vr)
            yield vr.device_path
        finally:
            summary = vr.stop()
            if on_close is not None:
                on_close(summary)
            if info and summary.get("plant") == "mujoco":
                for line in plant_lines(summary):
                    info(line)
        return
    yield port or autodetect(list_serial_ports())

