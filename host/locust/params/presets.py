"""Built-in robots, every value with its source.

Presets:

- ``seed``: the notebook's Part 2 robot, run the corrected way: settled on the floor before
  the schedule starts, servo commands at the servo's 50 Hz PWM rate, the SG90 servo model, a
  near-rigid loop closure, rounded link edges on the floor, links that collide with the floor
  but not with their own chassis (a flexure hinge does not collide with the plate it is folded
  from), a time step at which the hop has converged (docs/servo.md), audited.
- ``small`` / ``medium`` / ``large``: the seed team's robot as built (``AS_BUILT``: its
  photos, cut file and the SG90's datasheet, each value with its source) with the leg sets
  of Part 3, +0 / +10 / +20 mm on every link of the cut file's strip, each at the time step
  its hop needs (``LEG_SETS``, the one table that presets, reports and the hop fit build a
  leg set from).
- ``seed-notebook``: the notebook's Part 2 simulation exactly (dropped from 8 cm with the
  schedule already running, 60 Hz control frames of ``int(1/60/dt)`` steps, Euler at
  dt = 1e-4 s, 50 solver iterations, tolerance 1e-8), for reproducing its figures.
"""

from __future__ import annotations

import math
from typing import Any

from ..errors import ParamsError
from .legsets import LEG_SETS, leg_set
from .model import Provenance, Robot

# -- presets ------------------------------------------------------------------------
_SEED_SOURCE = Provenance(source="seed", note="notebook Part 2")
# The SG90 as identified by `locust calibrate servo sg90_aa_battery_step.csv
# sg90_unloaded_gyro_steps.txt --inertia-kgm2 3.3e-6 --inertia-kgm2 1e-6 --stall-torque-nm 0.15`
# (a real SG90 swinging an AA battery, filmed at 30 frames/s, the course's servo experiment;
# and a real SG90 with a gyro on its horn stepped 0 -> A -> 0, A = 10 ... 130 deg). kv held at
# 0: fitted, it is 0.002 +- 0.0015 and changes neither RMS. Uncertainties: the fit's 1 sigma
# (cluster-robust over the 33 steps); docs/servo.md has the figures.
_SG90_FIT = "fit:sg90_aa_battery_step.csv+sg90_unloaded_gyro_steps.txt"
_SG90_DATE = "2026-11-24"
SG90_SOURCE = {
    "servo.stall_torque_nm": Provenance(source="datasheet:SG90", uncertainty=0.015,
                                        note="1.5-1.8 kg*cm at 4.8-6 V; the fit's split of the ratios"),
    "servo.noload_speed_rad_per_s": Provenance(source=_SG90_FIT, uncertainty=0.11, date=_SG90_DATE,
                                               note="95% CI [10.08, 10.53]; datasheet: 0.1 s/60 deg = "
                                                    "10.5 rad/s at 4.8 V"),
    "servo.armature_kgm2": Provenance(source=_SG90_FIT, uncertainty=2.5e-5, date=_SG90_DATE,
                                      note="95% CI [4.14e-4, 5.15e-4]; reflected rotor inertia; scales with the "
                                           "stall torque 0.15 N*m"),
    "servo.kp_nm_per_rad": Provenance(source=_SG90_FIT, uncertainty=0.014, date=_SG90_DATE,
                                      note="95% CI [0.349, 0.405]; pinned by the gyro's small steps; scales with "
                                           "the stall torque 0.15 N*m"),
    "servo.kv_nms_per_rad": Provenance(source="model", note="a hobby servo has no velocity feedback; fitted to "
                                                            "both recordings 0.002 +- 0.0015, RMS unchanged"),
    # nobody has counted the team's horns: 21 is what the printed-horn spline libraries give an
    # SG90 (a round-toothed 21T, 4.8-4.9 mm across), but makers' batches differ
    "servo.spline_teeth": Provenance(source="estimate:SG90 spline", note=(
        "21 teeth, 17.1 deg a tooth: the SG90 spline of OpenSCAD horn libraries (21T, about 4.9 mm over the "
        "teeth) and of 9 g servo listings; some TowerPro micro servos are 20T (18 deg) and clones vary from batch "
        "to batch: count your horn's teeth")),
}


