"""A link swinging on a flexure hinge: its free ring-down -> hinge stiffness and damping.

The link turns about the hinge by theta (rad, counter-clockwise from the track's +x axis,
y up). With the link's inertia ``I`` about the hinge (given), its mass ``M`` and the
distance ``D`` of its centre of mass from the hinge (given, for gravity in the swing's
plane), the swing obeys, at any angle::

    I*theta'' = -k*(theta - theta0) - b*theta' [- M*g*D*cos(theta)] [- tau_c*sign(theta')]

- ``k`` [N*m/rad] the hinge's stiffness and ``theta0`` its neutral angle (fitted: a folded
  flexure rarely rests where it was cut);
- ``b`` [N*m*s/rad] its viscous damping;
- gravity in the swing's plane (a link swinging in a vertical plane): the weight's moment
  with the centre of mass on the line from the hinge to the marker, straight down being
  -90 deg (the track's y up); out of the plane (the hinge axis vertical): no moment;
- ``tau_c`` [N*m] Coulomb friction, fitted only when the data show it: kept when it lowers
  the residual beyond chance (F test, p < 0.001) and its 95 % interval excludes zero.

``k`` and ``b`` are the robot's ``compliance.hinge_stiffness_nm_per_rad`` and
``compliance.hinge_damping_nms_per_rad``, named so in the fit; ``theta0``, ``tau_c`` and the
rest are the rig's, under names of their own, and never written to a robot.

The swing starts at the fit window's start, its initial angle and rate fitted with ``k``,
``b``, ``theta0``: in closed form where the equation is linear (no weight's moment, no
Coulomb term), else integrated (LSODA, relative tolerance 1e-10) with its variational
equations for the Jacobian (one integration gives every column; :mod:`.hingeswing`). The residual is the
marker's position, x and y [m], against ``pivot + R*(cos theta, sin theta)``: the distance
``R`` from the hinge to the marker is fitted too, and so is the pivot unless ``--pivot``
gives it (its start: the centre of the circle fitted to the marker's arc), so its
uncertainty is in the intervals of ``k`` and ``b``. Intervals come from the residual Jacobian
(:mod:`.fitstats`). Start values come from the swing itself (:mod:`.hingestart`): the period from its zero
crossings, the decay from its successive peaks (never a spectral peak, which can lock onto
the record length). A rig no link can be is refused (:func:`check_rig`: in plane, ``I``
below ``M*D^2``), and a value the swing does not determine is not identifiable
(:func:`identifiable`: every one where the model does not follow the swing).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import optimize, stats

from ..errors import CalibrationError
from .curves import Curves
from .fitparams import FitParameter, FitParameters
from .fitstats import Estimate, covariance
from .hingestart import SwingShape, angle_noise_rad, circle_fit, release_window, start_values, swing_angle, swing_shape
from .hingeswing import HingeRig, check_rig, is_linear, simulate_hinge, swing_sensitivities

STIFFNESS = "compliance.hinge_stiffness_nm_per_rad"   # the robot values a swing determines
DAMPING = "compliance.hinge_damping_nms_per_rad"
MIN_SAMPLES = 20
COULOMB_P_VALUE = 1e-3
SMALL_ARC_DEG = 20.0             # a circle fit over less arc than this places the pivot poorly
MAX_RELATIVE_STD = 0.25          # identifiable: 95% interval within about +-50% of the value
AT_BOUND = 1e-6                  # a value below this share of its start has run to its bound, 0
# the model follows the swing when its residual is at most this share of the swing's own RMS
# (it explains three quarters of the swing's variance or more): the course's film hinge, whose
# model error is the largest seen in a real swing, leaves 0.15; a rig whose inertia, mass or
# centre of mass is wrong gives a model that cannot swing at the data's rate, 0.98 and more
FOLLOWS_SHARE = 0.5
MODEL = ("I*theta'' = -k*(theta - theta0) - b*theta' - M*g*D*cos(theta) [gravity in plane] "
         "- tau_c*sign(theta') [Coulomb, when significant]")
LINEAR_FD_STEP = 1e-6  # the closed form's central differences, per unit of the solver's variable



@dataclass(frozen=True)
class HingeFit:
    """The result of :func:`fit_hinge`: the hinge's values with their intervals, and how well
    the swing fits.

    Attributes
    ----------
    source : str
        The recording's name.
    rig : HingeRig
        The link as given.
    estimates : dict of str to Estimate
        The robot's values the swing measures, by their keys: ``k`` as
        ``compliance.hinge_stiffness_nm_per_rad`` and ``b`` as
        ``compliance.hinge_damping_nms_per_rad``.
    neutral_angle_deg : Estimate
        ``theta0`` (from the track's +x axis, counter-clockwise): the rig's, no robot value.
    coulomb_friction_nm : Estimate or None
        ``tau_c``, when kept (see ``coulomb_note``).
    coulomb_note : str
        Whether Coulomb friction was fitted and why.
    natural_frequency_hz, damping_ratio : float
        Of small swings about rest, gravity included (ratio dimensionless).
    rest_angle_deg : float
        Where spring and weight balance.
    pivot_m : tuple of float
        The hinge's position (x, y) in the track.
    pivot_source : str
        ``"given"`` (``--pivot``) or ``"fitted"`` (started at the circle fit).
    radius_m : float
        Hinge to marker.
    start_angle_deg : float
        The angle where the fit window starts (the first turning point after the release).
    rms_residual_m, rms_residual_deg : float
        RMS residual of the marker's position, and of its angle about the pivot.
    n_samples : int
        Samples in the fit window.
    fit_start_s, fit_end_s : float
        The fit window, on the recording's clock.
    fit_time_s : float
        Wall time the fit took.
    curves : Curves
        Data and model angle [deg], for the plot.
    notes : list of str
        Warnings for the report (a poorly placed pivot, a value the swing does not determine,
        a model that does not follow the swing).
    identifiable : dict of str to bool
        Whether the swing determines each of :attr:`estimates` (:func:`identifiable`); only
        those are written.
    """

    source: str
    rig: HingeRig
    estimates: dict[str, Estimate]
    neutral_angle_deg: Estimate
    coulomb_friction_nm: Estimate | None
    coulomb_note: str
    natural_frequency_hz: float              # small swings about rest, gravity included
    damping_ratio: float
    rest_angle_deg: float
    pivot_m: tuple[float, float]
    pivot_source: str                        # given | fitted (started at the circle fit)
    radius_m: float
    start_angle_deg: float                  # where the fit window starts (the first turning point after the release)
    rms_residual_m: float
    rms_residual_deg: float
    n_samples: int
    fit_start_s: float
    fit_end_s: float
    fit_time_s: float
    curves: Curves
    notes: list[str] = field(default_factory=list)
    identifiable: dict[str, bool] = field(default_factory=dict)

    def summary(self) -> dict:
        """The fit for JSON output.

        Returns
        -------
        dict
            ``experiment`` ("hinge"), the rig, each :class:`~.fitstats.Estimate` as its
            :meth:`~.fitstats.Estimate.as_dict` (None when absent; the robot's values under
            their keys), the fit's figures under the field names (units in them) and the
            model's equation.
        """
        out = {"experiment": "hinge", "source": self.source, "inertia_kgm2": self.rig.inertia_kgm2,
               "gravity": self.rig.gravity, "mass_kg": self.rig.mass_kg or None, "com_m": self.rig.com_m or None}
        for name, est in (*self.estimates.items(), ("neutral_angle_deg", self.neutral_angle_deg),
                          ("coulomb_friction_nm", self.coulomb_friction_nm)):
            out[name] = None if est is None else est.as_dict()
            if name in self.identifiable:
                out[name]["identifiable"] = self.identifiable[name]
        out.update(coulomb_friction=self.coulomb_note, natural_frequency_hz=self.natural_frequency_hz,
                   damping_ratio=self.damping_ratio, rest_angle_deg=self.rest_angle_deg,
                   pivot_m=list(self.pivot_m), pivot=self.pivot_source, radius_m=self.radius_m,
                   start_angle_deg=self.start_angle_deg, rms_residual_m=self.rms_residual_m,
                   rms_residual_deg=self.rms_residual_deg, n_samples=self.n_samples,
                   fit_window_s=[self.fit_start_s, self.fit_end_s], fit_time_s=self.fit_time_s, model=MODEL,
                   notes=list(self.notes))
        return out


# -- the fit ------------------------------------------------------------------------
def fit_hinge(t_s: np.ndarray, x_m: np.ndarray, y_m: np.ndarray, rig: HingeRig, *,
              pivot: tuple[float, float] | None = None, start_s: float | None = None, end_s: float | None = None,
              coulomb: str = "auto", source: str = "hinge",
              progress: Callable[[str, int], None] | None = None) -> HingeFit:
    """Fit the swing of the marker; see the module docstring.

    Parameters
    ----------
    t_s : array_like
        Sample times [s].
    x_m, y_m : array_like
        The marker's track [m], y up.
    rig : HingeRig
        The link.
    pivot : tuple of float, optional
        The hinge's position (x, y) [m], held; by default fitted from the circle through the arc.
    start_s, end_s : float, optional
        The fit window [s]; by default from the first turning point after the release to the end.
    coulomb : str
        ``"auto"`` (fit Coulomb friction when significant), ``"off"`` or ``"on"``.
    source : str
        The recording's name, for messages and the plot.
    progress : callable, optional
        ``progress(stage, evaluations)`` after each evaluation of the swing (an integration,
        or the closed form where the model is linear): the fit's stage (``viscous fit``,
        ``Coulomb test``, ``Coulomb fit``) and the evaluations done so far.

    Returns
    -------
    HingeFit

    Raises
    ------
    CalibrationError
        A rig no link can be (:func:`check_rig`), a flat signal, too few samples in the
        window, or too few swings.
    """
    clock = time.perf_counter()
    check_rig(rig)
    t_s, x_m, y_m = (np.asarray(a, dtype=float) for a in (t_s, x_m, y_m))
    notes = []
    centre = pivot if pivot is not None else circle_fit(x_m, y_m)[:2]
    theta_all, radius_all = swing_angle(x_m, y_m, centre)
    swing_deg = math.degrees(float(np.ptp(theta_all)))
    if swing_deg < 30 * math.degrees(angle_noise_rad(theta_all)) or swing_deg < 1.0:
        raise CalibrationError(f"{source}: flat signal, the marker turns {swing_deg:.3g} deg about the pivot",
                               "check the marker (is it on the swinging link?), --pivot, and that the link was "
                               "released (calibration/protocols/hinge.md)")
    window = release_window(t_s, theta_all, start_s, end_s)
    t, theta, x, y = t_s[window], theta_all[window], x_m[window], y_m[window]
    if len(t) < MIN_SAMPLES:
        raise CalibrationError(f"{source}: only {len(t)} samples in the fit window (need {MIN_SAMPLES})",
                               "widen --start-s/--end-s, or film longer")
    arc_deg = math.degrees(float(np.ptp(theta)))
    if pivot is None and arc_deg < SMALL_ARC_DEG:
        notes.append(f"the swing covers {arc_deg:.3g} deg: the fitted pivot is poorly placed; give --pivot")
    shape = swing_shape(t, theta, source)
    p0 = start_values(t, theta, rig, shape)
    problem = _Swing(t, x, y, rig, p0, shape, float(np.median(radius_all[window])), centre, fit_pivot=pivot is None,
                     progress=progress)
    base = problem.solve(problem.start())
    chosen, coulomb_note = base, "not fitted (--coulomb off)"
    if coulomb != "off":
        problem.stage = "Coulomb test"
        p_value = problem.coulomb_score_p(base)
        if coulomb == "on" or p_value < COULOMB_P_VALUE:
            problem.stage = "Coulomb fit"
            with_c = problem.solve(np.append(base.x, 1.0))
            tau = problem.estimates(with_c)["coulomb_friction_nm"]
            if coulomb == "on" or tau.ci95_low > 0:
                chosen = with_c
                coulomb_note = (f"fitted: significant (score test p = {p_value:.2g})" if p_value < COULOMB_P_VALUE
                                else f"fitted (--coulomb on), not significant (score test p = {p_value:.2g})")
            else:
                coulomb_note = (f"not significant: {tau.value:.3g} N*m, 95% CI [{tau.ci95_low:.3g}, "
                                f"{tau.ci95_high:.3g}] holds zero; left out")
        else:
            coulomb_note = f"not significant (score test p = {p_value:.2g}): left out"
    est = problem.estimates(chosen)
    p, radius, (px, py) = problem.split(chosen.x)
    model = simulate_hinge(t, p, rig, problem.width)
    k, b = float(p[0]), float(p[1])
    rest = _rest_angle(p, rig)
    stiff_total = k - rig.gravity_moment_nm * math.sin(rest)
    wn = math.sqrt(max(stiff_total, 0.0) / rig.inertia_kgm2)
    zeta = b / (2 * math.sqrt(max(stiff_total, 1e-300) * rig.inertia_kgm2))
    measured = swing_angle(x, y, (px, py))[0]
    measured += 2 * math.pi * np.round((model[0] - measured[0]) / (2 * math.pi))
    flags = identifiable(est, p0, measured, model, Path(source).name, notes)
    fine_t = np.linspace(t[0], t[-1], max(10 * len(t), 2000))
    curves = Curves(x=t, data=np.degrees(measured), model=np.degrees(model), x_label="t [s]",
                    y_label="link angle about the hinge [deg]", title=f"hinge: {Path(source).name}",
                    model_x=fine_t, model_fine=np.degrees(simulate_hinge(fine_t, p, rig, problem.width)))
    rx, ry = np.split(chosen.fun, 2)
    return HingeFit(
        source=source, rig=rig, estimates={key: est[key] for key in (STIFFNESS, DAMPING)},
        neutral_angle_deg=est["neutral_angle_deg"],
        coulomb_friction_nm=est.get("coulomb_friction_nm"), coulomb_note=coulomb_note,
        natural_frequency_hz=wn / (2 * math.pi), damping_ratio=zeta, rest_angle_deg=math.degrees(rest),
        pivot_m=(px, py), pivot_source="given" if pivot is not None else "fitted",
        radius_m=radius, start_angle_deg=math.degrees(float(theta[0])),
        rms_residual_m=float(np.sqrt(np.mean(rx**2 + ry**2))),
        rms_residual_deg=math.degrees(float(np.sqrt(np.mean((measured - model) ** 2)))), n_samples=len(t),
        fit_start_s=float(t[0]), fit_end_s=float(t[-1]), fit_time_s=time.perf_counter() - clock,
        curves=curves, notes=notes, identifiable=flags)


def identifiable(est: dict[str, Estimate], start: np.ndarray, measured: np.ndarray, model: np.ndarray,
                 name: str, notes: list[str]) -> dict[str, bool]:
    """Whether the swing determines ``k`` and ``b``, with a note for each it does not: every
    value untrustworthy where the model does not follow the swing (its residual above
    ``FOLLOWS_SHARE`` of the swing's RMS, the note first: the servo fit's rule), else each one
    that ran to its bound (0) or whose 95 % interval is wider than about +-50 %.

    Parameters
    ----------
    est : dict of str to Estimate
        The fit's estimates, by name.
    start : numpy.ndarray
        The fit's start values (k and b first).
    measured, model : numpy.ndarray
        The angle about the pivot, measured and fitted, over the window [rad].
    name : str
        The recording's name, for the notes.
    notes : list of str
        Appended to.

    Returns
    -------
    dict of str to bool
        ``compliance.hinge_stiffness_nm_per_rad`` and ``compliance.hinge_damping_nms_per_rad``
        -> identifiable.
    """
    keys = (STIFFNESS, DAMPING)
    residual = float(np.sqrt(np.mean((measured - model) ** 2)))
    swing = float(np.sqrt(np.mean((measured - np.mean(measured)) ** 2)))
    if residual > FOLLOWS_SHARE * swing:
        notes.insert(0, f"the model does not follow {name} (RMS {math.degrees(residual):.3g} deg about a swing of "
                        f"{math.degrees(swing):.3g} deg RMS): no value is trustworthy; check --inertia-kgm2, "
                        "--gravity, --mass-kg and --com-m (calibration/protocols/hinge.md)")
        return dict.fromkeys(keys, False)
    flags = {}
    for key, first in zip(keys, start[:2]):
        e = est[key]
        if e.value < AT_BOUND * first:
            notes.append(f"{key} ran to the edge of its range ({e.value:.3g}, its bound 0): the swing does not "
                         "bound it")
            flags[key] = False
        elif not (math.isfinite(e.std) and e.relative_std <= MAX_RELATIVE_STD):
            notes.append(f"{key} is not identifiable from this swing (its 95% interval is wider than about "
                         f"+-{200 * MAX_RELATIVE_STD:.0f}%)")
            flags[key] = False
        else:
            flags[key] = True
    return flags


class _Swing:
    """The least-squares problem: the marker's x and y residuals [m] of a swing.

    Its values (:meth:`parameters`), each linear in the solver's variable and scaled to order
    one: k/k0, b/b0, theta0, the start angle, the start rate in units of the damped angular
    frequency, the radius R/R0, then (when the pivot is fitted) its offsets from the circle
    fit in units of R0, then (when fitted) tau_c in units of a friction that would stop a
    tenth of the first swing's decay.
    """

    DYNAMIC = 5

    def __init__(self, t, x, y, rig: HingeRig, p0: np.ndarray, shape: SwingShape, radius_m: float,
                 centre, *, fit_pivot: bool, progress: Callable[[str, int], None] | None = None):
        self.t, self.x, self.y, self.rig = t, x, y, rig
        self.progress, self.stage, self.evaluations = progress, "viscous fit", 0
        self.p0, self.radius0, self.fit_pivot = p0, radius_m, fit_pivot
        self.centre = (float(centre[0]), float(centre[1]))
        self.width = 0.002 * max(shape.amplitude_rad, 1e-3) * shape.damped_omega_rad_per_s   # sign(rate), smoothed
        self.tau_ref = 0.05 * p0[1] * shape.amplitude_rad * shape.damped_omega_rad_per_s
        self.dyn_scale = np.array([p0[0], p0[1], 1.0, 1.0, max(shape.damped_omega_rad_per_s, 1e-3)])
        self.n_geo = 3 if fit_pivot else 1
        held = not fit_pivot
        k0, b0, th0, th_start, rate0 = (float(v) for v in p0)
        self.params = FitParameters([
            FitParameter(STIFFNESS, "N*m/rad", k0, 0.0, scale=self.dyn_scale[0]),
            FitParameter(DAMPING, "N*m*s/rad", b0, 0.0, scale=self.dyn_scale[1]),
            FitParameter("neutral_angle_rad", "rad", th0),
            FitParameter("start_angle_rad", "rad", th_start),
            FitParameter("start_rate_rad_per_s", "rad/s", rate0, scale=self.dyn_scale[4]),
            FitParameter("radius_m", "m", radius_m, 0.0, scale=radius_m),
            FitParameter("pivot_x_m", "m", self.centre[0], scale=radius_m, reference=self.centre[0], held=held,
                         source="given" if held else "circle fit"),
            FitParameter("pivot_y_m", "m", self.centre[1], scale=radius_m, reference=self.centre[1], held=held,
                         source="given" if held else "circle fit"),
        ])
        self.with_coulomb = self.params.extended(
            FitParameter("coulomb_friction_nm", "N*m", self.tau_ref, 0.0, scale=self.tau_ref))

    def parameters(self, q: np.ndarray) -> FitParameters:
        """The values of the solver's vector ``q``: with Coulomb friction when it is one longer."""
        return self.with_coulomb if len(q) > self.params.size else self.params

    def start(self) -> np.ndarray:
        return self.params.as_vector()

    def split(self, q: np.ndarray):
        """(simulate_hinge's params, radius [m], pivot [m]) of the scaled values ``q``."""
        v = self.parameters(q).from_vector(q)
        p = np.array([v[name] for name in self.params.free[:self.DYNAMIC]]
                     + ([v["coulomb_friction_nm"]] if "coulomb_friction_nm" in v else []))
        return p, v["radius_m"], (v["pivot_x_m"], v["pivot_y_m"])

    def angle(self, q: np.ndarray) -> np.ndarray:
        self._counted()
        return simulate_hinge(self.t, self.split(q)[0], self.rig, self.width)

    def _counted(self) -> None:
        """One more evaluation of the swing (an integration, or the closed form), told to ``progress``."""
        self.evaluations += 1
        if self.progress is not None:
            self.progress(self.stage, self.evaluations)

    def angle_derivatives(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[int]]:
        """The angle at ``q`` and its derivatives in the dynamic values (k, b, theta0, the start
        angle and rate, and tau_c when fitted), in the solver's variables: (theta, d theta / d q
        of those columns, their indices in ``q``). Where the swing has a closed form, by central
        differences of it (``LINEAR_FD_STEP``: exact to about 1e-9); elsewhere from the
        variational equations, one integration (:func:`swing_sensitivities`)."""
        p = self.split(q)[0]
        dynamic = list(range(self.DYNAMIC)) + ([len(q) - 1] if len(q) > self.DYNAMIC + self.n_geo else [])
        params = self.parameters(q)
        by_q = np.array([params[params.free[i]].derivative(q[i]) for i in dynamic])   # d value / d q
        if is_linear(p, self.rig):
            th = self.angle(q)
            cols = []
            for i in dynamic:
                h = LINEAR_FD_STEP * max(1.0, abs(q[i]))
                up, down = q.copy(), q.copy()
                up[i] += h
                down[i] -= h
                cols.append((self.angle(up) - self.angle(down)) / (2 * h))
            return th, np.column_stack(cols), dynamic
        self._counted()
        th, d_p = swing_sensitivities(self.t, p, self.rig, self.width)
        return th, d_p * by_q, dynamic

    def residual(self, q: np.ndarray, theta: np.ndarray | None = None) -> np.ndarray:
        _, radius, (px, py) = self.split(q)
        th = self.angle(q) if theta is None else theta
        return np.concatenate([px + radius * np.cos(th) - self.x, py + radius * np.sin(th) - self.y])

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """The dynamic columns from the swing's derivatives (:meth:`angle_derivatives`), the
        radius and pivot columns exactly."""
        _, radius, _ = self.split(q)
        th, d_th, dynamic = self.angle_derivatives(q)
        cos, sin = np.cos(th), np.sin(th)
        n = len(th)
        jac = np.zeros((2 * n, len(q)))
        for col, i in enumerate(dynamic):
            jac[:n, i], jac[n:, i] = -radius * sin * d_th[:, col], radius * cos * d_th[:, col]
        jac[:n, self.DYNAMIC], jac[n:, self.DYNAMIC] = self.radius0 * cos, self.radius0 * sin
        if self.fit_pivot:
            jac[:n, self.DYNAMIC + 1] = self.radius0
            jac[n:, self.DYNAMIC + 2] = self.radius0
        return jac

    def solve(self, q0: np.ndarray) -> optimize.OptimizeResult:
        """Least squares, k, b, the radius and tau_c kept positive."""
        lo, hi = self.parameters(q0).bounds()
        q0 = np.where(np.isfinite(lo), np.maximum(q0, 1e-9), q0)
        return optimize.least_squares(self.residual, q0, jac=self.jacobian, bounds=(lo, hi), method="trf",
                                      xtol=1e-10, ftol=1e-10, max_nfev=200)

    def estimates(self, result: optimize.OptimizeResult) -> dict[str, Estimate]:
        cov = covariance(result.jac, result.fun)
        q = result.x
        params = self.parameters(q)
        v = params.from_vector(q)
        out = {name: cov.estimate(v[name], params.gradient(q, name)) for name in (STIFFNESS, DAMPING)}
        out["neutral_angle_deg"] = cov.estimate(math.degrees(v["neutral_angle_rad"]),
                                                params.gradient(q, "neutral_angle_rad", math.degrees(1.0)))
        if "coulomb_friction_nm" in v:
            out["coulomb_friction_nm"] = cov.estimate(v["coulomb_friction_nm"],
                                                      params.gradient(q, "coulomb_friction_nm"))
        return out

    def coulomb_score_p(self, base: optimize.OptimizeResult) -> float:
        """p-value of adding Coulomb friction to the viscous fit ``base``: the residual's share
        along the friction's own direction (its Jacobian column at zero friction, the fitted
        columns projected out), against the residual variance (a score test, F(1, n-p-1))."""
        h = 1e-3
        col = (self.residual(np.append(base.x, h)) - base.fun) / h
        jac = base.jac
        coef, *_ = np.linalg.lstsq(jac, col, rcond=None)
        own = col - jac @ coef
        n, p = len(base.fun), len(base.x) + 1
        if not float(own @ own) > 0:
            return 1.0
        drop = float(own @ base.fun) ** 2 / float(own @ own)
        ssr = float(base.fun @ base.fun) - drop
        f_stat = drop / max(ssr / (n - p), 1e-300)
        return float(stats.f.sf(f_stat, 1, n - p))


def _rest_angle(p: np.ndarray, rig: HingeRig) -> float:
    """Where spring and weight balance: k*(theta - theta0) + M*g*D*cos(theta) = 0, nearest theta0."""
    k, th0, mgd = float(p[0]), float(p[2]), rig.gravity_moment_nm
    if mgd == 0 or k <= 0:
        return th0
    root = optimize.least_squares(lambda th: k * (th - th0) + mgd * np.cos(th), [th0]).x[0]
    return float(root)


