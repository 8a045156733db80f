"""What a servo fit is given: the rig's load, the recordings (a filmed horn's angle, a gyro on
the horn), each recording's command timing, and the checks a recording must pass."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ...errors import CalibrationError
from ...params import LIMITS

MIN_SAMPLES = 20
MIN_STEP_DEG = 5.0
MIN_EDGES_FOR_CLOCK = 3
RATE_WINDOW_S = 0.8       # a rate recording's step is fitted this long after its edge (an SG90 settles in 0.5 s)
RATE_PRE_SAMPLES = 2      # ... and from this many samples before it (at rest)


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
    kind: str

    @property
    def edges(self) -> np.ndarray:
        """Indices of the samples where the command changes."""
        return np.flatnonzero(np.abs(np.diff(self.command_deg)) > 1e-9) + 1

    @property
    def mean_edge_s(self) -> float:
        """Mean time of the command edges: the origin of :class:`Timing`'s clock ratio."""
        edges = self.edges
        return float(np.mean(self.t_s[edges])) if len(edges) else float(self.t_s[0])

    @property
    def fits_clock(self) -> bool:
        """Whether the fit gives it a clock ratio: an angle recording (two clocks) of
        ``MIN_EDGES_FOR_CLOCK`` command edges or more."""
        return self.kind == "angle" and len(self.edges) >= MIN_EDGES_FOR_CLOCK


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


def checked(rec: Recording) -> Recording:
    """A recording with float arrays, refused when it cannot be fitted.

    Parameters
    ----------
    rec : Recording
        An angle or rate recording.

    Returns
    -------
    Recording
        The same recording, its columns as float arrays.

    Raises
    ------
    CalibrationError
        Fewer than ``MIN_SAMPLES`` samples (in all, or after the first step), a command that
        never changes, or a flat signal.
    """
    t = np.asarray(rec.t_s, dtype=float)
    u = np.asarray(rec.command_deg, dtype=float)
    if rec.kind == "angle":
        rec = replace(rec, t_s=t, angle_deg=np.asarray(rec.angle_deg, dtype=float), command_deg=u)
    else:
        rec = replace(rec, t_s=t, rate_units=np.asarray(rec.rate_units, dtype=float), command_deg=u)
    if len(t) < MIN_SAMPLES:
        raise CalibrationError(f"{rec.source}: only {len(t)} samples (need {MIN_SAMPLES})",
                               "film at 30 frames/s or more and keep recording until the horn is still")
    edges = rec.edges
    if len(edges) == 0:
        raise CalibrationError(f"{rec.source}: the command never changes, so there is no step to fit",
                               "the command_deg column must hold the command sent, before and after the step")
    _check_moves(rec, edges)
    if len(t) - edges[0] < MIN_SAMPLES:
        raise CalibrationError(f"{rec.source}: only {len(t) - edges[0]} samples after the step (need {MIN_SAMPLES})",
                               "keep recording until the horn is still")
    return rec


def _check_moves(rec: Recording, edges: np.ndarray) -> None:
    """Refuse a flat signal: a gyro that reads nothing after the steps, a horn that hardly moves."""
    if rec.kind == "rate":
        if edges[0] < 1 or not np.any(rec.rate_units[edges[0]:]):
            raise CalibrationError(f"{rec.source}: flat signal, the gyro reads nothing after the steps",
                                   "check that the gyro's axis is the servo's and that its column is logged")
        return
    u = rec.command_deg
    step_deg = float(np.max(np.abs(np.diff(u)))) if len(u) > 1 else 0.0
    moved = float(np.ptp(rec.angle_deg))
    if moved < 0.2 * max(step_deg, MIN_STEP_DEG):
        raise CalibrationError(
            f"{rec.source}: flat signal, the horn moved {moved:.3g} deg for a {step_deg:.3g} deg step",
            "check that the angle column follows the horn (or the --pivot of the horn track)")


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