def _seed() -> Robot:
    measured = [
        "geometry.ground_m", "geometry.crank_m", "geometry.coupler_m", "geometry.leg_m",
        "geometry.crank_start_deg", "geometry.body_length_m", "geometry.body_width_m",
        "geometry.body_thickness_m", "geometry.body_mass_kg", "geometry.servo_axis_x_m",
        "geometry.leg_mount_y_m", "geometry.link_width_m", "geometry.link_thickness_m",
        "geometry.nose_x_m", "geometry.body_pitch_deg", "geometry.drop_height_m",
        "compliance.hinge_stiffness_nm_per_rad", "compliance.hinge_damping_nms_per_rad",
        "servo.stall_torque_nm", "servo.travel_deg", "contact.foot_friction", "contact.nose_friction",
        "contact.torsional_friction", "contact.rolling_friction", "schedule.push_deg",
        "schedule.push_s", "schedule.wait_s", "schedule.cycles",
    ]
    provenance = {k: _SEED_SOURCE for k in measured}
    provenance["contact.nose_friction"] = Provenance(
        source="seed", note="notebook Part 2: its floor's 1.6, which MuJoCo's mixing gave the plate's contact")
    provenance.update(SG90_SOURCE)
    return Robot(name="seed", provenance=provenance)


# -- the robot as built ----------------------------------------------------------------
# The seed team's robot (../shared/data/robot/: the top view, the folded loop, the flat strip,
# the cut files), each value a length, angle or mass with where it was read; docs/hardware.md,
# "Measure your robot", says how to measure yours. What the photos do not show is a datasheet
# figure or the notebook's, named as such.
_TOP = "photo:assembled_top_view.png"
# the top view's scale, read from the SG90s lying in it (the breadboard's 55 mm, 200 px, is
# farther from the camera and foreshortened): 32 mm over the tabs = 91 px, the 22.8 mm body
# = 71 px
_TOP_SCALE = "scale 3.0 +- 0.3 px/mm from the SG90s in the photo (32 mm over the tabs = 91 px)"
_SG90 = "datasheet:SG90"
_CUT = "cut_file:zz.dxf"
_HINGE = "fit:Damping_test.trk"
AS_BUILT: dict[str, tuple[Any, Provenance]] = {
    "geometry.ground_m": (0.04, Provenance(_CUT, note="hinge slots at 4, 8, 10, 16 cm of the 18 x 3 cm strip: "
                                                      "links 4, 4, 2, 6 cm, the last 2 cm glued over the first")),
    "geometry.crank_m": (0.04, Provenance(_CUT, note="strip 4-8 cm, on the servo horn")),
    "geometry.coupler_m": (0.02, Provenance(_CUT, note="strip 8-10 cm")),
    "geometry.leg_m": (0.06, Provenance(_CUT, note="strip 10-16 cm")),
    "geometry.link_width_m": (0.03, Provenance(_CUT, note="the strip is 3 cm wide")),
    # no photo shows the robot from the side: the crank's angle at rest and the ground link's
    # angle to the plate are estimates (locust measure stance measures them from two stills)
    "geometry.crank_start_deg": (-100.0, Provenance("estimate", uncertainty=10.0,
        note="the loose loop (folded_leg_loop.png) rests at 100 deg between ground link and crank, but on the "
             "servo the horn sits on its spline in steps of about 18 deg, which no photo shows: measure it")),
    "geometry.ground_angle_deg": (0.0, Provenance("estimate", uncertainty=15.0,
        note="the ground link taken along the servo's side, parallel to the plate; the top view looks down on "
             "the plate and cannot show this side-plane angle: measure it")),
    "geometry.body_length_m": (0.12, Provenance(_TOP, uncertainty=0.01,
        note=f"{_TOP_SCALE}: the plate's near edge 370 px = 123 mm, its far edge 328 px = 109 mm")),
    "geometry.body_width_m": (0.12, Provenance(_TOP, uncertainty=0.01,
        note=f"{_TOP_SCALE}: the plate's edge across the legs 353 px = 118 mm")),
    "geometry.nose_x_m": (-0.06, Provenance(_TOP, uncertainty=0.005, note="the plate's edge away from the legs")),
    "geometry.body_mass_kg": (0.004, Provenance("datasheet:cardstock", uncertainty=0.001,
        note="the plate alone: 12 x 12 cm of black cardstock at about 270 g/m^2; weigh yours")),
    "geometry.link_density_kg_per_m3": (700.0, Provenance("datasheet:cardstock", uncertainty=150.0,
        note="two 270 g/m^2 cardstock layers, 0.05 mm PET film, two adhesive layers: about 0.7 kg/m^2 "
             "over the 1 mm laminate (a Small strip 3.8 g); weigh a strip")),
    "geometry.servo_axis_x_m": (0.028, Provenance(_TOP, uncertainty=0.003,
        note=f"{_TOP_SCALE}: the visible horn's centre 96 px (32 +- 3 mm) in from the plate's leg-end edge, "
             "6 cm from the plate's middle (the loops reach past the edge)")),
    "geometry.leg_mount_y_m": (0.045, Provenance(_TOP, uncertainty=0.005,
        note="servos back to back on the centre line: 29 mm of servo, then half the 3 cm loop; the loops' "
             "tops are 40 and 55 mm from the servos' joint in the photo (perspective)")),
    "geometry.servo_axis_below_plate_m": (0.0065, Provenance(_SG90, uncertainty=0.002,
        note="the servo on its side under the plate, the shaft at mid-width of its 12 mm")),
    "geometry.servo_mass_kg": (0.009, Provenance(_SG90, uncertainty=0.0005)),
    "geometry.servo_length_m": (0.023, Provenance(_SG90)),
    "geometry.servo_width_m": (0.012, Provenance(_SG90)),
    "geometry.servo_height_m": (0.029, Provenance(_SG90)),
    "geometry.servo_body_x_m": (0.0055, Provenance(_SG90, uncertainty=0.001,
        note="the shaft 6 mm from one end of the 23 mm body; the body toward the plate's leg end (photo)")),
    "geometry.servo_body_y_m": (0.0145, Provenance(_SG90, uncertainty=0.002,
        note="half the servo's 29 mm: the top view shows them back to back on the centre line")),
    # locust calibrate hinge on the course's damping test (calibration/protocols/hinge.md): a
    # folded film hinge, not the cardstock beam (the seed's 0.056 was the beam's); viscous model,
    # link 8.5e-7 kg*m^2 about the hinge; the team's own fit gave 1.60e-4 and 2.14e-6
    "compliance.hinge_stiffness_nm_per_rad": (1.46e-4, Provenance(_HINGE, uncertainty=2.5e-7, date="2026-11-24",
        note="95% CI [1.456e-4, 1.466e-4], the fit's own; the hinge stiffens as it rings down (period "
             "0.50 -> 0.46 s), a model error larger than that interval (docs/calibrate.md)")),
    "compliance.hinge_damping_nms_per_rad": (1.59e-6, Provenance(_HINGE, uncertainty=1.8e-8, date="2026-11-24",
        note="95% CI [1.553e-6, 1.623e-6]")),
    "servo.reference_voltage_v": (5.0, Provenance("data:servo/sg90_aa_battery_step.csv",
        note="the recording's 5 V supply: the identified stall torque, speed and gain hold there")),
    "servo.winding_resistance_ohm": (10.0, Provenance(_SG90, uncertainty=1.5,
        note="stall current about 0.6 A at 6 V")),
    "power.supply_voltage_v": (5.0, Provenance("datasheet:USB", uncertainty=0.25,
        note="USB's 5 V +- 5 % at the servo plug with the servos at rest: the top view shows the servos on the "
             "USB-powered ESP32's 5 V, through the breadboard; the board's own 0.05 A through the cable takes "
             "0.025 V of it, inside the sd (locust measure supply reads it)")),
    "power.source_resistance_ohm": (0.5, Provenance("estimate:USB", uncertainty=0.3,
        note="USB cable (about 0.2 ohm a conductor) and breadboard contacts; measure the servo plug's "
             "voltage with both servos held stalled (locust measure supply)")),
    # the three below: estimates of a range, not drawn (no sd: docs/servo.md, "Power", says why
    # and what their ranges do); each note cites where its figure comes from
    "power.current_limit_a": (1.5, Provenance("estimate:USB port",
        note="0.7 to 2.5 A: USB 2.0 promises a port 0.5 A; ports limit above it: TI's power switches for 500 mA "
             "ports (TPS2041B/TPS2051B) at 0.7 A at the least, polyfuses and shared switches well beyond 0.6 A, "
             "USB 3.0 ports promise 0.9 A, phones draw 2.5 A from some (UL, IEEE ISPCE 2015); both servos "
             "stalled draw 0.91 A here (docs/servo.md, Power)")),
    "power.brownout_v": (3.5, Provenance("estimate:SG90",
        note="3 to 4.5 V: SG90 listings give 4.8-6 V rated and 3.0-3.5 V the least they run on; below about "
             "4 V servos jitter or stop holding; at 4.8 V SG90s ran where an MG90S batch stopped "
             "(roger-random.github.io, micro servo notes, 2020)")),
    "power.board_current_a": (0.05, Provenance("estimate:ESP32 dev board",
        note="0.03 to 0.07 A: an ESP32 with its radio off draws a base 20-40 mA (Espressif's low-power guide), "
             "a DevKitC's AMS1117 regulator 3.2 mA (measured by taking it off, kohacraft.com), the USB-serial "
             "bridge and the power LED a few mA")),
}


