"""The crank's swing in one push, read from its angle over time.

One rule for a filmed clip and for the model's own push (:mod:`locust.sim.push`), so that the
two are compared figure by figure:

- **rest**: the median angle over the frames before the crank leaves rest (the onset: the
  first frame more than :data:`ONSET_MIN_DEG`, or five of the angle's standard deviations,
  from the median of the first frames), those within :data:`GUARD_S` of the onset left out;
- **direction**: the way the largest excursion from rest turns (+1: the crank angle grows);
- **extreme**: the push's farthest angle from rest before the crank comes back (the first
  frame after which it has come back by half its excursion ends the push), the top of a
  quadratic fitted to the frames within :data:`TOP_BAND_DEG` (or four standard deviations)
  of the farthest frame, so that it may lie between frames;
- **stroke**: extreme less rest, in the push's direction [deg];
- **mean speed**: the swing from 10 % to 90 % of the stroke (:data:`SWING_LEVELS`) over the
  time it took, each crossing interpolated between frames [deg/s];
- **peak speed**: the largest slope of a cubic fitted to the frames within a quarter of that
  time of the steepest central difference [deg/s] (a cubic's slope is a parabola, the top of
  a speed's hump);

both none with fewer than :data:`MIN_SWING_FRAMES` frames between the crossings (film at
120 frames/s or more for them).

Intervals (:func:`swing_intervals`): a parametric bootstrap of the angle's noise (each frame
moved by its standard deviation, the frames at rest by one shared draw besides: a still
scene's error is one draw, not averaged away), the 2.5 and 97.5 percentiles about the value;
and, in quadrature, the extreme's sampling error between frames (how far the quadratic top
lies from the farthest frame), taken as uniform over that distance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..calibrate.fitstats import Estimate
from ..errors import MeasureError

ONSET_MIN_DEG = 1.0        # the crank has left rest this far from it (or 5 sd)
ONSET_SD = 5.0
FIRST_FRAMES = 5           # the provisional rest: the median of these
MIN_REST_FRAMES = 5        # frames at rest before the onset, at least
GUARD_S = 0.01             # frames this close before the onset are not rest
MIN_STROKE_DEG = 3.0       # a smaller excursion is no push
TOP_BAND_DEG = 0.5         # frames this near the farthest one shape the extreme's quadratic (or 4 sd)
TOP_SD = 4.0
SWING_LEVELS = (0.1, 0.9)
MIN_SWING_FRAMES = 4       # frames between the swing's 10 % and 90 % for its speeds (a cubic's four)
FIGURES = ("rest_deg", "extreme_deg", "stroke_deg", "peak_speed_deg_per_s", "mean_speed_deg_per_s")


@dataclass(frozen=True)
class Swing:
    """One push's swing read from an angle series (:func:`read_swing`).

    Attributes
    ----------
    direction : int
        +1 when the push turned the crank angle up, -1 down.
    rest_deg, extreme_deg : float
        The crank at rest and at the push's extreme [deg].
    stroke_deg : float
        ``direction * (extreme - rest)`` [deg].
    peak_speed_deg_per_s, mean_speed_deg_per_s : float or None
        The swing's largest and mean speed toward the extreme [deg/s]; None with fewer than
        :data:`MIN_SWING_FRAMES` frames in the swing.
    onset_s, extreme_s : float
        When the crank left rest and reached its extreme [s].
    swing_s : tuple of float or None
        When it passed 10 % and 90 % of the stroke [s].
    rest_frames : int
        Frames the rest was taken over.
    frame_s : float
        The median frame interval [s].
    sampling : dict of str to float
        Per figure, how far sampling between frames may move it (its own unit).
    """

    direction: int
    rest_deg: float
    extreme_deg: float
    stroke_deg: float
    peak_speed_deg_per_s: float | None
    mean_speed_deg_per_s: float | None
    onset_s: float
    extreme_s: float
    swing_s: tuple[float, float] | None
    rest_frames: int
    frame_s: float
    sampling: dict[str, float]

    def figures(self) -> dict[str, float | None]:
        """The figures by name (:data:`FIGURES`).

        Returns
        -------
        dict of str to float or None
            [deg] and [deg/s].
        """
        return {name: getattr(self, name) for name in FIGURES}


def _too_short(what: str, where: str) -> MeasureError:
    return MeasureError(f"{where}: {what}",
                        "film from a second before the push to half a second after it, the crank at rest at the "
                        "start (docs/hardware.md, \"Measure the stroke\")")


def _onset(t: np.ndarray, th: np.ndarray, sd: float, where: str) -> tuple[int, float, int]:
    """The onset's index, the rest angle and the push's direction."""
    start = float(np.median(th[:FIRST_FRAMES]))
    dev = th - start
    big = int(np.argmax(np.abs(dev)))
    if abs(dev[big]) < MIN_STROKE_DEG:
        raise MeasureError(f"{where}: the crank never turns more than {abs(dev[big]):.1f} deg from where it starts "
                           f"(a push turns it at least {MIN_STROKE_DEG:g} deg)",
                           "film the push itself: start the camera, then send the push (`locust hop` or "
                           "`locust pose -30 -30`)")
    direction = 1 if dev[big] > 0 else -1
    threshold = max(ONSET_MIN_DEG, ONSET_SD * sd)
    onset = int(np.argmax(direction * dev > threshold))
    rest = t < t[onset] - GUARD_S
    if rest.sum() < MIN_REST_FRAMES:
        raise _too_short(f"only {int(rest.sum())} frames at rest before the crank moves (at least "
                         f"{MIN_REST_FRAMES})", where)
    return onset, float(np.median(th[rest])), direction


def _push_end(u: np.ndarray, onset: int) -> int:
    """The first index after which the crank has come back by half its excursion (or the end)."""
    top = np.maximum.accumulate(np.where(np.arange(len(u)) >= onset, u, -np.inf))
    back = np.nonzero((np.arange(len(u)) > onset) & (top >= MIN_STROKE_DEG) & (u < top / 2))[0]
    return int(back[0]) if len(back) else len(u)


def _top(t: np.ndarray, u: np.ndarray, k: int, lo: int, hi: int, band: float) -> tuple[float, float]:
    """The quadratic top near frame ``k`` (frames lo..hi-1 allowed): its time and value."""
    a, b = k, k
    while a - 1 >= lo and u[a - 1] >= u[k] - band:
        a -= 1
    while b + 1 < hi and u[b + 1] >= u[k] - band:
        b += 1
    a, b = min(a, max(lo, k - 1)), max(b, min(hi - 1, k + 1))
    if b - a < 2:
        return float(t[k]), float(u[k])
    x = t[a:b + 1] - t[k]
    c2, c1, c0 = np.polyfit(x, u[a:b + 1], 2)
    if c2 >= 0:
        return float(t[k]), float(u[k])
    x_top = float(np.clip(-c1 / (2 * c2), x[0], x[-1]))
    return float(t[k] + x_top), float(c0 + c1 * x_top + c2 * x_top ** 2)


def _crossings(t: np.ndarray, u: np.ndarray, onset: int, k: int, stroke: float) -> tuple[float, float] | None:
    """When the swing first passes each of :data:`SWING_LEVELS` of the stroke, interpolated
    between frames; None with fewer than :data:`MIN_SWING_FRAMES` frames between them."""
    out = []
    for level in SWING_LEVELS:
        i = onset + int(np.argmax(u[onset:k + 1] >= level * stroke))
        if i == 0 or u[i - 1] >= level * stroke:
            return None
        out.append(float(t[i - 1] + (level * stroke - u[i - 1]) * (t[i] - t[i - 1]) / (u[i] - u[i - 1])))
    if np.sum((t > out[0]) & (t < out[1])) < MIN_SWING_FRAMES:
        return None
    return out[0], out[1]


def _peak_speed(t: np.ndarray, u: np.ndarray, cross: tuple[float, float]) -> float:
    """The largest slope of a cubic fitted to the frames within a quarter of the swing's time
    of its steepest central difference (four frames at least)."""
    j = np.nonzero((t > cross[0]) & (t < cross[1]))[0]
    j = j[(j > 0) & (j < len(t) - 1)]
    steep = j[int(np.argmax((u[j + 1] - u[j - 1]) / (t[j + 1] - t[j - 1])))]
    quarter = (cross[1] - cross[0]) / 4
    near = np.nonzero(np.abs(t - t[steep]) <= quarter)[0]
    if len(near) < MIN_SWING_FRAMES:
        near = np.argsort(np.abs(t - t[steep]))[:MIN_SWING_FRAMES]
    t0 = float(t[steep])
    cubic = np.polynomial.Polynomial.fit(t[near] - t0, u[near], 3).convert()
    xs = np.linspace(float(t[near].min()) - t0, float(t[near].max()) - t0, 201)
    return float(np.max(cubic.deriv()(xs)))


def read_swing(t_s: np.ndarray, angle_deg: np.ndarray, sd_deg: float = 0.0, where: str = "the clip") -> Swing:
    """The swing of the first push in an angle series (the rule is the module's).

    Parameters
    ----------
    t_s : ndarray
        Each sample's time [s], increasing.
    angle_deg : ndarray
        The crank's angle from its ground link at each [deg]; nan where not seen.
    sd_deg : float
        The angle's standard deviation, one sample [deg] (0: exact, a simulation's).
    where : str
        What the series is of, for messages.

    Returns
    -------
    Swing

    Raises
    ------
    MeasureError
        Too few samples at rest, no push, or a series that ends before the push's extreme.
    """
    ok = np.isfinite(angle_deg)
    t, th = np.asarray(t_s, float)[ok], np.asarray(angle_deg, float)[ok]
    if len(t) < MIN_REST_FRAMES + 3:
        raise _too_short(f"the crank is seen on only {len(t)} frames", where)
    onset, rest, direction = _onset(t, th, sd_deg, where)
    u = direction * (th - rest)
    end = _push_end(u, onset)
    k = onset + int(np.argmax(u[onset:end]))
    if k >= len(u) - 1:
        raise _too_short("it ends before the crank reaches the push's extreme", where)
    band = max(TOP_BAND_DEG, TOP_SD * sd_deg)
    t_top, top = _top(t, u, k, onset, end, band)
    cross = _crossings(t, u, onset, k, top)
    speeds = None if cross is None else (_peak_speed(t, u, cross),
                                         (SWING_LEVELS[1] - SWING_LEVELS[0]) * top / (cross[1] - cross[0]), cross)
    return Swing(direction=direction, rest_deg=rest, extreme_deg=rest + direction * top, stroke_deg=top,
                 peak_speed_deg_per_s=None if speeds is None else speeds[0],
                 mean_speed_deg_per_s=None if speeds is None else speeds[1],
                 onset_s=float(t[onset]), extreme_s=t_top, swing_s=None if speeds is None else speeds[2],
                 rest_frames=int(np.sum(t < t[onset] - GUARD_S)), frame_s=float(np.median(np.diff(t))),
                 sampling={"rest_deg": 0.0, "extreme_deg": top - float(u[k]), "stroke_deg": top - float(u[k]),
                           "peak_speed_deg_per_s": 0.0, "mean_speed_deg_per_s": 0.0})


def swing_intervals(t_s: np.ndarray, angle_deg: np.ndarray, sd_deg: np.ndarray | float, draws: int = 200,
                    seed: int = 0, where: str = "the clip") -> tuple[Swing, dict[str, Estimate | None]]:
    """The swing (:func:`read_swing`) and each figure's estimate with its 95 % interval.

    Parameters
    ----------
    t_s : ndarray
        Each frame's time [s].
    angle_deg : ndarray
        The crank's angle at each [deg]; nan where not seen.
    sd_deg : ndarray or float
        The angle's standard deviation per frame, or one for all [deg].
    draws : int
        Bootstrap draws.
    seed : int
        The bootstrap's seed.
    where : str
        What the series is of, for messages.

    Returns
    -------
    swing : Swing
        The figures read from the series as it is.
    estimates : dict of str to Estimate or None
        Per figure of :data:`FIGURES`, its value, standard deviation and 95 % interval (None
        where the swing has no such figure).

    Raises
    ------
    MeasureError
        As :func:`read_swing`.
    """
    angle = np.asarray(angle_deg, float)
    sd = np.broadcast_to(np.asarray(sd_deg, float), angle.shape)
    typical = float(np.nanmedian(sd))
    swing = read_swing(t_s, angle, typical, where)
    rng = np.random.default_rng(seed)
    at_rest = np.asarray(t_s) < swing.onset_s - GUARD_S
    rows = []
    for _ in range(draws):
        noisy = angle + rng.normal(0.0, 1.0, angle.shape) * sd + at_rest * rng.normal(0.0, typical)
        try:
            rows.append(read_swing(t_s, noisy, typical, where).figures())
        except MeasureError:
            continue
    estimates: dict[str, Estimate | None] = {}
    for name, value in swing.figures().items():
        got = [r[name] for r in rows if r[name] is not None]
        if value is None or len(got) < max(10, draws // 2):
            estimates[name] = None
            continue
        estimates[name] = _estimate(value, np.array(got), swing.sampling[name])
    return swing, estimates


def _estimate(value: float, draws: np.ndarray, sampling: float) -> Estimate:
    """The bootstrap's percentile interval about ``value``, widened in quadrature by a
    sampling error uniform over ``sampling`` (its sd ``sampling / sqrt(3)``)."""
    lo, hi = np.percentile(draws, [2.5, 97.5])
    shift = value - float(np.median(draws))
    lo, hi = lo + shift, hi + shift
    extra = sampling / math.sqrt(3.0)
    half_lo = math.hypot(value - lo, 1.96 * extra)
    half_hi = math.hypot(hi - value, 1.96 * extra)
    sd = math.hypot(float(np.std(draws, ddof=1)), extra)
    return Estimate(float(value), sd, value - half_lo, value + half_hi)


__all__ = ["FIGURES", "GUARD_S", "MIN_REST_FRAMES", "MIN_STROKE_DEG", "SWING_LEVELS", "Swing", "read_swing",
           "swing_intervals"]
