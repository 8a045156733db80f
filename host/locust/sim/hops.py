"""Per-hop figures from a simulated trajectory.

One hop per schedule cycle (push + wait). Heights are apexes above the standing height: the
robot's pose at the end of the settle phase (or, with no settle phase, at the end of the run,
when it stands still after the last wait).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .rollout import Trajectory


@dataclass(frozen=True)
class Hop:
    """One schedule cycle's figures from a simulated run.

    Attributes
    ----------
    cycle : int
        The cycle, from 1.
    distance_m : float
        Chassis x travelled during the cycle [m].
    nose_apex_m : float
        Highest nose point above standing nose height [m].
    com_apex_m : float
        Highest centre of mass above its standing height [m].
    flight_s : float
        Longest time with no part of the robot on the floor [s].
    end_turn_deg : float
        Plate pitch at the cycle's end less its standing pitch, nose up positive [deg].
    """

    cycle: int
    distance_m: float            # chassis x travelled during the cycle
    nose_apex_m: float           # highest nose point above standing nose height
    com_apex_m: float            # highest centre of mass above standing height
    flight_s: float              # longest time with no part of the robot on the floor
    end_turn_deg: float = 0.0    # plate pitch at the cycle's end less its standing pitch (nose up +)


@dataclass(frozen=True)
class HopSummary:
    """The whole run's figures and its hops.

    Attributes
    ----------
    hops : list of Hop
        One per cycle.
    distance_m : float
        Chassis x from the start of the schedule to the end of the run [m].
    max_nose_height_m : float
        Highest nose point during the run, above the floor [m] (the notebook's metric).
    standing_nose_m, standing_com_m : float
        Nose and centre-of-mass height standing, at the end of the settle phase [m].
    end_nose_rise_m : float
        Nose height at the end of the run above its standing height [m].
    end_turn_deg : float
        Plate pitch at the end of the run less its standing pitch, nose up positive [deg].
    """

    hops: list[Hop]
    distance_m: float            # chassis x, start of the schedule -> end of the run
    max_nose_height_m: float     # highest nose point during the run (the notebook's metric)
    standing_nose_m: float
    standing_com_m: float
    end_nose_rise_m: float       # nose height at the end of the run above its standing height
    end_turn_deg: float = 0.0    # plate pitch at the end of the run less its standing pitch (nose up +)


def _longest_run(mask: np.ndarray) -> int:
    if not mask.any():
        return 0
    padded = np.concatenate(([0], mask.astype(np.int8), [0]))
    edges = np.flatnonzero(np.diff(padded))
    return int((edges[1::2] - edges[::2]).max())


def plate_pitch_deg(nose_xyz: np.ndarray, chassis_xyz: np.ndarray) -> np.ndarray:
    """The plate's pitch in the legs' plane at each row: the angle of the line from the
    plate's centre to its nose above the floor, nose up positive, unwrapped over the rows so
    that a robot turning over past the vertical keeps counting (deg).

    Parameters
    ----------
    nose_xyz, chassis_xyz : ndarray
        (N, 3) nose and plate-centre positions [m].

    Returns
    -------
    ndarray
        (N,) pitch [deg].
    """
    d = np.asarray(nose_xyz) - np.asarray(chassis_xyz)
    return np.degrees(np.unwrap(np.arctan2(d[:, 2], d[:, 0])))


def summarise(traj: Trajectory) -> HopSummary:
    """Cut a rollout into its schedule's cycles and measure each hop.

    Parameters
    ----------
    traj : Trajectory
        The rollout, with its sensor data and control plan.

    Returns
    -------
    HopSummary
        The run's figures and one :class:`Hop` per cycle.
    """
    s, sd, plan = traj.built.sensors, traj.sensordata, traj.plan
    nose_z = sd[:, s.nose_pos][:, 2]
    com_z = sd[:, s.com_pos][:, 2]
    x = sd[:, s.chassis_pos][:, 0]
    airborne = sd[:, s.floor_contact][:, 0] < 0.5
    stand = plan.settle_steps - 1 if plan.settle_steps > 0 else len(x) - 1
    standing_nose, standing_com = float(nose_z[stand]), float(com_z[stand])
    turn = plate_pitch_deg(sd[:, s.nose_pos], sd[:, s.chassis_pos])
    turn = turn - turn[stand]
    x_start = (float(x[plan.settle_steps - 1]) if plan.settle_steps > 0
               else float(traj.initial_sensordata[s.chassis_pos][0]))

    hops = []
    starts = plan.cycle_start_steps
    for c in range(len(starts) - 1):
        a, b = int(starts[c]), int(starts[c + 1])
        x_a = float(x[a - 1]) if a > 0 else x_start
        hops.append(Hop(
            cycle=c + 1,
            distance_m=float(x[b - 1] - x_a),
            nose_apex_m=float(nose_z[a:b].max() - standing_nose),
            com_apex_m=float(com_z[a:b].max() - standing_com),
            flight_s=_longest_run(airborne[a:b]) * traj.timestep_s,
            end_turn_deg=float(turn[b - 1]),
        ))
    run_nose = nose_z[plan.settle_steps:]
    if plan.settle_steps == 0:  # the notebook counts the drop too
        run_nose = np.concatenate(([traj.initial_sensordata[s.nose_pos][2]], nose_z))
    return HopSummary(hops=hops, distance_m=float(x[-1] - x_start), max_nose_height_m=float(run_nose.max()),
                      standing_nose_m=standing_nose, standing_com_m=standing_com,
                      end_nose_rise_m=float(nose_z[-1] - standing_nose), end_turn_deg=float(turn[-1]))
