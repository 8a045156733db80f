"""The demo's bench: the virtual robot's parts measured as a student measures the real ones,
written as SYNTHETIC recordings (each file's header says so, and gives the truth).

- a hinge swing: a link on one of the robot's film hinges, released from rest, filmed at 60
  frames/s (the course's damping test, ``locust calibrate hinge``);
- a servo step with a light load and a stall against a weight too heavy for it (the servo
  experiment, ``locust calibrate servo``: the stall sets the torque, the step the speed, gain
  and rotor inertia);
- ramp trials: the robot on a tilted board until its feet slide (``locust calibrate ramp``);
- its plate on a kitchen scale before the legs go on (:func:`plate_on_a_scale`, what the
  robot file's estimate asks for: "weigh yours").

Each is made from the robot's own values by :mod:`locust.calibrate.synthetic` (not the fits'
own models), with the noise a phone camera or an inclinometer gives.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..calibrate import synthetic
from ..fileio import atomic_write_text
from ..params import Robot

SEED = 7001      # the noise's random generator (one seed a recording, from here on)
SCALE_RESOLUTION_G = 0.1     # a kitchen scale's last digit


def plate_on_a_scale(robot: Robot) -> float:
    """What a kitchen scale of :data:`SCALE_RESOLUTION_G` reads with ``robot``'s plate on it [g].

    Parameters
    ----------
    robot : locust.params.Robot

    Returns
    -------
    float
        The reading, to the scale's last digit.
    """
    grams = robot.geometry.body_mass_kg * 1000
    return round(round(grams / SCALE_RESOLUTION_G) * SCALE_RESOLUTION_G, 6)


@dataclass(frozen=True)
class BenchRecording:
    """One bench recording and how ``locust calibrate`` is told of its rig.

    Attributes
    ----------
    experiment : str
        The ``locust calibrate`` subcommand.
    paths : tuple of pathlib.Path
        The recording(s), fitted together.
    options : tuple of str
        The rig's options, as the command takes them.
    """

    experiment: str
    paths: tuple[Path, ...]
    options: tuple[str, ...]


def _servo_head(what: str, truth: synthetic.ServoTruth) -> list[str]:
    s = truth.servo
    return [f"SYNTHETIC servo recording ({what}) of the demo's virtual robot, made by locust.demo.bench",
            f"truth: noload_speed_rad_per_s={s.noload_speed_rad_per_s:.6g} armature_kgm2={s.armature_kgm2:.6g} "
            f"kp_nm_per_rad={s.kp_nm_per_rad:.6g} stall_torque_nm={s.stall_torque_nm:.6g}",
            f"rig: inertia_kgm2={truth.inertia_kgm2:g} gravity_moment_nm={truth.gravity_moment_nm:g}; "
            f"{truth.fps:g} frames/s, angle noise {truth.noise_deg} deg (1 sigma)"]


def write_bench(robot: Robot, folder: Path) -> list[BenchRecording]:
    """Write ``robot``'s bench recordings into ``folder``.

    Parameters
    ----------
    robot : locust.params.Robot
        The robot whose parts are measured (the demo's virtual robot).
    folder : pathlib.Path
        Where the recordings go (made if missing).

    Returns
    -------
    list of BenchRecording
        In the order a student would do them: hinge, servo, ramp.
    """
    c, k = robot.compliance, SEED
    hinge = dataclasses.replace(synthetic.HingeTruth(), hinge_stiffness_nm_per_rad=c.hinge_stiffness_nm_per_rad,
                                hinge_damping_nms_per_rad=c.hinge_damping_nms_per_rad)
    t, x, y = synthetic.hinge_swing_track(hinge, np.random.default_rng(k))
    head = ["SYNTHETIC hinge swing (t in s, x and y in m) of the demo's virtual robot, made by locust.demo.bench",
            f"truth: hinge_stiffness_nm_per_rad={hinge.hinge_stiffness_nm_per_rad:.6g} "
            f"hinge_damping_nms_per_rad={hinge.hinge_damping_nms_per_rad:.6g}",
            f"rig: inertia_kgm2={hinge.inertia_kgm2:g}, gravity {hinge.gravity}; {hinge.fps:g} frames/s, "
            f"marker noise {hinge.noise_m * 1000:g} mm (1 sigma)"]
    hinge_path = folder / "hinge_swing.csv"
    columns = {"t": t, "x": x, "y": y}
    atomic_write_text(hinge_path, synthetic.csv_text(head, columns, {"t": ".6f", "x": ".7f", "y": ".7f"}))

    step = dataclasses.replace(synthetic.ServoTruth(), servo=robot.servo)
    stall = dataclasses.replace(synthetic.STALL_SERVO, servo=robot.servo)
    servo_paths = []
    for name, truth, seed, what in (("servo_step.csv", step, k + 1, "a light load stepped 0 <-> 120 deg"),
                                    ("servo_stall.csv", stall, k + 2, "a weight too heavy: the horn stalls")):
        t, angle, command = synthetic.servo_step(truth, np.random.default_rng(seed))
        path = folder / name
        atomic_write_text(path, synthetic.csv_text(_servo_head(what, truth),
                                                   {"t_s": t, "angle_deg": angle, "command_deg": command},
                                                   {"t_s": ".6f", "angle_deg": ".3f", "command_deg": ".1f"}))
        servo_paths.append(path)

    ramp = synthetic.RampTruth(mu_static=robot.contact.foot_friction)
    angles = synthetic.ramp_angles(ramp, np.random.default_rng(k + 3))
    head = ["SYNTHETIC ramp trials of the demo's virtual robot, made by locust.demo.bench",
            f"truth: mu_static={ramp.mu_static:.6g} (critical angle {ramp.critical_angle_deg:.4f} deg); trial scatter "
            f"{ramp.scatter_deg} deg, reading error {ramp.reading_deg} deg, read to 0.1 deg"]
    ramp_path = folder / "ramp.csv"
    atomic_write_text(ramp_path, synthetic.csv_text(head, {"trial": np.arange(1, len(angles) + 1), "angle_deg": angles},
                                                    {"trial": "d", "angle_deg": ".1f"}))
    return [
        BenchRecording("hinge", (hinge_path,),
                       ("--inertia-kgm2", f"{hinge.inertia_kgm2!r}", "--gravity", hinge.gravity)),
        BenchRecording("servo", tuple(servo_paths),
                       ("--inertia-kgm2", f"{step.inertia_kgm2!r}", "--inertia-kgm2", f"{stall.inertia_kgm2!r}",
                        "--gravity-moment-nm", f"{step.gravity_moment_nm!r}",
                        "--gravity-moment-nm", f"{stall.gravity_moment_nm!r}")),
        BenchRecording("ramp", (ramp_path,), ()),
    ]
