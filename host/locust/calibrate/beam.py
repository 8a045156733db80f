"""Cantilever beam with a tip mass: damped oscillation -> stiffness and damping.

The tip moves as a damped linear oscillator after the mass is dropped on it::

    d(t) = c + exp(-zeta*wn*tau) * (A*cos(wd*tau) + B*sin(wd*tau)),  tau = t - t0,
    wd = wn*sqrt(1 - zeta^2)

fitted by least squares to the tip's displacement along the direction it moves most
(the first principal axis of the track, so the camera need not be level), started from the
best points of a grid over frequency and damping (:func:`_start_values`), with intervals
widened for residuals correlated from frame to frame (``fitstats.serial_covariance``) and for
what the window's first samples may hold that the model does not (a release transient at the
drop, skipped where it stands out of the noise: :func:`_past_release`; the values' move when
the window starts one sample later: :func:`_start_shift`). Then, with the
oscillating mass m (tip mass plus 33/140 of the beam's own mass, Rayleigh's cantilever
result):

    k = m*wn^2 [N/m],  b = 2*zeta*m*wn [N*s/m]

Hinge mapping for the model (pseudo-rigid-body, one lumped hinge at the clamp): the beam
is a rigid bar of length L on a torsional spring, the mass at its tip, small angles
(tip displacement = L*theta). Equal tip force for equal deflection gives

    k_rot = k*L^2 [N*m/rad],  b_rot = b*L^2 [N*m*s/rad],

the robot's ``compliance.hinge_stiffness_nm_per_rad`` and ``compliance.hinge_damping_nms_per_rad``,
named so in the fit (:attr:`BeamFit.estimates`); the oscillator's own values keep names of
their own and are never written to a robot.

Assumptions: small deflection (tip motion << L), mass concentrated at the tip, linear
viscous damping, the clamp rigid, the cardstock hinge of the robot made of the same
material and width as the beam.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy import optimize

from ..errors import CalibrationError
from ..io.importing import units_hint
from .curves import Curves
from .fitparams import FitParameter, FitParameters
from .fitstats import Estimate, serial_covariance

RAYLEIGH_TIP_FRACTION = 33.0 / 140.0  # share of a cantilever's own mass moving with its tip
MAPPING = ("k_rot = k*L^2, b_rot = b*L^2: rigid bar of length L on a torsional spring at the clamp, "
           "mass at the tip, small angles, viscous damping")
MIN_SAMPLES = 20
MIN_CYCLES = 1.5
MIN_FRAMES_PER_CYCLE = 4.0   # samples per period the fit needs (Nyquist is 2)
# plausible peak-to-peak swing of the tip: a 1-3 cm drop (calibration/protocols/beam.md), less than
# the beam is long; without --length-m, that of a desk-sized beam
SWING_OF_LENGTH = (1 / 500, 1.0, 0.1)       # (least, most, typical) swing as a share of L
SWING_M = (1e-4, 0.25, 0.01)                # (least, most, typical) without L
ZETA_BOUNDS = (1e-4, 0.95)                  # damping ratios the fit allows
LOWEST_CYCLES = 0.5                         # lowest frequency the fit allows: cycles over the fit window
START_FN_STEP = 0.01                        # relative step of the start grid's frequencies
START_ZETAS = (0.005, 0.02, 0.05, 0.1, 0.2, 0.35, 0.6)   # the start grid's damping ratios
START_COUNT = 3                             # starts refined by least squares: the grid's best local minima
RELEASE_S = 0.015                           # a release transient dies out within this of the drop ...
RELEASE_Z = 4.0                             # ... and leaves residuals above this many noise sigmas
START_SAMPLES = 2048                        # the start grid looks at the window's first samples (the ring-down)
STIFFNESS = "compliance.hinge_stiffness_nm_per_rad"   # the robot values the hinge mapping gives
DAMPING = "compliance.hinge_damping_nms_per_rad"


@dataclass(frozen=True)
class BeamFit:
    """The result of :func:`fit_beam`: the oscillator's values with their intervals, the
    tip's stiffness and damping, and (with the beam's length) their hinge equivalents.

    Attributes
    ----------
    source : str
        The recording's name.
    mass_kg, effective_mass_kg : float
        The dropped tip mass, and the oscillating mass (tip mass plus 33/140 of the beam's).
    length_m : float or None
        The beam's free length (None: not given, no hinge values).
    natural_frequency_hz, damping_ratio : Estimate
        The oscillator's undamped natural frequency [Hz] and damping ratio (dimensionless).
    damped_frequency_hz : float
        ``fn * sqrt(1 - zeta^2)``.
    stiffness_n_per_m, damping_ns_per_m : Estimate
        The tip's stiffness ``m*wn^2`` and damping ``2*zeta*m*wn``.
    estimates : dict of str to Estimate
        Their pseudo-rigid-body hinge equivalents ``k L^2`` and ``b L^2``, the robot's
        ``compliance.hinge_stiffness_nm_per_rad`` and ``compliance.hinge_damping_nms_per_rad``
        (empty without the length).
    amplitude_m, rms_residual_m : float
        The oscillation's amplitude at the window's start, and the fit's RMS residual.
    residual_autocorrelation : float
        Lag-1 autocorrelation of the residuals (dimensionless); above ``2/sqrt(n)`` the
        intervals are widened for it.
    n_samples : int
        Samples in the fit window.
    fit_start_s, fit_end_s : float
        The fit window, on the recording's clock.
    mapping : str
        The hinge mapping and its assumptions, for the report.
    curves : Curves
        Data and model, for the plot (displacement in mm).
    """

    source: str
    mass_kg: float
    effective_mass_kg: float
    length_m: float | None
    natural_frequency_hz: Estimate
    damping_ratio: Estimate
    damped_frequency_hz: float
    stiffness_n_per_m: Estimate
    damping_ns_per_m: Estimate
    estimates: dict[str, Estimate]
    amplitude_m: float
    rms_residual_m: float
    residual_autocorrelation: float     # lag-1; above 2/sqrt(n) the intervals are widened for it
    n_samples: int
    fit_start_s: float
    fit_end_s: float
    mapping: str
    curves: Curves

    def summary(self) -> dict:
        """The fit for JSON output.

        Returns
        -------
        dict
            ``experiment`` ("beam"), the inputs, each :class:`~.fitstats.Estimate` as its
            :meth:`~.fitstats.Estimate.as_dict` (the robot's values under their keys, None
            without the length) and the fit's figures, under the field names (units in them).
        """
        out = {"experiment": "beam", "source": self.source, "mass_kg": self.mass_kg,
               "effective_mass_kg": self.effective_mass_kg, "length_m": self.length_m}
        for name in ("natural_frequency_hz", "damping_ratio", "stiffness_n_per_m", "damping_ns_per_m"):
            out[name] = getattr(self, name).as_dict()
        for key in (STIFFNESS, DAMPING):
            out[key] = self.estimates[key].as_dict() if key in self.estimates else None
        out.update(damped_frequency_hz=self.damped_frequency_hz, amplitude_m=self.amplitude_m,
                   rms_residual_m=self.rms_residual_m, residual_autocorrelation=self.residual_autocorrelation,
                   n_samples=self.n_samples,
                   fit_window_s=[self.fit_start_s, self.fit_end_s], mapping=self.mapping)
        return out


def principal_displacement(x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """Displacement along the direction the tip moves most (sign: towards +y, else +x).

    Parameters
    ----------
    x_m, y_m : array_like
        The tip's track [m].

    Returns
    -------
    numpy.ndarray
        Its position along the track's first principal axis [m], measured from the track's
        origin (so the mean is the mean position's projection).
    """
    pts = np.column_stack([x_m - np.mean(x_m), y_m - np.mean(y_m)])
    _, _, vt = np.linalg.svd(pts, full_matrices=False)
    axis = vt[0]
    if abs(axis[1]) >= 1e-12 and axis[1] < 0 or abs(axis[1]) < 1e-12 and axis[0] < 0:
        axis = -axis
    return pts @ axis + (np.mean(x_m) * axis[0] + np.mean(y_m) * axis[1])


def tip_swing_warning(swing_m: float, length_m: float | None, units: str = "m",
                      source: str = "beam") -> str | None:
    """A warning when the tip's peak-to-peak swing is not plausible for the beam (a 5 cm beam
    whose tip swings 0.9 m: the track is in cm), naming the ``--units`` that would make it so.

    Parameters
    ----------
    swing_m : float
        The tip's peak-to-peak swing [m].
    length_m : float or None
        The beam's free length [m] (None: judged against a desk-sized beam).
    units : str
        The ``--units`` the track was read in.
    source : str
        The recording's name, for the message.

    Returns
    -------
    str or None
        The warning, or None when the swing is plausible.
    """
    if length_m is not None and length_m > 0:
        low, high, typical = (f * length_m for f in SWING_OF_LENGTH)
        beam = f"a {length_m:g} m beam"
    else:
        low, high, typical = SWING_M
        beam = "a desk-sized beam (no --length-m)"
    if low <= swing_m <= high:
        return None
    size = "more" if swing_m > high else "less"
    limit = high if swing_m > high else low
    return (f"{source}: the beam tip swings {swing_m:.3g} m peak to peak, {size} than {limit:.3g} m "
            f"is plausible for {beam}: {units_hint(swing_m, low, high, typical, units)}")


def damped_oscillation(t_s: np.ndarray, p: np.ndarray, t0_s: float) -> np.ndarray:
    """The model's tip displacement (see the module docstring).

    Parameters
    ----------
    t_s : array_like
        Sample times [s].
    p : array_like, shape (5,)
        Offset c [m], amplitudes A and B [m], natural frequency [Hz] and damping ratio
        (dimensionless).
    t0_s : float
        Start of the oscillation, ``tau = t - t0`` [s].

    Returns
    -------
    numpy.ndarray
        The displacement at ``t_s`` [m].
    """
    c, a, b, fn_hz, zeta = p
    wn = 2 * np.pi * fn_hz
    wd = wn * np.sqrt(max(1.0 - zeta**2, 1e-12))
    tau = t_s - t0_s
    env = np.exp(-zeta * wn * tau)
    return c + env * (a * np.cos(wd * tau) + b * np.sin(wd * tau))


def fit_beam(t_s: np.ndarray, displacement_m: np.ndarray, mass_kg: float, *, length_m: float | None = None,
             beam_mass_kg: float = 0.0, start_s: float | None = None, end_s: float | None = None,
             source: str = "beam") -> BeamFit:
    """Fit a damped oscillation to the tip displacement; see the module docstring.

    Parameters
    ----------
    t_s : array_like
        Sample times [s].
    displacement_m : array_like
        The tip's displacement along its motion [m] (:func:`principal_displacement`).
    mass_kg : float
        The dropped tip mass [kg].
    length_m : float, optional
        The beam's free length [m]: gives the hinge equivalents.
    beam_mass_kg : float
        The beam's own mass [kg]; 33/140 of it moves with the tip.
    start_s, end_s : float, optional
        The fit window [s]; by default from the drop (a release transient skipped) to the end.
    source : str
        The recording's name, for messages and the plot.

    Returns
    -------
    BeamFit

    Raises
    ------
    CalibrationError
        A mass or length not positive, a flat signal, too few samples in the window, an
        oscillation lost in the noise, no ring-down (damping at its bound), fewer than
        ``MIN_CYCLES`` cycles, or fewer than ``MIN_FRAMES_PER_CYCLE`` frames a cycle.
    """
    t, y = _checked_window(t_s, displacement_m, mass_kg, length_m, start_s, end_s, source)
    fs_hz = 1.0 / float(np.median(np.diff(t)))
    t, y, best = _past_release(t, y, fs_hz, pinned=start_s is not None)
    t0 = float(t[0])
    p, r = best.x, best.fun
    cov, rho = serial_covariance(best.jac, r)
    cov = replace(cov, shift=_start_shift(t, y, fs_hz, best))
    rms, amp, fn, zeta = _checked_oscillation(p, r, t, fs_hz, source)
    m = mass_kg + RAYLEIGH_TIP_FRACTION * beam_mass_kg
    wn = 2 * np.pi * fn
    params = _parameters(t, fs_hz)
    grad_fn = params.gradient(p, "natural_frequency_hz")
    grad_zeta = params.gradient(p, "damping_ratio")
    k = m * wn**2
    b = 2 * zeta * m * wn
    grad_k = grad_fn * 2 * k / fn
    grad_b = 2 * m * 2 * np.pi * (zeta * grad_fn + fn * grad_zeta)
    hinge = {}
    if length_m is not None:
        hinge = {STIFFNESS: cov.estimate(k * length_m**2, grad_k * length_m**2),
                 DAMPING: cov.estimate(b * length_m**2, grad_b * length_m**2)}
    fine_t = np.linspace(t[0], t[-1], max(20 * len(t), 2000))
    curves = Curves(x=t, data=y * 1e3, model=(y - r) * 1e3, x_label="t [s]",
                    y_label="tip displacement [mm]", title=f"beam: {Path(source).name}",
                    model_x=fine_t, model_fine=damped_oscillation(fine_t, p, t0) * 1e3)
    return BeamFit(
        source=source, mass_kg=mass_kg, effective_mass_kg=m, length_m=length_m,
        natural_frequency_hz=cov.estimate(fn, grad_fn), damping_ratio=cov.estimate(zeta, grad_zeta),
        damped_frequency_hz=fn * float(np.sqrt(1 - zeta**2)),
        stiffness_n_per_m=cov.estimate(k, grad_k), damping_ns_per_m=cov.estimate(b, grad_b),
        estimates=hinge, amplitude_m=amp,
        rms_residual_m=rms, residual_autocorrelation=rho, n_samples=len(t), fit_start_s=float(t[0]),
        fit_end_s=float(t[-1]),
        mapping=MAPPING, curves=curves,
    )


def _checked_window(t_s: np.ndarray, displacement_m: np.ndarray, mass_kg: float, length_m: float | None,
                    start_s: float | None, end_s: float | None, source: str) -> tuple[np.ndarray, np.ndarray]:
    """The samples (t, displacement) of the fit window, after refusing a mass or length that
    is not positive, a flat signal and a window of too few samples."""
    if not mass_kg > 0:
        raise CalibrationError(f"--mass-kg must be positive (got {mass_kg})", "weigh the dropped mass, in kg")
    if length_m is not None and not length_m > 0:
        raise CalibrationError(f"--length-m must be positive (got {length_m})", "the beam's free length, in m")
    t_s = np.asarray(t_s, dtype=float)
    d = np.asarray(displacement_m, dtype=float)
    if np.ptp(d) < 1e-9:
        raise CalibrationError(f"{source}: flat signal, the tip does not move ({np.ptp(d):.3g} m peak to peak)",
                               "check the marker (is it on the beam tip?) and the scale of the track")
    window = _window(t_s, d, start_s, end_s)
    t, y = t_s[window], d[window]
    if len(t) < MIN_SAMPLES:
        raise CalibrationError(f"{source}: only {len(t)} samples in the fit window (need {MIN_SAMPLES})",
                               "film at a higher frame rate (see calibration/protocols/beam.md) "
                               "or widen --start-s/--end-s")
    return t, y


def _least_squares(t: np.ndarray, y: np.ndarray, fs_hz: float):
    """The damped oscillation of least squares from each start of the grid (scipy's result):
    the frequency between LOWEST_CYCLES over the window and Nyquist."""
    t0 = float(t[0])
    params = _parameters(t, fs_hz)
    lo, hi = params.bounds()
    fn = params["natural_frequency_hz"]
    best = None
    for fn0, zeta0 in _start_values(t, y, fn.lower, fn.upper):
        c0, a0, b0 = _linear_part(t - t0, y, fn0, zeta0)
        start = dict(zip(params.free, (c0, a0, b0, fn0, zeta0)))
        p0 = np.clip(params.as_vector(start), np.nextafter(lo, np.inf), np.nextafter(hi, -np.inf))
        res = optimize.least_squares(lambda p: damped_oscillation(t, p, t0) - y, p0, bounds=(lo, hi),
                                     x_scale="jac", method="trf")
        if best is None or res.cost < best.cost:
            best = res
    return best


def _past_release(t: np.ndarray, y: np.ndarray, fs_hz: float, pinned: bool = False):
    """The window from where the oscillator holds, and its least-squares fit: (t, y, fit).

    The drop can leave a release transient the model does not explain (a finger leaving
    the mass, a higher mode of the strip dying out in a few milliseconds). A sample of the
    first ``RELEASE_S`` whose residual is more than ``RELEASE_Z`` times the noise of the rest
    of the window (its median absolute deviation) is such a transient: the window then
    starts after the last one and is fitted again. ``pinned``: the user gave the start.
    """
    best = _least_squares(t, y, fs_hz)
    while not pinned:
        r = best.fun
        lead = max(int(np.sum(t - t[0] < RELEASE_S)), 1)
        noise = 1.4826 * float(np.median(np.abs(r[lead:] - np.median(r[lead:]))))
        off = np.flatnonzero(np.abs(r[:lead]) > RELEASE_Z * noise)
        if not off.size or len(t) - off[-1] - 1 < MIN_SAMPLES:
            break
        t, y = t[off[-1] + 1:], y[off[-1] + 1:]
        best = _least_squares(t, y, fs_hz)
    return t, y, best


def _start_shift(t: np.ndarray, y: np.ndarray, fs_hz: float, best) -> np.ndarray:
    """How far the fitted values move when the window starts one sample later: what the
    start of a ring-down the model may not wholly explain (the drop's first frames) does to
    them, added to their uncertainty as a type-B part."""
    t1, y1 = t[1:], y[1:]
    t0 = float(t[0])
    res = optimize.least_squares(lambda p: damped_oscillation(t1, p, t0) - y1, best.x,
                                 bounds=_parameters(t, fs_hz).bounds(),
                                 x_scale="jac", method="trf")
    return res.x - best.x


def _parameters(t: np.ndarray, fs_hz: float) -> FitParameters:
    """The oscillation's values (:func:`damped_oscillation`'s ``p``, in its order), each the
    solver's variable itself: the offset and the two amplitudes unbounded, the frequency
    between ``LOWEST_CYCLES`` over the window and Nyquist, the damping ratio within
    ``ZETA_BOUNDS``. Their start comes from the grid (:func:`_start_values`)."""
    return FitParameters([
        FitParameter("offset_m", "m", 0.0),
        FitParameter("amplitude_cos_m", "m", 0.0),
        FitParameter("amplitude_sin_m", "m", 0.0),
        FitParameter("natural_frequency_hz", "Hz", LOWEST_CYCLES / (t[-1] - t[0]), LOWEST_CYCLES / (t[-1] - t[0]),
                     fs_hz / 2),
        FitParameter("damping_ratio", "1", ZETA_BOUNDS[0], *ZETA_BOUNDS),
    ])


def _checked_oscillation(p: np.ndarray, r: np.ndarray, t: np.ndarray, fs_hz: float,
                         source: str) -> tuple[float, float, float, float]:
    """(RMS residual, amplitude, natural frequency, damping ratio) of the fit, after refusing an
    oscillation lost in the noise, one that does not ring, too few cycles or too few frames a cycle."""
    rms = float(np.sqrt(np.mean(r**2)))
    amp = float(np.hypot(p[1], p[2]))
    if amp < 5 * rms:
        raise CalibrationError(
            f"{source}: flat signal, no oscillation above the noise (amplitude {amp * 1e3:.3g} mm, "
            f"residual {rms * 1e3:.3g} mm)",
            "drop the mass from higher, or track the tip more closely (see calibration/protocols/beam.md)",
        )
    fn, zeta = float(p[3]), float(p[4])
    creep = ("a tip that creeps to its new rest without ringing (a mass lowered by hand) has no oscillation "
             "to fit: add --static to read its static deflection (k = m*g/deflection)")
    if zeta >= 0.999 * ZETA_BOUNDS[1]:
        raise CalibrationError(f"{source}: no ring-down, the fitted damping ratio is at its bound {ZETA_BOUNDS[1]} "
                               f"({fn:.3g} Hz)", creep)
    cycles = (t[-1] - t[0]) * fn
    if cycles < MIN_CYCLES:
        raise CalibrationError(f"{source}: the fit window covers {cycles:.2g} oscillations (need {MIN_CYCLES})",
                               "record longer after the drop; " + creep)
    if fs_hz < MIN_FRAMES_PER_CYCLE * fn:
        raise CalibrationError(f"{source}: {fs_hz:.3g} frames/s for a {fn:.3g} Hz oscillation "
                               f"(need {MIN_FRAMES_PER_CYCLE:g} frames a cycle)",
                               "film in slow motion (see calibration/protocols/beam.md)")
    return rms, amp, fn, zeta


def _window(t_s: np.ndarray, d: np.ndarray, start_s: float | None, end_s: float | None) -> np.ndarray:
    """Samples to fit: from the drop (or ``start_s``) to ``end_s``.

    Before the drop the tip rests at its starting level; the drop is the first sample at
    which the tip has left that level by a quarter of its whole range, a few milliseconds
    after the mass landed. From then on the tip and the mass stuck to it move freely, and
    the fit takes the whole first swing: the fastest part of a heavily damped ring-down,
    where most of what fixes its frequency is.
    """
    end = t_s[-1] if end_s is None else end_s
    if start_s is None:
        level = np.median(d[:max(len(d) // 20, 3)])
        start_s = t_s[int(np.argmax(np.abs(d - level) > 0.25 * np.ptp(d)))]
    return (t_s >= start_s) & (t_s <= end)


def _start_values(t: np.ndarray, y: np.ndarray, fn_low_hz: float, fn_high_hz: float) -> list[tuple[float, float]]:
    """Starts (fn [Hz], zeta) for the least-squares fit: the best few of a grid.

    For each (fn, zeta) of a grid (fn log-spaced ``START_FN_STEP`` apart over the band the
    fit allows, zeta in ``START_ZETAS``) the offset and the two amplitudes, linear in the
    model, are solved exactly; the grid points of least residual that are local minima
    along fn are the starts. Every frequency is tried on the whole ring-down, heavily damped
    (one or two visible cycles) or not, so the start cannot lock onto the record's length
    or a noise peak the way a spectrum's highest peak can. Only the first ``START_SAMPLES``
    samples are looked at (8.5 s at 240 frames/s: the ring-down after the drop), so the grid's
    memory and time stay bounded on a long recording; the fit itself takes the whole window.
    """
    t, y = t[:START_SAMPLES], y[:START_SAMPLES]
    tau = t - t[0]
    fns = np.exp(np.arange(np.log(fn_low_hz), np.log(fn_high_hz), np.log1p(START_FN_STEP)))
    zetas = np.asarray(START_ZETAS)
    wn = 2 * np.pi * fns[:, None]
    pole = (-zetas * wn + 1j * wn * np.sqrt(1 - zetas**2)).astype(np.complex128)
    e = np.exp(pole[..., None] * tau)                # env*cos + i env*sin, (fn, zeta, samples)
    s1, s2, sa = e.sum(-1), (e * e).sum(-1), (e.real**2 + e.imag**2).sum(-1)
    gram = np.empty(e.shape[:2] + (3, 3))
    gram[..., 0, 0] = len(tau)
    gram[..., 0, 1] = gram[..., 1, 0] = s1.real
    gram[..., 0, 2] = gram[..., 2, 0] = s1.imag
    gram[..., 1, 1] = (sa + s2.real) / 2
    gram[..., 2, 2] = (sa - s2.real) / 2
    gram[..., 1, 2] = gram[..., 2, 1] = s2.imag / 2
    ey = e @ y
    rhs = np.stack([np.full(ey.shape, y.sum()), ey.real, ey.imag], axis=-1)
    coef = np.linalg.solve(gram + 1e-12 * np.eye(3) * np.trace(gram, axis1=-2, axis2=-1)[..., None, None],
                           rhs[..., None])[..., 0]
    ssr = float(y @ y) - np.einsum("fzi,fzi->fz", coef, rhs)
    profile = ssr.min(axis=1)                    # best zeta at each frequency
    inner = np.r_[True, profile[1:] <= profile[:-1]] & np.r_[profile[:-1] <= profile[1:], True]
    minima = np.flatnonzero(inner)
    minima = minima[np.argsort(profile[minima])][:START_COUNT]
    return [(float(fns[i]), float(zetas[int(np.argmin(ssr[i]))])) for i in minima]


def _linear_part(tau: np.ndarray, y: np.ndarray, fn_hz: float, zeta: float) -> np.ndarray:
    """Offset c and amplitudes A, B of the model at given fn and zeta (linear least squares)."""
    wn = 2 * np.pi * fn_hz
    env = np.exp(-zeta * wn * tau)
    phase = wn * np.sqrt(1 - zeta**2) * tau
    basis = np.column_stack([np.ones_like(tau), env * np.cos(phase), env * np.sin(phase)])
    return np.linalg.lstsq(basis, y, rcond=None)[0]
