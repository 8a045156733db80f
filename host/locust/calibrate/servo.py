"""Servo step responses -> no-load speed, armature and kp of the hobby-servo model.

The test rig, as a one-joint MuJoCo model: the servo horn carries a load (the battery) of
inertia ``J`` about the servo axis; optionally the load's weight gives a moment
``-M*cos(angle)`` (angle from the horizontal, positive lifting the load), where ``M`` is the
moment with the horn horizontal. The servo is the robot model's (:mod:`locust.sim.servo`)::

    (J + armature) * acc = clip(kp*(command(t) - angle), +-stall) - (stall/noload)*velocity - M*cos(angle)

Dividing by ``stall`` shows what one recording can tell: ``noload``, ``(J + armature)/stall``
and ``kp/stall``. The stall torque (a stall test, the datasheet: ``--stall-torque-nm``)
splits the ratios; so does a second recording with another load, or a load whose weight the
servo must hold (``gravity_moment_nm``), and the stall torque is then fitted too.

The recording's command column is the firmware's command, on the firmware's clock, while
the angle is on the camera's; each recording gets two timing parameters: a delay (the
servo's latency, plus any offset of the reconstructed command edges) and, when it holds
three or more command edges, the ratio of the two clocks. Both are fitted and reported;
neither is a property of the servo, and neither is written to ``robot.toml``.

All candidates of a solver iteration are simulated at once (``mujoco.rollout``, one model
per candidate) and the angle error is minimised with MuJoCo's own least-squares solver
(``mujoco.minimize.least_squares``) from the best few points of a batched grid. Standard
errors come from the residual Jacobian at the optimum; a parameter is reported *not
identifiable* when its 95% interval is wider than about +-50%, when it ran to the edge of
its range, or when halving and doubling it changes the fit by less than the noise.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import mujoco
import numpy as np
from mujoco import minimize, rollout

from ..errors import CalibrationError
from ..params import GRAVITY_M_PER_S2, Servo
from ..sim.servo import configure, with_servo
from .curves import Curves
from .fitstats import Estimate, covariance

PARAMS = ("noload_speed_rad_per_s", "armature_kgm2", "kp_nm_per_rad", "stall_torque_nm")
# search box of the physical parameters (wide: an SG90 sits well inside it)
LOWER = {"noload_speed_rad_per_s": 0.5, "armature_kgm2": 1e-8, "kp_nm_per_rad": 1e-3, "stall_torque_nm": 1e-3}
UPPER = {"noload_speed_rad_per_s": 200.0, "armature_kgm2": 1e-1, "kp_nm_per_rad": 1e3, "stall_torque_nm": 50.0}
DELAY_SCALE_S = 0.01          # the solver works in delay / 10 ms and (clock ratio - 1) / 1e-3
CLOCK_SCALE = 1e-3
MAX_DELAY_S = 0.2
MAX_CLOCK_ERROR = 0.05
MAX_RELATIVE_STD = 0.25   # identifiable: 95% interval within about +-50% of the value
MIN_SAMPLES = 20
MIN_STEP_DEG = 5.0
MIN_EDGES_FOR_CLOCK = 3
STARTS = 2                # solver runs from the best points of the grid (distinct armatures)
FD_STEP = 1e-6


@dataclass(frozen=True)
class ServoRig:
    """The test rig: load inertia about the servo axis, and its gravity moment."""

    inertia_kgm2: float
    gravity_moment_nm: float = 0.0   # load weight x lever arm, horn horizontal (angle 0)
    timestep_s: float = 1e-3     # converged: docs/servo.md compares 5e-4


@dataclass(frozen=True)
class StepRecording:
    """One recording: sample times, horn angle and the firmware's command (degrees)."""

    t_s: np.ndarray
    angle_deg: np.ndarray
    command_deg: np.ndarray
    rig: ServoRig
    source: str = "servo"

    @property
    def edges(self) -> np.ndarray:
        """Indices of the samples where the command changes."""
        return np.flatnonzero(np.abs(np.diff(self.command_deg)) > 1e-9) + 1

    @property
    def mean_edge_s(self) -> float:
        """Mean time of the command edges: the origin of :class:`Timing`'s clock ratio."""
        edges = self.edges
        return float(np.mean(self.t_s[edges])) if len(edges) else float(self.t_s[0])


