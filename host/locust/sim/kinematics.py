"""Where points on the model are at kept states: forward kinematics over a rollout.

A rollout made with its states kept (``simulate(..., keep_states=True)`` or
``run(..., keep_states=True).trajectory``) holds every step's full physics state; posing a
private ``MjData`` from a state row (``mj_kinematics``: positions only, no dynamics) gives
where any geom was at that step.
"""

from __future__ import annotations

import mujoco
import numpy as np

from ..errors import SimError
from .rollout import Trajectory

TRACE_HZ = 240.0   # marker samples a trace keeps per second, at least (a phone films at up to 240)
TRACE_LEAD_S = 0.3  # standing time a trace keeps before the schedule starts


def trace_rows(timestep_s: float, settle_steps: int, nstep: int) -> tuple[np.ndarray, int]:
    """State rows a marker trace is taken at, and the standing row among them.

    Every ``stride``-th row from ``TRACE_LEAD_S`` before the end of the settle phase to the
    last, the stride the largest that keeps at least ``TRACE_HZ`` samples a second, plus the
    last row of the settle phase (where the robot stood). The trace's times are
    ``(rows + 1 - settle_steps) * timestep_s``: row i is the state after step i + 1.

    Parameters
    ----------
    timestep_s : float
        The physics step [s].
    settle_steps : int
        Steps in the settle phase.
    nstep : int
        Steps in the rollout.

    Returns
    -------
    rows : ndarray
        The state rows, ascending.
    stand : int
        The standing row.
    """
    stride = max(1, int(1.0 / (TRACE_HZ * timestep_s)))
    stand = max(settle_steps - 1, 0)
    first = max(0, settle_steps - int(round(TRACE_LEAD_S / timestep_s)))
    return np.unique(np.concatenate(([stand], np.arange(first, nstep, stride)))), stand


def _marker_geom(model: mujoco.MjModel, marker: str) -> int:
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"marker_{marker}")


def carries_marker(traj: Trajectory, marker: str) -> bool:
    """Whether the trajectory's model carries the ``marker_<marker>`` disc.

    Parameters
    ----------
    traj : Trajectory
        The rollout.
    marker : str
        The marker's name (``nose``, ``foot``).

    Returns
    -------
    bool
        True when the model has the geom.
    """
    return _marker_geom(traj.built.model, marker) >= 0


def marker_positions(traj: Trajectory, marker: str, rows: np.ndarray) -> np.ndarray:
    """World position (N, 3), metres, of the ``marker_<marker>`` geom's centre at state rows ``rows``.

    Row i is the state after physics step i + 1 (as in ``traj.states``).

    Parameters
    ----------
    traj : Trajectory
        A rollout that kept its states.
    marker : str
        The marker's name.
    rows : ndarray
        State rows.

    Returns
    -------
    ndarray
        (len(rows), 3) positions [m].

    Raises
    ------
    SimError
        The trajectory kept no states, or the model has no such marker.
    """
    if traj.states is None:
        raise SimError("the trajectory kept no states to pose the model from",
                       "simulate with keep_states=True")
    model = traj.built.model
    gid = _marker_geom(model, marker)
    if gid < 0:
        raise SimError(f"the model carries no {marker!r} marker", "use a marker the model has: nose or foot")
    return geom_positions(model, traj.states, [gid], rows)[:, 0]


def marker_geoms(model: mujoco.MjModel, markers) -> list[int]:
    """Geom ids of the ``marker_<name>`` discs (-1 where the model has none).

    Parameters
    ----------
    model : mujoco.MjModel
        The model.
    markers : iterable of str
        Marker names.

    Returns
    -------
    list of int
        One geom id per marker.
    """
    return [_marker_geom(model, m) for m in markers]


def geom_positions(model: mujoco.MjModel, states: np.ndarray, geoms, rows: np.ndarray) -> np.ndarray:
    """World positions (len(rows), len(geoms), 3), metres, of geom centres at FULLPHYSICS state rows.

    Parameters
    ----------
    model : mujoco.MjModel
        The model.
    states : ndarray
        FULLPHYSICS states, one row per step.
    geoms : iterable of int
        Geom ids.
    rows : ndarray
        State rows.

    Returns
    -------
    ndarray
        (len(rows), len(geoms), 3) positions [m].
    """
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    geoms = list(geoms)
    pos = np.empty((len(rows), len(geoms), 3))
    for i, r in enumerate(rows):
        mujoco.mj_setState(model, data, states[r], spec)
        mujoco.mj_kinematics(model, data)
        pos[i] = data.geom_xpos[geoms]
    return pos


__all__ = ["carries_marker", "geom_positions", "marker_geoms", "marker_positions"]
