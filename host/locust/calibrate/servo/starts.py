"""Where the servo fit's solver starts: the no-load speed and each recording's timing read off
the data alone, and a grid of candidates around them simulated in one batch."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np

from .layout import LOWER, MAX_CLOCK_ERROR, MAX_DELAY_S, Layout, clock_name, delay_name, gain_name
from .recording import MIN_EDGES_FOR_CLOCK, Recording

STARTS = 2                # solver runs from the best points of the grid (distinct armatures)
NOLOAD_FACTORS = (1.0, 1.5, 2.5)             # times the fastest speed seen: a load slows the servo
TIME_CONSTANTS_S = (0.002, 0.01, 0.03)       # mechanical time constant (J+Ja)/b
LINEAR_RANGES_DEG = (3.0, 10.0, 25.0)        # stall/kp
KV_SHARES = (0.01, 0.3, 1.0)                 # kv against the back-EMF's stall/noload, when fitted
DELAY_FRAMES = (-1.0, -0.5, 0.0, 0.5)        # the delay guessed, moved by these frames


def speed_guess(rec: Recording) -> float:
    """No-load speed from the data: a high percentile of the angular speed between samples.

    Parameters
    ----------
    rec : Recording
        An angle or rate recording (checked).

    Returns
    -------
    float
        The speed [rad/s].
    """
    if rec.kind == "rate":
        speed = np.abs(rec.rate_units) / rec.gain_guess()
    else:
        speed = np.abs(np.diff(np.radians(rec.angle_deg)) / np.diff(rec.t_s))
    moving = speed[speed > 0.2 * speed.max()]
    return float(np.percentile(moving, 75)) if moving.size else float(speed.max())


def timing_guess(rec: Recording, noload: float) -> tuple[float, float]:
    """(delay, clock ratio) from the data. An angle recording: from when the horn passes the
    middle of each step, a straight line through (edge time, crossing time); at top speed the
    middle comes half a step late. A rate recording (one clock): when the speed first reaches
    a fifth of its peak after each edge, less a sample.

    Parameters
    ----------
    rec : Recording
        An angle or rate recording (checked).
    noload : float
        The servo's no-load speed [rad/s] taken for it.

    Returns
    -------
    delay_s : float
        Within +-``MAX_DELAY_S``.
    clock_ratio : float
        1 unless the recording has ``MIN_EDGES_FOR_CLOCK`` edges or more.
    """
    if rec.kind == "rate":
        return _rate_delay_guess(rec), 1.0
    edge_t, cross_t = _crossings(rec, noload)
    if not edge_t:
        return 0.0, 1.0
    edge_t, cross_t = np.array(edge_t), np.array(cross_t)
    t0 = rec.mean_edge_s
    ratio = 1.0
    if len(edge_t) >= MIN_EDGES_FOR_CLOCK:
        slope = np.polyfit(edge_t - t0, cross_t - t0, 1)[0]
        ratio = float(np.clip(slope, 1 - MAX_CLOCK_ERROR, 1 + MAX_CLOCK_ERROR))
    delay = float(np.median(cross_t - t0 - (edge_t - t0) * ratio))
    return float(np.clip(delay, -MAX_DELAY_S, MAX_DELAY_S)), ratio


def _rate_delay_guess(rec: Recording) -> float:
    """A rate recording's delay: when the speed first reaches a fifth of its peak after each
    edge (their median), less a sample."""
    t = rec.t_s
    lags = []
    for e, _, end in rec.windows():
        speed = np.abs(rec.rate_units[e:end])
        if speed.size and speed.max() > 0:
            lags.append(t[e + int(np.argmax(speed >= 0.2 * speed.max()))] - t[e])
    step_s = float(np.median(np.diff(t)))
    return float(np.clip(np.median(lags) - step_s if lags else 0.0, -MAX_DELAY_S, MAX_DELAY_S))


def _crossings(rec: Recording, noload: float) -> tuple[list[float], list[float]]:
    """An angle recording's edge times and, for each step the horn crosses the middle of, when
    it would have crossed at the edge's time at top speed."""
    t, u, q = rec.t_s, rec.command_deg, rec.angle_deg
    edge_t, cross_t = [], []
    for i, end in itertools.pairwise([*rec.edges, len(t)]):
        start = q[i - 1]
        mid = 0.5 * (start + u[i])
        side = np.sign(q[i - 1:end] - mid)
        flips = np.flatnonzero(side != side[0])
        if not len(flips):
            continue
        k = i - 1 + int(flips[0])
        frac = (mid - q[k - 1]) / (q[k] - q[k - 1]) if q[k] != q[k - 1] else 0.0
        edge_t.append(t[i])
        cross_t.append(t[k - 1] + frac * (t[k] - t[k - 1]) - math.radians(abs(u[i] - start)) / 2 / noload)
    return edge_t, cross_t