@dataclass(frozen=True)
class Timing:
    """When the command reaches the servo: ``t_servo = tm + delay + (t_command - tm) * clock_ratio``,
    with ``tm`` the mean time of the recording's command edges (so that the delay is the mean
    latency, and delay and clock ratio are nearly independent in the fit)."""

    delay_s: float = 0.0
    clock_ratio: float = 1.0


@dataclass(frozen=True)
class ServoFit:
    source: str
    recordings: list[StepRecording] = field(repr=False)
    estimates: dict[str, Estimate]           # PARAMS -> value; a given stall torque has std 0
    stall_torque_given: bool
    timings: list[Timing]
    timing_std: list[tuple[float, float]]
    identifiable: dict[str, bool]
    notes: list[str]
    rms_residual_deg: float
    rms_per_recording_deg: list[float]
    timestep_s: float
    rms_half_step_deg: float                 # the same fit simulated at half the step: convergence
    n_samples: int
    iterations: int
    wall_s: float
    curves: Curves = field(repr=False)

    @property
    def servo(self) -> Servo:
        """The fitted servo (other fields at their defaults)."""
        return Servo(**{name: self.estimates[name].value for name in PARAMS})

    def summary(self) -> dict:
        out = {"experiment": "servo", "source": self.source,
               "inertia_kgm2": [r.rig.inertia_kgm2 for r in self.recordings],
               "gravity_moment_nm": [r.rig.gravity_moment_nm for r in self.recordings]}
        for name in PARAMS:
            est = self.estimates[name]
            entry = {**est.as_dict(), "identifiable": self.identifiable[name]}
            if name == "stall_torque_nm" and self.stall_torque_given:
                entry = {"value": est.value, "std": None, "ci95": [None, None], "identifiable": True,
                         "given": True}
            out[name] = entry
        out["command_delay_s"] = [round(t.delay_s, 5) for t in self.timings]
        out["command_delay_std_s"] = [round(s[0], 5) for s in self.timing_std]
        out["command_clock_ratio"] = [round(t.clock_ratio, 6) for t in self.timings]
        out["command_clock_ratio_std"] = [round(s[1], 6) for s in self.timing_std]
        out.update(rms_residual_deg=self.rms_residual_deg, rms_per_recording_deg=self.rms_per_recording_deg,
                   timestep_s=self.timestep_s, rms_half_step_deg=self.rms_half_step_deg,
                   n_samples=self.n_samples, iterations=self.iterations, wall_s=round(self.wall_s, 2),
                   notes=self.notes)
        return out


# -- the rig model --------------------------------------------------------------------
def rig_model(rig: ServoRig, servo: Servo | None = None) -> mujoco.MjModel:
    """One hinge (axis -y, so positive angles lift a load hanging along +x) and the servo."""
    if not (rig.inertia_kgm2 > 0 and math.isfinite(rig.inertia_kgm2)):
        raise CalibrationError(f"--inertia-kgm2 must be positive (got {rig.inertia_kgm2})",
                               "the load's moment of inertia about the servo axis, "
                               "e.g. m*r^2 for a battery at radius r")
    j, moment = rig.inertia_kgm2, abs(rig.gravity_moment_nm)
    if moment > 0:
        # A point-like load at radius r with m*g*r = M and m*r^2 <= J: put half the inertia
        # in the load's offset, the rest about its own centre.
        r = 0.5 * j * GRAVITY_M_PER_S2 / moment
        mass = moment / (GRAVITY_M_PER_S2 * r)
        x = math.copysign(r, rig.gravity_moment_nm)
    else:
        mass, x = 1.0, 0.0
    jc = j - mass * x * x
    spec = mujoco.MjSpec()
    spec.modelname = "servo_rig"
    spec.option.timestep = rig.timestep_s
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = [0.0, 0.0, -GRAVITY_M_PER_S2]
    # a diverging candidate must show as NaN (and be rejected), not be silently reset
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
    horn = spec.worldbody.add_body(name="horn", mass=mass, ipos=[x, 0, 0], inertia=[jc, jc, jc])
    joint = horn.add_joint(name="servo", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, -1, 0])
    act = spec.add_actuator(name="servo", target="servo", trntype=mujoco.mjtTrn.mjTRN_JOINT)
    configure(joint, act, servo or Servo())
    return spec.compile()


