"""The stroke the servo delivers: ``locust measure stroke FLOOR.mp4 [HELD.mp4]``.

A side clip of the push on the floor (the hop's first push, the robot standing) and one of
the same push with the robot held up by its plate (the legs swinging free), each with the
stickers of ``locust measure stance`` on the side filmed. From each clip the crank's angle
from its ground link over time (:mod:`.crankclip`), and from it the push's swing
(:mod:`.swing`): the rest angle, the extreme, the stroke between them, and the swing's peak
and mean speed, each with a 95 % interval. The model's robot makes the same push on the floor
and held up (:mod:`locust.sim.push`), its crank read from the same four points by the same
rule, so that each figure is printed beside the model's with the difference.

The model's figures come with no interval: they are the robot file's values run once. What
the clips measure is the stroke and the speeds themselves; no robot value is fitted to them.
Each figure is set by the servo's stall torque, no-load speed, gearbox inertia and holding
gain together; the whole curves would pin them only through the model of the legs, folds and
floor around the servo, which the clips cannot check apart from it (``locust calibrate
servo`` fits the servo on a bench rig of known load).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..calibrate.fitstats import Estimate
from ..errors import MeasureError
from ..params import Robot
from ..track.pipeline import Bars, no_bars
from .crankclip import CrankSeries, crank_angle_deg, read_crank_clip
from .swing import FIGURES, Swing, read_swing, swing_intervals

KINDS = ("floor", "held")
KIND_WORDS = {"floor": "on the floor", "held": "held up"}
BOOTSTRAP_DRAWS = 200


@dataclass(frozen=True)
class PushReading:
    """One clip's swing, and the model's for the same push.

    Attributes
    ----------
    kind : str
        ``floor`` or ``held``.
    series : CrankSeries
        The crank's angle over the clip.
    swing : Swing
        The clip's swing, read as it is.
    estimates : dict of str to Estimate or None
        Per figure of :data:`locust.measure.swing.FIGURES`, its value and 95 % interval.
    model : Swing
        The model's swing for the same push.
    model_t_s : ndarray
        The model's times from its push command [s].
    model_angle_deg : ndarray
        The model's crank angle from its ground link, read from its points [deg].
    """

    kind: str
    series: CrankSeries
    swing: Swing
    estimates: dict[str, Estimate | None]
    model: Swing
    model_t_s: np.ndarray
    model_angle_deg: np.ndarray

    def model_at_frames_deg(self) -> np.ndarray:
        """The model's crank angle at the clip's frame times, the two onsets aligned [deg].

        Returns
        -------
        ndarray
            One per frame [deg].
        """
        t = self.series.t_s - self.swing.onset_s + self.model.onset_s
        out = np.interp(t, self.model_t_s, self.model_angle_deg)
        return np.where((t >= self.model_t_s[0]) & (t <= self.model_t_s[-1]), out, np.nan)

    def differences(self) -> dict[str, float | None]:
        """Per figure, the clip's less the model's (None where either has none).

        Returns
        -------
        dict of str to float or None
            [deg] and [deg/s].
        """
        model = self.model.figures()
        return {k: None if e is None or model[k] is None else e.value - model[k] for k, e in self.estimates.items()}


@dataclass(frozen=True)
class StrokeResult:
    """What the clips say about the push, beside the model's.

    Attributes
    ----------
    robot_name : str
        The robot compared with.
    push_deg : float
        The push command [deg].
    readings : tuple of PushReading
        One per clip, in the order given.
    draws : int
        Bootstrap draws of each interval.
    """

    robot_name: str
    push_deg: float
    readings: tuple[PushReading, ...]
    draws: int

    def reading(self, kind: str) -> PushReading | None:
        """The reading of ``kind`` (``floor`` or ``held``), or None.

        Parameters
        ----------
        kind : str

        Returns
        -------
        PushReading or None
        """
        return next((r for r in self.readings if r.kind == kind), None)

    def to_json(self) -> dict:
        """The result as ``--json`` prints it (angles in deg, speeds in deg/s).

        Returns
        -------
        dict
        """
        out = {"robot": self.robot_name, "push_command_deg": self.push_deg,
               "interval_method": f"parametric bootstrap of the stickers' scatter, {self.draws} draws, with the "
                                  "extreme's sampling between frames", "clips": {}}
        for r in self.readings:
            s = r.series
            out["clips"][r.kind] = {
                "clip": str(s.path), "side": {"L": "left", "R": "right"}[s.side], "frames": s.frames, "fps": s.fps,
                "sticker_sd_px": s.sticker_sd_px, "angle_sd_deg": float(np.nanmedian(s.sd_deg)),
                "rest_frames": r.swing.rest_frames, "onset_s": r.swing.onset_s, "extreme_s": r.swing.extreme_s,
                "measured": {k: None if e is None else e.as_dict() for k, e in r.estimates.items()},
                "model": r.model.figures(), "difference": r.differences(),
                "direction_as_model": r.swing.direction == r.model.direction}
        return out


def model_push(robot: Robot, kind: str, side: str) -> tuple[np.ndarray, np.ndarray]:
    """The model's crank angle over its push, read from its four points as a clip's is.

    Parameters
    ----------
    robot : Robot
        The robot.
    kind : str
        ``floor`` or ``held``.
    side : str
        ``L`` or ``R``.

    Returns
    -------
    t_s : ndarray
        From the push command [s].
    angle_deg : ndarray
        The crank from its ground link [deg].
    """
    from ..sim.push import simulate_push

    run = simulate_push(robot, kind, side)
    # the picture of a camera on that side: x to the right (world -x from +y, +x from -y), y down
    toward = 1.0 if side == "L" else -1.0
    px = {n: -toward * p[:, 0] for n, p in run.points_m.items()}
    py = {n: -p[:, 2] for n, p in run.points_m.items()}
    return run.t_s, crank_angle_deg(px, py, side, robot.geometry.ground_angle_deg)


def _read(robot: Robot, kind: str, path: Path, side: str | None, fps: float | None, draws: int, seed: int,
          bars: Bars) -> PushReading:
    series = read_crank_clip(path, robot.geometry.ground_angle_deg, side=side, fps=fps, bars=bars)
    swing, estimates = swing_intervals(series.t_s, series.angle_deg, series.sd_deg, draws=draws, seed=seed,
                                       where=path.name)
    t, angle = model_push(robot, kind, series.side)
    model = read_swing(t, angle, 0.0, where=f"the model's {KIND_WORDS[kind]} push")
    return PushReading(kind, series, swing, estimates, model, t, angle)


def measure_stroke(robot: Robot, clips: Sequence[str | Path], kinds: Sequence[str] = KINDS, side: str | None = None,
                   fps: float | None = None, draws: int = BOOTSTRAP_DRAWS, seed: int = 0,
                   bars: Bars = no_bars) -> StrokeResult:
    """Read the push's swing from each clip and the model's from the same push.

    Parameters
    ----------
    robot : Robot
        The robot filmed (its ground angle and push; the model compared with).
    clips : sequence of path
        One or two side clips.
    kinds : sequence of str
        What each clip shows, in order: ``floor`` or ``held`` (default: the floor's first).
    side : str, optional
        ``L`` or ``R``: the side the clips must show (None: whichever they show).
    fps : float, optional
        The clips' true frame rate [1/s] (a slow-motion clip's file may say 30).
    draws : int
        Bootstrap draws for the intervals.
    seed : int
        The bootstrap's seed.
    bars : callable
        Progress over each clip's frames (:data:`locust.track.pipeline.Bars`).

    Returns
    -------
    StrokeResult

    Raises
    ------
    MeasureError
        No clip, an unknown kind, a clip without the stickers or too short for the push.
    """
    if not 1 <= len(clips) <= len(KINDS):
        raise MeasureError(f"{len(clips)} clips given", "give the floor clip, and the held one after it")
    kinds = tuple(kinds)[:len(clips)]
    if len(kinds) < len(clips) or any(k not in KINDS for k in kinds) or len(set(kinds)) < len(kinds):
        raise MeasureError(f"clip kinds {', '.join(kinds)}: each clip is one of {', '.join(KINDS)}, once",
                           "give the floor clip first, the held one second")
    readings = tuple(_read(robot, kind, Path(path), side, fps, draws, seed + k, bars)
                     for k, (kind, path) in enumerate(zip(kinds, clips)))
    return StrokeResult(robot.name, robot.schedule.push_deg, readings, draws)


__all__ = ["BOOTSTRAP_DRAWS", "FIGURES", "KINDS", "PushReading", "StrokeResult", "measure_stroke", "model_push"]
