"""``locust.simulate``: one audited simulation, kept with its rollout for traces, videos and plots."""

from __future__ import annotations

import os
from pathlib import Path

from ..params import Robot
from ..sim.job import SimOptions, run_simulation
from ..sim.result import SimResult


def simulate(robot: Robot, cycles: int | None = None, samples: int = 0, seed: int = 0,
             keep_states: bool = True, progress=None, sensitivity: bool | None = None, *,
             leg_set: str | None = None, check_convergence: bool = False, video: str | os.PathLike | None = None,
             camera: str = "track", still: str | os.PathLike | None = None,
             still_push: str | os.PathLike | None = None, board: str | None = None,
             push_clip: str | os.PathLike | None = None, push_clip_held: str | os.PathLike | None = None,
             push_fps: int = 240, side: str = "left", explain: bool = False) -> SimResult:
    """Settle the robot on the floor, run its hop schedule, audit the run and measure the hops.

    Parameters
    ----------
    robot : Robot
        From :func:`locust.robot`.
    cycles : int, optional
        Hop cycles (push + wait) to run; default the robot's ``schedule.cycles``.
    samples : int, default 0
        With N >= 2, also simulate N draws of the values that carry an uncertainty in the
        robot (one batched rollout): ``result.spread``, with ``outcomes`` (each outcome's
        share of the valid draws and the mean and sd of its own distance and highest nose:
        near the threshold the draws split, and one sd across both would hide it) and the
        draws themselves.
    seed : int, default 0
        Random seed of the draws.
    keep_states : bool, default True
        Keep every step's state for ``trace()`` and ``video()`` (False: the figures only, for
        runs of many cycles).
    progress : callable, optional
        ``progress(0)`` as the draws begin, then ``progress(k)`` as each batch of ``k`` draws
        is done (``samples``), then of ``k`` runs of the explanation (``explain``).
    sensitivity : bool, optional
        Which measured values decide the outcome: each uncertain value alone at -/+ 2 sd
        (``result.sensitivity``, :func:`locust.sim.sensitivity.outcome_sensitivity`). True:
        always; False: never; None (default): when the draws of ``samples`` split between
        outcomes.
    leg_set : {"small", "medium", "large"}, optional
        Put this leg set on the robot in place of the one it carries (``robot.leg_set``).
    check_convergence : bool, default False
        Rerun at half the time step: ``result.convergence``, the relative changes and whether
        each is within 1 % or 0.1 mm.
    video : path-like, optional
        Render the run to this MP4 (offscreen) with its true marker pixels beside it
        (``<video>.truth.csv``), as ``result.video(video, camera=camera)`` does; noted in
        ``result.notes``.
    camera : {"track", "fixed"}, default "track"
        For ``video``: follow the robot, or hold still.
    still : path-like, optional
        Render a side photo (PNG) of the robot settled at the 0 deg command, with the board and
        the stickers ``locust measure stance`` reads, and their true pixels beside it.
    still_push : path-like, optional
        The same of the robot held up at the push command (the same camera).
    board : str, optional
        For the stills: the board beside the robot (default ``aruco:4X4_50:5x4:40:10``).
    push_clip : path-like, optional
        Render one push on the floor (MP4, fixed camera) with the stickers ``locust measure
        stroke`` reads, and the crank's true angle beside it (``<clip>.crank.csv``).
    push_clip_held : path-like, optional
        The same push with the robot held up by its plate.
    push_fps : int, default 240
        The push clips' frames per second.
    side : {"left", "right"}, default "left"
        The side the stills and push clips show (the right leg is at -y, the camera there).
    explain : bool, default False
        Why the robot does what it does (``result.explanation``,
        :class:`locust.sim.explain.Explanation`): how it went over (when, on what, the centre
        of mass's distance behind its supports, the servo torque), or how close it came; for
        every uncertain and design value, how far the outcome's threshold is (in its unit and
        its sd); the tornado of each uncertain value's -/+2 sd effect on nose rise and
        distance; and it in plain words (``result.explanation.words``). Some 300 runs of the
        robot: ``progress`` counts them.

    Returns
    -------
    SimResult
        ``.valid`` (a run that breaks its own audit is never a result: ``.reasons`` says why),
        ``.outcome`` (``goes_over``, ``rears_and_returns`` or ``stays_low``), ``.distance_m``,
        ``.max_nose_height_m``, ``.hops``, ``.nose_load_kg``, ``.trace()``, ``.video(path)``,
        ``.plot()``. The same call gives the same numbers every time.

    Raises
    ------
    locust.errors.GeometryError
        The linkage cannot be assembled.
    locust.errors.ParamsError
        A value out of range for simulating.
    locust.errors.SimError
        A video or still path that cannot be written, or a render asked of an invalid run.

    Examples
    --------
    >>> import locust
    >>> r = locust.simulate(locust.robot("small"), cycles=2)
    >>> r.valid, len(r.hops)
    (True, 2)
    >>> r.trace().columns[:3].tolist()
    ['t_s', 'nose_x_m', 'nose_z_m']
    """
    options = SimOptions(cycles=cycles, leg_set=leg_set, samples=samples, seed=seed, sensitivity=sensitivity,
                         keep_states=keep_states, check_convergence=check_convergence,
                         video=None if video is None else Path(video), camera=camera,
                         still=None if still is None else Path(still),
                         still_push=None if still_push is None else Path(still_push), board=board,
                         push_clip=None if push_clip is None else Path(push_clip),
                         push_clip_held=None if push_clip_held is None else Path(push_clip_held), push_fps=push_fps,
                         side=_side(side), explain=explain)
    return run_simulation(robot, options, progress=progress)


def _side(side: str) -> str:
    if side not in ("left", "right"):
        from ..errors import SimError

        raise SimError(f"side {side!r} is not known", "give side='left' or side='right'")
    return "L" if side == "left" else "R"


__all__ = ["SimResult", "simulate"]