def servo_edges_s(rec: StepRecording, timing: Timing) -> np.ndarray:
    """When each command change reaches the servo, on the camera's clock [s]."""
    tm = rec.mean_edge_s
    return tm + timing.delay_s + (rec.t_s[rec.edges] - tm) * timing.clock_ratio


def simulate_deg(model: mujoco.MjModel, servos: list[Servo], timings: list[Timing], rec: StepRecording,
                 angle0_deg: float, t_out: np.ndarray | None = None) -> np.ndarray:
    """Angle [deg] at ``t_out`` (default: the recording's times) for each candidate: shape (n, len(t_out)).

    The command is held between edges, so between two edges the rig runs on its own: each
    edge is put on the nearest physics step and the response after it is read off shifted
    by the rounding. The simulated angle is then continuous in the timing (a saturated servo
    would otherwise not notice an edge moving inside one step), at no cost in steps.
    """
    t, u = rec.t_s, rec.command_deg
    t_out = t if t_out is None else np.asarray(t_out, dtype=float)
    dt = model.opt.timestep
    nstep = math.ceil((t[-1] - t[0]) / dt) + 1
    held = np.radians(np.concatenate([[u[0]], u[rec.edges]]))   # command before the first edge, after each
    steps = np.arange(nstep)
    ctrl = np.empty((len(servos), nstep, 1))
    read_t = np.empty((len(servos), len(t_out)))
    for c, timing in enumerate(timings):
        edge_s = servo_edges_s(rec, timing)
        edge_step = np.clip(np.rint((edge_s - t[0]) / dt), 0, nstep).astype(int)
        shift_s = edge_s - (t[0] + edge_step * dt)
        ctrl[c, :, 0] = held[np.searchsorted(edge_step, steps, side="right")]
        segment = np.maximum(np.searchsorted(edge_s, t_out, side="right") - 1, 0)
        read_t[c] = t_out - shift_s[segment]
    data = mujoco.MjData(model)
    data.qpos[0] = math.radians(angle0_deg)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state0, spec)
    models = [with_servo(model, s) for s in servos]
    state, _ = rollout.rollout(models, data, np.repeat(state0[None], len(servos), axis=0), ctrl)
    qpos_col = 1  # FULLPHYSICS: time, qpos, qvel, ...
    q = np.concatenate([np.full((len(servos), 1), math.radians(angle0_deg)), state[:, :, qpos_col]], axis=1)
    grid = t[0] + dt * np.arange(nstep + 1)
    return np.degrees(np.array([np.interp(rt, grid, qi) for rt, qi in zip(read_t, q)]))


