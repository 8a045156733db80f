"""Cantilever beam under a tip load, at rest: static deflection -> stiffness, bending stiffness.

The course's first experiment: the tip of a clamped strip is filmed at rest, loaded (a mass
hung on it, lowered by hand), and filmed again once it holds still. The deflection is the
tip's move from its rest level to its settled level, along the direction it moves most (the
track's first principal axis, :func:`.beam.principal_displacement`: a camera not level still
gives it); the stiffness is the load over it, and with the beam's free length the bending
stiffness of Euler-Bernoulli's clamped beam under a point load at its tip::

    k = m*g / delta [N/m],   E*I = k*L^3/3 [N*m^2]

(small deflection; at delta/L = 0.1 the large-deflection tip moves about 1 % less than this
line says, so k and E*I read about 1 % high there).

The windows, unless given (``rest_s``, ``settled_s``):

- rest: the tip's level is the median of the samples before it first leaves it by a quarter
  of its whole move, its scatter 1.4826 times their median absolute deviation; the window
  runs from the first sample to the last one within ``BAND_SD`` scatters of the level before
  that quarter crossing (walking back: where the loading began);
- settled: the level is the median of the last ``TAIL_SHARE`` of the samples; the window
  runs from the first sample within ``BAND_SD`` rest scatters or ``SETTLED_SHARE`` of the move
  (the larger) of that level, after the tip last passed three quarters of its move (walking
  forward: where the loading ended), to the last sample;
- the rest window must be at rest: a straight line through it may move no more than
  ``DRIFT_SHARE`` of the deflection or ``DRIFT_SD`` scatters (the larger) over it (a clip that
  starts as the loading does has no rest level to read);
- both then stop ``GUARD_SHARE`` of the loading's time (from the one's end to the other's
  start) short of it: the loading's first and last moments lie inside the bands, and would pull
  each level towards the other (by 0.2 % of the deflection on the synthetic tracks of
  :func:`locust.calibrate.synthetic.static_beam_track`; 0.01 % with the guard).

Intervals: each level is its window's mean, its variance that of the mean of a scatter
correlated from frame to frame (first-order autoregressive: a tip clicked by hand or tracked
wanders by tenths of a pixel over seconds; :func:`_levels`), with Student's t on the effective
degrees of freedom; the scale's relative standard uncertainty (how well the track's metres are
known: for a Tracker project, its calibration stick's two hand-placed ends over the stick's
length in pixels, :func:`stick_scale_std`) is a type-B part of the deflection (a scale 1 % long
makes every length 1 % long), combined by Welch-Satterthwaite. The mass and g are taken as
exact (a kitchen scale's 0.1 g on 95 g is 0.1 %).

Creep: cardstock is viscoelastic, and a loaded strip keeps sagging for seconds. The settled
window's slope (a straight line through it, the same covariance) is reported; where its
interval excludes zero the deflection is the window's mean and a later reading would be larger.
It is said, not folded into the interval: it changes what is measured (the deflection after
so many seconds), not how well.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import CalibrationError
from ..params import GRAVITY_M_PER_S2
from .beam import principal_displacement
from .curves import Curves
from .fitstats import Covariance, Estimate, serial_covariance

BAND_SD = 3.0           # a sample this many scatters from a level is off it
SETTLED_SHARE = 0.02    # ... or this share of the move from the settled level
TAIL_SHARE = 0.05       # the settled level: the median of the track's last samples
GUARD_SHARE = 0.1       # each window stops this share of the loading's time short of it
MIN_WINDOW = 10         # samples a level needs
MIN_MOVE_SD = 10.0      # a deflection smaller than this many scatters is not measured
DRIFT_SHARE, DRIFT_SD = 0.05, 3.0   # a rest window whose line moves more than both of these is no rest
CLICK_SD_PX = 0.25      # a hand-placed point's scatter along a line, at Tracker's zoom (see stick_scale_std)
MAPPING = ("k = m*g/delta, E*I = k*L^3/3: a clamped beam with a point load at its tip, small deflection; "
           "the cardstock's bending, not a folded hinge's stiffness")


@dataclass(frozen=True)
class StaticBeamFit:
    """The result of :func:`fit_static_beam`.

    Attributes
    ----------
    source : str
        The recording's name.
    mass_kg : float
        The tip load's mass.
    load_n : float
        Its weight ``m*g`` [N].
    length_m : float or None
        The beam's free length, clamp to load (None: not given, no bending stiffness).
    deflection_m : Estimate
        The tip's move from its rest level to its settled level [m].
    stiffness_n_per_m : Estimate
        ``m*g/delta`` [N/m].
    bending_stiffness_nm2 : Estimate or None
        ``E*I = k*L^3/3`` [N*m^2] (None without the length).
    creep_m_per_s : Estimate
        The settled window's slope, along the deflection [m/s].
    rest_scatter_m : float
        The rest window's sample standard deviation [m].
    residual_autocorrelation : float
        Lag-1 autocorrelation of the samples about their levels; above ``2/sqrt(n)`` the
        intervals are widened for it.
    scale_relative_std : float
        The scale's relative standard uncertainty used (dimensionless).
    scale_note : str
        Where it comes from.
    rest_window_s, settled_window_s : tuple of float
        The windows, on the recording's clock [s].
    n_rest, n_settled : int
        Samples in each.
    mapping : str
        The model and what it is not, for the report.
    curves : Curves
        Data and levels, for the plot (the tip's deflection from its rest level, in mm).
    """

    source: str
    mass_kg: float
    load_n: float
    length_m: float | None
    deflection_m: Estimate
    stiffness_n_per_m: Estimate
    bending_stiffness_nm2: Estimate | None
    creep_m_per_s: Estimate
    rest_scatter_m: float
    residual_autocorrelation: float
    scale_relative_std: float
    scale_note: str
    rest_window_s: tuple[float, float]
    settled_window_s: tuple[float, float]
    n_rest: int
    n_settled: int
    mapping: str
    curves: Curves

    @property
    def creeping(self) -> bool:
        """Whether the tip still moves in the settled window (the slope's interval excludes 0)."""
        return self.creep_m_per_s.ci95_low > 0 or self.creep_m_per_s.ci95_high < 0

    def figures(self) -> dict[str, Estimate]:
        """The measured figures by name (units in the names): deflection, stiffness and, with the
        length, the bending stiffness.

        Returns
        -------
        dict of str to Estimate
        """
        out = {"deflection_m": self.deflection_m, "stiffness_n_per_m": self.stiffness_n_per_m}
        if self.bending_stiffness_nm2 is not None:
            out["bending_stiffness_nm2"] = self.bending_stiffness_nm2
        return out

    def summary(self) -> dict:
        """The fit for JSON output.

        Returns
        -------
        dict
            ``experiment`` ("static-beam": it names the plot, which has no space), the inputs,
            each :class:`~.fitstats.Estimate` as its :meth:`~.fitstats.Estimate.as_dict` (None
            when absent), the windows and the scale's
            uncertainty, under the field names (units in them).
        """
        out = {"experiment": "static-beam", "source": self.source, "mass_kg": self.mass_kg, "load_n": self.load_n,
               "length_m": self.length_m}
        for name in ("deflection_m", "stiffness_n_per_m", "bending_stiffness_nm2", "creep_m_per_s"):
            est = getattr(self, name)
            out[name] = None if est is None else est.as_dict()
        out.update(rest_scatter_m=self.rest_scatter_m, residual_autocorrelation=self.residual_autocorrelation,
                   scale_relative_std=self.scale_relative_std, rest_window_s=list(self.rest_window_s),
                   settled_window_s=list(self.settled_window_s), n_rest=self.n_rest, n_settled=self.n_settled,
                   mapping=self.mapping)
        return out

    def notes(self) -> list[str]:
        """What a person should know about these figures: the scale's uncertainty, and creep.

        Returns
        -------
        list of str
        """
        out = [f"scale: {self.scale_note}"]
        if self.creeping:
            rate = self.creep_m_per_s.value
            window = self.settled_window_s[1] - self.settled_window_s[0]
            out.append(f"the tip still creeps {rate * 1000:.3g} mm/s in the settled window "
                       f"({self.settled_window_s[0]:.2f}-{self.settled_window_s[1]:.2f} s: "
                       f"{abs(rate) * window * 1000:.2g} mm over it, {abs(rate) / self.deflection_m.value * 100:.2g} % "
                       "of the deflection a second): the deflection is that window's mean, and a later "
                       "reading would be larger (cardstock creeps under load)")
        return out


def stick_scale_std(length_px: float, click_sd_px: float = CLICK_SD_PX) -> float:
    """The relative standard uncertainty of a scale set by a stick of ``length_px`` whose two
    ends were placed by hand, each ``click_sd_px`` along the stick.

    ``CLICK_SD_PX`` is the scatter of hand clicks measured on Tracker's own example projects
    (0.22-0.25 px per axis about the marked object, at the screen's zoom; ``../shared/data``'s
    README): the stick's length in pixels is known to ``sqrt(2)`` of it. The world length
    typed for the stick is taken as exact: how far apart the marks it was laid on really are
    is the ruler's, which a project does not say.

    Parameters
    ----------
    length_px : float
        The stick's length on the image [px].
    click_sd_px : float
        Each end's standard deviation along the stick [px].

    Returns
    -------
    float
        Dimensionless.
    """
    return math.sqrt(2.0) * click_sd_px / length_px


def fit_static_beam(t_s: np.ndarray, x_m: np.ndarray, y_m: np.ndarray, mass_kg: float, *,
                    scale_relative_std: float = 0.0, scale_note: str = "taken as exact",
                    length_m: float | None = None, rest_s: tuple[float, float] | None = None,
                    settled_s: tuple[float, float] | None = None, source: str = "beam") -> StaticBeamFit:
    """The static deflection of a loaded cantilever's tip and its stiffness; see the module docstring.

    Parameters
    ----------
    t_s : array_like
        Sample times [s].
    x_m, y_m : array_like
        The tip's track [m] (finite samples only).
    mass_kg : float
        The tip load's mass [kg].
    scale_relative_std : float
        The relative standard uncertainty of the track's scale (dimensionless).
    scale_note : str
        Where that comes from, for the output.
    length_m : float, optional
        The beam's free length, clamp to load [m]: gives the bending stiffness.
    rest_s, settled_s : (float, float), optional
        The windows [s] (default: found from the track).
    source : str
        The recording's name, for messages and the plot.

    Returns
    -------
    StaticBeamFit

    Raises
    ------
    CalibrationError
        A mass or length not positive, a negative scale uncertainty, a flat track, a window
        of too few samples or one outside the track, or a move lost in the scatter.
    """
    if not mass_kg > 0:
        raise CalibrationError(f"--mass-kg must be positive (got {mass_kg})", "weigh the tip load, in kg")
    if length_m is not None and not length_m > 0:
        raise CalibrationError(f"--length-m must be positive (got {length_m})", "the beam's free length, in m")
    if not (scale_relative_std >= 0 and math.isfinite(scale_relative_std)):
        raise CalibrationError(f"the scale's uncertainty must be a share of at least 0 (got {scale_relative_std})",
                               "give --scale-std-pct as a percentage, e.g. 1")
    t = np.asarray(t_s, dtype=float)
    d = principal_displacement(np.asarray(x_m, dtype=float), np.asarray(y_m, dtype=float))
    if np.ptp(d) < 1e-9:
        raise CalibrationError(f"{source}: flat signal, the tip does not move ({np.ptp(d):.3g} m)",
                               "check the marker (is it on the beam tip?) and that the track covers the loading")
    rest = _given(t, rest_s, "--rest-s", source) if rest_s is not None else _rest_window(d)
    settled = _given(t, settled_s, "--settled-s", source) if settled_s is not None else _settled_window(d, rest)
    if rest_s is None and settled_s is None and rest.any() and settled.any():
        rest, settled = _guarded(t, rest, settled)
    for name, window, hint in (
            ("rest", rest, "film the tip at rest for a second or two before loading it, or give --rest-s A,B"),
            ("settled", settled, "film until the tip holds still after loading (a few seconds), or give "
                                 "--settled-s A,B")):
        if window.sum() < MIN_WINDOW:
            raise CalibrationError(f"{source}: only {int(window.sum())} samples in the {name} window "
                                   f"(need {MIN_WINDOW})", hint)
    if (rest & settled).any():
        raise CalibrationError(f"{source}: the rest and settled windows overlap", "give --rest-s and --settled-s apart")
    levels, cov, rho = _levels(d, rest, settled)
    move = levels[1] - levels[0]
    scatter = float(np.std(d[rest], ddof=1))
    if abs(move) < MIN_MOVE_SD * scatter:
        raise CalibrationError(
            f"{source}: the tip moves {abs(move) * 1e3:.3g} mm from rest to settled, less than "
            f"{MIN_MOVE_SD:g} times its scatter ({scatter * 1e3:.3g} mm)",
            "load the beam more, or track the tip more closely (a sharper mark, a closer camera)")
    drift = abs(_creep(t[rest], d[rest]).value) * float(np.ptp(t[rest]))
    if drift > max(DRIFT_SHARE * abs(move), DRIFT_SD * scatter):
        raise CalibrationError(
            f"{source}: the tip is not at rest before the loading: it moves {drift * 1e3:.3g} mm over the rest "
            f"window ({t[rest][0]:.3g}-{t[rest][-1]:.3g} s), more than {DRIFT_SHARE:.0%} of its deflection",
            "film the tip at rest for a second or two before loading it, or give --rest-s A,B")
    sign = math.copysign(1.0, move)
    full = Covariance(np.pad(cov.matrix, ((0, 1), (0, 1))), cov.dof, method=cov.method,
                      fixed=np.diag([0.0, 0.0, scale_relative_std ** 2]))
    delta = abs(move)
    grad_delta = sign * np.array([-1.0, 1.0, move])        # delta = scale * |settled - rest|, scale = 1
    load = mass_kg * GRAVITY_M_PER_S2
    k = load / delta
    grad_k = -load / delta ** 2 * grad_delta
    bending = None
    if length_m is not None:
        bending = full.estimate(k * length_m ** 3 / 3, grad_k * length_m ** 3 / 3)
    creep = _creep(t[settled], d[settled] * sign)
    shown = sign * (d - levels[0]) * 1e3                      # from the rest level, towards the load
    fine = np.where(rest, 0.0, np.where(settled, delta * 1e3, np.nan))
    curves = Curves(x=t, data=shown, model=fine, x_label="t [s]", y_label="tip deflection from rest [mm]",
                    title=f"static beam: {Path(source).name}", model_x=t, model_fine=fine)
    return StaticBeamFit(
        source=source, mass_kg=mass_kg, load_n=load, length_m=length_m,
        deflection_m=full.estimate(delta, grad_delta), stiffness_n_per_m=full.estimate(k, grad_k),
        bending_stiffness_nm2=bending, creep_m_per_s=creep, rest_scatter_m=scatter, residual_autocorrelation=rho,
        scale_relative_std=scale_relative_std, scale_note=scale_note,
        rest_window_s=(float(t[rest][0]), float(t[rest][-1])),
        settled_window_s=(float(t[settled][0]), float(t[settled][-1])),
        n_rest=int(rest.sum()), n_settled=int(settled.sum()), mapping=MAPPING, curves=curves)


def _rest_window(d: np.ndarray) -> np.ndarray:
    """The samples from the start to where the loading began (see the module docstring)."""
    quarter = int(np.argmax(np.abs(d - np.median(d[:max(len(d) // 20, 3)])) > 0.25 * np.ptp(d)))
    before = d[:quarter]
    out = np.zeros(len(d), bool)
    if before.size < MIN_WINDOW:
        return out
    level = float(np.median(before))
    band = BAND_SD * 1.4826 * float(np.median(np.abs(before - level)))
    inside = np.flatnonzero(np.abs(before - level) <= band)
    if inside.size:
        out[:inside[-1] + 1] = True
    return out


def _settled_window(d: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """The samples from where the loading ended to the end (see the module docstring)."""
    out = np.zeros(len(d), bool)
    if rest.sum() < MIN_WINDOW:
        return out
    level = float(np.median(d[-max(int(len(d) * TAIL_SHARE), 3):]))
    rest_level = float(np.median(d[rest]))
    move = level - rest_level
    scatter = 1.4826 * float(np.median(np.abs(d[rest] - rest_level)))
    band = max(BAND_SD * scatter, SETTLED_SHARE * abs(move))
    short = np.flatnonzero(np.abs(d - rest_level) < 0.75 * abs(move))     # not yet three quarters of the way
    start = short[-1] + 1 if short.size else 0
    arrived = np.flatnonzero(np.abs(d[start:] - level) <= band)
    if arrived.size:
        out[start + arrived[0]:] = True
    return out & ~rest


def _guarded(t: np.ndarray, rest: np.ndarray, settled: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Both windows cut back by ``GUARD_SHARE`` of the loading's time between them: its first
    and last moments lie within the bands, but are not yet (or no longer) the level."""
    t_rest, t_settled = float(t[rest][-1]), float(t[settled][0])
    guard = GUARD_SHARE * (t_settled - t_rest)
    return rest & (t <= t_rest - guard), settled & (t >= t_settled + guard)


def _given(t: np.ndarray, window: tuple[float, float], option: str, source: str) -> np.ndarray:
    a, b = window
    if not a < b:
        raise CalibrationError(f"{option} {a:g},{b:g}: the window must start before it ends", f"e.g. {option} 0,1.5")
    if b < t[0] or a > t[-1]:
        raise CalibrationError(f"{source}: {option} {a:g},{b:g} lies outside the track ({t[0]:.3g} to {t[-1]:.3g} s)",
                               "give times on the recording's clock, in s")
    return (t >= a) & (t <= b)


def _levels(d: np.ndarray, rest: np.ndarray, settled: np.ndarray) -> tuple[np.ndarray, Covariance, float]:
    """The two windows' means, their covariance and the scatter's lag-1 autocorrelation.

    The scatter is taken as first-order autoregressive, one ``rho`` for both windows (one
    tracker, one tip): ``rho`` from the pairs of neighbours within each window, less the
    downward bias of that estimate on a short series with its mean removed (``(1 + 3 rho)/n``,
    Kendall's), so that a wandering tip's intervals are not a tenth too narrow; each mean's
    variance is then ``s^2 f / n`` with ``f = 1 + 2 sum_k (1 - k/n) rho^k`` (the finite series'
    own factor, ``(1 + rho)/(1 - rho)`` when long) and ``s^2 = SSR / (n - f)`` (the scatter about
    a correlated series' own mean is short of its variance by ``f/n``), and the t factor has the
    Welch-Satterthwaite degrees of freedom of the two effective sample sizes ``n / f``."""
    windows = [np.flatnonzero(rest), np.flatnonzero(settled)]
    levels = np.array([d[w].mean() for w in windows])
    resid = [d[w] - m for w, m in zip(windows, levels)]
    pairs = sum(float(r[1:] @ r[:-1]) for r in resid)
    power = sum(float(r @ r) for r in resid)
    rho = pairs / power if power > 0 else 0.0
    n_mean = float(np.mean([len(r) for r in resid]))
    rho = min(max(rho + (1 + 3 * rho) / n_mean, 0.0), 0.99) if rho > 0 else rho
    var, eff = [], []
    for r in resid:
        n = len(r)
        k = np.arange(1, n)
        f = 1.0 + 2.0 * float(np.sum((1 - k / n) * rho ** k)) if rho > 0 else 1.0
        var.append(float(r @ r) / max(n - f, 1.0) * f / n)
        eff.append(n / f)
    dof = sum(var) ** 2 / sum(v ** 2 / max(e - 1.0, 1.0) for v, e in zip(var, eff))
    method = f"window means, AR(1) scatter rho={rho:.3g} (bias-corrected), t(Welch-Satterthwaite)"
    return levels, Covariance(np.diag(var), max(int(dof), 1), method=method), rho


def _creep(t: np.ndarray, d: np.ndarray) -> Estimate:
    """The slope of the settled window's straight line [m/s], signed along the deflection."""
    jac = np.column_stack([np.ones_like(t), t - t.mean()])
    coef = np.linalg.lstsq(jac, d, rcond=None)[0]
    cov, _ = serial_covariance(jac, d - jac @ coef)
    return cov.parameter(coef, 1)
