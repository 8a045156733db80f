"""Servo step responses -> no-load speed, armature, kp and kv of the hobby-servo model.

The test rig, as a one-joint MuJoCo model: the servo horn carries a load (the battery, a
gyro board) of inertia ``J`` about the servo axis; optionally the load's weight gives a
moment ``-M*cos(angle)`` (angle from the horizontal, positive lifting the load), where ``M``
is the moment with the horn horizontal. The servo is the robot model's
(:mod:`locust.sim.servo`)::

    (J + armature) * acc = clip(kp*(command(t) - angle) - kv*velocity, +-stall)
                           - (stall/noload)*velocity - M*cos(angle)

Dividing by ``stall`` shows what one recording can tell: ``noload``, ``(J + armature)/stall``
and ``kp/stall`` (and ``kv/stall``, which one large swing cannot tell from ``kp``: steps of
several sizes can). The stall torque (a stall test, the datasheet: ``--stall-torque-nm``)
splits the ratios; so does a second recording with another load, or a load whose weight the
servo must hold (``gravity_moment_nm``), and the stall torque is then fitted too.

Two kinds of recording are fitted, together if given together: an angle recording
(:class:`StepRecording`: a filmed horn) and a rate recording (:class:`RateRecording`: a gyro
on the horn, read by :mod:`.gyro_log`, its gain in its own unknown unit fitted too).

An angle recording's command column is the firmware's command, on the firmware's clock,
while the angle is on the camera's; it gets two timing parameters: a delay (the servo's
latency, plus any offset of the reconstructed command edges) and, when it holds three or
more command edges, the ratio of the two clocks. A gyro log has one clock: a delay only.
Both are fitted and reported; neither is a property of the servo, and neither is written
to ``robot.toml``.

The fitted values are named by their robot keys (``servo.noload_speed_rad_per_s``, ...:
``KEYS``); a recording's own values (``command_delay_s[k]``, ``command_clock_error[k]``,
``gyro_gain_units_per_rad_per_s[k]``) are named by what they are and written nowhere.

All candidates of a solver iteration are simulated at once (``mujoco.rollout``, one model
per candidate, on every core) and the error, each recording's divided by its own RMS, is minimised with
MuJoCo's own least-squares solver (``mujoco.minimize.least_squares``) from the best few
points of a batched grid. Standard errors come from the residual Jacobian at the optimum
(cluster-robust over the steps when there are enough of them); a parameter is reported *not
identifiable* when its 95% interval is wider than about +-50%, when it ran to the edge of
its range, or when halving and doubling it changes the fit by less than the noise.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..errors import CalibrationError
from ..params import GRAVITY_M_PER_S2, LIMITS, Servo
from ..params.model import split_key
from ..sim.gl import minimize, mujoco  # MuJoCo as locust.sim imports it (its OpenGL checked first)
from ..sim.rollout import available_cores, rollout_threads
from ..sim.servo import configure, with_servo
from .curves import Curves
from .fitparams import FitParameter, FitParameters
from .fitstats import Estimate, cluster_covariance, covariance, linear_shift

KEYS = ("servo.noload_speed_rad_per_s", "servo.armature_kgm2", "servo.kp_nm_per_rad", "servo.kv_nms_per_rad",
        "servo.stall_torque_nm")
UNITS = {"servo.noload_speed_rad_per_s": "rad/s", "servo.armature_kgm2": "kg*m^2", "servo.kp_nm_per_rad": "N*m/rad",
         "servo.kv_nms_per_rad": "N*m*s/rad", "servo.stall_torque_nm": "N*m"}
# search box of the physical parameters (wide: an SG90 sits well inside it)
LOWER = {"servo.noload_speed_rad_per_s": 0.5, "servo.armature_kgm2": 1e-8, "servo.kp_nm_per_rad": 1e-3,
         "servo.kv_nms_per_rad": 1e-6, "servo.stall_torque_nm": 1e-3}
UPPER = {"servo.noload_speed_rad_per_s": 200.0, "servo.armature_kgm2": 1e-1, "servo.kp_nm_per_rad": 1e3,
         "servo.kv_nms_per_rad": 10.0, "servo.stall_torque_nm": 50.0}
DELAY_SCALE_S = 0.01          # the solver works in delay / 10 ms and (clock ratio - 1) / 1e-3
CLOCK_SCALE = 1e-3
MAX_DELAY_S = 0.2
MAX_CLOCK_ERROR = 0.05
MAX_RELATIVE_STD = 0.25   # identifiable: 95% interval within about +-50% of the value
MIN_SAMPLES = 20
MIN_STEP_DEG = 5.0
MIN_EDGES_FOR_CLOCK = 3
RATE_WINDOW_S = 0.8       # a rate recording's step is fitted this long after its edge (an SG90 settles in 0.5 s)
RATE_PRE_SAMPLES = 2      # ... and from this many samples before it (at rest)
# The samples of one step share their errors (the model is not the servo, the command's
# PWM period moves each edge): with enough steps the covariance is cluster-robust, each
# step a cluster (fitstats.cluster_covariance); with fewer, s^2 (J^T J)^-1.
CLUSTERS_PER_PARAMETER = 2
STARTS = 2                # solver runs from the best points of the grid (distinct armatures)
MAX_ITER = 60             # iterations of one solver run at most
EXPECTED_ITERATIONS = 15  # what a run takes, for progress until one has run (both SG90s: 43 in 3 runs)
# the solver's regularisation grows by this factor after each rejected step (MuJoCo's default
# 10**0.1): at the optimum, where every step is rejected, a run ends after a few dozen single
# simulations instead of about 140 (both SG90 recordings: the same values to 6 digits, 32 -> 21 s
# of CPU)
MU_FACTOR = 10 ** 0.5
FD_STEP = 1e-6


def servo_of(values) -> Servo:
    """The servo of the fit's values.

    Parameters
    ----------
    values : mapping of str to float
        At least each of ``KEYS``, by its robot key.

    Returns
    -------
    locust.params.Servo
        Those values, its other fields at their defaults.
    """
    return Servo(**{split_key(key)[1]: values[key] for key in KEYS})


def values_of(servo: Servo) -> dict[str, float]:
    """A servo's values of ``KEYS``, by their robot keys (the inverse of :func:`servo_of`).

    Parameters
    ----------
    servo : locust.params.Servo
        The servo.

    Returns
    -------
    dict of str to float
    """
    return {key: getattr(servo, split_key(key)[1]) for key in KEYS}


@dataclass(frozen=True)
class ServoRig:
    """The test rig: load inertia about the servo axis, and its gravity moment.

    Attributes
    ----------
    inertia_kgm2 : float
        The load's moment of inertia about the servo axis.
    gravity_moment_nm : float
        The load's weight times its lever arm with the horn horizontal (angle 0); 0: no weight
        to lift.
    timestep_s : float
        The rig model's physics step.

    Raises
    ------
    CalibrationError
        A gravity moment beyond the stall torque's limit (a typo or a unit slip).
    """

    inertia_kgm2: float
    gravity_moment_nm: float = 0.0   # load weight x lever arm, horn horizontal (angle 0)
    timestep_s: float = 1e-3     # converged: docs/servo.md compares 5e-4

    def __post_init__(self):
        # a load no hobby servo holds up is a typo or a unit slip: the stall torque's limit
        most = LIMITS["servo.stall_torque_nm"]
        if not abs(self.gravity_moment_nm) <= most.high:
            raise CalibrationError(f"--gravity-moment-nm {self.gravity_moment_nm:g} is beyond +-{most.high:g} N*m "
                                   f"({most.reason})", "the load's weight x lever arm in N*m with the horn "
                                   "horizontal, e.g. 0.023 kg x 9.81 m/s^2 x 0.03 m = 0.0068")


class _Commanded:
    """What every recording has: sample times and the command [deg]."""

    t_s: np.ndarray
    command_deg: np.ndarray

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
class StepRecording(_Commanded):
    """An angle recording: sample times, horn angle and the firmware's command (degrees).

    Attributes
    ----------
    t_s : numpy.ndarray
        Sample times, on the camera's clock.
    angle_deg : numpy.ndarray
        The horn's angle.
    command_deg : numpy.ndarray
        The command sent, on the firmware's clock.
    rig : ServoRig
        The load it carried.
    source : str
        The recording's name.
    """

    t_s: np.ndarray
    angle_deg: np.ndarray
    command_deg: np.ndarray
    rig: ServoRig
    source: str = "servo"
    kind = "angle"


@dataclass(frozen=True)
class RateRecording(_Commanded):
    """A rate recording: a gyro on the horn, logged with the command on one clock. The gyro's
    unit is unknown (``rate_units``): its gain [units per rad/s] is fitted with the servo.
    Between steps the horn is at rest at the command (a level held for RATE_WINDOW_S or more);
    each step is simulated from rest and fitted over RATE_WINDOW_S after its edge.

    Attributes
    ----------
    t_s : numpy.ndarray
        Sample times, one clock for gyro and command.
    rate_units : numpy.ndarray
        The gyro's reading, in its own unit.
    command_deg : numpy.ndarray
        The command sent.
    rig : ServoRig
        The load it carried.
    source : str
        The recording's name.
    """

    t_s: np.ndarray
    rate_units: np.ndarray
    command_deg: np.ndarray
    rig: ServoRig
    source: str = "gyro"
    kind = "rate"

    def windows(self) -> list[tuple[int, int, int]]:
        """Each step's fitted window.

        Returns
        -------
        list of tuple of int
            (edge, first, end) sample indices: the command's change, the window's first sample
            (``RATE_PRE_SAMPLES`` before the edge, at rest) and one past its last (``RATE_WINDOW_S``
            after the edge, or the next edge).
        """
        edges = list(self.edges)
        sample_s = float(np.median(np.diff(self.t_s)))
        out = []
        for k, e in enumerate(edges):
            nxt = edges[k + 1] if k + 1 < len(edges) else len(self.t_s)
            end = min(nxt, int(np.searchsorted(self.t_s, self.t_s[e] + RATE_WINDOW_S)))
            first = max(e - RATE_PRE_SAMPLES, edges[k - 1] if k else 0,   # at rest, not across a gap in time
                        int(np.searchsorted(self.t_s, self.t_s[e] - (RATE_PRE_SAMPLES + 0.5) * sample_s)))
            out.append((e, first, end))
        return out

    def sample_weights(self) -> np.ndarray:
        """Weight of each fitted sample: each step's samples by the inverse of its peak reading
        (relative to the mean peak), so that every step counts by its relative error.

        Returns
        -------
        numpy.ndarray
            One dimensionless weight per fitted sample, in :meth:`samples`' order.
        """
        peaks = [max(float(np.max(np.abs(self.rate_units[e:end]))), 1.0) for e, _, end in self.windows()]
        mean = float(np.mean(peaks))
        return np.concatenate([np.full(end - first, mean / p) for (e, first, end), p in zip(self.windows(), peaks)])

    def samples(self) -> np.ndarray:
        """The fitted samples.

        Returns
        -------
        numpy.ndarray of int
            Their indices, every window's in order.
        """
        return np.concatenate([np.arange(first, end) for _, first, end in self.windows()])

    @property
    def gain_sign(self) -> float:
        """+1 when the gyro reads positive as the angle rises, -1 otherwise (from the data)."""
        u = self.command_deg
        total = sum(float(np.sum(self.rate_units[e:end])) * math.copysign(1, u[e] - u[e - 1])
                    for e, _, end in self.windows())
        return 1.0 if total >= 0 else -1.0

    def gain_guess(self) -> float:
        """|gain| [units per rad/s] from the data alone: the gyro's integral over each step
        against the step (the horn settles at the command).

        Returns
        -------
        float
            The gain's magnitude [gyro units per rad/s]; 1 when no step moves the command.
        """
        area, step = 0.0, 0.0
        for e, _, end in self.windows():
            area += abs(float(np.trapezoid(self.rate_units[e - 1:end], self.t_s[e - 1:end])))
            step += abs(math.radians(self.command_deg[e] - self.command_deg[e - 1]))
        return area / step if step > 0 else 1.0


Recording = StepRecording | RateRecording


@dataclass(frozen=True)
class Timing:
    """When the command reaches the servo: ``t_servo = tm + delay + (t_command - tm) * clock_ratio``,
    with ``tm`` the mean time of the recording's command edges (so that the delay is the mean
    latency, and delay and clock ratio are nearly independent in the fit).

    Attributes
    ----------
    delay_s : float
        Mean latency from command to servo.
    clock_ratio : float
        Camera seconds per firmware second (dimensionless).
    """

    delay_s: float = 0.0
    clock_ratio: float = 1.0


@dataclass(frozen=True)
class ServoFit:
    """The result of :func:`fit_servo`: the servo's values with their intervals, each
    recording's timing (and gyro gain), and how well the recordings fit.

    Attributes
    ----------
    source : str
        The recordings' names.
    recordings : list of Recording
        The recordings fitted (checked).
    estimates : dict of str to Estimate
        Each of ``KEYS`` by its robot key (units in the names); a held (given) one has std 0.
    given : tuple of str
        The ``KEYS`` held at a given value, not fitted.
    timings : list of Timing
        Each recording's fitted timing.
    timing_std : list of tuple of float
        Their standard uncertainties: (delay [s], clock ratio).
    gains : list of Estimate or None
        Per recording: a rate recording's gyro gain [gyro units per rad/s] (None for an angle one).
    identifiable : dict of str to bool
        Whether the data tell each value (see the module docstring), by its robot key.
    notes : list of str
        Why a value is not identifiable, misfits, convergence in the time step.
    rms_residual_deg : float or None
        RMS residual over the angle recordings (None: there are none).
    rms_per_recording : list of float
        Each recording's RMS residual in its unit: deg (angle), rad/s (rate).
    timestep_s : float
        The rig model's physics step.
    rms_half_step : list of float
        The same RMS at half the step: convergence.
    n_samples : int
        Samples fitted.
    iterations : int
        Solver iterations, all runs.
    wall_s : float
        Wall time the fit took.
    interval : str
        How the intervals were computed.
    curves : list of Curves
        Each recording against the model, for the plots.
    """

    source: str
    recordings: list[Recording] = field(repr=False)
    estimates: dict[str, Estimate]           # KEYS -> value; a held one (given) has std 0
    given: tuple[str, ...]                   # the KEYS held at a given value, not fitted
    timings: list[Timing]
    timing_std: list[tuple[float, float]]
    gains: list[Estimate | None]             # per recording: the gyro gain [units per rad/s] of a rate recording
    identifiable: dict[str, bool]
    notes: list[str]
    rms_residual_deg: float | None           # over the angle recordings (None: there are none)
    rms_per_recording: list[float]           # in each recording's unit: deg (angle), rad/s (rate)
    timestep_s: float
    rms_half_step: list[float]               # the same at half the step: convergence
    n_samples: int
    iterations: int
    wall_s: float
    interval: str = "s^2 (J^T J)^-1, t(n-p)"
    curves: list[Curves] = field(default_factory=list, repr=False)

    @property
    def servo(self) -> Servo:
        """The fitted servo (other fields at their defaults)."""
        return servo_of({key: self.estimates[key].value for key in KEYS})

    @property
    def rms_residual_rad_per_s(self) -> float | None:
        """RMS residual over the rate recordings [rad/s] (None: there are none)."""
        rates = [r for rec, r in zip(self.recordings, self.rms_per_recording) if rec.kind == "rate"]
        return float(np.sqrt(np.mean(np.square(rates)))) if rates else None

    @property
    def rate_gain(self) -> float | None:
        """The gyro's gain of the fitted rate recordings [gyro units per rad/s] (their mean; None without one)."""
        gains = [g.value for g in self.gains if g is not None]
        return float(np.mean(gains)) if gains else None

    def summary(self) -> dict:
        """The fit for JSON output.

        Returns
        -------
        dict
            ``experiment`` ("servo"), each recording's kind and rig, each of ``KEYS`` (by its
            robot key) as its :meth:`~.fitstats.Estimate.as_dict` with ``identifiable`` (a
            given one without interval), the timings and gains per recording, and the fit's
            figures.
        """
        out = {"experiment": "servo", "source": self.source,
               "kind": [r.kind for r in self.recordings],
               "inertia_kgm2": [r.rig.inertia_kgm2 for r in self.recordings],
               "gravity_moment_nm": [r.rig.gravity_moment_nm for r in self.recordings]}
        for key in KEYS:
            est = self.estimates[key]
            entry = {**est.as_dict(), "identifiable": self.identifiable[key]}
            if key in self.given:
                entry = {"value": est.value, "std": None, "ci95": [None, None], "identifiable": True,
                         "given": True}
            out[key] = entry
        out["interval"] = self.interval
        out["command_delay_s"] = [round(t.delay_s, 5) for t in self.timings]
        out["command_delay_std_s"] = [round(s[0], 5) for s in self.timing_std]
        out["command_clock_ratio"] = [round(t.clock_ratio, 6) for t in self.timings]
        out["command_clock_ratio_std"] = [round(s[1], 6) for s in self.timing_std]
        out["gyro_gain_units_per_rad_per_s"] = [g.as_dict() if g is not None else None for g in self.gains]
        out.update(rms_residual_deg=self.rms_residual_deg, rms_residual_rad_per_s=self.rms_residual_rad_per_s,
                   rms_per_recording=self.rms_per_recording,
                   rms_unit=["deg" if r.kind == "angle" else "rad/s" for r in self.recordings],
                   timestep_s=self.timestep_s, rms_half_step=self.rms_half_step,
                   n_samples=self.n_samples, iterations=self.iterations, wall_s=round(self.wall_s, 2),
                   notes=self.notes)
        return out