# -- the fit ----------------------------------------------------------------------------
@dataclass(frozen=True)
class _Layout:
    """Which solver variables there are: log of each fitted physical parameter, then per
    recording the scaled delay and (if it has enough edges) the scaled clock error."""

    fitted: tuple[str, ...]
    clock: tuple[bool, ...]
    stall_given: float | None

    @property
    def size(self) -> int:
        return len(self.fitted) + len(self.clock) + sum(self.clock)

    def unpack(self, x: np.ndarray) -> tuple[Servo, list[Timing]]:
        values = dict(zip(self.fitted, np.exp(x[:len(self.fitted)])))
        if self.stall_given is not None:
            values["stall_torque_nm"] = self.stall_given
        timings, i = [], len(self.fitted)
        for has_clock in self.clock:
            delay = float(x[i]) * DELAY_SCALE_S
            i += 1
            ratio = 1.0
            if has_clock:
                ratio = 1.0 + float(x[i]) * CLOCK_SCALE
                i += 1
            timings.append(Timing(delay, ratio))
        return Servo(**{k: float(v) for k, v in values.items()}), timings

    def timing_scales(self) -> list[float]:
        """Physical size of one solver unit of each timing variable, in order."""
        return [s for has_clock in self.clock
                for s in ((DELAY_SCALE_S, CLOCK_SCALE) if has_clock else (DELAY_SCALE_S,))]

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo = [math.log(LOWER[n]) for n in self.fitted]
        hi = [math.log(UPPER[n]) for n in self.fitted]
        for has_clock in self.clock:
            lo.append(-MAX_DELAY_S / DELAY_SCALE_S)
            hi.append(MAX_DELAY_S / DELAY_SCALE_S)
            if has_clock:
                lo.append(-MAX_CLOCK_ERROR / CLOCK_SCALE)
                hi.append(MAX_CLOCK_ERROR / CLOCK_SCALE)
        return np.array(lo), np.array(hi)