def grid_starts(recs: list[Recording], layout: Layout, residual: Callable[[np.ndarray], np.ndarray],
                bounds: tuple[np.ndarray, np.ndarray]) -> list[np.ndarray]:
    """Starting points: a grid of no-load speed (at and above the fastest speed seen: a load
    slows the servo), armature, linear range (stall/kp), kv and delay, simulated in one batch;
    the best few with distinct speed and armature.

    Parameters
    ----------
    recs : list of Recording
        The recordings (checked).
    layout : Layout
        The fit's table.
    residual : callable
        The residual of candidate vectors as columns (``fit.Residual``).
    bounds : tuple of numpy.ndarray
        The solver's bounds.

    Returns
    -------
    list of numpy.ndarray
        Up to ``STARTS`` solver vectors, the best first.
    """
    stall = layout.stall_given or 0.15
    seen_speed = max(speed_guess(rec) for rec in recs) * 1.02
    frame_s = [float(np.median(np.diff(rec.t_s))) for rec in recs]
    j = recs[0].rig.inertia_kgm2
    kv_shares = KV_SHARES if "servo.kv_nms_per_rad" in layout.fitted else (None,)
    timings = {}
    cands = []
    for factor, tau_s, linear_deg, kv_share, delay_frames in itertools.product(
            NOLOAD_FACTORS, TIME_CONSTANTS_S, LINEAR_RANGES_DEG, kv_shares, DELAY_FRAMES):
        noload = factor * seen_speed
        if factor not in timings:
            timings[factor] = [timing_guess(rec, noload) for rec in recs]
        values = {"servo.noload_speed_rad_per_s": noload,
                  "servo.armature_kgm2": max(tau_s * stall / noload - j, LOWER["servo.armature_kgm2"] * 10),
                  "servo.kp_nm_per_rad": stall / math.radians(linear_deg), "servo.stall_torque_nm": stall,
                  "servo.kv_nms_per_rad": (kv_share or 0.0) * stall / noload}
        for k, rec in enumerate(recs):
            delay_s, ratio = timings[factor][k]
            lag = tau_s if rec.kind == "angle" else 0.0
            values[delay_name(k)] = delay_s - lag + delay_frames * frame_s[k]
            values[clock_name(k)] = ratio - 1.0      # used where the clock is fitted
            if rec.kind == "rate":
                values[gain_name(k)] = rec.gain_sign * rec.gain_guess()
        cands.append(layout.params.as_vector(values))
    lo, hi = bounds
    xs = np.clip(np.array(cands), lo + 1e-6, hi - 1e-6)
    cost = np.sum(residual(xs.T) ** 2, axis=0)
    return _distinct_best(xs, cost)


def _distinct_best(xs: np.ndarray, cost: np.ndarray) -> list[np.ndarray]:
    """The ``STARTS`` cheapest candidates, no two alike in their first two variables (no-load
    speed and armature)."""
    picked, seen = [], set()
    for i in np.argsort(cost):
        key = (round(xs[i, 0], 3), round(xs[i, 1], 3))
        if key not in seen:
            seen.add(key)
            picked.append(xs[i])
        if len(picked) == STARTS:
            break
    return picked
