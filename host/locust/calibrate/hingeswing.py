"""The swinging link of a hinge test and its equation of motion.

At any angle::

    I*theta'' = -k*(theta - theta0) - b*theta' [- M*g*D*cos(theta)] [- tau_c*sign(theta')]

(:mod:`.hinge` names the terms). :class:`HingeRig` is the link as given (its inertia about the
hinge, and for gravity in the swing's plane its mass and centre of mass), refused where no link
can be it (:func:`check_rig`). The swing from its start angle and rate is in closed form where
the equation is linear (no weight's moment, no Coulomb term: :func:`linear_swing`), else
integrated (LSODA, relative tolerance 1e-10) with its variational equations for the Jacobian
(:func:`swing_sensitivities`: one integration gives every column).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import integrate

from ..errors import CalibrationError
from ..params import GRAVITY_M_PER_S2

GRAVITY_CHOICES = ("in-plane", "out-of-plane")
RTOL = 1e-10          # LSODA's relative tolerance on the swing (its angle and rate)
ATOL = 1e-12          # ... and absolute [rad, rad/s]


@dataclass(frozen=True)
class HingeRig:
    """The swinging link: inertia about the hinge, and where its weight acts.

    Attributes
    ----------
    inertia_kgm2 : float
        The link's moment of inertia about the hinge.
    gravity : str
        ``"in-plane"`` (the link swings in a vertical plane) or ``"out-of-plane"`` (the hinge
        axis vertical: the weight has no moment).
    mass_kg : float
        The link's mass (in plane only).
    com_m : float
        Hinge to centre of mass, along the hinge-marker line (in plane only).
    """

    inertia_kgm2: float
    gravity: str = "out-of-plane"          # in-plane | out-of-plane
    mass_kg: float = 0.0
    com_m: float = 0.0                     # hinge to centre of mass [m], along the hinge-marker line

    @property
    def gravity_moment_nm(self) -> float:
        """M*g*D: the weight's largest moment about the hinge (0 out of plane)."""
        return self.mass_kg * GRAVITY_M_PER_S2 * self.com_m if self.gravity == "in-plane" else 0.0


def simulate_hinge(t_s: np.ndarray, params: np.ndarray, rig: HingeRig,
                   coulomb_width_rad_per_s: float = 0.0) -> np.ndarray:
    """The swing's angle from ``t_s[0]`` (see the module docstring): in closed form where the
    model is linear (no weight's moment, no Coulomb term), else integrated (LSODA).

    Parameters
    ----------
    t_s : array_like
        Times [s], increasing.
    params : array_like
        k [N*m/rad], b [N*m*s/rad], theta0 [rad], the angle [rad] and rate [rad/s] at
        ``t_s[0]``, and optionally tau_c [N*m].
    rig : HingeRig
        The link.
    coulomb_width_rad_per_s : float
        Rate over which the Coulomb torque turns (``tau_c * tanh(rate / width)``); must be
        positive when tau_c is nonzero.

    Returns
    -------
    numpy.ndarray
        theta at ``t_s`` [rad].
    """
    t = np.asarray(t_s, dtype=float) - t_s[0]
    if is_linear(params, rig):
        return linear_swing(t, params, rig.inertia_kgm2)
    return _integrate(t, params, rig, coulomb_width_rad_per_s, sensitivities=False)[:, 0]


def is_linear(params: np.ndarray, rig: HingeRig) -> bool:
    """Whether the swing equation is linear (no weight's moment, no Coulomb term): it then has
    a closed form.

    Parameters
    ----------
    params : array_like
        As :func:`simulate_hinge` takes them.
    rig : HingeRig

    Returns
    -------
    bool
    """
    return rig.gravity_moment_nm == 0 and len(params) == 5