# -- the rig model --------------------------------------------------------------------
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


# -- the fit ----------------------------------------------------------------------------
class _Layout:
    """The fit's values (:class:`.fitparams.FitParameters`): the servo's physical ones, each
    log-scaled within ``LOWER``-``UPPER`` or held at a given value, then per recording its
    delay (in ``DELAY_SCALE_S``), when it has enough edges and two clocks its clock error
    (ratio - 1, in ``CLOCK_SCALE``), and for a rate recording the log of its gyro gain (the
    gain's sign held from the recording)."""

    def __init__(self, held: dict[str, float | None], clock: tuple[bool, ...], gain: tuple[bool, ...],
                 signs: tuple[float, ...] = ()):
        self.clock, self.gain = clock, gain
        params = []
        for key in KEYS:
            value = held.get(key)
            # a fitted one's nominal: the middle of its box in log (the grid's starts replace it)
            nominal = math.sqrt(LOWER[key] * UPPER[key]) if value is None else value
            params.append(FitParameter(key, UNITS[key], nominal, LOWER[key], UPPER[key], scaling="log",
                                       held=value is not None, source="given" if value is not None else ""))
        self._nuisance = []
        for k, (has_clock, has_gain) in enumerate(zip(clock, gain)):
            params.append(FitParameter(f"command_delay_s[{k}]", "s", 0.0, -MAX_DELAY_S, MAX_DELAY_S,
                                       scale=DELAY_SCALE_S))
            self._nuisance.append((k, "delay"))
            if has_clock:
                params.append(FitParameter(f"command_clock_error[{k}]", "1", 0.0, -MAX_CLOCK_ERROR, MAX_CLOCK_ERROR,
                                           scale=CLOCK_SCALE))
                self._nuisance.append((k, "clock"))
            if has_gain:
                sign = signs[k]
                params.append(FitParameter(f"gyro_gain_units_per_rad_per_s[{k}]", "units per rad/s", sign,
                                           sign * 1e-9, sign * 1e9, scaling="log", reference=sign))
                self._nuisance.append((k, "gain"))
        self.params = FitParameters(params)
        self.fitted = tuple(key for key in KEYS if key in self.params.free)

    @property
    def size(self) -> int:
        return self.params.size

    @property
    def stall_given(self) -> float | None:
        """The stall torque [N*m] when held, else None."""
        stall = self.params["servo.stall_torque_nm"]
        return stall.start if stall.held else None

    def unpack(self, x: np.ndarray) -> tuple[Servo, list[Timing], list[float | None]]:
        values = self.params.from_vector(x)
        timings, gains = [], []
        for k, (has_clock, has_gain) in enumerate(zip(self.clock, self.gain)):
            ratio = 1.0 + values[f"command_clock_error[{k}]"] if has_clock else 1.0
            timings.append(Timing(values[f"command_delay_s[{k}]"], ratio))
            gains.append(values[f"gyro_gain_units_per_rad_per_s[{k}]"] if has_gain else None)
        return servo_of(values), timings, gains

    def nuisance(self) -> list[tuple[int, str]]:
        """(recording, what) of each variable after the physical ones, in order."""
        return list(self._nuisance)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.params.bounds()


