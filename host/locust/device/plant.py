"""What the virtual robot's servos drive: a plant that takes horn angles over time.

- ``RecordingPlant`` keeps every command in memory; tests and ``--plant record`` use it.
- ``MujocoPlant`` drives the simulation's live MuJoCo model
  (``locust.sim.live.LiveSim``), so a hop on the virtual robot moves the simulated robot.
  Its video has a fixed camera framed on the robot's planned schedule (``robot.schedule``:
  ``locust hop`` puts its own options there), with ``.truth.csv`` and ``.camera.json``
  beside it, so ``locust track`` gives metres.

A plant gets ``command(t_s, left_deg, right_deg)``: horn angles in firmware units (rest 0,
push -30 on both legs) taking effect at ``t_s`` seconds since the virtual robot started.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from ..errors import DeviceError

PLANTS = ("auto", "mujoco", "record")
VIDEO_FPS = 60    # the virtual robot's camera [frames/s], as docs/hardware.md asks of a real one
FPS_RANGE = (1, 1000)    # the rates its video may be rendered at [frames/s]


class Plant(Protocol):
    """What a virtual robot's servos drive: it takes horn angles over time and sums up at the end."""

    def command(self, t_s: float, left_deg: float, right_deg: float) -> None:
        """Set both horns at ``t_s``.

        Parameters
        ----------
        t_s : float
            Time since the virtual robot started [s].
        left_deg, right_deg : float
            Horn angles in firmware units (rest 0, push negative) [deg].
        """

    def close(self, t_s: float) -> dict:
        """End at ``t_s``.

        Parameters
        ----------
        t_s : float
            Time of the end since the virtual robot started [s].

        Returns
        -------
        dict
            The plant's summary, with its name under ``"plant"``.
        """


@dataclass(frozen=True)
class ServoCommand:
    """Both horn angles as commanded at one time.

    Attributes
    ----------
    t_s : float
        Time since the virtual robot started [s].
    left_deg, right_deg : float
        Horn angles in firmware units (rest 0, push negative) [deg].
    """

    t_s: float
    left_deg: float
    right_deg: float


class RecordingPlant:
    """A plant that keeps every command in memory (tests and ``--plant record``)."""

    def __init__(self):
        self.commands: list[ServoCommand] = []
        self._lock = threading.Lock()

    def command(self, t_s: float, left_deg: float, right_deg: float) -> None:
        """Keep one command.

        Parameters
        ----------
        t_s : float
            Time since the virtual robot started [s].
        left_deg, right_deg : float
            Horn angles [deg].
        """
        with self._lock:
            self.commands.append(ServoCommand(t_s, left_deg, right_deg))

    def close(self, t_s: float) -> dict:
        """The plant's summary.

        Parameters
        ----------
        t_s : float
            Time of the end [s] (unused).

        Returns
        -------
        dict
            ``{"plant": "record", "commands": N}``.
        """
        return {"plant": "record", "commands": len(self.commands)}


IDLE_LAG_S = 0.5     # idle, the model is stepped up to this long before now: no command comes that late
HOP_REST_S = 0.5     # servos at rest this long after a push: the hop is done (or the next push starts)
# a filmed run goes on this long after the robot is stopped, so that its clip ends, as it opens
# (sim.live.PREROLL_S), on the robot standing: the last hop's rest is in the frames whatever the
# host's latency, and no longer the whole time the rendering lagged behind the clock
VIDEO_TAIL_S = 0.5


