"""What a hinge swing shows before any fit: the pivot from the circle through the marker's arc,
the angle about it, the free swing's window after the release, and start values from the
swing's own shape (the period from its crossings of rest, the decay from its successive peaks,
never a spectral peak, which can lock onto the record's length).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ..errors import CalibrationError
from .hingeswing import HingeRig

MIN_HALF_SWINGS = 3              # zero crossings needed for a period


def circle_fit(x_m: np.ndarray, y_m: np.ndarray) -> tuple[float, float, float]:
    """The circle nearest the points: the algebraic (Kasa) fit, refined by Levenberg-Marquardt
    on the geometric distances.

    Parameters
    ----------
    x_m, y_m : array_like
        The points [m].

    Returns
    -------
    tuple of float
        Centre x, centre y and radius [m].
    """
    x, y = np.asarray(x_m, float), np.asarray(y_m, float)
    a = np.column_stack([x, y, np.ones_like(x)])
    sol, *_ = np.linalg.lstsq(a, x**2 + y**2, rcond=None)
    cx, cy = sol[0] / 2, sol[1] / 2
    r = math.sqrt(max(sol[2] + cx**2 + cy**2, 0.0))
    res = optimize.least_squares(lambda p: np.hypot(x - p[0], y - p[1]) - p[2], [cx, cy, r], method="lm")
    cx, cy, r = res.x
    return float(cx), float(cy), float(abs(r))


def swing_angle(x_m: np.ndarray, y_m: np.ndarray, pivot: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The marker's angle about the pivot and its distance from it.

    Parameters
    ----------
    x_m, y_m : array_like
        The marker's track [m].
    pivot : tuple of float
        The pivot (x, y) [m].

    Returns
    -------
    tuple of numpy.ndarray
        The angle [rad] (unwrapped, from +x, counter-clockwise) and the distance [m].
    """
    dx, dy = np.asarray(x_m) - pivot[0], np.asarray(y_m) - pivot[1]
    return np.unwrap(np.arctan2(dy, dx)), np.hypot(dx, dy)



@dataclass(frozen=True)
class SwingShape:
    """What the swing shows before any fit: rest angle, damped period, decay rate, amplitude.

    Attributes
    ----------
    rest_rad : float
        The final rest angle (median of the last fifth).
    damped_omega_rad_per_s : float
        Damped angular frequency, from the median spacing of the rest crossings.
    decay_per_s : float
        Exponential decay rate of the peaks (0 with fewer than two clear peaks).
    amplitude_rad : float
        Largest excursion from rest.
    crossings : int
        Crossings of the rest angle.
    """

    rest_rad: float
    damped_omega_rad_per_s: float
    decay_per_s: float
    amplitude_rad: float
    crossings: int