def _built() -> Robot:
    """The seed team's robot as built: the seed's values where nothing better was measured,
    every value the photos, cut files and datasheets give replaced (AS_BUILT)."""
    robot = _seed()
    for key, (value, prov) in AS_BUILT.items():
        robot = robot.with_values({key: value}, prov)
    return robot



def _seed_notebook() -> Robot:
    prov = Provenance(source="seed", note="notebook Part 2 simulation loop, reproduced exactly")
    return _seed().with_values(
        {   # the notebook's servo: a stiff position actuator, no speed limit, no rotor inertia
            "servo.kp_nm_per_rad": 20.0, "servo.kv_nms_per_rad": 0.0069, "servo.stall_torque_nm": 0.15,
            "servo.noload_speed_rad_per_s": math.inf, "servo.armature_kgm2": 0.0,
            "solver.timestep_s": 1e-4, "solver.integrator": "euler", "solver.iterations": 50,
            "solver.tolerance": 1e-8, "solver.control_hz": 60.0, "solver.settle_s": 0.0,
            "contact.self_collision": True, "contact.rounded_edges": False,
            "solver.loop_timeconst_s": 0.02, "solver.loop_dmin": 0.9, "solver.loop_dmax": 0.95,
            # the notebook closed the loop with a bare connect: its loop fold had no spring
            "folds.loop_stiffness_nm_per_rad": 0.0, "folds.loop_damping_nms_per_rad": 0.0,
        },
        prov,
    ).renamed("seed-notebook")


# the robot a command or the API runs on when told neither a robot file nor a preset, and no
# calibration/robot.toml is at hand (locust.io.robot_toml.default_robot): the robot as built
DEFAULT_PRESET = "small"


def _as_built_leg_set(name: str):
    def build() -> Robot:
        return leg_set(_built(), name).renamed(name)
    return build


PRESETS = {
    "seed": _seed,
    # the filmed leg sets of the robot as built (AS_BUILT), each at its converged step
    **{name: _as_built_leg_set(name) for name in LEG_SETS},
    "seed-notebook": _seed_notebook,
}


def preset(name: str) -> Robot:
    """A built-in robot, every value with its source.

    Parameters
    ----------
    name : str
        One of :data:`PRESETS`: ``seed``; ``small``, ``medium``, ``large`` (the robot as built
        with each filmed leg set); ``seed-notebook``.

    Returns
    -------
    Robot
        A new copy.

    Raises
    ------
    locust.errors.ParamsError
        An unknown name.
    """
    try:
        return PRESETS[name]()
    except KeyError:
        raise ParamsError(f"unknown preset {name!r}", f"choose one of {', '.join(PRESETS)}") from None


