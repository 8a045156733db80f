"""Servo step response -> kp, kv and torque limit of the model's position servo.

The test rig, as a one-joint MuJoCo model: the servo horn carries a load (the battery) of
inertia ``J`` about the servo axis; optionally the load's weight gives a moment
``-M*cos(angle)`` (angle from the horizontal, positive lifting the load), where ``M`` is
the moment with the horn horizontal. The servo is the same MuJoCo ``position`` actuator the
robot model uses::

    torque = clip(kp*(command - angle) - kv*velocity, -limit, +limit)

(``gainprm[0] = kp``, ``biasprm = [0, -kp, -kv]``, ``forcerange = [-limit, limit]``).

The three gains are identified by simulating the rig with MuJoCo for a batch of candidate
gains at once (``mujoco.rollout``, one model per candidate) and minimising the angle error
with MuJoCo's own least-squares solver (``mujoco.minimize.least_squares``, in log-gains so
that kp ~ 1 and kv ~ 0.01 are scaled alike). Standard errors come from the residual
Jacobian at the optimum. A parameter is reported *not identifiable* when its 95% interval
is wider than its value allows to use, e.g. kp and kv when the step is torque-limited
throughout (the linear range ``limit/kp`` is then hidden in the angle noise), or the limit
when the torque never reaches it.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import mujoco
import numpy as np
from mujoco import minimize, rollout

from ..errors import CalibrationError
from .curves import Curves
from .fitstats import Estimate, covariance

G_M_PER_S2 = 9.81
PARAMS = ("kp_nm_per_rad", "kv_nms_per_rad", "torque_limit_nm")
LOG_LOWER = np.log([1e-3, 1e-6, 1e-4])
LOG_UPPER = np.log([1e4, 10.0, 100.0])
MAX_RELATIVE_STD = 0.25   # identifiable: 95% interval within about +-50% of the value
MIN_SAMPLES = 20
MIN_STEP_DEG = 5.0


@dataclass(frozen=True)
class ServoRig:
    """The test rig: load inertia about the servo axis, and its gravity moment."""

    inertia_kgm2: float
    gravity_moment_nm: float = 0.0   # load weight x lever arm, horn horizontal (angle 0)
    timestep_s: float = 1e-4


@dataclass(frozen=True)
class ServoGains:
    kp_nm_per_rad: float
    kv_nms_per_rad: float
    torque_limit_nm: float

    def as_array(self) -> np.ndarray:
        return np.array([self.kp_nm_per_rad, self.kv_nms_per_rad, self.torque_limit_nm])


@dataclass(frozen=True)
class ServoFit:
    source: str
    rig: ServoRig
    kp_nm_per_rad: Estimate
    kv_nms_per_rad: Estimate
    torque_limit_nm: Estimate
    identifiable: dict[str, bool]
    notes: list[str]
    rms_residual_deg: float
    n_samples: int
    saturated_fraction: float      # share of samples after the step with the torque at its limit
    linear_range_deg: float        # |command - angle| below which the servo is not torque limited (at rest)
    iterations: int
    curves: Curves = field(repr=False)

    def summary(self) -> dict:
        out = {"experiment": "servo", "source": self.source, "inertia_kgm2": self.rig.inertia_kgm2,
               "gravity_moment_nm": self.rig.gravity_moment_nm}
        for name in PARAMS:
            out[name] = {**getattr(self, name).as_dict(), "identifiable": self.identifiable[name]}
        out.update(rms_residual_deg=self.rms_residual_deg, n_samples=self.n_samples,
                   saturated_fraction=self.saturated_fraction, linear_range_deg=self.linear_range_deg,
                   iterations=self.iterations, notes=self.notes)
        return out


# -- the rig model --------------------------------------------------------------------
def rig_model(rig: ServoRig, gains: ServoGains | None = None) -> mujoco.MjModel:
    """One hinge (axis -y, so positive angles lift a load hanging along +x) and the servo."""
    if not rig.inertia_kgm2 > 0:
        raise CalibrationError(f"--inertia-kgm2 must be positive (got {rig.inertia_kgm2})",
                               "the load's moment of inertia about the servo axis, e.g. m*r^2 for a battery at radius r")
    j, moment = rig.inertia_kgm2, abs(rig.gravity_moment_nm)
    if moment > 0:
        # A point-like load at radius r with m*g*r = M and m*r^2 <= J: put half the inertia
        # in the load's offset, the rest about its own centre.
        r = 0.5 * j * G_M_PER_S2 / moment
        mass = moment / (G_M_PER_S2 * r)
        x = math.copysign(r, rig.gravity_moment_nm)
    else:
        mass, x = 1.0, 0.0
    jc = j - mass * x * x
    gains = gains or ServoGains(1.0, 0.01, 1.0)
    xml = f"""