def linear_swing(t: np.ndarray, params: np.ndarray, inertia_kgm2: float) -> np.ndarray:
    """The linear swing ``I*theta'' = -k*(theta - theta0) - b*theta'`` in closed form: under-,
    critically or over-damped, from the angle and rate at ``t = 0``.

    Parameters
    ----------
    t : numpy.ndarray
        Times from the start [s].
    params : array_like
        k [N*m/rad], b [N*m*s/rad], theta0 [rad], the start angle [rad] and rate [rad/s].
    inertia_kgm2 : float

    Returns
    -------
    numpy.ndarray
        theta at ``t`` [rad].
    """
    k, b, th0, th_start, w_start = (float(v) for v in params[:5])
    alpha = b / (2 * inertia_kgm2)
    wd2 = k / inertia_kgm2 - alpha * alpha
    u0 = th_start - th0
    v0 = w_start + alpha * u0
    decay = np.exp(-alpha * t)
    if wd2 > 0:
        wd = math.sqrt(wd2)
        u = decay * (u0 * np.cos(wd * t) + v0 * np.sin(wd * t) / wd)
    elif wd2 < 0:
        g = math.sqrt(-wd2)
        # e^(-alpha t) cosh(g t) and sinh(g t)/g without overflow (g t large) or cancellation (small)
        fast, slow = np.exp((g - alpha) * t), np.exp(-(g + alpha) * t)
        near = g * t < 1.0
        cosh_part = np.where(near, decay * np.cosh(np.where(near, g * t, 0.0)), (fast + slow) / 2)
        sinh_part = np.where(near, decay * np.sinh(np.where(near, g * t, 0.0)) / g, (fast - slow) / (2 * g))
        u = u0 * cosh_part + v0 * sinh_part
    else:
        u = decay * (u0 + v0 * t)
    return th0 + u