def _residual_parts(recs: list[Recording], models: list[mujoco.MjModel],
                    cands: list[tuple[Servo, list[Timing], list[float | None]]]) -> list[np.ndarray]:
    """Per recording, (candidates, samples) residuals in its own unit: rad (angle), gyro units (rate).

    The recordings are simulated side by side, one thread each (``mujoco.rollout`` releases
    the GIL): a line search's single candidate then uses a core per recording, and every
    figure is the same as one after the other.
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


def _rms_in_unit(rec: Recording, part: np.ndarray, gain: float | None) -> float:
    """RMS of one recording's residual in deg (angle) or rad/s (rate)."""
    rms = float(np.sqrt(np.mean(part ** 2)))
    return math.degrees(rms) if rec.kind == "angle" else rms / abs(gain)


def _checked_inputs(recordings: list[Recording], stall_torque_nm: float | None,
                    kv_nms_per_rad: float | None) -> list[Recording]:
    """The recordings, checked, and the held values refused where they cannot be used."""
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
    if kv_nms_per_rad is not None and not (kv_nms_per_rad >= 0 and math.isfinite(kv_nms_per_rad)):
        raise CalibrationError(f"--kv-nms-per-rad must be 0 or more (got {kv_nms_per_rad})",
                               "0 holds the servo without velocity feedback inside its drive")
    return recs


