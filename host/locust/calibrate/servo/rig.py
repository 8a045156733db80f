"""The rig model: the servo's horn and its load as a one-joint MuJoCo model, each recording
simulated for many candidate servos at once, the residuals against the recordings, and the
curves of a recording against the model."""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from ...errors import CalibrationError
from ...params import GRAVITY_M_PER_S2, Servo
from ...sim.gl import mujoco  # MuJoCo as locust.sim imports it (its OpenGL checked first)
from ...sim.rollout import available_cores, rollout_threads
from ...sim.servo import configure, with_servo
from ..curves import Curves
from .recording import RATE_WINDOW_S, RateRecording, Recording, ServoRig, StepRecording, Timing

# one candidate: the servo, each recording's timing and each one's gyro gain (None: an angle recording)
Candidate = tuple[Servo, list[Timing], list[float | None]]


def rig_model(rig: ServoRig, servo: Servo | None = None) -> mujoco.MjModel:
    """The rig as a MuJoCo model: one hinge (axis -y, so positive angles lift a load hanging
    along +x) and the servo.

    Parameters
    ----------
    rig : ServoRig
        The load and the physics step.
    servo : Servo, optional
        The servo's values (default: :class:`~locust.params.Servo`'s).

    Returns
    -------
    mujoco.MjModel

    Raises
    ------
    CalibrationError
        An inertia not positive and finite.
    """
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
    """When each command change reaches the servo.

    Parameters
    ----------
    rec : StepRecording
        The recording (its command edges).
    timing : Timing
        Its delay and clock ratio.

    Returns
    -------
    numpy.ndarray
        One time per edge, on the camera's clock [s].
    """
    tm = rec.mean_edge_s
    return tm + timing.delay_s + (rec.t_s[rec.edges] - tm) * timing.clock_ratio


def simulate_deg(model: mujoco.MjModel, servos: list[Servo], timings: list[Timing], rec: StepRecording,
                 angle0_deg: float, t_out: np.ndarray | None = None) -> np.ndarray:
    """Angle [deg] at ``t_out`` (default: the recording's times) for each candidate: shape (n, len(t_out)).

    The command is held between edges, so between two edges the rig runs on its own: each
    edge is put on the nearest physics step and the response after it is read off shifted
    by the rounding. The simulated angle is then continuous in the timing (a saturated servo
    would otherwise not notice an edge moving inside one step), at no cost in steps.

    Parameters
    ----------
    model : mujoco.MjModel
        The rig (:func:`rig_model`).
    servos : list of Servo
        The candidates' servos.
    timings : list of Timing
        The candidates' timings, one per servo.
    rec : StepRecording
        The recording (its times and command).
    angle0_deg : float
        The horn's angle at the first sample [deg].
    t_out : array_like, optional
        Times to read the angle at [s] (default: the recording's).

    Returns
    -------
    numpy.ndarray, shape (len(servos), len(t_out))
        The angle [deg].
    """
    # candidates alike in servo and timing (a Jacobian's columns of another recording's
    # variables) share one simulation
    keys = list(zip(servos, timings))
    unique = list(dict.fromkeys(keys))
    if len(unique) < len(keys):
        sims = simulate_deg(model, [k[0] for k in unique], [k[1] for k in unique], rec, angle0_deg, t_out)
        return sims[[unique.index(k) for k in keys]]
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
    models = [with_servo(model, s, scratch=data) for s in servos]
    state, _, _ = rollout_threads(models, np.repeat(state0[None], len(servos), axis=0), ctrl)
    qpos_col = 1  # FULLPHYSICS: time, qpos, qvel, ...
    q = np.concatenate([np.full((len(servos), 1), math.radians(angle0_deg)), state[:, :, qpos_col]], axis=1)
    grid = t[0] + dt * np.arange(nstep + 1)
    return np.degrees(np.array([np.interp(rt, grid, qi) for rt, qi in zip(read_t, q)]))