def fit_servo(recordings: list[StepRecording], stall_torque_nm: float | None = None, *, max_iter: int = 60,
              progress: Callable[[int], None] | None = None) -> ServoFit:
    """Identify the servo from one or more step recordings; see the module docstring."""
    import time

    t_start = time.perf_counter()
    if not recordings:
        raise CalibrationError("no recording given", "give the CSV of a servo step")
    recs = [_checked(r) for r in recordings]
    if stall_torque_nm is not None and not (stall_torque_nm > 0 and math.isfinite(stall_torque_nm)):
        raise CalibrationError(f"--stall-torque-nm must be positive (got {stall_torque_nm})",
                               "the SG90's datasheet gives about 0.15 N*m")
    if stall_torque_nm is None and len({r.rig.inertia_kgm2 for r in recs}) < 2 \
            and not any(r.rig.gravity_moment_nm for r in recs):
        raise CalibrationError(
            "one load gives only ratios (speed, armature/stall, kp/stall): the stall torque is needed to split them",
            "give --stall-torque-nm (stall test or datasheet: about 0.15 N*m for an SG90), or a second recording "
            "with another load")
    fitted = tuple(n for n in PARAMS if not (n == "stall_torque_nm" and stall_torque_nm is not None))
    layout = _Layout(fitted, tuple(len(r.edges) >= MIN_EDGES_FOR_CLOCK for r in recs), stall_torque_nm)
    models = [rig_model(r.rig) for r in recs]
    angle0 = [float(r.angle_deg[0]) for r in recs]

    def residual(x: np.ndarray) -> np.ndarray:
        xs = np.atleast_2d(np.asarray(x).T).reshape(-1, layout.size)
        cands = [layout.unpack(row) for row in xs]
        parts = []
        for k, (rec, model) in enumerate(zip(recs, models)):
            sim = simulate_deg(model, [c[0] for c in cands], [c[1][k] for c in cands], rec, angle0[k])
            parts.append(np.radians(sim - rec.angle_deg[None, :]))
        r = np.concatenate(parts, axis=1).T
        return np.where(np.isfinite(r), r, 1e3)

    bounds = layout.bounds()
    starts = _grid_starts(recs, layout, residual, bounds)
    best, best_cost, iterations = None, math.inf, 0
    for x0 in starts:
        def on_iter(trace):
            if progress:
                progress(1)
        x, trace = minimize.least_squares(x0, residual, bounds=bounds, max_iter=max_iter, verbose=0,
                                          iter_callback=on_iter, eps=FD_STEP, xtol=1e-8, gtol=1e-10)
        x = np.asarray(x).ravel()
        iterations += len(trace)
        cost = float(np.sum(residual(x.reshape(-1, 1)) ** 2))
        if cost < best_cost:
            best, best_cost = x, cost
    x = best
    r = residual(x.reshape(-1, 1)).ravel()
    jac, _ = minimize.jacobian_fd(residual, x.reshape(-1, 1), r.reshape(-1, 1), np.float64(1e-6), 0,
                                  [b.reshape(-1, 1) for b in bounds])
    nphys = len(fitted)
    phys = np.exp(x[:nphys])
    scale = np.concatenate([phys, layout.timing_scales()])
    # d r / d p = d r / d x / (d p / d x): p = exp(x) for the physical ones, p = scale*x for timing
    cov = covariance(jac / scale[None, :], r)
    servo, timings = layout.unpack(x)
    estimates, identifiable = {}, {}
    for i, name in enumerate(fitted):
        estimates[name] = cov.parameter(phys, i)
    if stall_torque_nm is not None:
        estimates["stall_torque_nm"] = Estimate(stall_torque_nm, 0.0, stall_torque_nm, stall_torque_nm)
        identifiable["stall_torque_nm"] = True
    tvals = np.concatenate([[t.delay_s] + ([t.clock_ratio] if c else []) for t, c in zip(timings, layout.clock)])
    stds = iter([cov.parameter(np.concatenate([phys, tvals]), nphys + j).std for j in range(len(tvals))])
    timing_std = [(next(stds), next(stds) if has_clock else 0.0) for has_clock in layout.clock]

    rms_deg = float(np.degrees(np.sqrt(np.mean(r**2))))
    per_rec, k0 = [], 0
    for rec in recs:
        n = len(rec.t_s)
        per_rec.append(float(np.degrees(np.sqrt(np.mean(r[k0:k0 + n] ** 2)))))
        k0 += n
    notes: list[str] = []
    profile = _profile_ok(residual, x, r, nphys)
    for i, name in enumerate(fitted):
        ok = bool(np.isfinite(estimates[name].std) and estimates[name].relative_std <= MAX_RELATIVE_STD)
        if min(x[i] - bounds[0][i], bounds[1][i] - x[i]) < 1e-3:
            ok = False
            notes.append(f"{name} ran to the edge of its range ({estimates[name].value:.3g}): the recording does "
                         "not bound it")
        elif ok and not profile[i]:
            ok = False
            notes.append(f"{name} is not identifiable from this recording: halving or doubling it changes the "
                         "fit by less than the noise")
        elif not ok:
            notes.append(f"{name} is not identifiable from this recording (its 95% interval is wider than "
                         f"about +-{200 * MAX_RELATIVE_STD:.0f}%)")
        identifiable[name] = ok
    _physics_notes(servo, recs, notes)
    steps = [abs(float(np.ptp(rec.command_deg))) for rec in recs]
    if rms_deg > max(3.0, 0.05 * max(steps)):
        identifiable = dict.fromkeys(identifiable, False)
        notes.insert(0, f"the model does not follow the recording (RMS {rms_deg:.3g} deg): no value is "
                        "trustworthy; check --inertia-kgm2, --gravity-moment-nm and the command column")
    rms_half = _rms_half_step(recs, servo, timings, angle0)
    if abs(rms_half - rms_deg) > 0.05 * rms_deg:
        notes.append(f"not converged in the time step: the fit's RMS is {rms_deg:.3g} deg at "
                     f"{recs[0].rig.timestep_s:g} s and {rms_half:.3g} deg at half of it")
    curves = _curves(models[0], servo, timings[0], recs[0], angle0[0])
    source = recs[0].source if len(recs) == 1 else "+".join(Path(rec.source).name for rec in recs)
    return ServoFit(source=source, recordings=recs, estimates=estimates, stall_torque_given=stall_torque_nm is not None,
                    timings=timings, timing_std=timing_std, identifiable=identifiable, notes=notes,
                    rms_residual_deg=rms_deg, rms_per_recording_deg=per_rec,
                    timestep_s=recs[0].rig.timestep_s, rms_half_step_deg=rms_half,
                    n_samples=int(sum(len(rec.t_s) for rec in recs)), iterations=iterations,
                    wall_s=time.perf_counter() - t_start, curves=curves)