class _Residual:
    """The fit's residual vector for one or more candidate vectors ``x`` (columns), each
    recording's part in units of its noise (``scales``), so that recordings of different
    kinds weigh by their information: a first guess (1 deg; a gyro unit), then each one's
    own RMS (:meth:`weigh_by_own_noise`)."""

    def __init__(self, recs: list[Recording], layout: _Layout):
        self.recs, self.layout = recs, layout
        self.models = [rig_model(r.rig) for r in recs]
        self.scales = [math.radians(1.0) if r.kind == "angle" else 1.0 for r in recs]

    def __call__(self, x: np.ndarray, on: list[mujoco.MjModel] | None = None) -> np.ndarray:
        xs = np.atleast_2d(np.asarray(x).T).reshape(-1, self.layout.size)
        parts = _residual_parts(self.recs, on or self.models, [self.layout.unpack(row) for row in xs])
        r = np.concatenate([p / sc for p, sc in zip(parts, self.scales)], axis=1).T
        return np.where(np.isfinite(r), r, 1e3)

    def weigh_by_own_noise(self, x: np.ndarray) -> None:
        parts = _residual_parts(self.recs, self.models, [self.layout.unpack(x)])
        self.scales = [max(float(np.sqrt(np.mean(p ** 2))), 1e-12) for p in parts]


def _solve(residual: _Residual, max_iter: int, progress: Callable[[int], None] | None) -> tuple[np.ndarray, int]:
    """Least squares from each grid start, the best kept; with several recordings, each then
    weighed by its own noise and the best polished. Returns (x, iterations)."""
    # Progress: each run is max_iter steps, an iteration worth max_iter / (the iterations the
    # run before took; EXPECTED_ITERATIONS for the first), never past its run's end until it
    # ends; a run that ends early fills its share then. A bar's rate is then about a run's
    # time, and its time left the runs still to go (tests/test_calibrate_servo.py).
    shown = [0, EXPECTED_ITERATIONS]   # steps shown in this run, iterations the last run took

    def on_iter(trace):
        if progress:
            step = min(max(1, round(max_iter / shown[1])), max_iter - 1 - shown[0])
            if step > 0:
                shown[0] += step
                progress(step)

    def least_squares(x0):
        x, trace = minimize.least_squares(x0, residual, bounds=bounds, max_iter=max_iter, verbose=0,
                                          iter_callback=on_iter, eps=FD_STEP, xtol=1e-8, gtol=1e-10,
                                          mu_factor=MU_FACTOR)
        if progress:
            progress(max_iter - shown[0])
        shown[:] = [0, max(len(trace), 1)]
        return np.asarray(x).ravel(), len(trace)

    bounds = residual.layout.bounds()
    best, best_cost, iterations = None, math.inf, 0
    starts = _grid_starts(residual.recs, residual.layout, residual, bounds)
    if progress and len(starts) < STARTS:   # fewer distinct starts than planned
        progress(max_iter * (STARTS - len(starts)))
    for x0 in starts:
        x, n = least_squares(x0)
        iterations += n
        cost = float(np.sum(residual(x.reshape(-1, 1)) ** 2))
        if cost < best_cost:
            best, best_cost = x, cost
    x = best
    if len(residual.recs) > 1:   # weigh each recording by its own noise, and polish
        residual.weigh_by_own_noise(x)
        x, n = least_squares(x)
        iterations += n
    return x, iterations