def simulate_rate(model: mujoco.MjModel, servos: list[Servo], delays_s: list[float], rec: RateRecording,
                  t_out: np.ndarray | None = None) -> np.ndarray:
    """Horn speed [rad/s] at the fitted samples of a rate recording (``t_out``: other times,
    given per window as times after each edge, shape (windows, m)) for each candidate.

    Each step is simulated from rest at the previous command, the new command held from the
    moment it reaches the servo (the edge's time plus the delay): the speed is read at the
    samples' times after that moment, so it moves continuously with the delay.

    Parameters
    ----------
    model : mujoco.MjModel
        The rig (:func:`rig_model`).
    servos : list of Servo
        The candidates' servos.
    delays_s : list of float
        The candidates' delays [s], one per servo.
    rec : RateRecording
        The recording (its times, command and windows).
    t_out : list of array_like, optional
        Per window, the times after its edge to read the speed at [s].

    Returns
    -------
    numpy.ndarray, shape (len(servos), samples)
        The horn's speed [rad/s], the windows end to end.
    """
    dt = model.opt.timestep
    wins = rec.windows()
    t, u = rec.t_s, rec.command_deg
    after = ([t[first:end] - t[e] for e, first, end in wins] if t_out is None
             else [np.asarray(row, dtype=float) for row in t_out])
    span = max(float(a.max()) for a in after) - min(0.0, min(delays_s))
    nstep = math.ceil(span / dt) + 2
    # without a weight to lift, a step's response depends only on its size, and a step down is
    # a step up mirrored: each size is simulated once, from 0, and read with its sign
    # (exact for a symmetric clamp and damping; with a weight, each step from where it starts)
    steps = [(u[e - 1], u[e]) for e, _, _ in wins]
    if rec.rig.gravity_moment_nm == 0:
        sign = [1.0 if b > a else -1.0 for a, b in steps]
        steps = [(0.0, abs(b - a)) for a, b in steps]
    else:
        sign = [1.0] * len(steps)
    kinds = list(dict.fromkeys(steps))
    of_window = [kinds.index(st) for st in steps]
    nkind = len(kinds)
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    size = mujoco.mj_stateSize(model, spec)
    state0 = np.zeros((nkind, size))
    for w, (start, _) in enumerate(kinds):
        data.qpos[0], data.qvel[0] = math.radians(start), 0.0
        mujoco.mj_getState(model, data, state0[w], spec)
    ctrl = np.repeat(np.radians([end for _, end in kinds])[:, None, None], nstep, axis=1)
    # the delay only moves where the response is read: candidates that differ in it alone
    # (a Jacobian's timing and gain columns, the grid's delays) share one simulation
    unique = list(dict.fromkeys(servos))
    which = [unique.index(s) for s in servos]
    nsim = len(unique)
    models = [m for s in unique for m in [with_servo(model, s, scratch=data)] * nkind]
    state, _, _ = rollout_threads(models, np.tile(state0, (nsim, 1)), np.tile(ctrl, (nsim, 1, 1)))
    qvel_col = 1 + model.nq
    v = np.concatenate([np.zeros((nsim * nkind, 1)), state[:, :, qvel_col]], axis=1).reshape(nsim, nkind, -1)
    v = v[:, of_window] * np.array(sign)[None, :, None]
    grid = dt * np.arange(nstep + 1)
    out = []
    for c, delay in zip(which, delays_s):
        parts = [np.where(a > delay, np.interp(a - delay, grid, v[c, w]), 0.0) for w, a in enumerate(after)]
        out.append(np.concatenate(parts))
    return np.array(out)


