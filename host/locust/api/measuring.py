"""``locust.measure_stroke``: the stroke the servo delivers, from side clips of a push, beside the model's."""

from __future__ import annotations

import os
from pathlib import Path

from ..measure.stroke import StrokeResult
from ..measure.strokejob import StrokeOptions, stroke_job
from ..params import Robot

SIDES = {"left": "L", "right": "R", None: None}


def measure_stroke(robot: Robot, floor: str | os.PathLike | None = None, held: str | os.PathLike | None = None, *,
                   side: str | None = None, fps: float | None = None, csv: str | os.PathLike | None = None,
                   plot: str | os.PathLike | None = None, force: bool = False, draws: int = 200,
                   seed: int = 0) -> StrokeResult:
    """The crank's swing in a push filmed on the floor and held up, beside the model's robot
    making the same push (``locust measure stroke``, every option of it).

    Parameters
    ----------
    robot : Robot
        The robot filmed (its ground angle and push), and the model compared with
        (:func:`locust.robot`).
    floor : path-like, optional
        A side clip of the push on the floor.
    held : path-like, optional
        A side clip of the push with the robot held up by its plate.
    side : {"left", "right"}, optional
        The side the clips must show (None: whichever they show).
    fps : float, optional
        The clips' true frame rate [1/s] (a slow-motion file often says 30).
    csv : path-like, optional
        Write the crank's angle over time, clip and model, a row per frame.
    plot : path-like, optional
        Draw the swing against the model's.
    force : bool, default False
        Replace an existing CSV or plot.
    draws : int, default 200
        Bootstrap draws for the intervals.
    seed : int, default 0
        The bootstrap's seed.

    Returns
    -------
    locust.measure.stroke.StrokeResult
        ``.readings`` (one per clip: ``.estimates``, each figure's value and 95 % interval;
        ``.model``, the model's swing; ``.differences()``), ``.reading("floor")``,
        ``.to_json()``.

    Raises
    ------
    locust.errors.MeasureError
        No clip, a clip without the stickers or too short for the push, a bad side, or an
        output that exists.
    """
    from ..errors import MeasureError

    if side not in SIDES:
        raise MeasureError(f"side {side!r} is not known", "give side='left' or side='right'")
    clips = [c for c in (floor, held) if c is not None]
    if not clips:
        raise MeasureError("no clip given", "give floor=CLIP and/or held=CLIP")
    options = StrokeOptions(held_only=floor is None, side=SIDES[side], fps=fps,
                            csv=None if csv is None else Path(csv), plot=None if plot is None else Path(plot),
                            force=force, draws=draws, seed=seed)
    return stroke_job(robot, clips, options).result


__all__ = ["measure_stroke"]