def progress_steps(n_recordings: int, max_iter: int = MAX_ITER) -> int:
    """Steps that :func:`fit_servo`'s ``progress`` reports in all: ``max_iter`` per solver run,
    one per start and a polish with several recordings (see ``_solve``).

    Parameters
    ----------
    n_recordings : int
        Recordings to fit.
    max_iter : int
        Iterations of one solver run at most.

    Returns
    -------
    int
        The steps' total.
    """
    return (STARTS + (n_recordings > 1)) * max_iter


def _covariance(residual: _Residual, x: np.ndarray, r: np.ndarray):
    """The covariance of the values (physical, then nuisance) at the solution ``x``: clustered
    by servo step when there are enough steps, with the time step's shift as a type-B part."""
    recs, layout = residual.recs, residual.layout
    jac, _ = minimize.jacobian_fd(residual, x.reshape(-1, 1), r.reshape(-1, 1), np.float64(1e-6), 0,
                                  [b.reshape(-1, 1) for b in layout.bounds()])
    clusters = np.concatenate([_step_clusters(rec) + 10_000 * k for k, rec in enumerate(recs)])
    jac_p = layout.params.to_values_jacobian(jac, x)      # d r / d p = (d r / d x) / (d p / d x)
    # the fit's time step: implicitfast is first order, so the values' distance to the dt -> 0
    # limit is about twice their shift when the step is halved (Richardson); a type-B part
    half = [rig_model(replace(rec.rig, timestep_s=rec.rig.timestep_s / 2)) for rec in recs]
    shift = 2.0 * linear_shift(jac_p, residual(x.reshape(-1, 1), half).ravel() - r)
    if len(np.unique(clusters)) > CLUSTERS_PER_PARAMETER * layout.size:
        return cluster_covariance(jac_p, r, clusters, shift=shift)
    return replace(covariance(jac_p, r), shift=shift)


def _estimates(cov, values: np.ndarray, layout: _Layout, held: dict[str, float | None], n_recs: int):
    """Estimates of the physical values (the held ones exact), the timing std per recording
    (delay, clock) and the gain estimate of each rate recording."""
    estimates, identifiable = {}, {}
    for i, name in enumerate(layout.fitted):
        estimates[name] = cov.parameter(values, i)
    for name, value in held.items():
        if value is not None:
            estimates[name] = Estimate(value, 0.0, value, value)
            identifiable[name] = True
    timing_std = [[0.0, 0.0] for _ in range(n_recs)]
    gain_est: list[Estimate | None] = [None] * n_recs
    for j, (k, what) in enumerate(layout.nuisance()):
        est = cov.parameter(values, len(layout.fitted) + j)
        if what == "gain":
            gain_est[k] = est
        else:
            timing_std[k][0 if what == "delay" else 1] = est.std
    return estimates, identifiable, timing_std, gain_est


def _identifiable(residual: _Residual, x: np.ndarray, r: np.ndarray, estimates: dict[str, Estimate],
                  identifiable: dict[str, bool], notes: list[str]) -> None:
    """Mark each fitted value identifiable or not (interval, edge of its range, profile),
    with a note for each that is not."""
    fitted = residual.layout.fitted
    at_edge = residual.layout.params.near_bound(x, 1e-3)
    profile = _profile_ok(residual, x, r, len(fitted))
    for i, name in enumerate(fitted):
        ok = bool(np.isfinite(estimates[name].std) and estimates[name].relative_std <= MAX_RELATIVE_STD)
        if at_edge[i]:
            ok = False
            notes.append(f"{name} ran to the edge of its range ({estimates[name].value:.3g}): the recordings do "
                         "not bound it")
        elif ok and not profile[i]:
            ok = False
            notes.append(f"{name} is not identifiable from these recordings: halving or doubling it changes the "
                         "fit by less than the noise")
        elif not ok:
            notes.append(f"{name} is not identifiable from these recordings (its 95% interval is wider than "
                         f"about +-{200 * MAX_RELATIVE_STD:.0f}%)")
        identifiable[name] = ok


def _misfit_notes(recs: list[Recording], per_rec: list[float], gains: list[float | None],
                  identifiable: dict[str, bool], notes: list[str]) -> dict[str, bool]:
    """A recording the model does not follow makes every value untrustworthy: the
    identifiable flags then, all False, with the note first."""
    for rec, rms, g in zip(recs, per_rec, gains):
        if rec.kind == "angle":
            bad = rms > max(3.0, 0.05 * float(np.ptp(rec.command_deg)))
        else:
            bad = rms > 0.15 * float(np.max(np.abs(rec.rate_units))) / abs(g)
        if bad:
            identifiable = dict.fromkeys(identifiable, False)
            unit = "deg" if rec.kind == "angle" else "rad/s"
            notes.insert(0, f"the model does not follow {Path(rec.source).name} (RMS {rms:.3g} {unit}): no value "
                            "is trustworthy; check --inertia-kgm2, --gravity-moment-nm and the command column")
    return identifiable


def _convergence_notes(recs: list[Recording], per_rec: list[float], rms_half: list[float], notes: list[str]) -> None:
    """A note for each recording whose RMS moves by more than 5 % at half the time step."""
    for rec, full, half in zip(recs, per_rec, rms_half):
        if abs(half - full) > 0.05 * full:
            notes.append(f"not converged in the time step: {Path(rec.source).name}'s RMS is {full:.3g} at "
                         f"{rec.rig.timestep_s:g} s and {half:.3g} at half of it")


