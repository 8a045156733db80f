"""Ramp tilted until the robot slides: static friction mu = tan(critical angle).

From several trials (one critical angle each) the estimate is ``mu = tan(mean angle)``,
with the 95% interval ``tan(mean +- t * s / sqrt(n))`` (Student's t on the angles; tan is
monotonic below 90 deg) and a one-sigma uncertainty ``sec^2(mean) * s / sqrt(n)``. The
trials' spread ``s`` is never taken below what the angle's reading resolution leaves
unknown, ``resolution / sqrt(12)`` (a protractor's 1 deg graduation: 0.29 deg): trials read
alike are alike to the graduation, not identical, and give an interval of that width.

The estimate is the robot's friction the command names (``contact.foot_friction`` by default,
``contact.nose_friction`` for a robot sliding on its nose), under that key.

A trial can also come from a side-view track of the ramp (markers at both ends of the
board) and the robot: the ramp angle is that of the board, and the robot starts to slide
when its distance along the board leaves its resting value. The onset is located by
fitting "at rest, then sliding with constant acceleration" to the distance along the board,
which finds it to a fraction of a frame instead of waiting for the slip to exceed a
threshold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import CalibrationError
from ..io.importing import units_hint
from .curves import Curves
from .fitstats import Estimate, t95

MIN_TRIALS = 2
READING_RESOLUTION_DEG = 1.0   # a protractor's graduation: the angle is read to the nearest degree
BOARD_M = (0.05, 3.0, 0.3)     # (least, most, typical) length between the ramp's two markers
FRICTIONS = ("contact.foot_friction", "contact.nose_friction")   # the robot values a ramp measures


@dataclass(frozen=True)
class RampFit:
    """The ramp's fit: static friction from the trials' critical angles.

    Attributes
    ----------
    source : str
        The recording(s).
    estimates : dict of str to locust.calibrate.fitstats.Estimate
        ``tan(mean angle)`` (no unit) with its 95% interval, under the friction's robot key
        (one of :data:`FRICTIONS`).
    mean_angle_deg, std_angle_deg : float
        The trials' mean and standard deviation [deg] (at least the reading's resolution / sqrt(12)).
    n_trials : int
        Trials used.
    angles_deg : list of float
        Each trial's critical angle [deg].
    curves : Curves
        tan(angle) per trial against the fitted mu.
    notes : list of str
        What was assumed (the spread raised to the reading resolution's).
    """

    source: str
    estimates: dict[str, Estimate]
    mean_angle_deg: float
    std_angle_deg: float
    n_trials: int
    angles_deg: list[float] = field(repr=False)
    curves: Curves = field(repr=False)
    resolution_deg: float = READING_RESOLUTION_DEG
    notes: list[str] = field(default_factory=list)

    def summary(self) -> dict:
        """Every figure of the fit, as ``locust calibrate ramp --json`` prints it.

        Returns
        -------
        dict
        """
        return {"experiment": "ramp", "source": self.source, **{k: e.as_dict() for k, e in self.estimates.items()},
                "mean_angle_deg": self.mean_angle_deg, "std_angle_deg": self.std_angle_deg,
                "n_trials": self.n_trials, "angles_deg": self.angles_deg, "resolution_deg": self.resolution_deg,
                "notes": self.notes}


def fit_ramp(angles_deg: np.ndarray, source: str = "ramp",
             resolution_deg: float = READING_RESOLUTION_DEG, key: str = FRICTIONS[0]) -> RampFit:
    """Static friction ``mu = tan(mean critical angle)`` with a Student-t 95% interval.

    Parameters
    ----------
    angles_deg : array_like
        The trials' critical angles [deg from the horizontal]; NaN are dropped.
    source : str
        The recording's name, for messages and provenance.
    resolution_deg : float, default 1.0
        How finely each angle was read [deg]; the trials' spread is taken as at least
        ``resolution_deg / sqrt(12)`` (see the module docstring).
    key : str, default "contact.foot_friction"
        The robot's friction the estimate is (one of :data:`FRICTIONS`).

    Returns
    -------
    RampFit

    Raises
    ------
    locust.errors.CalibrationError
        Fewer than two trials, an angle outside 0..90 deg, a resolution that is not positive, or
        a key that is no friction of the model.
    """
    if key not in FRICTIONS:
        raise CalibrationError(f"{key!r}: not a friction of the model", "choose " + " or ".join(FRICTIONS))
    if not (math.isfinite(resolution_deg) and resolution_deg > 0):
        raise CalibrationError(f"--resolution-deg {resolution_deg:g} must be a finite number above 0",
                               "the angle's reading resolution, e.g. 1 for a protractor read to the degree")
    a = np.asarray(angles_deg, dtype=float)
    a = a[np.isfinite(a)]
    if len(a) < MIN_TRIALS:
        raise CalibrationError(f"{source}: {len(a)} trial{'s' if len(a) != 1 else ''} (need at least {MIN_TRIALS} "
                               "for a confidence interval)", "repeat the tilt at least 5 times and record each angle")
    if np.any((a <= 0) | (a >= 90)):
        bad = a[(a <= 0) | (a >= 90)][0]
        raise CalibrationError(f"{source}: critical angle {bad:g} deg is not between 0 and 90 deg",
                               "angles are in degrees from the horizontal")
    mean, sd, n = float(a.mean()), float(a.std(ddof=1)), len(a)
    floor, notes = resolution_deg / math.sqrt(12.0), []
    if sd < floor:
        notes.append(f"the trials' spread {sd:.3g} deg is below the reading resolution's {floor:.3g} deg "
                     f"({resolution_deg:g} deg / sqrt(12)): the interval uses {floor:.3g} deg")
        sd = floor
    se = sd / math.sqrt(n)
    k = t95(n - 1)
    mu = math.tan(math.radians(mean))
    std = se * math.radians(1.0) / math.cos(math.radians(mean)) ** 2
    lo, hi = (math.tan(math.radians(min(max(mean + s * k * se, 0.0), 89.999))) for s in (-1, 1))
    trials = np.arange(1, n + 1, dtype=float)
    curves = Curves(x=trials, data=np.tan(np.radians(a)), model=np.full(n, mu), x_label="trial",
                    y_label="tan(critical angle)", title=f"ramp: {source}")
    return RampFit(source=source, estimates={key: Estimate(mu, std, lo, hi)}, mean_angle_deg=mean, std_angle_deg=sd,
                   n_trials=n, angles_deg=[float(x) for x in a], curves=curves, resolution_deg=resolution_deg,
                   notes=notes)


@dataclass(frozen=True)
class SlipOnset:
    """When the robot starts to slide down the tilting board.

    Attributes
    ----------
    critical_angle_deg : float
        The board's angle at the onset [deg].
    onset_s : float
        The onset's time in the track [s].
    slip_m : float
        How far the robot slid by the end of the record [m].
    """

    critical_angle_deg: float
    onset_s: float
    slip_m: float          # how far the robot slid by the end of the record


def board_length_warning(length_m: float, units: str = "m", source: str = "ramp") -> str | None:
    """A warning when the distance between the ramp's markers is not a board's, naming the
    ``--units`` that would make it one.

    Parameters
    ----------
    length_m : float
        The markers' distance as read [m].
    units : str
        The ``--units`` the track was read in.
    source : str
        The recording's name, for the message.

    Returns
    -------
    str or None
        The warning; None for a plausible board (or a length that is not finite).
    """
    low, high, typical = BOARD_M
    if not math.isfinite(length_m) or low <= length_m <= high:
        return None
    return (f"{source}: the ramp's markers are {length_m:.3g} m apart, not the {low:g}-{high:g} m of a ramp "
            f"board: {units_hint(length_m, low, high, typical, units)}")


def critical_angle_from_track(t_s: np.ndarray, ramp_a: tuple[np.ndarray, np.ndarray],
                              ramp_b: tuple[np.ndarray, np.ndarray], robot: tuple[np.ndarray, np.ndarray], *,
                              source: str = "ramp", min_slip_m: float = 0.005) -> SlipOnset:
    """Ramp angle when the robot starts to slide, from a side-view track (see module doc).

    Parameters
    ----------
    t_s : numpy.ndarray
        Time [s].
    ramp_a, ramp_b : tuple of numpy.ndarray
        x and y [m] of the markers on the board's hinge end and far end.
    robot : tuple of numpy.ndarray
        x and y [m] of the robot's marker.
    source : str
        The recording's name, for messages.
    min_slip_m : float, default 0.005
        The slide along the board [m] that counts as the robot sliding.

    Returns
    -------
    SlipOnset

    Raises
    ------
    locust.errors.CalibrationError
        Fewer than 10 frames with all three markers, a board that does not tilt, or a robot
        that never slides.
    """
    t = np.asarray(t_s, dtype=float)
    ax, ay = ramp_a
    bx, by = ramp_b
    rx, ry = robot
    keep = (np.isfinite(t) & np.isfinite(ax) & np.isfinite(ay) & np.isfinite(bx) & np.isfinite(by)
            & np.isfinite(rx) & np.isfinite(ry))
    t, ax, ay, bx, by, rx, ry = (v[keep] for v in (t, ax, ay, bx, by, rx, ry))
    if len(t) < 10:
        raise CalibrationError(f"{source}: only {len(t)} frames with all three markers (need 10)",
                               "check that the ramp ends and the robot were found in the track")
    ux, uy = bx - ax, by - ay
    length = np.hypot(ux, uy)
    angle = np.degrees(np.arctan2(np.abs(uy), np.abs(ux)))
    s = ((rx - ax) * ux + (ry - ay) * uy) / length
    disp = np.abs(s - np.median(s[: max(len(s) // 10, 3)]))
    if np.ptp(angle) < 1.0:
        raise CalibrationError(f"{source}: flat signal, the ramp does not tilt ({np.ptp(angle):.2g} deg)",
                               "check the ramp markers (one at each end of the board)")
    moved = np.flatnonzero(disp > min_slip_m)
    if len(moved) == 0:
        raise CalibrationError(f"{source}: the robot never slides (largest move {disp.max() * 1e3:.2g} mm)",
                               "tilt the ramp further, or check the robot marker")
    first = int(moved[0])
    onset = _onset_time(t, s, first)
    return SlipOnset(critical_angle_deg=float(np.interp(onset, t, angle)), onset_s=onset, slip_m=float(disp[-1]))


def _onset_time(t: np.ndarray, s: np.ndarray, first: int) -> float:
    """Best break time tc for s = s0 (t < tc), s0 + 0.5*a*(t - tc)^2 (t >= tc), searched on a
    fine grid between the last quiet frames and the first clear slip."""
    lo = max(first - int(0.5 / np.median(np.diff(t))), 0)
    window = slice(lo, min(first + 8, len(t)))
    tw, sw = t[window], s[window]
    best_tc, best_cost = tw[0], np.inf
    for tc in np.linspace(tw[0], t[first], 400):
        basis = np.column_stack([np.ones_like(tw), 0.5 * np.clip(tw - tc, 0, None) ** 2])
        coef, *_ = np.linalg.lstsq(basis, sw, rcond=None)
        cost = float(np.sum((basis @ coef - sw) ** 2))
        if cost < best_cost:
            best_tc, best_cost = tc, cost
    return float(best_tc)