def residuals(recs: list[Recording], models: list[mujoco.MjModel], cands: list[Candidate]) -> list[np.ndarray]:
    """Per recording, (candidates, samples) residuals in its own unit: rad (angle), gyro units (rate).

    The recordings are simulated side by side, one thread each (``mujoco.rollout`` releases
    the GIL): a line search's single candidate then uses a core per recording, and every
    figure is the same as one after the other.

    Parameters
    ----------
    recs : list of Recording
        The recordings (checked).
    models : list of mujoco.MjModel
        Each one's rig (:func:`rig_model`).
    cands : list of Candidate
        The candidates: a servo, each recording's timing and each one's gyro gain.

    Returns
    -------
    list of numpy.ndarray
        One (candidates, samples) array per recording; a rate recording's samples weighed by
        :meth:`RateRecording.sample_weights`.
    """
    servos = [c[0] for c in cands]

    def part(k: int) -> np.ndarray:
        rec, model = recs[k], models[k]
        if rec.kind == "angle":
            sim = simulate_deg(model, servos, [c[1][k] for c in cands], rec, float(rec.angle_deg[0]))
            return np.radians(sim - rec.angle_deg[None, :])
        sim = simulate_rate(model, servos, [c[1][k].delay_s for c in cands], rec)
        gains = np.array([c[2][k] for c in cands])[:, None]
        return (gains * sim - rec.rate_units[rec.samples()][None, :]) * rec.sample_weights()[None, :]

    workers = min(len(recs), available_cores())
    if workers < 2:
        return [part(k) for k in range(len(recs))]
    with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="locust-servo-fit") as pool:
        return list(pool.map(part, range(len(recs))))


def rms_in_unit(rec: Recording, part: np.ndarray, gain: float | None) -> float:
    """RMS of one recording's residual in deg (angle) or rad/s (rate).

    Parameters
    ----------
    rec : Recording
        The recording.
    part : numpy.ndarray
        Its residual for one candidate (:func:`residuals`).
    gain : float or None
        A rate recording's gyro gain [gyro units per rad/s].

    Returns
    -------
    float
        The RMS [deg] or [rad/s].
    """
    rms = float(np.sqrt(np.mean(part ** 2)))
    return math.degrees(rms) if rec.kind == "angle" else rms / abs(gain)


def recording_curves(model, servo: Servo, timing: Timing, gain: float | None, rec: Recording,
                     label: str = "") -> Curves:
    """The recording against the model: the angle [deg] over time, or the speed [rad/s] over
    each step's window, the windows laid end to end.

    Parameters
    ----------
    model : mujoco.MjModel
        The rig (:func:`rig_model`).
    servo : Servo
        The servo.
    timing : Timing
        The recording's timing.
    gain : float or None
        A rate recording's gyro gain [gyro units per rad/s] (None for an angle one).
    rec : Recording
        The recording.
    label : str
        Put before the recording's name in the title.

    Returns
    -------
    Curves
    """
    name = f"{label}{Path(rec.source).name}"
    if rec.kind == "angle":
        sim = simulate_deg(model, [servo], [timing], rec, float(rec.angle_deg[0]))[0]
        fine_t = np.linspace(rec.t_s[0], rec.t_s[-1], 3000)
        fine = simulate_deg(model, [servo], [timing], rec, float(rec.angle_deg[0]), t_out=fine_t)[0]
        return Curves(x=rec.t_s, data=rec.angle_deg, model=sim, x_label="t [s]", y_label="horn angle [deg]",
                      title=f"servo: {name}", model_x=fine_t, model_fine=fine)
    wins = rec.windows()
    offsets = np.arange(len(wins)) * RATE_WINDOW_S * 1.25
    x = np.concatenate([rec.t_s[first:end] - rec.t_s[e] + off for (e, first, end), off in zip(wins, offsets)])
    fine_after = [np.linspace(rec.t_s[first] - rec.t_s[e], rec.t_s[end - 1] - rec.t_s[e], 120)
                  for e, first, end in wins]
    sim = simulate_rate(model, [servo], [timing.delay_s], rec)[0]
    fine = simulate_rate(model, [servo], [timing.delay_s], rec, t_out=fine_after)[0]
    fine_x = np.concatenate([a + off for a, off in zip(fine_after, offsets)])
    return Curves(x=x, data=rec.rate_units[rec.samples()] / gain, model=sim,
                  x_label="t after each command step [s] (steps laid end to end)",
                  y_label="horn speed [rad/s]", title=f"servo: {name}", model_x=fine_x, model_fine=fine)