def fit_servo(recordings: list[Recording], stall_torque_nm: float | None = None, *,
              kv_nms_per_rad: float | None = None, max_iter: int = MAX_ITER,
              progress: Callable[[int], None] | None = None) -> ServoFit:
    """Identify the servo from one or more recordings (angle or rate); see the module docstring.
    ``stall_torque_nm`` and ``kv_nms_per_rad``, when given, are held at that value.

    Parameters
    ----------
    recordings : list of Recording
        Angle and rate recordings, fitted together.
    stall_torque_nm : float, optional
        The stall torque [N*m], held (a stall test, the datasheet); fitted when not given.
    kv_nms_per_rad : float, optional
        The servo law's velocity gain [N*m*s/rad], held; fitted when not given.
    max_iter : int
        Iterations of one solver run at most.
    progress : callable, optional
        Called with the number of steps done since its last call; they add up to
        :func:`progress_steps`.

    Returns
    -------
    ServoFit

    Raises
    ------
    CalibrationError
        No recording; a stall torque not positive or a negative kv; one load only (one
        inertia, no weight to lift) without a stall torque; or a recording too short, without
        a step, or with a flat signal.
    """
    import time

    t_start = time.perf_counter()
    recs = _checked_inputs(recordings, stall_torque_nm, kv_nms_per_rad)
    held = {"servo.stall_torque_nm": stall_torque_nm, "servo.kv_nms_per_rad": kv_nms_per_rad}
    layout = _Layout(held, tuple(r.kind == "angle" and len(r.edges) >= MIN_EDGES_FOR_CLOCK for r in recs),
                     tuple(r.kind == "rate" for r in recs),
                     tuple(r.gain_sign if r.kind == "rate" else 1.0 for r in recs))
    residual = _Residual(recs, layout)
    x, iterations = _solve(residual, max_iter, progress)
    r = residual(x.reshape(-1, 1)).ravel()
    servo, timings, gains = layout.unpack(x)
    cov = _covariance(residual, x, r)
    estimates, identifiable, timing_std, gain_est = _estimates(cov, layout.params.free_values(x), layout, held,
                                                               len(recs))

    parts = _residual_parts(recs, residual.models, [(servo, timings, gains)])
    per_rec = [_rms_in_unit(rec, p[0], g) for rec, p, g in zip(recs, parts, gains)]
    angle_rms = [(rms, len(rec.t_s)) for rec, rms in zip(recs, per_rec) if rec.kind == "angle"]
    rms_deg = (math.sqrt(sum(rms ** 2 * n for rms, n in angle_rms) / sum(n for _, n in angle_rms))
               if angle_rms else None)
    notes: list[str] = []
    _identifiable(residual, x, r, estimates, identifiable, notes)
    _physics_notes(servo, recs, notes)
    identifiable = _misfit_notes(recs, per_rec, gains, identifiable, notes)
    rms_half = _rms_half_step(recs, servo, timings, gains)
    _convergence_notes(recs, per_rec, rms_half, notes)
    curves = [recording_curves(model, servo, timing, gain, rec)
              for model, rec, timing, gain in zip(residual.models, recs, timings, gains)]
    source = recs[0].source if len(recs) == 1 else "+".join(Path(rec.source).name for rec in recs)
    given = tuple(n for n, v in held.items() if v is not None)
    return ServoFit(source=source, recordings=recs, estimates=estimates, given=given,
                    timings=timings, timing_std=[tuple(ts) for ts in timing_std], gains=gain_est,
                    identifiable=identifiable, notes=notes, rms_residual_deg=rms_deg, rms_per_recording=per_rec,
                    timestep_s=recs[0].rig.timestep_s, rms_half_step=rms_half,
                    n_samples=int(sum(p.shape[1] for p in parts)), iterations=iterations,
                    wall_s=time.perf_counter() - t_start, interval=cov.method, curves=curves)


def _step_clusters(rec: Recording) -> np.ndarray:
    """The step each fitted sample belongs to (0, 1, ...; samples before the first edge: 0)."""
    if rec.kind == "rate":
        return np.concatenate([np.full(end - first, k) for k, (_, first, end) in enumerate(rec.windows())])
    return np.maximum(np.searchsorted(rec.edges, np.arange(len(rec.t_s)), side="right") - 1, 0)


def _checked(rec: Recording) -> Recording:
    t = np.asarray(rec.t_s, dtype=float)
    u = np.asarray(rec.command_deg, dtype=float)
    if rec.kind == "angle":
        rec = replace(rec, t_s=t, angle_deg=np.asarray(rec.angle_deg, dtype=float), command_deg=u)
        moved = float(np.ptp(rec.angle_deg))
    else:
        rec = replace(rec, t_s=t, rate_units=np.asarray(rec.rate_units, dtype=float), command_deg=u)
    step_deg = float(np.max(np.abs(np.diff(u)))) if len(u) > 1 else 0.0
    if len(t) < MIN_SAMPLES:
        raise CalibrationError(f"{rec.source}: only {len(t)} samples (need {MIN_SAMPLES})",
                               "film at 30 frames/s or more and keep recording until the horn is still")
    edges = rec.edges
    if len(edges) == 0:
        raise CalibrationError(f"{rec.source}: the command never changes, so there is no step to fit",
                               "the command_deg column must hold the command sent, before and after the step")
    if rec.kind == "rate":
        if edges[0] < 1 or not np.any(rec.rate_units[edges[0]:]):
            raise CalibrationError(f"{rec.source}: flat signal, the gyro reads nothing after the steps",
                                   "check that the gyro's axis is the servo's and that its column is logged")
    elif moved < 0.2 * max(step_deg, MIN_STEP_DEG):
        raise CalibrationError(
            f"{rec.source}: flat signal, the horn moved {moved:.3g} deg for a {step_deg:.3g} deg step",
            "check that the angle column follows the horn (or the --pivot of the horn track)")
    if len(t) - edges[0] < MIN_SAMPLES:
        raise CalibrationError(f"{rec.source}: only {len(t) - edges[0]} samples after the step (need {MIN_SAMPLES})",
                               "keep recording until the horn is still")
    return rec


def _speed_guess(rec: Recording) -> float:
    """No-load speed from the data: a high percentile of the angular speed between samples."""
    if rec.kind == "rate":
        speed = np.abs(rec.rate_units) / rec.gain_guess()
    else:
        speed = np.abs(np.diff(np.radians(rec.angle_deg)) / np.diff(rec.t_s))
    moving = speed[speed > 0.2 * speed.max()]
    return float(np.percentile(moving, 75)) if moving.size else float(speed.max())


