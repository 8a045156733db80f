"""Synthetic recordings of the four experiments, from known parameters, with realistic noise.

Used by ``calibration/make_synthetic.py`` (the demo recordings) and by the tests (truth to
compare the fits with). Everything here is SYNTHETIC: made from a model, not measured.

Noise figures are those of a phone filming in slow motion: a tracked point is good to
about half a pixel, which at 0.6 mm/px is 0.3 mm; a horn tip 5 cm from the axis tracked to
0.25 mm gives 0.3 deg of angle; a protractor or phone inclinometer reads a ramp to 0.5 deg.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate

from ..params import GRAVITY_M_PER_S2, Servo
from .servo import RateRecording, ServoRig, StepRecording, Timing, rig_model, simulate_deg, simulate_rate


@dataclass(frozen=True)
class BeamTruth:
    """A cardstock cantilever with a mass dropped on its tip, filmed from the side (SYNTHETIC
    truth for the beam fit).

    Attributes
    ----------
    damping_ratio : float
        The tip's damping ratio (no unit).
    drop_height_m, drop_at_s : float
        The mass's fall onto the tip [m] and when it lands [s].
    fps : float
        Frames per second of the camera.
    noise_m : float
        The track's noise, one standard deviation [m].
    transient_m, transient_s, transient_hz : float
        A release transient at the drop: its size [m], its decay to e^-3 [s], its ringing
        frequency [Hz] (0: a decaying offset).
    """

    mass_kg: float = 0.010
    length_m: float = 0.05
    hinge_stiffness_nm_per_rad: float = 0.056375      # the seed's value
    damping_ratio: float = 0.04                        # a lightly damped cardstock strip
    drop_height_m: float = 0.02
    fps: float = 240.0
    duration_s: float = 1.5
    drop_at_s: float = 0.1
    noise_m: float = 0.0003
    # a release transient at the drop (a finger leaving the mass, a higher mode of the strip):
    # extra tip displacement that starts at the drop and dies out within transient_s
    transient_m: float = 0.0                           # its size at the drop, along the tip's motion
    transient_s: float = 0.005                         # gone (to e^-3) after this long
    transient_hz: float = 0.0                          # 0: a decaying offset; else a decaying ringing

    @property
    def stiffness_n_per_m(self) -> float:
        """The tip's stiffness, hinge stiffness / length² [N/m]."""
        return self.hinge_stiffness_nm_per_rad / self.length_m**2

    @property
    def damping_ns_per_m(self) -> float:
        """The tip's damping from the damping ratio [N·s/m]."""
        return 2 * self.damping_ratio * math.sqrt(self.stiffness_n_per_m * self.mass_kg)

    @property
    def hinge_damping_nms_per_rad(self) -> float:
        """The hinge's damping, tip damping × length² [N·m·s/rad]."""
        return self.damping_ns_per_m * self.length_m**2

    @property
    def natural_frequency_hz(self) -> float:
        """The undamped natural frequency of the loaded tip [Hz]."""
        return math.sqrt(self.stiffness_n_per_m / self.mass_kg) / (2 * math.pi)


