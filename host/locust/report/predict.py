"""What the simulation predicts for one configuration: the audited result and the tracked
marker's trace.

The result is :func:`locust.sim.run.run`'s, unchanged: the predicted distances are the
pipeline's own. The camera follows a marker (the ``marker_<name>`` disc the model carries
where the sticker goes, e.g. on the chassis' side, up and back from the nose edge), not the
model's ``nose`` site, and a point on a pitching body rises by its own amount: so the
predicted trace and apexes are those of the same marker, from the very rollout the result
comes from (``run(..., keep_states=True)``, thinned to ``sim.kinematics.TRACE_HZ``; the marker is posed by
:func:`locust.sim.kinematics.marker_positions`), measured with the same functions as the
track. A run that fails its audit is kept as invalid, with its reasons, and has no trace.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..errors import GeometryError, ReportError
from ..params import Robot
from ..trials.measure import Aligned, MeasuredHop, measure_hops, onset_time


@dataclass
class Prediction:
    """What the simulation predicts for one configuration.

    Attributes
    ----------
    config : str
        The configuration.
    robot : Robot
        The robot simulated.
    result : SimResult
        The audited result of :func:`locust.sim.run.run`.
    trace : Aligned or None
        The marker on the schedule's clock [s, m]; None when invalid.
    hops : list of MeasuredHop
        The marker's hops, measured like a track's (empty when invalid).
    onset_latency_s : float
        First marker motion after the first push [s] (nan when invalid).
    trajectory : Trajectory or None
        The rollout with every step's state: only with ``predict(..., keep_states=True)`` and a
        valid run.
    """

    config: str
    robot: Robot
    result: object                 # locust.sim.result.SimResult
    trace: Aligned | None          # the marker on the schedule's clock; None when invalid
    hops: list[MeasuredHop]        # the marker's hops, measured like a track's (empty when invalid)
    onset_latency_s: float         # first marker motion after the first push (nan when invalid)
    # the rollout itself, every step's state: only with predict(..., keep_states=True) and a valid run
    trajectory: object | None = field(default=None, repr=False)

    @property
    def valid(self) -> bool:
        """Whether the simulation passed its audit."""
        return bool(self.result.valid)


def predict(config: str, robot: Robot, cycles: int, marker: str = "nose", keep_states: bool = False) -> Prediction:
    """Simulate ``robot`` and take its marker's trace and hops as a track's are taken.

    Parameters
    ----------
    config : str
        The configuration's name.
    robot : Robot
        Its robot.
    cycles : int
        Cycles to simulate.
    marker : str
        The model's ``marker_<marker>`` disc to follow.
    keep_states : bool
        Keep the rollout (``Prediction.trajectory``) for a video of it (:mod:`.sidebyside`);
        otherwise its states go once the trace is taken.

    Returns
    -------
    Prediction
        Invalid, with the audit's reasons, when the simulation fails its audit or the geometry
        cannot be built.

    Raises
    ------
    ReportError
        The model carries no such marker.
    """
    from ..sim.run import invalid_result, run

    try:
        result = run(robot, cycles=cycles, keep_states=True)
    except GeometryError as exc:
        reason = exc.message + (f" ({exc.hint})" if exc.hint else "")
        return Prediction(config, robot, invalid_result(robot, reason, cycles), None, [], math.nan)
    traj, result.trajectory = result.trajectory, None   # the states are not kept past the trace
    if not result.valid:
        return Prediction(config, robot, result, None, [], math.nan)
    trace = marker_trace(traj, marker)
    onset, _, _ = onset_time(trace.t_s, trace.x_m, trace.y_m, where=f"simulated {config}")
    period = robot.schedule.push_s + robot.schedule.wait_s
    return Prediction(config, robot, result, trace, measure_hops(trace, period, cycles), onset,
                      traj if keep_states else None)


def marker_trace(traj, marker: str) -> Aligned:
    """The ``marker_<marker>`` disc's centre, t = 0 at the first push, from where it stood
    at the end of the settle phase; x forward, y up.

    Parameters
    ----------
    traj : Trajectory
        A rollout that kept its states.
    marker : str
        The marker's name (``nose``, ``foot``).

    Returns
    -------
    Aligned
        ``t_s`` [s] and ``x_m``, ``y_m`` [m], thinned to ``sim.kinematics.TRACE_HZ``.

    Raises
    ------
    ReportError
        The model carries no such marker.
    """
    from ..sim.kinematics import carries_marker, marker_positions, trace_rows

    if not carries_marker(traj, marker):
        raise ReportError(f"the model carries no {marker!r} marker to compare the track with",
                          "track a marker the model has: nose or foot (--marker)")
    dt, settle = traj.timestep_s, traj.plan.settle_steps
    rows, stand = trace_rows(dt, settle, len(traj.states))
    pos = marker_positions(traj, marker, rows)
    x0, z0 = pos[rows == stand][0, [0, 2]]
    return Aligned(t_s=(rows + 1 - settle) * dt, x_m=pos[:, 0] - x0, y_m=pos[:, 2] - z0,
                   onset_s=math.nan, start_s=0.0)