def _grid_starts(recs, layout: _Layout, residual, bounds) -> list[np.ndarray]:
    """Starting points: a grid of no-load speed (at and above the fastest speed seen: a load
    slows the servo), armature, linear range (stall/kp), kv and delay, simulated in one batch;
    the best few with distinct speed and armature."""
    stall = layout.stall_given or 0.15
    seen_speed = max(_speed_guess(rec) for rec in recs) * 1.02
    frame_s = [float(np.median(np.diff(rec.t_s))) for rec in recs]
    j = recs[0].rig.inertia_kgm2
    cands = []
    for noload in (seen_speed, 1.5 * seen_speed, 2.5 * seen_speed):
        timing = [_timing_guess(rec, noload) for rec in recs]
        for tau_s in (0.002, 0.01, 0.03):                        # mechanical time constant (J+Ja)/b
            armature = max(tau_s * stall / noload - j, LOWER["servo.armature_kgm2"] * 10)
            for linear_deg in (3.0, 10.0, 25.0):
                kv_shares = (0.01, 0.3, 1.0) if "servo.kv_nms_per_rad" in layout.fitted else (None,)
                for kv_share in kv_shares:                       # kv against the back-EMF's stall/noload
                    for delay_frames in (-1.0, -0.5, 0.0, 0.5):
                        phys = {"servo.noload_speed_rad_per_s": noload, "servo.armature_kgm2": armature,
                                "servo.kp_nm_per_rad": stall / math.radians(linear_deg),
                                "servo.stall_torque_nm": stall,
                                "servo.kv_nms_per_rad": (kv_share or 0.0) * stall / noload}
                        values = dict(phys)
                        for k, rec in enumerate(recs):
                            delay_s, ratio = timing[k]
                            lag = tau_s if rec.kind == "angle" else 0.0
                            values[f"command_delay_s[{k}]"] = delay_s - lag + delay_frames * frame_s[k]
                            values[f"command_clock_error[{k}]"] = ratio - 1.0      # used where the clock is fitted
                            if rec.kind == "rate":
                                values[f"gyro_gain_units_per_rad_per_s[{k}]"] = rec.gain_sign * rec.gain_guess()
                        cands.append(layout.params.as_vector(values))
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


def _timing_guess(rec: Recording, noload: float) -> tuple[float, float]:
    """(delay, clock ratio). An angle recording: from when the horn passes the middle of each
    step, a straight line through (edge time, crossing time); at top speed the middle comes
    half a step late. A rate recording (one clock): when the speed first reaches a fifth of
    its peak after each edge, less a sample."""
    t, u = rec.t_s, rec.command_deg
    if rec.kind == "rate":
        lags = []
        for e, _, end in rec.windows():
            speed = np.abs(rec.rate_units[e:end])
            if speed.size and speed.max() > 0:
                lags.append(t[e + int(np.argmax(speed >= 0.2 * speed.max()))] - t[e])
        step_s = float(np.median(np.diff(t)))
        return float(np.clip(np.median(lags) - step_s if lags else 0.0, -MAX_DELAY_S, MAX_DELAY_S)), 1.0
    q = rec.angle_deg
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


def _physics_notes(servo: Servo, recs: list[Recording], notes: list[str]) -> None:
    """Plain-language facts about the fitted servo that a user should check."""
    linear_deg = math.degrees(servo.stall_torque_nm / servo.kp_nm_per_rad)
    j = recs[0].rig.inertia_kgm2
    tau_ms = 1000 * (j + servo.armature_kgm2) * servo.noload_speed_rad_per_s / servo.stall_torque_nm
    zeta = ((servo.kv_nms_per_rad + servo.stall_torque_nm / servo.noload_speed_rad_per_s)
            / (2 * math.sqrt(servo.kp_nm_per_rad * (j + servo.armature_kgm2))))
    notes.append(f"top speed {servo.noload_speed_rad_per_s:.3g} rad/s, reached with a time constant of "
                 f"{tau_ms:.3g} ms on this load; full torque until {linear_deg:.3g} deg from the command; "
                 f"damping ratio {zeta:.2g} inside that range")


def _rms_half_step(recs: list[Recording], servo: Servo, timings: list[Timing],
                   gains: list[float | None]) -> list[float]:
    """Each recording's RMS residual (its unit) with the fitted servo simulated at half the step."""
    models = [rig_model(replace(rec.rig, timestep_s=rec.rig.timestep_s / 2)) for rec in recs]
    parts = _residual_parts(recs, models, [(servo, timings, gains)])
    return [_rms_in_unit(rec, p[0], g) for rec, p, g in zip(recs, parts, gains)]


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


# -- validation: predicting recordings the fit never saw ---------------------------------
@dataclass(frozen=True)
class StepPeak:
    """One step's peak speed, measured and predicted.

    Attributes
    ----------
    step_deg : float
        The signed command change.
    peak_speed_measured_rad_per_s, peak_speed_predicted_rad_per_s : float
        The largest speed in the step's window; the prediction sampled at the recording's
        own sample times.
    """

    step_deg: float                            # the signed command change
    peak_speed_measured_rad_per_s: float
    peak_speed_predicted_rad_per_s: float      # sampled at the recording's own sample times

    @property
    def error(self) -> float:
        """Predicted over measured peak, minus one (dimensionless)."""
        return self.peak_speed_predicted_rad_per_s / self.peak_speed_measured_rad_per_s - 1.0


@dataclass(frozen=True)
class Validation:
    """A fitted servo predicting a recording it was not fitted to; only the recording's own
    timing (delay; clock ratio for an angle recording of three edges or more) is fitted to it,
    and a rate recording's gyro gain is the fitted recordings' (the same gyro) or, without
    one, its own integral over each step against the step.

    Attributes
    ----------
    source : str
        The recording's name.
    kind : str
        ``"angle"`` or ``"rate"``.
    rms : float
        RMS of prediction minus recording: deg (angle) or rad/s (rate).
    timing : Timing
        The recording's timing, fitted to it.
    gain : float or None
        The gyro gain used [gyro units per rad/s] (None for an angle recording).
    steps : list of StepPeak
        Each step's peak speed.
    curves : Curves
        The recording against the prediction.
    """

    source: str
    kind: str
    rms: float                                 # deg (angle) or rad/s (rate)
    timing: Timing
    gain: float | None
    steps: list[StepPeak]
    curves: Curves = field(repr=False)

    def summary(self) -> dict:
        """The validation for JSON output.

        Returns
        -------
        dict
            The fields (rms with its unit, the timing rounded, each step's peaks and error).
        """
        return {"source": self.source, "kind": self.kind, "rms": self.rms,
                "rms_unit": "deg" if self.kind == "angle" else "rad/s",
                "command_delay_s": round(self.timing.delay_s, 5),
                "command_clock_ratio": round(self.timing.clock_ratio, 6),
                "gyro_gain_units_per_rad_per_s": self.gain,
                "steps": [{"step_deg": p.step_deg,
                           "peak_speed_measured_rad_per_s": p.peak_speed_measured_rad_per_s,
                           "peak_speed_predicted_rad_per_s": p.peak_speed_predicted_rad_per_s,
                           "error": p.error} for p in self.steps]}