def beam_tip_track(truth: BeamTruth, rng: np.random.Generator, tilt_deg: float = 3.0):
    """(t_s, x_m, y_m) of the beam tip: at rest, then the mass lands on it at ``drop_at_s``.

    Exact solution of m*y'' + b*y' + k*y = -m*g from y = 0, y' = -sqrt(2*g*h); the camera
    is tilted by ``tilt_deg`` (the fit must not need a level camera). With ``transient_m``
    the drop leaves a release transient the oscillator does not explain (a finger or a
    higher mode of the strip): ``transient_m * exp(-3*tau/transient_s)``, times
    ``cos(2*pi*transient_hz*tau)`` when that is not 0, added along the tip's motion.

    Parameters
    ----------
    truth : BeamTruth
    rng : numpy.random.Generator
        The noise's source.
    tilt_deg : float, default 3
        The camera's tilt [deg].

    Returns
    -------
    t_s, x_m, y_m : numpy.ndarray
        Time [s] and the tip's position in the camera's frame [m] (SYNTHETIC).
    """
    t = np.arange(int(truth.duration_s * truth.fps)) / truth.fps
    wn = 2 * math.pi * truth.natural_frequency_hz
    zeta = truth.damping_ratio
    wd = wn * math.sqrt(1 - zeta**2)
    y_eq = -truth.mass_kg * GRAVITY_M_PER_S2 / truth.stiffness_n_per_m
    v0 = -math.sqrt(2 * GRAVITY_M_PER_S2 * truth.drop_height_m)
    tau = np.clip(t - truth.drop_at_s, 0, None)
    a = -y_eq
    b = (v0 + zeta * wn * a) / wd
    y = np.where(t < truth.drop_at_s, 0.0,
                 y_eq + np.exp(-zeta * wn * tau) * (a * np.cos(wd * tau) + b * np.sin(wd * tau)))
    if truth.transient_m:
        y = y + np.where(t < truth.drop_at_s, 0.0, truth.transient_m * np.exp(-3 * tau / truth.transient_s)
                         * np.cos(2 * math.pi * truth.transient_hz * tau))
    tilt = math.radians(tilt_deg)
    x_m = 0.05 - math.sin(tilt) * y + rng.normal(0, truth.noise_m, len(t))
    y_m = 0.12 + math.cos(tilt) * y + rng.normal(0, truth.noise_m, len(t))
    return t, x_m, y_m


@dataclass(frozen=True)
class StaticBeamTruth:
    """A cardstock cantilever loaded at its tip by hand and filmed at rest before and after
    (SYNTHETIC truth for the static beam fit; the course's test: 0.095 kg on 48 mm, 60 frames/s).

    Attributes
    ----------
    stiffness_n_per_m : float
        The tip's stiffness [N/m].
    rest_s, load_s, settled_s : float
        How long the tip is filmed at rest, being loaded (a smooth ramp to its deflection) and
        settled [s].
    scatter_m, scatter_rho : float
        The track's scatter about the tip, one standard deviation per axis [m], and its
        frame-to-frame correlation (AR(1): a hand-clicked or tracked tip wanders).
    scale_relative_std : float
        How well the track's scale is known: each track's metres are off by a factor drawn
        from N(1, this) (no unit).
    """

    mass_kg: float = 0.095
    length_m: float = 0.048
    stiffness_n_per_m: float = 169.0
    fps: float = 60.0
    rest_s: float = 2.0
    load_s: float = 1.5
    settled_s: float = 1.5
    scatter_m: float = 5e-5
    scatter_rho: float = 0.8
    scale_relative_std: float = 0.009

    @property
    def deflection_m(self) -> float:
        """The tip's static deflection, m*g/k [m]."""
        return self.mass_kg * GRAVITY_M_PER_S2 / self.stiffness_n_per_m


def static_beam_track(truth: StaticBeamTruth, rng: np.random.Generator, tilt_deg: float = 3.0):
    """(t_s, x_m, y_m) of the tip: at rest, lowered to its deflection (smoothstep), settled.

    Each axis carries AR(1) scatter of ``scatter_m`` and ``scatter_rho``; the whole track is
    scaled by a factor drawn from ``N(1, scale_relative_std)`` (the scale's own error, which
    the fit is told of, not of its draw); the camera is tilted by ``tilt_deg``.

    Parameters
    ----------
    truth : StaticBeamTruth
    rng : numpy.random.Generator
        The scatter's and the scale's source.
    tilt_deg : float, default 3
        The camera's tilt [deg].

    Returns
    -------
    t_s, x_m, y_m : numpy.ndarray
        Time [s] and the tip's position in the camera's frame [m] (SYNTHETIC).
    """
    n = int(round((truth.rest_s + truth.load_s + truth.settled_s) * truth.fps))
    t = np.arange(n) / truth.fps
    u = np.clip((t - truth.rest_s) / truth.load_s, 0.0, 1.0)
    y = -truth.deflection_m * u * u * (3 - 2 * u)
    tilt = math.radians(tilt_deg)

    def wander() -> np.ndarray:
        e = rng.normal(0.0, truth.scatter_m * math.sqrt(1 - truth.scatter_rho ** 2), n)
        e[0] = rng.normal(0.0, truth.scatter_m)
        for i in range(1, n):
            e[i] += truth.scatter_rho * e[i - 1]
        return e

    scale = 1.0 + rng.normal(0.0, truth.scale_relative_std)
    x_m = scale * (0.05 - math.sin(tilt) * y + wander())
    y_m = scale * (0.12 + math.cos(tilt) * y + wander())
    return t, x_m, y_m


