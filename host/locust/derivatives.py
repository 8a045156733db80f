"""Velocity and acceleration of a sampled position: Tracker's finite differences, in one place.

Tracker (Open Source Physics; its point mass's default "finite difference" algorithm,
``PointMass`` with ``FirstDerivative`` at a spill of 1 step and ``SecondDerivative`` at a
spill of 2) gives a point's velocity at step ``i`` as the central difference over its two
neighbour steps, and its acceleration as the second derivative of the least-squares parabola
through the five steps ``i-2 .. i+2``::

    v[i] = (x[i+1] - x[i-1]) / (2 dt)
    a[i] = (2 x[i-2] - x[i-1] - 2 x[i] - x[i+1] + 2 x[i+2]) / (7 dt^2)

``dt`` being the clip's step (its frame interval times its step size). A value is given only
where every step it reads is marked, its own included: the velocity needs ``i-1, i, i+1``,
the acceleration all five; elsewhere Tracker leaves the cell blank, here it is NaN (the
clip's first and last steps, and next to a frame where the marker was lost).

A step here is a row of the track (a tracked frame; ``--step`` frames apart when the clip
was tracked every ``--step``), and ``dt`` is taken from the rows' own times: the velocity
over ``t[i+1] - t[i-1]``, the acceleration from the parabola of least squares through the
five samples at their times. On a steady clip (Tracker's only kind: a constant frame
interval) these are the two formulas above to rounding; on a clip whose frames came at
uneven times (a phone's variable rate, the report's simulated trace with its standing row)
each sample keeps its own time rather than a mean step.

Every table locust writes or hands out with a velocity or an acceleration takes it from
here: the tracks CSV's columns (:mod:`locust.io.tracks_csv`), the API's ``Tracks`` frames
and the report's take-off speed (:mod:`locust.trials.measure`).
"""

from __future__ import annotations

import numpy as np


def velocity(t_s: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Tracker's velocity: the central difference over each sample's two neighbours.

    Parameters
    ----------
    t_s : array_like
        Sample times [s], increasing.
    x : array_like
        One coordinate [its unit]; NaN where not measured.

    Returns
    -------
    numpy.ndarray
        ``dx/dt`` [the unit per s]; NaN at both ends, where a neighbour or the sample itself
        is NaN, or where the neighbours' times do not increase.
    """
    t, x = np.asarray(t_s, dtype=float), np.asarray(x, dtype=float)
    out = np.full(len(x), np.nan)
    if len(x) < 3:
        return out
    span = t[2:] - t[:-2]
    seen = np.isfinite(x[2:]) & np.isfinite(x[1:-1]) & np.isfinite(x[:-2]) & (span > 0)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):   # (a value beyond any track's: inf)
        out[1:-1] = np.where(seen, (x[2:] - x[:-2]) / span, np.nan)
    return out


def acceleration(t_s: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Tracker's acceleration: twice the quadratic coefficient of the least-squares parabola
    through each sample and its two neighbours on either side.

    Parameters
    ----------
    t_s : array_like
        Sample times [s], increasing.
    x : array_like
        One coordinate [its unit]; NaN where not measured.

    Returns
    -------
    numpy.ndarray
        ``d2x/dt2`` [the unit per s^2]; NaN within two samples of either end, where any of
        the five samples is NaN, or where their times do not increase.
    """
    t, x = np.asarray(t_s, dtype=float), np.asarray(x, dtype=float)
    n = len(x)
    out = np.full(n, np.nan)
    if n < 5:
        return out
    window = np.arange(2, n - 2)[:, None] + np.arange(-2, 3)
    tw, xw = t[window], x[window]
    seen = (np.isfinite(tw).all(axis=1) & np.isfinite(xw).all(axis=1)
            & (np.diff(tw, axis=1) > 0).all(axis=1))
    if not seen.any():
        return out
    tw, xw = tw[seen], xw[seen]
    with np.errstate(invalid="ignore", over="ignore"):          # (a value beyond any track's: inf or nan)
        step = (tw[:, 4] - tw[:, 0]) / 4.0                       # the window's mean step: u is about -2..2
        u = (tw - tw[:, 2:3]) / step[:, None]
        y = xw - xw[:, 2:3]                                      # about the middle sample: no cancellation
        basis = np.stack([np.ones_like(u), u, u * u], axis=-1)   # (m, 5, 3): p + q u + c u^2
        normal = np.einsum("mki,mkj->mij", basis, basis)
        rhs = np.einsum("mki,mk->mi", basis, y)
        coef = np.linalg.solve(normal, rhs[..., None])[..., 0]
        out[2:n - 2][seen] = 2.0 * coef[:, 2] / step**2
    return out


__all__ = ["acceleration", "velocity"]
