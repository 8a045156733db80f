"""Hops measured from a nose track: where the schedule started, and each hop's figures.

The camera's clock and the firmware's are not the same, so the schedule's start is found in
the track itself: the nose's first departure of more than ``ONSET_M`` from its first frame
(interpolated between frames); where it stood is the median of the frames before that. The
simulation's nose trace goes through the same detector, and the measured start is put where
the simulated one is relative to its first push, so the two are lined up by the same rule,
never by fitting one to the other.

Per hop (schedule cycle ``k`` of period ``T``: ``[start + (k-1)T, start + kT)``):

- distance: nose x at rest at the end of the cycle minus at its start (median of the
  samples in the last ``REST_WINDOW_S`` of each cycle; the robot stands still by then, so
  nose and chassis travel agree);
- apex: highest nose point in the cycle above the standing nose height (median before the
  first push), the definition :mod:`locust.sim.hops` uses;
- rest height: nose y at rest at the end of the cycle above where it stood (the same median
  window as the distance): near zero on a robot back on its feet, high on one lying on its back;
- take-off speed: the nose's highest speed from the cycle's start to its apex, the speed it
  leaves the floor with (it gains speed while the legs push and loses it in flight), by
  Tracker's finite difference (:mod:`locust.derivatives`, what a student reads off Tracker's
  ``v`` column); none beside a lost frame (the trace holds the frames found only: a step more
  than half again the usual is a frame lost there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..derivatives import velocity
from ..errors import TrialError

ONSET_M = 0.003          # nose motion that counts as the first push (camera noise is ~0.5 mm)
REST_WINDOW_S = 0.2      # end of a cycle averaged as the rest position
MIN_STANDING_SAMPLES = 2   # frames before the first motion: the standing pose
LOST_STEP = 1.5          # a step this many times the usual one has a lost frame in it


@dataclass(frozen=True)
class Aligned:
    """A nose trace on the schedule's clock: t = 0 at the first push, from where it stood."""

    t_s: np.ndarray
    x_m: np.ndarray          # forward travel since standing
    y_m: np.ndarray          # height above standing
    onset_s: float           # first motion, on the trace's own clock
    start_s: float           # schedule start, on the trace's own clock


@dataclass(frozen=True)
class MeasuredHop:
    """One hop of a filmed trial, measured on the nose's track.

    Attributes
    ----------
    hop : int
        The hop's number, from 1.
    distance_m : float
        How far forward the nose's rest moved over that cycle [m]; NaN when the track does not
        cover it.
    apex_m : float
        The nose's highest point in that cycle above where it stood [m]; NaN when not covered.
    rest_height_m : float
        The nose at rest at the end of that cycle above where it stood [m]; NaN when not covered.
    takeoff_speed_m_per_s : float
        The nose's highest speed from the cycle's start to its apex [m/s]; NaN when not covered.
    """

    hop: int
    distance_m: float        # nan when the track does not cover the cycle
    apex_m: float
    rest_height_m: float = math.nan
    takeoff_speed_m_per_s: float = math.nan


def onset_time(t_s: np.ndarray, x_m: np.ndarray, y_m: np.ndarray, threshold_m: float = ONSET_M,
               where: str = "track") -> tuple[float, float, float]:
    """(time the nose first moved ``threshold_m`` from where it stood, standing x, standing y).

    Parameters
    ----------
    t_s, x_m, y_m : numpy.ndarray
        The nose's track: time [s], forward and up [m].
    threshold_m : float
        The move that counts as motion [m].
    where : str
        The track's name, for messages.

    Returns
    -------
    onset_s : float
        When the nose first moved (interpolated between frames) [s].
    x0_m, y0_m : float
        Where it stood [m].

    Raises
    ------
    locust.errors.TrialError
        The nose never moves that far, or is already moving when the clip starts.
    """
    dist = np.hypot(x_m - x_m[0], y_m - y_m[0])
    moved = np.flatnonzero(dist > threshold_m)
    if moved.size == 0:
        raise TrialError(f"{where}: the nose never moves more than {threshold_m * 1000:g} mm",
                          "is this a hop? check the clip covers the hops and the scale is in metres")
    i = int(moved[0])
    if i < MIN_STANDING_SAMPLES:
        raise TrialError(f"{where}: the nose is already moving at t = {t_s[i]:.3f} s, the clip's start",
                          "the report needs the robot standing still before the first push: start the clip earlier")
    x0, y0 = float(np.median(x_m[:i])), float(np.median(y_m[:i]))
    d_prev, d_now = float(np.hypot(x_m[i - 1] - x0, y_m[i - 1] - y0)), float(np.hypot(x_m[i] - x0, y_m[i] - y0))
    frac = 0.0 if d_now <= d_prev else min(max((threshold_m - d_prev) / (d_now - d_prev), 0.0), 1.0)
    return float(t_s[i - 1] + frac * (t_s[i] - t_s[i - 1])), x0, y0