SG90_AA_SWING = Servo(kp_nm_per_rad=0.26, stall_torque_nm=0.15, noload_speed_rad_per_s=10.2, armature_kgm2=3.1e-4,
                      kv_nms_per_rad=0.0)
"""The SG90 fitted to the course's AA-battery swing alone (kv held at 0): the servo of the
demo recordings ``calibration/recordings/synthetic_servo*.csv``."""


@dataclass(frozen=True)
class ServoTruth:
    """A servo rig filmed through a square-wave command: the servo (locust.params.Servo), the
    load, the camera and the firmware-to-camera timing. Default: the AA swing's SG90
    (SG90_AA_SWING) swinging a load five times the course's AA battery, filmed at 60 frames/s."""

    servo: Servo = field(default_factory=lambda: SG90_AA_SWING)
    inertia_kgm2: float = 1.5e-5        # a 20 g weight 2.7 cm from the axis
    gravity_moment_nm: float = 0.0      # 0: horizontal rig
    start_deg: float = 0.0
    target_deg: float = 120.0
    edges: int = 3                      # command changes, one every half period
    half_period_s: float = 0.8
    first_edge_s: float = 0.2
    fps: float = 60.0
    noise_deg: float = 0.3
    delay_s: float = 0.012              # command edge to servo (a PWM period at most, plus latency)
    clock_ratio: float = 1.002          # camera clock / firmware clock
    timestep_s: float = 2.5e-4          # finer than the fit's, so the fit does not meet its own grid

    @property
    def rig(self) -> ServoRig:
        """The rig the fit is given: load inertia, gravity moment, time step."""
        return ServoRig(self.inertia_kgm2, self.gravity_moment_nm, timestep_s=self.timestep_s)

    @property
    def duration_s(self) -> float:
        """The recording's length: the first edge and every half period after it [s]."""
        return self.first_edge_s + self.edges * self.half_period_s


STALL_SERVO = ServoTruth(inertia_kgm2=4e-4, gravity_moment_nm=0.2, start_deg=-90.0, target_deg=90.0, edges=1,
                         half_period_s=1.0, fps=120.0, delay_s=0.0, clock_ratio=1.0)
"""The SG90 lifting a weight too heavy for it (the notebook's stall test): from hanging
straight down the horn rises until 0.2*cos(angle) = 0.15 N*m and stalls there, 131 deg short
of the command, torque-limited for the whole step. With the gravity moment given the stall
torque is identifiable; kp is not (any kp that saturates the drive fits alike)."""


@dataclass(frozen=True)
class GyroTruth:
    """A servo stepped 0 -> A -> 0 for each A, each level held ``level_s``, logged with a rate
    gyro on the horn (the layout of ``../shared/data/servo/sg90_unloaded_gyro_steps.txt``):
    readings ``gain * speed + noise``, rounded to whole units as an IMU's raw counts are."""

    servo: Servo = field(default_factory=Servo)
    inertia_kgm2: float = 1e-6              # the gyro board on the horn
    steps_deg: tuple[float, ...] = (15.0, 45.0, 100.0)
    level_s: float = 1.0
    sample_s: float = 0.013                 # about 75 samples/s
    first_edge_s: float = 0.2
    gain_units_per_rad_per_s: float = 8.0
    delay_s: float = 0.025
    noise_units: float = 0.5
    timestep_s: float = 2.5e-4              # finer than the fit's

    @property
    def rig(self) -> ServoRig:
        """The rig the fit is given: the gyro board's inertia, no gravity moment."""
        return ServoRig(self.inertia_kgm2, timestep_s=self.timestep_s)


