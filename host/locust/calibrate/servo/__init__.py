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
on the horn, read by :mod:`..gyro_log`, its gain in its own unknown unit fitted too).

An angle recording's command column is the firmware's command, on the firmware's clock,
while the angle is on the camera's; it gets two timing parameters: a delay (the servo's
latency, plus any offset of the reconstructed command edges) and, when it holds three or
more command edges, the ratio of the two clocks. A gyro log has one clock: a delay only.
Both are fitted and reported; neither is a property of the servo, and neither is written
to ``robot.toml``.

The fitted values are named by their robot keys (``servo.noload_speed_rad_per_s``, ...:
:data:`KEYS`); a recording's own values (``command_delay_s[k]``, ``command_clock_error[k]``,
``gyro_gain_units_per_rad_per_s[k]``) are named by what they are and written nowhere.

All candidates of a solver iteration are simulated at once (``mujoco.rollout``, one model
per candidate, on every core) and the error, each recording's divided by its own RMS, is minimised with
MuJoCo's own least-squares solver (``mujoco.minimize.least_squares``) from the best few
points of a batched grid. Standard errors come from the residual Jacobian at the optimum
(cluster-robust over the steps when there are enough of them); a parameter is reported *not
identifiable* when its 95% interval is wider than about +-50%, when it ran to the edge of
its range, or when halving and doubling it changes the fit by less than the noise.

The modules, in the order a fit uses them:

- :mod:`.recording`: the rig's load, the two kinds of recording, their timing and checks;
- :mod:`.rig`: the rig model, the simulations of a recording, the residuals, the curves;
- :mod:`.layout`: the fit's parameter table and the solver's vector;
- :mod:`.starts`: the guesses from the data and the batched grid of starts;
- :mod:`.fit`: :func:`fit_servo`;
- :mod:`.intervals`: the covariance, what is identifiable, the notes;
- :mod:`.result`: :class:`ServoFit`;
- :mod:`.validation`: :func:`validate`, predicting recordings the fit never saw.
"""

from .fit import MAX_ITER, fit_servo, progress_steps
from .layout import KEYS, servo_of, values_of
from .recording import (
    MIN_SAMPLES,
    RATE_WINDOW_S,
    RateRecording,
    Recording,
    ServoRig,
    StepRecording,
    Timing,
    horn_angle_deg,
)
from .result import ServoFit
from .rig import recording_curves, rig_model, servo_edges_s, simulate_deg, simulate_rate
from .validation import StepPeak, Validation, peak_speeds, step_windows, validate

__all__ = ["KEYS", "MAX_ITER", "MIN_SAMPLES", "RATE_WINDOW_S", "RateRecording", "Recording", "ServoFit", "ServoRig",
           "StepPeak", "StepRecording", "Timing", "Validation", "fit_servo", "horn_angle_deg", "peak_speeds",
           "progress_steps", "recording_curves", "rig_model", "servo_edges_s", "servo_of", "simulate_deg",
           "simulate_rate", "step_windows", "validate", "values_of"]