<mujoco model="servo_rig">
  <option timestep="{rig.timestep_s}" integrator="implicitfast" gravity="0 0 {-G_M_PER_S2}"/>
  <worldbody>
    <body name="horn">
      <joint name="servo" type="hinge" axis="0 -1 0" damping="0"/>
      <inertial pos="{x!r} 0 0" mass="{mass!r}" diaginertia="{jc!r} {jc!r} {jc!r}"/>
    </body>
  </worldbody>
  <actuator>
    <position name="servo" joint="servo" kp="1" kv="0.01" forcelimited="true" forcerange="-1 1"/>
  </actuator>
</mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    # a diverging candidate must show as NaN (and be rejected), not be silently reset
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
    return with_gains(model, gains)


def with_gains(model: mujoco.MjModel, gains: ServoGains) -> mujoco.MjModel:
    """A copy of ``model`` whose servo has ``gains`` (the position actuator's parameters)."""
    m = copy.copy(model)
    kp, kv, limit = gains.as_array()
    m.actuator_gainprm[0, 0] = kp
    m.actuator_biasprm[0, :3] = (0.0, -kp, -kv)
    m.actuator_forcerange[0] = (-limit, limit)
    return m


def simulate_deg(model: mujoco.MjModel, gains: list[ServoGains], t_s: np.ndarray, command_deg: np.ndarray,
                 angle0_deg: float) -> np.ndarray:
    """Angle [deg] at the times ``t_s`` for each candidate in ``gains``: shape (len(gains), len(t_s)).

    One rollout of the batch of models; the command is held between samples (a servo's
    PWM command changes in steps).
    """
    dt = model.opt.timestep
    nstep = int(math.ceil((t_s[-1] - t_s[0]) / dt)) + 1
    step_t = t_s[0] + dt * np.arange(nstep)
    idx = np.clip(np.searchsorted(t_s, step_t, side="right") - 1, 0, len(t_s) - 1)
    ctrl = np.radians(command_deg[idx])[None, :, None]
    data = mujoco.MjData(model)
    data.qpos[0] = math.radians(angle0_deg)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    models = [with_gains(model, g) for g in gains]
    state, _ = rollout.rollout(models, data, state0[None], ctrl)
    qpos_col = 1  # FULLPHYSICS: time, qpos, qvel, ...
    q = np.concatenate([np.full((len(gains), 1), math.radians(angle0_deg)), state[:, :, qpos_col]], axis=1)
    grid = np.concatenate([[t_s[0]], step_t + dt])
    return np.degrees(np.array([np.interp(t_s, grid, qi) for qi in q]))