def gyro_steps(truth: GyroTruth, rng: np.random.Generator):
    """(t_s, command_deg, rate_units): the rig model's speed at the samples, the horn at rest
    between steps, plus noise, rounded.

    Parameters
    ----------
    truth : GyroTruth
    rng : numpy.random.Generator
        The noise's source.

    Returns
    -------
    t_s, command_deg, rate_units : numpy.ndarray
        Time [s], command [deg], the gyro's reading in whole counts (SYNTHETIC).
    """
    duration = truth.first_edge_s + 2 * len(truth.steps_deg) * truth.level_s
    t = np.arange(int(duration / truth.sample_s)) * truth.sample_s
    level = np.floor((t - truth.first_edge_s) / truth.level_s).astype(int)
    command = np.where((level >= 0) & (level % 2 == 0),
                       np.array(truth.steps_deg)[np.clip(level // 2, 0, len(truth.steps_deg) - 1)], 0.0)
    rec = RateRecording(t, np.zeros_like(t), command, truth.rig, source="synthetic")
    speed = np.zeros_like(t)
    speed[rec.samples()] = simulate_rate(rig_model(truth.rig), [truth.servo], [truth.delay_s], rec)[0]
    rate = truth.gain_units_per_rad_per_s * speed + rng.normal(0, truth.noise_units, len(t))
    return t, command, np.round(rate)


def _rest_deg(truth: ServoTruth) -> float:
    """Where the horn rests before the first edge: servo torque kp*(start - q), clipped at the
    stall torque, holds the load's moment M*cos(q) (bisection; the torque falls as q rises)."""
    s, m = truth.servo, truth.gravity_moment_nm
    lo, hi = truth.start_deg - 90.0, truth.start_deg + 90.0

    def net(q_deg: float) -> float:
        drive = s.kp_nm_per_rad * math.radians(truth.start_deg - q_deg)
        return max(-s.stall_torque_nm, min(s.stall_torque_nm, drive)) - m * math.cos(math.radians(q_deg))

    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if net(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def servo_step(truth: ServoTruth, rng: np.random.Generator):
    """(t_s, angle_deg, command_deg): the rig model stepped from rest, plus angle noise.

    Parameters
    ----------
    truth : ServoTruth
    rng : numpy.random.Generator
        The noise's source.

    Returns
    -------
    t_s, angle_deg, command_deg : numpy.ndarray
        Time [s], horn angle and command [deg] (SYNTHETIC).
    """
    t = np.arange(int(truth.duration_s * truth.fps)) / truth.fps
    n_edges = np.clip(np.floor((t - truth.first_edge_s) / truth.half_period_s) + 1, 0, truth.edges)
    command = np.where(n_edges % 2 == 1, truth.target_deg, truth.start_deg)
    rec = StepRecording(t, np.zeros_like(t), command, truth.rig, source="synthetic")
    angle = simulate_deg(rig_model(truth.rig), [truth.servo], [Timing(truth.delay_s, truth.clock_ratio)], rec,
                         _rest_deg(truth))[0]
    return t, angle + rng.normal(0, truth.noise_deg, len(t)), command


@dataclass(frozen=True)
class RampTruth:
    """Tilt trials of a robot on a ramp (SYNTHETIC truth for the ramp fit).

    Attributes
    ----------
    mu_static : float
        The true static friction (no unit).
    trials : int
        Trials drawn.
    scatter_deg, reading_deg : float
        Trial-to-trial scatter of the critical angle and the inclinometer's reading error,
        one standard deviation each [deg].
    """

    mu_static: float = 1.7          # the seed's foot friction
    trials: int = 10
    scatter_deg: float = 0.8        # trial-to-trial scatter of the critical angle
    reading_deg: float = 0.5        # reading error of the inclinometer

    @property
    def critical_angle_deg(self) -> float:
        """atan(mu_static) [deg]."""
        return math.degrees(math.atan(self.mu_static))


def ramp_angles(truth: RampTruth, rng: np.random.Generator) -> np.ndarray:
    """The trials' critical angles as read, to 0.1 deg (SYNTHETIC).

    Parameters
    ----------
    truth : RampTruth
    rng : numpy.random.Generator

    Returns
    -------
    numpy.ndarray
        ``truth.trials`` angles [deg].
    """
    sd = math.hypot(truth.scatter_deg, truth.reading_deg)
    return np.round(truth.critical_angle_deg + rng.normal(0, sd, truth.trials), 1)


def ramp_tilt_track(truth: RampTruth, rng: np.random.Generator, *, fps: float = 60.0, rate_deg_per_s: float = 4.0,
                    board_m: float = 0.30, noise_m: float = 0.0005, mu_kinetic_ratio: float = 0.8):
    """One tilting trial filmed from the side: markers ``ramp_a`` (hinge end), ``ramp_b`` (far
    end of the board) and ``robot``. Returns (t_s, {marker: (x_m, y_m)}, critical_angle_deg).

    Parameters
    ----------
    truth : RampTruth
    rng : numpy.random.Generator
        The noise's source.
    fps : float, default 60
        Frames per second.
    rate_deg_per_s : float, default 4
        How fast the board tilts [deg/s].
    board_m : float, default 0.30
        The distance between the board's markers [m].
    noise_m : float, default 0.0005
        The markers' noise, one standard deviation [m].
    mu_kinetic_ratio : float, default 0.8
        Sliding friction as a share of static friction.

    Returns
    -------
    t_s : numpy.ndarray
        Time [s].
    markers : dict of str to (numpy.ndarray, numpy.ndarray)
        Marker -> x and y [m] (SYNTHETIC).
    critical_angle_deg : float
        The true angle at which the robot starts to slide [deg].
    """
    crit = truth.critical_angle_deg
    t = np.arange(int((crit + 8) / rate_deg_per_s * fps)) / fps
    theta = np.radians(rate_deg_per_s * t)
    tc = math.radians(crit) / math.radians(rate_deg_per_s)
    s = np.full(len(t), 0.2)
    mu_k = truth.mu_static * mu_kinetic_ratio
    v = 0.0
    for i in range(1, len(t)):
        if t[i] > tc:
            a = GRAVITY_M_PER_S2 * (math.sin(theta[i]) - mu_k * math.cos(theta[i]))
            v += max(a, 0.0) / fps
            s[i] = max(s[i - 1] - v / fps, 0.0)
    along = np.column_stack([np.cos(theta), np.sin(theta)])
    normal = np.column_stack([-np.sin(theta), np.cos(theta)])
    pts = {
        "ramp_a": np.zeros((len(t), 2)),
        "ramp_b": board_m * along,
        "robot": s[:, None] * along + 0.01 * normal,
    }
    out = {k: (v[:, 0] + rng.normal(0, noise_m, len(t)), v[:, 1] + rng.normal(0, noise_m, len(t)))
           for k, v in pts.items()}
    return t, out, crit


@dataclass(frozen=True)
class HingeTruth:
    """A link swinging on a flexure hinge, released from rest (the course's damping test).
    Default: the course's film hinge (k 1.6e-4 N*m/rad, b 2.1e-6 N*m*s/rad) on a link of
    8.5e-7 kg*m^2 whose hinge axis is vertical (gravity out of the swing's plane), filmed at
    60 frames/s, tracked to 0.1 mm (half a pixel at 7200 px/m)."""

    inertia_kgm2: float = 8.5e-7
    hinge_stiffness_nm_per_rad: float = 1.6e-4
    hinge_damping_nms_per_rad: float = 2.1e-6
    neutral_angle_deg: float = 95.0
    gravity: str = "out-of-plane"           # in-plane | out-of-plane
    mass_kg: float = 0.0
    com_m: float = 0.0
    release_angle_deg: float = 130.0
    radius_m: float = 0.064                 # hinge to marker
    pivot_m: tuple[float, float] = (0.004, -0.002)
    fps: float = 60.0
    hold_s: float = 0.5                     # held at the release angle, then let go
    duration_s: float = 8.0
    noise_m: float = 0.0001
    units: str = "m"                        # the unit the track is written in: m | mm
    coulomb_nm: float = 0.0                 # dry friction torque in the hinge [N*m]

    @property
    def gravity_moment_nm(self) -> float:
        """The link's weight moment with it horizontal [N·m]; 0 out of plane."""
        return self.mass_kg * GRAVITY_M_PER_S2 * self.com_m if self.gravity == "in-plane" else 0.0


IN_PLANE_HINGE = HingeTruth(inertia_kgm2=4.2e-7, hinge_stiffness_nm_per_rad=9.9e-4, hinge_damping_nms_per_rad=8.2e-6,
                            neutral_angle_deg=-80.0, gravity="in-plane", mass_kg=0.0025, com_m=0.003,
                            release_angle_deg=-175.0, radius_m=0.020, pivot_m=(0.0005, 0.0003), hold_s=0.2,
                            duration_s=1.5, fps=240.0, noise_m=0.00005)
"""A 3D-printed link on a foam hinge swinging in a vertical plane, released near horizontal
(after the course's pu-foam pendulum: 2.5 g, centre of mass 3 mm from the hinge, 8 Hz)."""


def hinge_swing_track(truth: HingeTruth, rng: np.random.Generator):
    """(t_s, x, y) of the marker, in ``truth.units``: held, then released from rest.

    I*theta'' = -k*(theta - theta0) - b*theta' - M*g*D*cos(theta) - tau_c*sign(theta') (gravity
    in plane only), integrated by an explicit Runge-Kutta method of order 8 (DOP853, relative
    tolerance 1e-11; the sign smoothed over 1e-4 rad/s): not the fit's own integrator.
    Gaussian noise of ``noise_m`` on each coordinate.

    Parameters
    ----------
    truth : HingeTruth
    rng : numpy.random.Generator
        The noise's source.

    Returns
    -------
    t_s, x, y : numpy.ndarray
        Time [s] and the marker's position in ``truth.units`` (SYNTHETIC).
    """
    t = np.arange(int(round(truth.duration_s * truth.fps))) / truth.fps
    k, b = truth.hinge_stiffness_nm_per_rad, truth.hinge_damping_nms_per_rad
    th0, mgd, inertia = math.radians(truth.neutral_angle_deg), truth.gravity_moment_nm, truth.inertia_kgm2

    tau_c = truth.coulomb_nm

    def rhs(_t, s):
        friction = tau_c * math.tanh(s[1] / 1e-4) if tau_c else 0.0
        return [s[1], (-k * (s[0] - th0) - b * s[1] - mgd * math.cos(s[0]) - friction) / inertia]

    free = t >= truth.hold_s
    theta = np.full(len(t), math.radians(truth.release_angle_deg))
    sol = integrate.solve_ivp(rhs, (truth.hold_s, t[-1]), [theta[0], 0.0], method="DOP853", t_eval=t[free],
                              rtol=1e-11, atol=1e-13)
    theta[free] = sol.y[0]
    scale = {"m": 1.0, "mm": 1000.0}[truth.units]
    x = truth.pivot_m[0] + truth.radius_m * np.cos(theta) + rng.normal(0, truth.noise_m, len(t))
    y = truth.pivot_m[1] + truth.radius_m * np.sin(theta) + rng.normal(0, truth.noise_m, len(t))
    return t, x * scale, y * scale


def csv_text(header_lines: list[str], columns: dict[str, np.ndarray], fmt: dict[str, str]) -> str:
    """A recording as the calibration commands read it: ``#`` header lines, a row of column
    names, one row per sample.

    Parameters
    ----------
    header_lines : list of str
        Comment lines (each written after ``# ``): say SYNTHETIC and the truth.
    columns : dict of str to numpy.ndarray
        Column name -> values, all the same length.
    fmt : dict of str to str
        Column name -> format spec (default ``.6f``); a float nan is written ``nan``.

    Returns
    -------
    str
    """
    out = io.StringIO()
    for line in header_lines:
        out.write(f"# {line}\n")
    names = list(columns)
    out.write(",".join(names) + "\n")
    for i in range(len(columns[names[0]])):
        cells = []
        for n in names:
            v = columns[n][i]
            cells.append("nan" if isinstance(v, float) and np.isnan(v) else format(v, fmt.get(n, ".6f")))
        out.write(",".join(cells) + "\n")
    return out.getvalue()