def swing_sensitivities(t_s: np.ndarray, params: np.ndarray, rig: HingeRig,
                        coulomb_width_rad_per_s: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The swing's angle and its derivative in each of ``params``, integrated together: the
    swing equation and its variational equations in one LSODA run, the step chosen by the
    swing's own tolerance (the derivatives follow the same steps). One integration gives
    every column of the fit's Jacobian, exact to the integrator's tolerance; finite
    differences would take one integration a column, each carrying the tolerance divided by
    the step (the step 3e-5: 2e-4 of the column, where these agree with wide central
    differences to 4e-6).

    Parameters
    ----------
    t_s : array_like
        Times [s], increasing.
    params : array_like
        As :func:`simulate_hinge` takes them (5, or 6 with tau_c).
    rig : HingeRig
    coulomb_width_rad_per_s : float
        As :func:`simulate_hinge`.

    Returns
    -------
    theta : numpy.ndarray, shape (n,)
        [rad].
    dtheta : numpy.ndarray, shape (n, len(params))
        d theta / d param, in rad per the parameter's unit.
    """
    t = np.asarray(t_s, dtype=float) - t_s[0]
    sol = _integrate(t, params, rig, coulomb_width_rad_per_s, sensitivities=True)
    return sol[:, 0], sol[:, 2:2 + len(params)]


def _integrate(t: np.ndarray, params: np.ndarray, rig: HingeRig, eps: float, *, sensitivities: bool) -> np.ndarray:
    """LSODA of the swing (columns theta, rate), with ``sensitivities`` its variational
    equations after them (d theta / d p for each p, then d rate / d p)."""
    k, b, th0, th_start, w_start = (float(v) for v in params[:5])
    tau_c = float(params[5]) if len(params) > 5 else 0.0
    n = len(params)
    inv_i, mgd = 1.0 / rig.inertia_kgm2, rig.gravity_moment_nm

    def rhs(_t, s):
        th, w = s[0], s[1]
        torque = -k * (th - th0) - b * w - mgd * math.cos(th)
        if tau_c:
            torque -= tau_c * math.tanh(w / eps)
        return [w, torque * inv_i]

    # the variational equations: d/dt (d theta / dp) = d rate / dp, and
    # d/dt (d rate / dp) = (d torque/d theta * d theta/dp + d torque/d rate * d rate/dp + d torque/dp) / I,
    # written out for the five values and for the six (with tau_c): LSODA calls this some
    # 10^4 times a swing, and a loop or a numpy array here costs it more than the arithmetic
    cos, sin, tanh = math.cos, math.sin, math.tanh

    def rhs5(_t, s):
        th, w, a1, a2, a3, a4, a5, r1, r2, r3, r4, r5 = s.tolist()
        torque = -k * (th - th0) - b * w - mgd * cos(th)
        ba, br = (-k + mgd * sin(th)) * inv_i, -b * inv_i
        return [w, torque * inv_i, r1, r2, r3, r4, r5,
                ba * a1 + br * r1 + (th0 - th) * inv_i, ba * a2 + br * r2 - w * inv_i,
                ba * a3 + br * r3 + k * inv_i, ba * a4 + br * r4, ba * a5 + br * r5]

    def rhs6(_t, s):
        th, w, a1, a2, a3, a4, a5, a6, r1, r2, r3, r4, r5, r6 = s.tolist()
        turn = tanh(w / eps)
        torque = -k * (th - th0) - b * w - mgd * cos(th) - tau_c * turn
        ba = (-k + mgd * sin(th)) * inv_i
        br = (-b - tau_c * (1.0 - turn * turn) / eps) * inv_i
        return [w, torque * inv_i, r1, r2, r3, r4, r5, r6,
                ba * a1 + br * r1 + (th0 - th) * inv_i, ba * a2 + br * r2 - w * inv_i,
                ba * a3 + br * r3 + k * inv_i, ba * a4 + br * r4, ba * a5 + br * r5,
                ba * a6 + br * r6 - turn * inv_i]

    if not sensitivities:
        return integrate.odeint(rhs, [th_start, w_start], t, tfirst=True, rtol=RTOL, atol=ATOL, mxstep=50000)
    start = np.zeros(2 + 2 * n)
    start[:2] = th_start, w_start
    start[2 + 3] = 1.0           # d theta / d start angle at the start
    start[2 + n + 4] = 1.0       # d rate / d start rate at the start
    # the step is the swing's: its two states carry the tolerance, the derivatives none of it
    rtol = np.r_[RTOL, RTOL, np.full(2 * n, RTOL)]
    atol = np.r_[ATOL, ATOL, np.full(2 * n, 1e300)]
    return integrate.odeint(rhs5 if n == 5 else rhs6, start, t, tfirst=True, rtol=rtol, atol=atol, mxstep=50000)



def check_rig(rig: HingeRig) -> None:
    """Refuse a rig no link can be: an inertia not positive, an unknown gravity, in-plane
    gravity without the weight's moment, or an inertia about the hinge below ``M*D^2`` (the
    parallel-axis theorem: the link's own inertia about its centre of mass is never negative).

    Parameters
    ----------
    rig : HingeRig

    Raises
    ------
    locust.errors.CalibrationError
        Naming the values and what a link of them would be.
    """
    _check_rig(rig)
    least = rig.mass_kg * rig.com_m ** 2
    if rig.gravity == "in-plane" and rig.inertia_kgm2 < least * (1 - 1e-9):
        raise CalibrationError(
            f"--inertia-kgm2 {rig.inertia_kgm2:g} is below --mass-kg x --com-m^2 = {rig.mass_kg:g} x "
            f"{rig.com_m:g}^2 = {least:.3g} kg*m^2: no link has less inertia about its hinge than its mass "
            "has at its centre of mass",
            "check the three (calibration/protocols/hinge.md): a uniform bar of mass M and length L hinged "
            "at one end has D = L/2 and I = M*L^2/3 = 4/3 M*D^2")


def _check_rig(rig: HingeRig) -> None:
    if not rig.inertia_kgm2 > 0:
        raise CalibrationError(f"--inertia-kgm2 must be positive (got {rig.inertia_kgm2})",
                               "the link's moment of inertia about the hinge, in kg*m^2 "
                               "(calibration/protocols/hinge.md)")
    if rig.gravity not in GRAVITY_CHOICES:
        raise CalibrationError(f"--gravity {rig.gravity!r}: expected in-plane or out-of-plane",
                               "in-plane: the link swings in a vertical plane; "
                               "out-of-plane: the hinge axis is vertical")
    if rig.gravity == "in-plane" and not (rig.mass_kg > 0 and rig.com_m > 0):
        raise CalibrationError("--gravity in-plane needs --mass-kg and --com-m (the weight's moment M*g*D)",
                               "weigh the link and measure the hinge-to-centre-of-mass distance "
                               "(calibration/protocols/hinge.md)")