# -- the fit ----------------------------------------------------------------------------
def fit_servo(t_s: np.ndarray, angle_deg: np.ndarray, command_deg: np.ndarray, rig: ServoRig, *,
              source: str = "servo", max_iter: int = 60,
              progress: Callable[[int], None] | None = None) -> ServoFit:
    """Identify kp, kv and the torque limit from one step response; see the module docstring."""
    t = np.asarray(t_s, dtype=float)
    q = np.asarray(angle_deg, dtype=float)
    u = np.asarray(command_deg, dtype=float)
    step_i = _step_index(u, source)
    step_deg = float(u[step_i] - u[max(step_i - 1, 0)]) if step_i > 0 else float(u[0] - q[0])
    if np.ptp(q) < 0.2 * max(abs(step_deg), MIN_STEP_DEG):
        raise CalibrationError(
            f"{source}: flat signal, the horn moved {np.ptp(q):.3g} deg for a {step_deg:.3g} deg step",
            "check that the angle column follows the horn (or the --pivot of the horn track)")
    if len(t) - step_i < MIN_SAMPLES:
        raise CalibrationError(f"{source}: only {len(t) - step_i} samples after the step (need {MIN_SAMPLES})",
                               "film at 240 frames/s or more and keep recording until the horn is still")
    # Start the model at rest at the held angle, one sample before the step: the hold
    # before it says nothing about the gains that a real servo's deadband would not spoil.
    angle0 = float(np.mean(q[: step_i])) if step_i > 0 else float(q[0])
    i0 = max(step_i - 1, 0)
    t, q, u, step_i = t[i0:], q[i0:], u[i0:], step_i - i0
    model = rig_model(rig)

    def residual(logp: np.ndarray) -> np.ndarray:
        p = np.exp(np.atleast_2d(logp.T)).reshape(-1, 3)
        sim = simulate_deg(model, [ServoGains(*row) for row in p], t, u, angle0)
        r = np.radians(sim - q[None, :]).T
        return np.where(np.isfinite(r), r, 1e3)

    bounds = _log_bounds(rig)
    x0 = _initial_guess(t, q, u, step_i, rig, residual, bounds)
    iterations = []

    def on_iter(trace):
        iterations.append(len(trace))
        if progress:
            progress(1)

    logp, trace = minimize.least_squares(x0, residual, bounds=bounds, max_iter=max_iter,
                                         verbose=0, iter_callback=on_iter, xtol=1e-10, gtol=1e-12)
    logp = np.asarray(logp).ravel()
    p = np.exp(logp)
    r = residual(logp.reshape(3, 1)).ravel()
    jac_log, _ = minimize.jacobian_fd(residual, logp.reshape(3, 1), r.reshape(-1, 1), np.float64(1e-6), 0,
                                      [b.reshape(3, 1) for b in bounds])
    cov = covariance(jac_log / p[None, :], r)   # d r / d p = d r / d log p / p
    est = [cov.parameter(p, i) for i in range(3)]
    gains = ServoGains(*p)
    sat, peak = _torque_profile(model, gains, t, u, angle0, step_i)
    profile = _profile_ok(residual, logp, r)
    final_error_deg = float(np.mean(np.abs(u - q)[-max(len(q) // 5, 1):]))
    identifiable, notes = _identifiability(est, gains, sat, peak, r, logp, bounds, step_deg, final_error_deg)
    for name, flat in profile.items():
        if identifiable[name] and not flat:
            identifiable[name] = False
            notes.append(f"{name} is not identifiable from this recording: halving or doubling it changes the fit "
                         "by less than the noise (its value is only bounded on one side)")
    sim = simulate_deg(model, [gains], t, u, angle0)[0]
    fine_t = np.linspace(t[0], t[-1], 2000)
    fine_u = u[np.clip(np.searchsorted(t, fine_t, side="right") - 1, 0, len(t) - 1)]
    curves = Curves(x=t, data=q, model=sim, x_label="t [s]", y_label="horn angle [deg]",
                    title=f"servo: {Path(source).name}", model_x=fine_t,
                    model_fine=simulate_deg(model, [gains], fine_t, fine_u, angle0)[0])
    return ServoFit(
        source=source, rig=rig, kp_nm_per_rad=est[0], kv_nms_per_rad=est[1], torque_limit_nm=est[2],
        identifiable=identifiable, notes=notes, rms_residual_deg=float(np.degrees(np.sqrt(np.mean(r**2)))),
        n_samples=len(t), saturated_fraction=sat, linear_range_deg=float(np.degrees(p[2] / p[0])),
        iterations=len(trace), curves=curves,
    )


def _step_index(u: np.ndarray, source: str) -> int:
    """Index of the first sample at the new command (the step)."""
    changes = np.flatnonzero(np.abs(np.diff(u)) > 1e-9)
    if len(changes) == 0:
        return 0  # the command was already at its target when the recording started
    return int(changes[0]) + 1


def _log_bounds(rig: ServoRig) -> tuple[np.ndarray, np.ndarray]:
    """Search box in log-gains; kp is capped where the rig would oscillate faster than the
    simulation step resolves (omega*dt <= 0.5)."""
    upper = LOG_UPPER.copy()
    upper[0] = min(upper[0], math.log(0.25 * rig.inertia_kgm2 / rig.timestep_s**2))
    return LOG_LOWER.copy(), upper


def _initial_guess(t, q, u, step_i, rig, residual, bounds) -> np.ndarray:
    """A start for the solver: the torque limit from the time to half the step (constant
    acceleration at the limit), then the best of a small grid of limits, linear ranges and
    damping ratios, all simulated in one batch."""
    target, start = float(u[-1]), float(q[max(step_i - 1, 0)])
    span = math.radians(target - start)
    frac = np.radians(q - start) / span if abs(span) > 1e-9 else np.zeros_like(q)
    after = np.arange(len(q)) >= step_i
    crossed = np.flatnonzero(after & (frac >= 0.5))
    if len(crossed):
        i = int(crossed[0])
        t_half = float(np.interp(0.5, frac[i - 1:i + 1], t[i - 1:i + 1])) - t[max(step_i - 1, 0)]
        accel = abs(span) / max(t_half, 1e-6) ** 2
    else:
        accel = abs(span) / max(t[-1] - t[step_i], 1e-6) ** 2
    gravity = abs(rig.gravity_moment_nm) * abs(math.cos(math.radians(start) + 0.25 * span))
    limit0 = max(rig.inertia_kgm2 * accel + gravity, 1e-3)
    limits = [limit0 * f for f in (0.5, 0.7, 0.85, 1.0, 1.2, 1.4, 2.0)]
    final = float(np.mean(q[-max(len(q) // 5, 1):]))
    if abs(final - target) > 5.0 and rig.gravity_moment_nm:
        # stopped short of the target: a stall, where the limit balances the weight
        limits.append(abs(rig.gravity_moment_nm * math.cos(math.radians(final))))
    cands = []
    for limit in limits:
        for linear_rad in (0.005, 0.02, 0.08, 0.3, 1.0):
            kp = limit / linear_rad
            for zeta in (0.3, 0.7, 1.5):
                cands.append([kp, 2 * zeta * math.sqrt(kp * rig.inertia_kgm2), limit])
    lower, upper = bounds
    logc = np.clip(np.log(np.array(cands)), lower + 1e-6, upper - 1e-6).T
    cost = np.sum(residual(logc) ** 2, axis=0)
    return logc[:, int(np.argmin(cost))]


def _profile_ok(residual, logp: np.ndarray, r: np.ndarray) -> dict[str, bool]:
    """Whether halving *and* doubling each gain (the others kept) worsens the fit by more
    than two standard errors would. The Jacobian alone can call a gain determined at a
    point where it only just starts to act; this catches the one-sided cases."""
    ssr = float(r @ r)
    s2 = ssr / max(len(r) - 3, 1)
    trials = []
    for i in range(3):
        for factor in (0.5, 2.0):
            x = logp.copy()
            x[i] += math.log(factor)
            trials.append(x)
    rr = residual(np.array(trials).T)
    rise = np.sum(rr**2, axis=0) - ssr
    return {name: bool(min(rise[2 * i], rise[2 * i + 1]) > 4.0 * s2) for i, name in enumerate(PARAMS)}


def _torque_profile(model, gains: ServoGains, t, u, angle0, step_i) -> tuple[float, float]:
    """Along the fitted trajectory: the share of samples after the step with the torque at its
    limit, and the largest unclipped torque |kp*(command - angle) - kv*velocity|."""
    m = with_gains(model, gains)
    data = mujoco.MjData(m)
    data.qpos[0] = math.radians(angle0)
    kp, kv, limit = gains.as_array()
    n_sat = n_all = 0
    peak = 0.0
    for i in range(len(t) - 1):
        data.ctrl[0] = math.radians(u[i])
        while data.time < t[i + 1] - t[0] - 1e-12:
            mujoco.mj_step(m, data)
            peak = max(peak, abs(kp * (data.ctrl[0] - data.qpos[0]) - kv * data.qvel[0]))
        if i + 1 >= step_i:
            n_all += 1
            n_sat += abs(kp * (data.ctrl[0] - data.qpos[0]) - kv * data.qvel[0]) >= limit
    return n_sat / max(n_all, 1), peak


def _identifiability(est, gains: ServoGains, sat: float, peak: float, r: np.ndarray, logp: np.ndarray,
                     bounds: tuple[np.ndarray, np.ndarray], step_deg: float,
                     final_error_deg: float) -> tuple[dict[str, bool], list[str]]:
    ok = {name: bool(np.isfinite(e.std) and e.relative_std <= MAX_RELATIVE_STD) for name, e in zip(PARAMS, est)}
    notes = []
    for i, name in enumerate(PARAMS):
        if min(logp[i] - bounds[0][i], bounds[1][i] - logp[i]) < 1e-3:
            ok[name] = False
            notes.append(f"{name} ran to the edge of the search range ({est[i].value:.3g}): the recording does not bound it")
    rms_deg = float(np.degrees(np.sqrt(np.mean(r**2))))
    if rms_deg > max(3.0, 0.05 * abs(step_deg)):
        ok = dict.fromkeys(ok, False)
        notes.append(f"the model does not follow the recording (RMS {rms_deg:.3g} deg): no value is trustworthy; "
                     "check --inertia-kgm2, --gravity-moment-nm and the command column")
        return ok, notes
    noise_deg = float(np.degrees(np.sqrt(np.mean(r**2))))
    linear_deg = math.degrees(gains.torque_limit_nm / gains.kp_nm_per_rad)
    if final_error_deg > max(5.0, 3 * math.degrees(gains.torque_limit_nm / gains.kp_nm_per_rad)):
        ok["kp_nm_per_rad"] = ok["kv_nms_per_rad"] = False
        notes.append(f"the horn stalled {final_error_deg:.3g} deg short of the command: the servo was torque-limited "
                     "for the whole step, so kp_nm_per_rad and kv_nms_per_rad are not identifiable (the torque "
                     "limit is, from the stall); repeat with a load the servo can lift")
    if not ok["kp_nm_per_rad"] and not notes:
        notes.append(
            f"kp_nm_per_rad is not identifiable from this recording: the servo is torque-limited for "
            f"{100 * sat:.0f}% of the samples after the step and its linear range (|error| < limit/kp = "
            f"{linear_deg:.2g} deg) is hidden in the angle noise ({noise_deg:.2g} deg RMS); "
            "use a heavier load or a smaller step so that the approach to the target is visible")
    if not ok["kv_nms_per_rad"] and not notes:
        notes.append("kv_nms_per_rad is not identifiable from this recording: the velocity term never acts "
                     "outside the torque limit long enough to be seen")
    if peak < gains.torque_limit_nm * 1.001:
        ok["torque_limit_nm"] = False
        notes.append(f"torque_limit_nm is not identifiable: the torque never reaches a limit; the recording only "
                     f"shows limit >= {peak:.3g} N*m (use a larger step or a heavier load)")
    elif not ok["torque_limit_nm"]:
        notes.append("torque_limit_nm is not identifiable from this recording (its interval is too wide)")
    return ok, notes


def horn_angle_deg(x_m: np.ndarray, y_m: np.ndarray, pivot_x_m: float, pivot_y_m: float) -> np.ndarray:
    """Angle of the horn tip about the pivot, from the track's +x axis (y up), unwrapped."""
    return np.degrees(np.unwrap(np.arctan2(y_m - pivot_y_m, x_m - pivot_x_m)))