class MujocoPlant:
    """The live MuJoCo model, stepped up to each command's time (and, idle, close behind the
    clock); ``on_hop`` gets each hop's row (:class:`locust.sim.hops.Hop`'s fields) once it is done.

    Parameters
    ----------
    robot : Robot
        The robot simulated.
    video_path : Path, optional
        A video to render from a fixed camera (with ``.truth.csv`` and ``.camera.json`` beside it).
    video_fps : int, default 60
        The video's frame rate [frames/s].
    on_hop : callable, optional
        ``on_hop(row)`` for each hop once it is done.

    Raises
    ------
    DeviceError
        The live MuJoCo model cannot be imported.
    """

    def __init__(self, robot, video_path: Path | None = None, video_fps: int = 60,
                 on_hop: Callable[[dict], None] | None = None):
        try:
            from ..sim.live import LiveSim
        except ImportError as exc:
            raise DeviceError(f"the live MuJoCo model is not available ({exc})",
                              "use --plant record, or install the simulation part of locust") from None
        self.sim = LiveSim(robot, video_path=str(video_path) if video_path else None, fps=video_fps)
        self.on_hop = on_hop
        self._told = 0
        self.films = video_path is not None   # it renders a video

    def command(self, t_s: float, left_deg: float, right_deg: float) -> None:
        """Step the model up to ``t_s``, then set both servos.

        Parameters
        ----------
        t_s : float
            Time since the virtual robot started [s].
        left_deg, right_deg : float
            Horn angles in firmware units [deg].
        """
        self.sim.advance_to(t_s)
        self.sim.set_servo_angles_deg(left_deg, right_deg)
        self._tell()

    def idle(self, t_s: float) -> None:
        """No command for a while: step the model up to ``IDLE_LAG_S`` before ``t_s`` (the
        same steps a later command would take it through) and tell the hops now done.

        Parameters
        ----------
        t_s : float
            The virtual robot's clock now [s].
        """
        if self.on_hop is None:
            return
        if t_s - IDLE_LAG_S > self.sim.sim_time_s:
            self.sim.advance_to(t_s - IDLE_LAG_S)
        self._tell()

    def _tell(self) -> None:
        if self.on_hop is None:
            return
        hops = self.sim.finished_hops(HOP_REST_S)
        for hop in hops[self._told:]:
            self.on_hop(hop)
        self._told = max(self._told, len(hops))

    def close(self, t_s: float) -> dict:
        """Step the model up to ``t_s`` (a filmed one ``VIDEO_TAIL_S`` further) and finish the
        simulation (and its video).

        Parameters
        ----------
        t_s : float
            Time of the end since the virtual robot started [s].

        Returns
        -------
        dict
            ``{"plant": "mujoco", ...}`` with the live simulation's summary (its hops).
        """
        self.sim.advance_to(t_s + (VIDEO_TAIL_S if self.films else 0.0))
        return {"plant": "mujoco", **(self.sim.close() or {})}

    def abort(self) -> None:
        """After a failure: no half-written video is left."""
        self.sim.abort()

    def cancel(self) -> None:
        """From another thread: make the thread feeding this plant stop soon (it then aborts)."""
        self.sim.cancel()


def mujoco_available() -> bool:
    """Whether the live MuJoCo model (``locust.sim.live``) can be imported.

    Returns
    -------
    bool
        True when it is installed.
    """
    import importlib.util

    try:
        return importlib.util.find_spec("locust.sim.live") is not None
    except ImportError:
        return False


def make_plant(kind: str, robot=None, video_path: Path | None = None, video_fps: int = 60,
               on_hop: Callable[[dict], None] | None = None) -> Plant:
    """The plant named ``kind``: ``auto`` is the MuJoCo model when it is installed (or a video is
    asked for), else a recorder.

    Parameters
    ----------
    kind : str
        ``auto``, ``mujoco`` or ``record``.
    robot : Robot, optional
        The robot the MuJoCo plant simulates (the seed preset when None).
    video_path : Path, optional
        A video the MuJoCo plant renders.
    video_fps : int, default 60
        The video's frame rate [frames/s].
    on_hop : callable, optional
        ``on_hop(row)`` for each finished hop (MuJoCo plant).

    Returns
    -------
    Plant
        A :class:`MujocoPlant` or a :class:`RecordingPlant`.

    Raises
    ------
    DeviceError
        An unknown ``kind``, or MuJoCo asked for and not available.
    """
    if kind == "auto":
        kind = "mujoco" if (video_path is not None or mujoco_available()) else "record"
    if kind == "mujoco":
        if robot is None:
            from ..params import preset
            robot = preset("seed")
        return MujocoPlant(robot, video_path, video_fps, on_hop)
    if kind == "record":
        return RecordingPlant()
    raise DeviceError(f"unknown plant {kind!r}", f"choose one of {', '.join(PLANTS)}")