def align(t_s: np.ndarray, x_m: np.ndarray, y_m: np.ndarray, onset_latency_s: float,
          where: str = "track") -> Aligned:
    """Put a trace on the schedule's clock, its start ``onset_latency_s`` before its first motion.

    Parameters
    ----------
    t_s, x_m, y_m : numpy.ndarray
        The nose's track: time [s], forward and up [m].
    onset_latency_s : float
        The delay from the schedule's start to the nose's first motion [s] (the model's).
    where : str
        The track's name, for messages.

    Returns
    -------
    Aligned
        The trace from where the nose stood [m], on the schedule's clock [s].

    Raises
    ------
    locust.errors.TrialError
        No onset found (see :func:`onset_time`).
    """
    onset, x0, y0 = onset_time(t_s, x_m, y_m, where=where)
    start = onset - onset_latency_s
    return Aligned(t_s=t_s - start, x_m=x_m - x0, y_m=y_m - y0, onset_s=onset, start_s=start)


def measure_hops(trace: Aligned, period_s: float, cycles: int) -> list[MeasuredHop]:
    """Distance and apex of each of ``cycles`` hops of an aligned trace.

    Parameters
    ----------
    trace : Aligned
        A trace on the schedule's clock.
    period_s : float
        One cycle, push and wait [s].
    cycles : int
        Cycles hopped.

    Returns
    -------
    list of MeasuredHop
    """
    t, x, y = trace.t_s, trace.x_m, trace.y_m
    speed = nose_speed(t, x, y)
    t_end = float(t[-1])
    rest, rest_y = [0.0], [0.0]  # standing, by construction of the aligned trace
    for k in range(1, cycles + 1):
        b = k * period_s
        sel = (t > b - REST_WINDOW_S) & (t <= b)
        seen = sel.any() and t_end >= b - REST_WINDOW_S / 2
        rest.append(float(np.median(x[sel])) if seen else math.nan)
        rest_y.append(float(np.median(y[sel])) if seen else math.nan)
    hops = []
    for k in range(1, cycles + 1):
        a, b = (k - 1) * period_s, k * period_s
        inside = (t >= a) & (t < b)
        covered = inside.any() and t_end >= b - REST_WINDOW_S / 2
        apex = float(y[inside].max()) if covered else math.nan
        takeoff = math.nan
        if covered:
            rising = np.flatnonzero(inside)[:int(np.argmax(y[inside])) + 1]    # the cycle's start to its apex
            seen = speed[rising][np.isfinite(speed[rising])]
            takeoff = float(seen.max()) if seen.size else math.nan
        hops.append(MeasuredHop(hop=k, distance_m=rest[k] - rest[k - 1], apex_m=apex, rest_height_m=rest_y[k],
                                takeoff_speed_m_per_s=takeoff))
    return hops


def nose_speed(t_s: np.ndarray, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """The nose's speed at each sample by Tracker's central difference, NaN beside a lost frame.

    Parameters
    ----------
    t_s, x_m, y_m : numpy.ndarray
        A trace of the frames found: time [s], forward and up [m].

    Returns
    -------
    numpy.ndarray
        [m/s]; NaN at the ends and where the step before or after a sample is more than
        :data:`LOST_STEP` times the usual (a frame lost there, as Tracker leaves it blank).
    """
    speed = np.hypot(velocity(t_s, x_m), velocity(t_s, y_m))
    if len(t_s) > 2:
        step = np.diff(t_s)
        gap = step > LOST_STEP * float(np.median(step))
        speed[np.r_[False, gap] | np.r_[gap, False]] = np.nan
    return speed
