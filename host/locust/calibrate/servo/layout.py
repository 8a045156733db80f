"""The servo fit's parameter table: the robot keys it identifies, each with its unit and search
box, then the recordings' own values (command delay, clock error, gyro gain), none of them a
robot parameter; and the solver's vector of them (:class:`.fitparams.FitParameters`)."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ...params import Servo
from ...params.model import split_key
from ..fitparams import FitParameter, FitParameters
from .recording import Timing

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
FD_STEP = 1e-6                # the solver's finite-difference step in its own variables


def delay_name(k: int) -> str:
    """Recording ``k``'s command delay [s] in the table (a recording's value, not the robot's)."""
    return f"command_delay_s[{k}]"


def clock_name(k: int) -> str:
    """Recording ``k``'s clock error (clock ratio - 1) in the table."""
    return f"command_clock_error[{k}]"


def gain_name(k: int) -> str:
    """Recording ``k``'s gyro gain [gyro units per rad/s] in the table."""
    return f"gyro_gain_units_per_rad_per_s[{k}]"


def servo_of(values: Mapping[str, float]) -> Servo:
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


class Layout:
    """The fit's values (:class:`.fitparams.FitParameters`): the servo's physical ones, each
    log-scaled within ``LOWER``-``UPPER`` or held at a given value, then per recording its
    delay (in ``DELAY_SCALE_S``), when it has enough edges and two clocks its clock error
    (ratio - 1, in ``CLOCK_SCALE``), and for a rate recording the log of its gyro gain (the
    gain's sign held from the recording).

    Parameters
    ----------
    held : dict of str to float or None
        Robot key -> the value it is held at (None or absent: fitted).
    clock, gain : tuple of bool
        Per recording: whether its clock ratio, its gyro gain are fitted.
    signs : tuple of float
        Per recording: the sign of its gyro gain (where ``gain``).
    """

    def __init__(self, held: Mapping[str, float | None], clock: tuple[bool, ...], gain: tuple[bool, ...],
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
            params.append(FitParameter(delay_name(k), "s", 0.0, -MAX_DELAY_S, MAX_DELAY_S, scale=DELAY_SCALE_S))
            self._nuisance.append((k, "delay"))
            if has_clock:
                params.append(FitParameter(clock_name(k), "1", 0.0, -MAX_CLOCK_ERROR, MAX_CLOCK_ERROR,
                                           scale=CLOCK_SCALE))
                self._nuisance.append((k, "clock"))
            if has_gain:
                sign = signs[k]
                params.append(FitParameter(gain_name(k), "units per rad/s", sign, sign * 1e-9, sign * 1e9,
                                           scaling="log", reference=sign))
                self._nuisance.append((k, "gain"))
        self.params = FitParameters(params)
        self.fitted = tuple(key for key in KEYS if key in self.params.free)

    @property
    def size(self) -> int:
        """The length of the solver's vector."""
        return self.params.size

    @property
    def stall_given(self) -> float | None:
        """The stall torque [N*m] when held, else None."""
        stall = self.params["servo.stall_torque_nm"]
        return stall.start if stall.held else None

    def unpack(self, x: np.ndarray) -> tuple[Servo, list[Timing], list[float | None]]:
        """The servo, timings and gains of a solver vector.

        Parameters
        ----------
        x : numpy.ndarray
            The solver's vector.

        Returns
        -------
        servo : locust.params.Servo
        timings : list of Timing
            Per recording.
        gains : list of float or None
            Per recording: its gyro gain [gyro units per rad/s] (None for an angle one).
        """
        values = self.params.from_vector(x)
        timings, gains = [], []
        for k, (has_clock, has_gain) in enumerate(zip(self.clock, self.gain)):
            ratio = 1.0 + values[clock_name(k)] if has_clock else 1.0
            timings.append(Timing(values[delay_name(k)], ratio))
            gains.append(values[gain_name(k)] if has_gain else None)
        return servo_of(values), timings, gains

    def nuisance(self) -> list[tuple[int, str]]:
        """(recording, what) of each variable after the physical ones, in order.

        Returns
        -------
        list of tuple of (int, str)
            ``what``: ``"delay"``, ``"clock"`` or ``"gain"``.
        """
        return list(self._nuisance)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The solver's bounds.

        Returns
        -------
        lower, upper : numpy.ndarray
            In the solver's variables.
        """
        return self.params.bounds()
