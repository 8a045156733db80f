"""``locust.hop``: the hop schedule on the robot (or the virtual robot), kept as a run record,
as ``locust hop`` runs it."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from ..device.hop_job import HopOptions, run_hop_job
from ..device.plant import VIDEO_FPS
from ..io.run_record import RunRecord, hop_default


def hop(port: str | None = None, cycles: int | None = None, push_deg: float | None = None,
        push_ms: int | None = None, wait_ms: int | None = None,
        heartbeat_ms: int = hop_default("heartbeat_ms"), out: str | Path | None = None,
        leg_set: str | None = None, plant: str = "auto", video: str | Path | None = None, fps: int = VIDEO_FPS,
        preset: str | None = None, config: str | Path | None = None,
        sets: Mapping[str, object] | Sequence[str] = (), say: Callable[[str], None] | None = None) -> RunRecord:
    """Run the bang-bang hop schedule (push, wait; N cycles) on the robot and keep its run record,
    as ``locust hop`` does: each argument is the option of the same name.

    The phases are timed on the robot (``ticks_us``); ``run.json`` gets the commanded and
    measured start of every phase and the jitter, which robot and leg set were hopped, and the
    board's config read back before the hop. Ctrl-C or a lost cable: the robot goes to rest,
    the record keeps what arrived and the error says where it is.

    Parameters
    ----------
    port : str, optional
        A serial port (e.g. ``/dev/ttyUSB0``), or ``"sim"`` for a virtual robot that runs for
        the hop (flashed once with ``locust flash --port sim``); default the one likely ESP32.
    cycles : int, optional
        Hop cycles; default the robot's ``schedule.cycles``.
    push_deg : float, optional
        Horn angle of the push [deg]; default the robot's schedule.
    push_ms : int, optional
        Push time [ms]; default the robot's schedule.
    wait_ms : int, optional
        Wait (rest) time [ms]; default the robot's schedule.
    heartbeat_ms : int, default 750
        The robot returns to rest if the host is silent this long [ms].
    out : path-like, optional
        Folder for ``run.json`` (must not hold one); default ``data/runs/<timestamp>/`` under
        the current folder. A hop the board never answered leaves no folder.
    leg_set : str, optional
        The legs on the robot (small, medium, large, or a name of your own), recorded in
        ``run.json`` for ``locust report``; default the ``preset`` when it is a leg set. A known
        leg set is built on the ``config`` robot for the virtual robot.
    plant : {"auto", "mujoco", "record"}, default "auto"
        With the virtual robot: what the servos drive (the live model, or only a record of
        the commands; auto: the model when installed).
    video : path-like, optional
        With the virtual robot: render the simulated robot to this video (fixed camera framed
        on the planned hops, with ``.truth.csv`` and ``.camera.json`` beside it).
    fps : int, default 60
        With ``video``: its frames per second [frames/s].
    preset : str, optional
        A built-in parameter set; with neither ``preset`` nor ``config``, the robot the
        command line takes (``calibration/robot.toml`` in the current folder, else the robot
        as built).
    config : path-like, optional
        A robot.toml; overrides ``preset``.
    sets : mapping or sequence of str, optional
        Overrides by dotted name: ``{"servo.kp_nm_per_rad": 0.4}`` or ``["servo.kp_nm_per_rad=0.4"]``.
    say : callable, optional
        ``say(line)`` with each line the command prints before its summary (the output folder
        first); default nothing. A progress bar shows on stderr as for the command.

    Returns
    -------
    locust.io.run_record.RunRecord
        The record as written in ``run.json`` (``.to_dict()`` is what ``locust hop --json``
        prints): ``.status`` is ``complete`` only when every phase was reported and the
        firmware finished the schedule, ``default_config`` when the board ran on its default
        config (its config.json unreadable), ``incomplete`` when the firmware ended it early;
        ``.phases``, ``.board``, ``.robot``.

    Raises
    ------
    locust.errors.DeviceError
        A value out of its limits, no board, nothing flashed on the virtual robot, or a hop
        the board refused, stopped reporting, rebooted in or lost its port in, or one that
        was interrupted: the message gives what was recorded and where.
    locust.errors.ParamsError
        A robot that cannot be read or built.

    Examples
    --------
    Not run as a doctest: it needs the firmware flashed to the virtual robot.

    >>> import locust
    >>> rec = locust.hop(port="sim", cycles=1, push_ms=50, wait_ms=50, plant="record",
    ...                  out="run")                                          # doctest: +SKIP
    >>> rec.status, len(rec.phases)                                          # doctest: +SKIP
    ('complete', 2)
    """
    if isinstance(sets, Mapping):
        sets = [f"{key}={value}" for key, value in sets.items()]
    options = HopOptions(port=port, cycles=cycles, push_deg=push_deg, push_ms=push_ms, wait_ms=wait_ms,
                         heartbeat_ms=heartbeat_ms, out=None if out is None else Path(out), leg_set=leg_set,
                         plant=plant, video=None if video is None else Path(video), video_fps=fps, preset=preset,
                         config=None if config is None else Path(config), sets=tuple(sets))
    return run_hop_job(options, say=say).record