def _checked(rec: StepRecording) -> StepRecording:
    t = np.asarray(rec.t_s, dtype=float)
    q = np.asarray(rec.angle_deg, dtype=float)
    u = np.asarray(rec.command_deg, dtype=float)
    rec = replace(rec, t_s=t, angle_deg=q, command_deg=u)
    if len(t) < MIN_SAMPLES:
        raise CalibrationError(f"{rec.source}: only {len(t)} samples (need {MIN_SAMPLES})",
                               "film at 30 frames/s or more and keep recording until the horn is still")
    edges = rec.edges
    if len(edges) == 0:
        raise CalibrationError(f"{rec.source}: the command never changes, so there is no step to fit",
                               "the command_deg column must hold the command sent, before and after the step")
    step_deg = float(np.max(np.abs(np.diff(u))))
    if np.ptp(q) < 0.2 * max(step_deg, MIN_STEP_DEG):
        raise CalibrationError(
            f"{rec.source}: flat signal, the horn moved {np.ptp(q):.3g} deg for a {step_deg:.3g} deg step",
            "check that the angle column follows the horn (or the --pivot of the horn track)")
    if len(t) - edges[0] < MIN_SAMPLES:
        raise CalibrationError(f"{rec.source}: only {len(t) - edges[0]} samples after the step (need {MIN_SAMPLES})",
                               "keep recording until the horn is still")
    return rec


def _speed_guess(rec: StepRecording) -> float:
    """No-load speed from the data: a high percentile of the angular speed between samples."""
    speed = np.abs(np.diff(np.radians(rec.angle_deg)) / np.diff(rec.t_s))
    moving = speed[speed > 0.2 * speed.max()]
    return float(np.percentile(moving, 75)) if moving.size else float(speed.max())


def _grid_starts(recs, layout: _Layout, residual, bounds) -> list[np.ndarray]:
    """Starting points: a grid of no-load speed (at and above the fastest speed seen: a load
    slows the servo), armature, linear range (stall/kp) and delay, simulated in one batch;
    the best few with distinct speed and armature."""
    stall = layout.stall_given or 0.15
    seen_speed = max(_speed_guess(rec) for rec in recs) * 1.02
    frame_s = float(np.median(np.diff(recs[0].t_s)))
    j = recs[0].rig.inertia_kgm2
    cands = []
    for noload in (seen_speed, 1.5 * seen_speed, 2.5 * seen_speed):
        timing = [_timing_guess(rec, noload) for rec in recs]
        for tau_s in (0.002, 0.01, 0.03):                        # mechanical time constant (J+Ja)/b
            armature = max(tau_s * stall / noload - j, LOWER["armature_kgm2"] * 10)
            for linear_deg in (3.0, 10.0, 25.0):
                for delay_frames in (-1.0, -0.5, 0.0, 0.5):
                    x = [math.log(noload), math.log(armature), math.log(stall / math.radians(linear_deg))]
                    if "stall_torque_nm" in layout.fitted:
                        x.append(math.log(stall))
                    for has_clock, (delay_s, ratio) in zip(layout.clock, timing):
                        x.append((delay_s - tau_s + delay_frames * frame_s) / DELAY_SCALE_S)
                        if has_clock:
                            x.append((ratio - 1.0) / CLOCK_SCALE)
                    cands.append(x)
    lo, hi = bounds
    xs = np.clip(np.array(cands), lo + 1e-6, hi - 1e-6)
    cost = np.sum(residual(xs.T) ** 2, axis=0)
    picked, seen = [], set()
    for i in np.argsort(cost):
        key = (round(xs[i, 0], 3), round(xs[i, 1], 3))
        if key not in seen:
            seen.add(key)
            picked.append(xs[i])
        if len(picked) == STARTS:
            break
    return picked