def step_windows(rec: Recording) -> list[tuple[int, int]]:
    """Each step's window: to the next edge, at most ``RATE_WINDOW_S``.

    Parameters
    ----------
    rec : Recording
        The recording.

    Returns
    -------
    list of tuple of int
        (edge, end) sample indices, ``end`` one past the last.
    """
    if rec.kind == "rate":
        return [(e, end) for e, _, end in rec.windows()]
    edges = list(rec.edges) + [len(rec.t_s)]
    return [(e, min(nxt, int(np.searchsorted(rec.t_s, rec.t_s[e] + RATE_WINDOW_S))))
            for e, nxt in itertools.pairwise(edges)]


def peak_speeds(rec: Recording, predicted: np.ndarray, gain: float | None) -> list[StepPeak]:
    """Each step's peak speed, measured and predicted (``predicted``: the model's angle [deg]
    at every sample of an angle recording, its speed [rad/s] at the fitted samples of a rate
    recording). An angle's speed is its change between samples over their interval.

    Parameters
    ----------
    rec : Recording
        The recording.
    predicted : numpy.ndarray
        The model's angle [deg] or speed [rad/s], as above.
    gain : float or None
        A rate recording's gyro gain [gyro units per rad/s] (unused for an angle one).

    Returns
    -------
    list of StepPeak
    """
    out = []
    if rec.kind == "rate":
        measured = rec.rate_units[rec.samples()] / gain
        k0 = 0
        for e, first, end in rec.windows():
            n = end - first
            sl = slice(k0 + (e - first), k0 + n)
            out.append(StepPeak(float(rec.command_deg[e] - rec.command_deg[e - 1]),
                                float(np.max(np.abs(measured[sl]))), float(np.max(np.abs(predicted[sl])))))
            k0 += n
        return out
    dt = np.diff(rec.t_s)
    meas = np.radians(np.diff(rec.angle_deg)) / dt
    pred = np.radians(np.diff(predicted)) / dt
    for e, end in step_windows(rec):
        sl = slice(e - 1, end - 1)
        out.append(StepPeak(float(rec.command_deg[e] - rec.command_deg[e - 1]),
                            float(np.max(np.abs(meas[sl]))), float(np.max(np.abs(pred[sl])))))
    return out


def validate(servo: Servo, rec: Recording, gain: float | None = None) -> Validation:
    """Predict a recording with a fitted servo; see :class:`Validation`.

    Parameters
    ----------
    servo : Servo
        The fitted servo.
    rec : Recording
        A recording it was not fitted to.
    gain : float, optional
        The gyro's gain [gyro units per rad/s] (its sign is taken from the data); by default
        the recording's own.

    Returns
    -------
    Validation

    Raises
    ------
    CalibrationError
        A recording too short, without a step, or with a flat signal.
    """
    rec = _checked(rec)
    if rec.kind == "rate" and gain is None:
        gain = rec.gain_sign * rec.gain_guess()
    elif rec.kind == "rate":
        gain = rec.gain_sign * abs(gain)
    has_clock = rec.kind == "angle" and len(rec.edges) >= MIN_EDGES_FOR_CLOCK
    layout = _Layout(values_of(servo), (has_clock,), (False,))
    model = rig_model(rec.rig)

    def residual(x: np.ndarray) -> np.ndarray:
        xs = np.atleast_2d(np.asarray(x).T).reshape(-1, layout.size)
        cands = [(servo, layout.unpack(row)[1], [gain]) for row in xs]
        r = _residual_parts([rec], [model], cands)[0].T
        return np.where(np.isfinite(r), r, 1e3)

    noload = servo.noload_speed_rad_per_s if math.isfinite(servo.noload_speed_rad_per_s) else 10.0
    delay_s, ratio = _timing_guess(rec, noload)
    frame_s = float(np.median(np.diff(rec.t_s)))
    starts = [layout.params.as_vector({"command_delay_s[0]": delay_s + f * frame_s,
                                         "command_clock_error[0]": ratio - 1.0})
              for f in (-1.5, -1.0, -0.5, 0.0, 0.5)]
    bounds = layout.bounds()
    lo, hi = bounds
    xs = np.clip(np.array(starts), lo + 1e-6, hi - 1e-6)
    x0 = xs[int(np.argmin(np.sum(residual(xs.T) ** 2, axis=0)))]
    x, _ = minimize.least_squares(x0, residual, bounds=bounds, max_iter=40, verbose=0, eps=FD_STEP)
    timing = layout.unpack(np.asarray(x).ravel())[1][0]
    if rec.kind == "angle":
        predicted = simulate_deg(model, [servo], [timing], rec, float(rec.angle_deg[0]))[0]
        rms = float(np.sqrt(np.mean((predicted - rec.angle_deg) ** 2)))
    else:
        predicted = simulate_rate(model, [servo], [timing.delay_s], rec)[0]
        rms = float(np.sqrt(np.mean((predicted - rec.rate_units[rec.samples()] / gain) ** 2)))
    return Validation(rec.source, rec.kind, rms, timing, gain, peak_speeds(rec, predicted, gain),
                      recording_curves(model, servo, timing, gain, rec, label="predicted: "))


def horn_angle_deg(x_m: np.ndarray, y_m: np.ndarray, pivot_x_m: float, pivot_y_m: float) -> np.ndarray:
    """Angle of the horn tip about the pivot, from the track's +x axis (y up), unwrapped.

    Parameters
    ----------
    x_m, y_m : numpy.ndarray
        The horn tip's track [m].
    pivot_x_m, pivot_y_m : float
        The servo axis in the track [m].

    Returns
    -------
    numpy.ndarray
        The angle [deg].
    """
    return np.degrees(np.unwrap(np.arctan2(y_m - pivot_y_m, x_m - pivot_x_m)))
