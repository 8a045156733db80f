"""The simulation job: what ``locust sim`` and :func:`locust.simulate` both run.

:class:`SimOptions` holds every setting of ``locust sim`` but the robot and how the result is
printed; :func:`run_simulation` checks the files it will write (before simulating, not after),
runs the audited simulation with its standing load, its draws and their sensitivity, then the
dt/2 convergence check, the video and the stills asked for, each noted in the result.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import GeometryError, SimError
from ..params import Robot, check_robot, leg_set
from . import run as _run
from .result import SimResult


@dataclass(frozen=True, kw_only=True)
class SimOptions:
    """The settings of one simulation, as ``locust sim`` takes them (its robot aside).

    Attributes
    ----------
    cycles : int or None
        Hop cycles to run (None: the robot's ``schedule.cycles``).
    leg_set : str or None
        Put this leg set (small, medium, large) on the robot in place of the one it carries.
    samples : int
        With N >= 2, also N draws of the values that carry an uncertainty (``result.spread``).
    seed : int
        Random seed of the draws.
    sensitivity : bool or None
        Each uncertain value alone at -/+ 2 sd (True: always; None: when the draws split).
    keep_states : bool
        Keep every step's state (a video keeps them whatever this says).
    check_convergence : bool
        Rerun at half the time step (``result.convergence``).
    video : Path or None
        Render the run to this MP4, with its truth sidecars.
    camera : str
        For ``video``: ``track`` (follow the robot) or ``fixed``.
    still, still_push : Path or None
        Render side stills of the robot settled at the 0 deg command, and held up at the push
        command, with their truth sidecars.
    board : str or None
        For the stills: the board beside the robot (None: the default board).
    push_clip, push_clip_held : Path or None
        Render one push on the floor, and one with the robot held up, for ``locust measure
        stroke`` (:mod:`.pushclip`), with their truth sidecars.
    push_fps : int
        The push clips' frame rate [1/s].
    side : str
        The side the stills and push clips show: ``L`` (the robot's left) or ``R``.
    invalid_linkage_result : bool
        A linkage that cannot be assembled is an invalid result with its reason, not an error.
    explain : bool
        Why the robot does what it does (``result.explanation``, :mod:`locust.sim.explain`).
    """

    cycles: int | None = None
    leg_set: str | None = None
    samples: int = 0
    seed: int = 0
    sensitivity: bool | None = None
    keep_states: bool = True
    check_convergence: bool = False
    video: Path | None = None
    camera: str = "track"
    still: Path | None = None
    still_push: Path | None = None
    board: str | None = None
    push_clip: Path | None = None
    push_clip_held: Path | None = None
    push_fps: int = 240
    side: str = "L"
    invalid_linkage_result: bool = False
    explain: bool = False


def prepared(robot: Robot, options: SimOptions):
    """The robot simulated (with ``options.leg_set`` on it), the outputs' paths checked, and
    the stills' board read: refused before anything is simulated.

    Parameters
    ----------
    robot : Robot
        The robot as given.
    options : SimOptions
        The settings.

    Returns
    -------
    robot : Robot
        The robot to simulate.
    board : locust.arucoboard.BoardSpec or None
        The stills' board (None without stills).

    Raises
    ------
    ParamsError
        The robot with the leg set is out of range.
    SimError
        A video or still path that cannot be written.
    TrackError
        A board that cannot be read.
    """
    if options.leg_set is not None:
        if options.leg_set != robot.leg_set:
            robot = leg_set(robot, options.leg_set, source=f"leg-set:{options.leg_set}").renamed(
                f"{robot.name} ({options.leg_set} legs)")
        robot = check_robot(robot)
    videos = [p for p in (options.video, options.push_clip, options.push_clip_held) if p is not None]
    if videos:
        from .clip import check_video_path

        for path in videos:
            check_video_path(path)
    if options.still is None and options.still_push is None:
        return robot, None
    from ..arucoboard import DEFAULT_BOARD, parse_board
    from .still import check_still_path

    for path in (options.still, options.still_push):
        if path is not None:
            check_still_path(path)
    return robot, parse_board(options.board or DEFAULT_BOARD)


def simulated(robot: Robot, options: SimOptions, progress: Callable[[int], None] | None = None) -> SimResult:
    """The audited run, its standing load, its draws and which values decide its outcome.

    Parameters
    ----------
    robot : Robot
        The robot.
    options : SimOptions
        ``cycles``, ``samples``, ``seed``, ``sensitivity``, ``keep_states`` (and ``video``,
        which keeps the states).
    progress : callable, optional
        ``progress(0)`` as the run begins, then ``progress(k)`` as each ``k`` runs are done (the
        run, each batch of draws and sensitivity ends, the explanation's: :func:`planned_runs`).

    Returns
    -------
    SimResult
        With its robot (``robot``).

    Raises
    ------
    GeometryError
        The linkage cannot be assembled.
    ParamsError
        A value out of range for simulating.
    """
    cycles = options.cycles
    if options.samples:
        from .samples import check_draws

        check_draws(robot, options.samples, cycles)   # before the robot's own run
    if progress:
        progress(0)
    # the video and the explanation reuse the rollout
    keep = options.keep_states or options.video is not None or options.explain
    result = dataclasses.replace(_run.run(robot, cycles=cycles, keep_states=keep), robot=robot)
    if progress:
        progress(1)
    if result.valid:
        from .statics import standing_load

        load = standing_load(robot)
        result.nose_load_kg, result.total_mass_kg = load.nose_load_kg, load.total_mass_kg
    _draws_and_ends(robot, result, options, progress)
    if options.explain and result.valid:
        result.explanation = explained(robot, result, cycles, progress)
        if not options.keep_states and options.video is None:
            result.trajectory = None
    return result


def planned_runs(robot: Robot, options: SimOptions) -> tuple[int, str]:
    """The runs :func:`simulated` reports to its ``progress``, at most, and what they are
    (a progress bar's length and label): the run itself, the draws, the sensitivity's ends
    (asked for, or with the draws: run only when they split, else counted done), the
    explanation's runs, and the run and its draws again at dt/2 (``check_convergence``).

    Parameters
    ----------
    robot : Robot
    options : SimOptions

    Returns
    -------
    runs : int
    label : str
    """
    from .sensitivity import end_robots

    parts, runs = ["the run"], 1
    if options.samples:
        parts.append(f"{options.samples} draws")
        runs += options.samples
    if options.sensitivity or (options.sensitivity is None and options.samples):
        ends = len(end_robots(robot))
        parts.append(f"{ends} sensitivity ends" + (" (if the draws split)" if options.sensitivity is None else ""))
        runs += ends
    if options.explain:
        from .explain import explain_runs

        parts.append(f"explaining ({explain_runs(robot)} runs at most)")
        runs += explain_runs(robot)
    if options.check_convergence:
        parts.append("the run" + (f" and its {options.samples} draws" if options.samples else "") + " at dt/2")
        runs += 1 + options.samples
    return runs, " + ".join(parts)


def _draws_and_ends(robot: Robot, result: SimResult, options: SimOptions,
                    progress: Callable[[int], None] | None) -> None:
    """The draws (``result.spread``) and the sensitivity (``result.sensitivity``) of a valid
    run: asked for together, their runs go in one batched pass; the sensitivity asked for
    only where the draws split runs after them (or is counted done, where they do not)."""
    from .figures import run_figures
    from .samples import draw, spread_of
    from .sensitivity import end_robots, sensitivity_of

    if not result.valid:
        return
    n, cycles = options.samples, options.cycles
    ends = end_robots(robot) if options.sensitivity or (options.sensitivity is None and n) else []
    together = ends if options.sensitivity else []
    figures = run_figures((draw(robot, n, options.seed) if n else []) + together, cycles, progress)
    if n:
        result.spread = spread_of(robot, n, options.seed, figures[:n])
    mixed = result.spread is not None and max(o.share for o in result.spread.outcomes.values()) < 1.0
    if together:
        result.sensitivity = sensitivity_of(robot, result.outcome, figures[n:])
    elif ends and mixed:
        result.sensitivity = sensitivity_of(robot, result.outcome, run_figures(ends, cycles, progress))
    elif ends and progress:
        progress(len(ends))      # the draws agree: no sensitivity to run


def explained(robot: Robot, result: SimResult, cycles: int | None, progress: Callable[[int], None] | None):
    """The explanation of ``result`` (:func:`locust.sim.explain.explain`, on its own rollout).

    Parameters
    ----------
    robot : Robot
        The robot simulated.
    result : SimResult
        Its valid run, its rollout kept.
    cycles : int or None
        Hop cycles.
    progress : callable, optional
        ``progress(k)`` as each batch of ``k`` runs is done.

    Returns
    -------
    locust.sim.explain.Explanation
    """
    from .explain import explain
    from .figures import RunFigures

    figures = RunFigures(outcome=result.outcome or "", nose_rise_m=result.hops[0].nose_apex_m if result.hops else 0.0,
                         distance_m=result.distance_m)
    return explain(robot, cycles, progress, trajectory=result.trajectory, figures=figures)


def rendered(result: SimResult, robot: Robot, options: SimOptions, board) -> None:
    """Render the video, the stills and the push clips asked for, each noted in ``result.notes``.

    Parameters
    ----------
    result : SimResult
        The run (its rollout kept when a video is asked for).
    robot : Robot
        The robot simulated.
    options : SimOptions
        ``video``, ``camera``, ``still``, ``still_push``, ``push_clip``, ``push_clip_held``, ``push_fps``,
        ``side``.
    board : locust.arucoboard.BoardSpec or None
        The stills' board.

    Raises
    ------
    SimError
        The run is invalid, or a render fails.
    """
    if options.video is not None:
        if not result.valid:
            raise SimError("not rendering an invalid simulation", "fix the reasons listed above first")
        info = result.video(options.video, camera=options.camera)
        result.notes.append(f"video: {info.video_path} ({info.frames} frames); truth: {info.truth_path}")
    if options.still is not None or options.still_push is not None:
        from .still import render_stills

        if not result.valid:
            raise SimError("not rendering stills of an invalid robot", "fix the reasons listed above first")
        for still in render_stills(robot, options.still, options.still_push, board=board, side=options.side):
            result.notes.append(f"still: {still.path} ({still.pose.kind}, crank {still.pose.crank_deg:.2f} deg from "
                                f"the ground link); truth: {still.truth_path}")
    if options.push_clip is not None or options.push_clip_held is not None:
        from .pushclip import render_push_clips

        if not result.valid:
            raise SimError("not rendering push clips of an invalid robot", "fix the reasons listed above first")
        for clip in render_push_clips(robot, options.push_clip, options.push_clip_held, side=options.side,
                                      fps=options.push_fps):
            result.notes.append(f"push clip: {clip.clip.video_path} ({clip.kind}, {clip.clip.frames} frames); crank "
                                f"truth: {clip.crank_path}")


def run_simulation(robot: Robot, options: SimOptions, progress: Callable[[int], None] | None = None) -> SimResult:
    """Simulate ``robot`` as ``options`` say: checks, the audited run and its draws, the
    convergence check, the video and the stills.

    Parameters
    ----------
    robot : Robot
        The robot (:func:`locust.robot`).
    options : SimOptions
        The settings.
    progress : callable, optional
        ``progress(0)`` as the run begins, then ``progress(k)`` as each ``k`` runs are done (the
        run, each batch of draws and sensitivity ends, the explanation's: :func:`planned_runs`).

    Returns
    -------
    SimResult
        The result with its robot, spread, sensitivity and convergence as asked, and a note for
        each file rendered.

    Raises
    ------
    GeometryError
        The linkage cannot be assembled (unless ``options.invalid_linkage_result``).
    ParamsError
        A value out of range for simulating.
    SimError
        A path that cannot be written, or a render asked of an invalid run.
    """
    robot, board = prepared(robot, options)
    try:
        result = simulated(robot, options, progress)
    except GeometryError as exc:
        if not options.invalid_linkage_result:
            raise
        reason = exc.message + (f" ({exc.hint})" if exc.hint else "")
        result = dataclasses.replace(_run.invalid_result(robot, reason, options.cycles), robot=robot)
    if options.check_convergence and result.valid:
        result.convergence = _run.check_convergence(robot, result, cycles=options.cycles)
        if progress:
            progress(1)
        if result.spread is not None:   # the draws' shares and percentiles at dt/2 (sim/ensemble.py)
            from .ensemble import ensemble_convergence

            result.ensemble_convergence = ensemble_convergence(robot, result.spread, options.cycles, progress)
    rendered(result, robot, options, board)
    return result


__all__ = ["SimOptions", "planned_runs", "prepared", "rendered", "run_simulation", "simulated"]