def _timing_guess(rec: StepRecording, noload: float) -> tuple[float, float]:
    """(delay, clock ratio) from when the horn passes the middle of each step: a straight
    line through (edge time, crossing time); at top speed the middle comes half a step late."""
    t, q, u = rec.t_s, rec.angle_deg, rec.command_deg
    edge_t, cross_t = [], []
    edges = list(rec.edges) + [len(t)]
    for i, end in itertools.pairwise(edges):
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


def _profile_ok(residual, x: np.ndarray, r: np.ndarray, nphys: int) -> list[bool]:
    """Whether halving *and* doubling each physical parameter (the others kept) worsens the
    fit by more than two standard errors would. The Jacobian alone can call a parameter
    determined at a point where it only just starts to act; this catches the one-sided cases."""
    ssr = float(r @ r)
    s2 = ssr / max(len(r) - len(x), 1)
    trials = []
    for i in range(nphys):
        for factor in (0.5, 2.0):
            xi = x.copy()
            xi[i] += math.log(factor)
            trials.append(xi)
    rr = residual(np.array(trials).T)
    rise = np.sum(rr**2, axis=0) - ssr
    return [bool(min(rise[2 * i], rise[2 * i + 1]) > 4.0 * s2) for i in range(nphys)]


def _physics_notes(servo: Servo, recs: list[StepRecording], notes: list[str]) -> None:
    """Plain-language facts about the fitted servo that a user should check."""
    linear_deg = math.degrees(servo.stall_torque_nm / servo.kp_nm_per_rad)
    j = recs[0].rig.inertia_kgm2
    tau_ms = 1000 * (j + servo.armature_kgm2) * servo.noload_speed_rad_per_s / servo.stall_torque_nm
    notes.append(f"top speed {servo.noload_speed_rad_per_s:.3g} rad/s, reached with a time constant of "
                 f"{tau_ms:.3g} ms on this load; full torque until {linear_deg:.3g} deg from the command")


def _rms_half_step(recs: list[StepRecording], servo: Servo, timings: list[Timing], angle0: list[float]) -> float:
    """RMS residual [deg] of the fitted servo simulated at half the fit's time step."""
    sq, n = 0.0, 0
    for rec, timing, a0 in zip(recs, timings, angle0):
        model = rig_model(replace(rec.rig, timestep_s=rec.rig.timestep_s / 2))
        err = simulate_deg(model, [servo], [timing], rec, a0)[0] - rec.angle_deg
        sq, n = sq + float(err @ err), n + len(err)
    return math.sqrt(sq / n)


def _curves(model, servo: Servo, timing: Timing, rec: StepRecording, angle0: float) -> Curves:
    sim = simulate_deg(model, [servo], [timing], rec, angle0)[0]
    fine_t = np.linspace(rec.t_s[0], rec.t_s[-1], 3000)
    fine = simulate_deg(model, [servo], [timing], rec, angle0, t_out=fine_t)[0]
    return Curves(x=rec.t_s, data=rec.angle_deg, model=sim, x_label="t [s]", y_label="horn angle [deg]",
                  title=f"servo: {Path(rec.source).name}", model_x=fine_t, model_fine=fine)


def horn_angle_deg(x_m: np.ndarray, y_m: np.ndarray, pivot_x_m: float, pivot_y_m: float) -> np.ndarray:
    """Angle of the horn tip about the pivot, from the track's +x axis (y up), unwrapped."""
    return np.degrees(np.unwrap(np.arctan2(y_m - pivot_y_m, x_m - pivot_x_m)))