def swing_shape(t_s: np.ndarray, theta: np.ndarray, source: str) -> SwingShape:
    """The swing's shape from its crossings of the final rest angle and the peaks between them.

    Parameters
    ----------
    t_s : array_like
        Sample times [s].
    theta : numpy.ndarray
        The link's angle [rad].
    source : str
        The recording's name, for the message.

    Returns
    -------
    SwingShape

    Raises
    ------
    CalibrationError
        Fewer than ``MIN_HALF_SWINGS`` crossings.
    """
    rest = float(np.median(theta[len(theta) * 4 // 5:]))
    u = theta - rest
    noise = angle_noise_rad(theta)
    amp = float(np.max(np.abs(u)))
    band = max(3 * noise, 0.02 * amp)                             # hysteresis: noise at rest is no crossing
    crossings, peaks, side, last = [], [], 0, 0
    for i, v in enumerate(u):
        s = 1 if v > band else -1 if v < -band else 0
        if s == 0:
            continue
        if side and s != side:
            j = max(k for k in range(last, i) if np.sign(u[k]) == side)   # the last sample on the old side
            tc = t_s[j] + (t_s[j + 1] - t_s[j]) * u[j] / (u[j] - u[j + 1]) if u[j] != u[j + 1] else t_s[j]
            crossings.append(float(tc))
            seg = np.abs(u[last:i])
            peaks.append((float(t_s[last + int(np.argmax(seg))]), float(seg.max())))
        if s != side:
            last = i
        side = s
    if len(crossings) < MIN_HALF_SWINGS:
        raise CalibrationError(f"{source}: the link crosses its rest angle {len(crossings)} times in the fit window "
                               f"(need {MIN_HALF_SWINGS})",
                               "film until the swing has died out, or widen --start-s/--end-s; "
                               "see calibration/protocols/hinge.md")
    half = float(np.median(np.diff(crossings)))
    wd = math.pi / half
    decay = 0.0
    big = [(tp, a) for tp, a in peaks if a > 3 * band]
    if len(big) >= 2:
        slope = np.polyfit([p[0] for p in big], np.log([p[1] for p in big]), 1)[0]
        decay = max(-float(slope), 0.0)
    return SwingShape(rest, wd, decay, amp, len(crossings))


def start_values(t_s: np.ndarray, theta: np.ndarray, rig: HingeRig, shape: SwingShape) -> np.ndarray:
    """Start values of the fit from the linearised swing about its rest.

    Parameters
    ----------
    t_s : array_like
        Sample times of the fit window [s].
    theta : numpy.ndarray
        The angle there [rad].
    rig : HingeRig
        The link.
    shape : SwingShape
        The swing's shape (:func:`swing_shape`).

    Returns
    -------
    numpy.ndarray, shape (5,)
        k [N*m/rad], b [N*m*s/rad], theta0 [rad], the first angle [rad] and rate [rad/s].
    """
    wn = math.hypot(shape.damped_omega_rad_per_s, shape.decay_per_s)
    stiff_total = rig.inertia_kgm2 * wn**2
    mgd = rig.gravity_moment_nm
    k0 = stiff_total + mgd * math.sin(shape.rest_rad)
    k0 = max(k0, 0.05 * stiff_total)
    b0 = max(2 * shape.decay_per_s * rig.inertia_kgm2, 1e-3 * 2 * rig.inertia_kgm2 * wn)
    th0 = shape.rest_rad + mgd * math.cos(shape.rest_rad) / k0
    n = min(5, len(t_s))
    rate = float(np.polyfit(t_s[:n] - t_s[0], theta[:n], 2)[1]) if n >= 3 else 0.0
    return np.array([k0, b0, th0, float(theta[0]), rate])


def angle_noise_rad(theta: np.ndarray) -> float:
    """The angle's tracking noise: from its second differences where the link is quietest (the
    first or the last fifth of the record: held before the release, or at rest after it).

    Parameters
    ----------
    theta : numpy.ndarray
        The angle [rad], evenly sampled.

    Returns
    -------
    float
        Standard deviation of one angle sample [rad] (the second difference's over sqrt(6)).
    """
    fifth = max(len(theta) // 5, 4)
    parts = [np.diff(theta[:fifth], 2), np.diff(theta[-fifth:], 2)]
    return min(float(np.std(p)) for p in parts if len(p)) / math.sqrt(6)


def release_window(t_s: np.ndarray, theta: np.ndarray, start_s: float | None, end_s: float | None) -> np.ndarray:
    """Samples to fit: the free swing from the first turning point after the release (or from
    ``start_s``) to ``end_s``.

    The release is the last moment the link is held at its largest excursion from the final
    rest in the first half of the record: the last sample, before the link has swung a tenth
    of the way back, within three noise deviations of the level it was held at. A hand lets
    go over a few hundredths of a second, which is no free swing: the fit starts at the far
    end of that first swing, where the link turns (a drop's impact is skipped alike in
    :mod:`.beam`).

    Parameters
    ----------
    t_s : numpy.ndarray
        Sample times [s].
    theta : numpy.ndarray
        The angle [rad].
    start_s, end_s : float or None
        The window's ends [s] (None: found as above, and the record's end).

    Returns
    -------
    numpy.ndarray of bool
        Which samples are in the window.
    """
    end = t_s[-1] if end_s is None else end_s
    if start_s is None:
        rest = np.median(theta[len(theta) * 4 // 5:])
        signed = theta - rest
        u = np.abs(signed)
        noise = angle_noise_rad(theta)
        i = int(np.argmax(u[:max(len(u) // 2, 1)]))
        leaving = np.nonzero(u[i:] < u[i] - max(0.1 * u[i], 6 * noise))[0]
        j = i + (int(leaving[0]) if len(leaving) else len(u) - i)
        level = float(np.median(u[i:j]))
        release = i + int(np.nonzero(u[i:j] >= level - 3 * noise)[0][-1])
        start_s = t_s[_first_turn(signed, release, max(3 * noise, 0.02 * u[i]))]
    return (t_s >= start_s) & (t_s <= end)


def _first_turn(u: np.ndarray, release: int, band: float) -> int:
    """The far extreme of the first swing after ``release`` (``release`` itself without one)."""
    side = np.sign(u[release])
    over = np.nonzero(u[release:] * -side > band)[0]
    if not len(over):
        return release
    c1 = release + int(over[0])
    back = np.nonzero(u[c1:] * side > band)[0]
    if not len(back):
        return release
    c2 = c1 + int(back[0])
    return c1 + int(np.argmax(np.abs(u[c1:c2])))
