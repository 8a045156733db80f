"""Build the hopper's MuJoCo model from a :class:`~locust.params.Robot` with ``MjSpec``.

The chassis is a free body (a thin plate) carrying the two servo bodies; each leg is a
planar four-bar hung from it: ground link (fixed to the chassis at the servo axis, at
``geometry.ground_angle_deg`` to the plate) -> crank (servo joint) -> coupler (knee hinge) ->
leg (ankle hinge) -> loop closed back onto the ground link's front pivot by a ``connect``
equality. Each of the four folds is a spring of its own (:func:`locust.params.side_values`):
the servo, knee and ankle folds on their joints (``stiffness``, ``damping``, ``springref``
relative to the assembled pose), the loop fold on a fixed tendon over the three joints whose
length is that fold's deflection (:func:`loop_fold_coefficients`). The floor's contacts are
explicit pairs, each with its part's friction. Every body is placed in its leg's assembled
pose from :mod:`.fourbar` (each side's crank at its own start angle, its tooth included), so
the loop is closed before the first step (``connect`` anchors are defined in the assembled
pose).

Numbers come from the robot parameters only; each one's provenance is in ``robot.toml``.
The structure follows the notebook's Part 2 model so that the ``seed-notebook`` preset
reproduces its figures; differences a preset asks for are parameter values, not code paths.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..errors import SimError
from ..markers import MARKER_COLOURS, hex_to_rgb01
from ..params import GRAVITY_M_PER_S2, FoldValues, Robot, SideValues, side_values
from .fourbar import Assembly, side_assembly
from .servo import at_supply
from .servo import configure as configure_servo
from .supply import ServoSupply, servo_torque_cap_nm, supply_limits

SIDES = ("L", "R")  # left leg at +y (faces the default camera), right leg at -y
LINK_RGBA = {  # the notebook's colours
    "ground": (0.2, 0.6, 1.0, 1.0),
    "crank": (0.8, 0.8, 0.0, 1.0),
    "coupler": (0.0, 1.0, 0.0, 1.0),
    "leg": (1.0, 0.0, 0.0, 1.0),
}
# Tracker markers: flat emissive discs facing the camera (+y), drawn only (no mass, no contact).
# Their size keeps them a few pixels across when a fixed 640x360 camera frames a six-hop run
# (about 2.5 mm per pixel); they sit clear of the floor (see _marker) so that the floor does
# not hide half of them whenever the robot stands.
MARKER_RADIUS_M = 0.010
MARKER_HALF_THICKNESS_M = 0.0001
INTEGRATORS = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
}


@dataclass(frozen=True)
class SensorLayout:
    """Column slices of ``sensordata`` (one row per step in a rollout).

    Each field is the slice of one sensor's columns; the sensors' values are in SI units.

    Attributes
    ----------
    nose_pos, foot_pos, com_pos, chassis_pos : slice
        World position (x, y, z) of the nose site, the left foot site (the knee point, the
        linkage's lowest point), the whole robot's centre of mass and the chassis body [m].
    loop_a, loop_b : dict of str to slice
        Per side (``"L"``, ``"R"``), world position of the loop's anchor on the ground link
        and on the leg's end [m]; they coincide when the loop is closed.
    floor_contact : slice
        1 when any part of the robot touches the floor, else 0.
    energy_potential, energy_kinetic : slice
        The whole model's potential and kinetic energy [J].
    actuator_force : slice
        Each servo actuator's torque, (L, R): the clamped controller's, without the joint's
        back-EMF damping [N·m].
    actuator_velocity : slice
        Each servo's shaft speed, (L, R) [rad/s].
    """

    nose_pos: slice
    foot_pos: slice          # left foot (knee point, the lowest point of the linkage)
    com_pos: slice           # centre of mass of the whole robot
    chassis_pos: slice
    loop_a: dict[str, slice]  # loop anchor on the ground link, per side
    loop_b: dict[str, slice]  # loop anchor on the leg's end, per side
    floor_contact: slice     # 1 when any part of the robot touches the floor
    energy_potential: slice
    energy_kinetic: slice
    actuator_force: slice    # one column per servo
    actuator_velocity: slice


@dataclass(frozen=True)
class BuiltModel:
    """The compiled MuJoCo model of one robot, with what is needed to run and read it.

    Attributes
    ----------
    model : mujoco.MjModel
        The compiled model.
    assemblies : dict of str to Assembly
        Each leg (``"L"``, ``"R"``) in the assembled pose its bodies were placed in.
    sensors : SensorLayout
        Where each sensor is in ``sensordata``.
    servo_actuators : tuple of int
        The servos' actuator ids, (L, R).
    link_lengths_m : tuple of float
        Ground, crank, coupler and leg lengths [m].
    supply : ServoSupply or None
        Where the supply limits the servos (:func:`.supply.supply_limits`), each servo as
        identified and the supply, for the model to be stepped (:mod:`.supply_rollout`); None
        where the compiled numbers are the servos on their supply.
    """

    model: mujoco.MjModel
    assemblies: dict[str, Assembly]
    sensors: SensorLayout
    servo_actuators: tuple[int, int]   # actuator ids (L, R)
    link_lengths_m: tuple[float, float, float, float]  # ground, crank, coupler, leg
    supply: ServoSupply | None = None


def _quat_euler_deg(x: float, y: float, z: float) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_euler2Quat(q, np.radians([x, y, z]), "xyz")
    return q


def build_spec(robot: Robot) -> tuple[mujoco.MjSpec, dict[str, Assembly]]:
    """The model as an ``MjSpec``, not yet compiled.

    Parameters
    ----------
    robot : Robot
        The robot's parameters, each leg's resolved by :func:`locust.params.side_values`; each
        servo acts on the supply (:func:`.servo.at_supply`).

    Returns
    -------
    spec : mujoco.MjSpec
        The model's specification.
    assemblies : dict of str to Assembly
        Each leg's linkage in the assembled pose its bodies are placed in.

    Raises
    ------
    GeometryError
        The link lengths make no four-bar, or a leg's loop cannot close at its crank's start
        angle (``geometry.crank_start_deg`` and its tooth).
    SimError
        ``solver.integrator`` is not one of :data:`INTEGRATORS`.
    """
    sol = robot.solver
    asms = {side: side_assembly(robot, side) for side in SIDES}
    if sol.integrator not in INTEGRATORS:
        raise SimError(f"solver.integrator = {sol.integrator!r} is not known",
                       f"choose one of {', '.join(INTEGRATORS)}")

    spec = mujoco.MjSpec()
    _set_options(spec, robot)
    _add_scene(spec)
    chassis = _add_chassis(spec, robot)
    for side in SIDES:
        _add_leg(spec, chassis, robot, side_values(robot, side), asms[side])
    _floor_pairs(spec, robot.contact)
    _add_sensors(spec)
    return spec, asms


def _set_options(spec: mujoco.MjSpec, robot: Robot) -> None:
    """Name, solver options (time step, integrator, gravity, disabled features) and the
    offscreen rendering settings."""
    sol = robot.solver
    spec.modelname = f"locust-{robot.name}"
    spec.compiler.degree = False
    spec.option.timestep = sol.timestep_s
    spec.option.integrator = INTEGRATORS[sol.integrator]
    spec.option.iterations = int(sol.iterations)
    spec.option.tolerance = sol.tolerance
    spec.option.gravity = [0.0, 0.0, -GRAVITY_M_PER_S2]
    # no mjENBL_ENERGY: the energy sensors compute it on demand, once per step for the state
    # the other sensors see (the flag would also compute it in every rk4 stage, and leave the
    # kinetic energy of the last stage in the record)
    # MuJoCo's autoreset would silently restart a diverged run: the audit must see it.
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
    # one robot is one constraint island: discovering islands costs a tenth of a step and
    # changes nothing in the result (bench/sim_speed.py)
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_ISLAND
    spec.visual.global_.offwidth = 1280
    spec.visual.global_.offheight = 720
    spec.visual.quality.shadowsize = 2048
    spec.visual.map.fogstart = 100
    spec.visual.map.fogend = 1000


def _add_scene(spec: mujoco.MjSpec) -> None:
    """The floor (checker texture, its collision bits), the marker materials and the lights."""
    spec.add_texture(name="grid", type=mujoco.mjtTexture.mjTEXTURE_2D,
                     builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER, width=512, height=512,
                     rgb1=[0.2, 0.2, 0.25], rgb2=[0.15, 0.15, 0.2])
    mat = spec.add_material(name="floor", texrepeat=[5, 5], texuniform=True, reflectance=0.2)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "grid"
    for colour_name, (hex_colour, _) in MARKER_COLOURS.items():
        spec.add_material(name=f"marker_{colour_name}", rgba=[*hex_to_rgb01(hex_colour), 1.0], emission=1.0)

    world = spec.worldbody
    world.add_light(pos=[-2, -5, 5], dir=[0.5, 0.5, -1], castshadow=True)
    world.add_light(pos=[5, 5, 8], dir=[-0.5, -0.5, -1], castshadow=True)
    world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[10, 5, 0.1],
                   material="floor", contype=FLOOR_BITS[0], conaffinity=FLOOR_BITS[1])


def _add_chassis(spec: mujoco.MjSpec, robot: Robot):
    """The plate on its free joint at the drop height, with the nose site and nose marker."""
    g, k = robot.geometry, robot.contact
    chassis = spec.worldbody.add_body(name="chassis", pos=[0, 0, g.drop_height_m],
                                      quat=_quat_euler_deg(180.0, g.body_pitch_deg, 180.0))
    chassis.add_freejoint(name="free")
    chassis.add_geom(name="plate", type=mujoco.mjtGeom.mjGEOM_BOX,
                     size=[g.body_length_m / 2, g.body_width_m / 2, g.body_thickness_m / 2],
                     rgba=[0.1, 0.1, 0.1, 1], mass=g.body_mass_kg,
                     friction=[k.nose_friction, k.torsional_friction, k.rolling_friction],
                     contype=ROBOT_BITS[bool(k.self_collision)][0], conaffinity=ROBOT_BITS[bool(k.self_collision)][1])
    chassis.add_site(name="nose", pos=[g.nose_x_m, 0, 0], size=[0.005, 0, 0], rgba=[1, 0, 0, 1])
    # nose dot: on the chassis' camera-facing side, up and back from the nose edge (which
    # touches the floor when the robot stands nose-down)
    _marker(chassis, "nose", [g.nose_x_m + MARKER_NOSE_BACK * MARKER_RADIUS_M, g.body_width_m / 2,
                              -MARKER_NOSE_UP * MARKER_RADIUS_M])
    return chassis


def _add_leg(spec: mujoco.MjSpec, chassis, robot: Robot, values: SideValues, asm: Assembly) -> None:
    """One side's servo body and four-bar leg (ground, crank on the servo joint, coupler and
    leg on folded hinges), the loop-closing equality, the loop fold's tendon and the servo's
    actuator (on the robot's supply, docs/servo.md "Power"), from the side's ``values``."""
    g, k, sol = robot.geometry, robot.contact, robot.solver
    side, folds = values.side, values.folds
    s = at_supply(values.servo, robot.power)
    trim = math.radians(values.trim_deg)
    half_w, half_t = g.link_width_m / 2, g.link_thickness_m / 2
    foot_material = [k.foot_friction, k.torsional_friction, k.rolling_friction]
    rho, selfc, rounded = g.link_density_kg_per_m3, bool(k.self_collision), bool(k.rounded_edges)
    y = g.leg_mount_y_m if side == "L" else -g.leg_mount_y_m
    # the servo under the plate (chassis +z is the legs' side): its body carries its mass,
    # drawn and massive but not colliding (the leg loops reach the floor first)
    chassis.add_geom(name=f"{side}_servo_body", type=mujoco.mjtGeom.mjGEOM_BOX,
                     pos=[g.servo_axis_x_m + g.servo_body_x_m, math.copysign(g.servo_body_y_m, y),
                          g.servo_axis_below_plate_m],
                     size=[g.servo_length_m / 2, g.servo_height_m / 2, g.servo_width_m / 2],
                     mass=g.servo_mass_kg, rgba=[0.25, 0.35, 0.9, 0.8], contype=0, conaffinity=0)
    # the ground link from the servo axis to the front pivot, at ground_angle_deg to the plate
    mount = chassis.add_body(name=f"{side}_mount", pos=[g.servo_axis_x_m, y, g.servo_axis_below_plate_m],
                             quat=_quat_euler_deg(0, g.ground_angle_deg, 0))
    ground = mount.add_body(name=f"{side}_ground", pos=[g.ground_m / 2, 0, 0])
    _ghost_box(ground, g.ground_m, half_w, half_t, LINK_RGBA["ground"], rho)
    ground.add_site(name=f"{side}_loop_a", pos=[g.ground_m / 2, 0, 0])
    # Joint angles about +y turn +x toward -z, the mirror of the fourbar frame's
    # counter-clockwise angles: pass the fourbar angles through unchanged and the
    # chain is the mirror image of the planar solution, closed at the same anchor.
    crank = ground.add_body(name=f"{side}_crank", pos=[-g.ground_m / 2, 0, 0],
                            quat=_quat_euler_deg(0, asm.crank_deg, 0))
    # the crank turns on the servo shaft, in parallel with the laminate's folded hinge; the
    # horn's travel about the rest its trim gives it
    servo_joint = crank.add_joint(name=f"{side}_servo", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0],
                                  range=[trim - math.radians(s.travel_deg), trim + math.radians(s.travel_deg)],
                                  limited=mujoco.mjtLimited.mjLIMITED_TRUE,
                                  stiffness=folds["servo"].stiffness_nm_per_rad,
                                  springref=math.radians(folds["servo"].rest_offset_deg))
    _link_box(crank, g.crank_m, half_w, half_t, LINK_RGBA["crank"], foot_material, rho, selfc, rounded)
    coupler = crank.add_body(name=f"{side}_coupler", pos=[g.crank_m, 0, 0],
                             quat=_quat_euler_deg(0, asm.coupler_rel_deg, 0))
    _hinge(coupler, f"{side}_knee", folds["knee"])
    _link_box(coupler, g.coupler_m, half_w, half_t, LINK_RGBA["coupler"], foot_material, rho, selfc, rounded)
    leg = coupler.add_body(name=f"{side}_leg", pos=[g.coupler_m, 0, 0],
                           quat=_quat_euler_deg(0, asm.leg_rel_deg, 0))
    _hinge(leg, f"{side}_ankle", folds["ankle"])
    _link_box(leg, g.leg_m, half_w, half_t, LINK_RGBA["leg"], foot_material, rho, selfc, rounded)
    leg.add_site(name=f"{side}_foot", pos=[0, 0, 0], size=[0.004, 0, 0])
    if side == "L":   # foot dot: on the leg's camera-facing face, up the leg from the foot
        _marker(leg, "foot", [MARKER_FOOT_UP * MARKER_RADIUS_M, g.link_width_m / 2, 0])
    end = leg.add_body(name=f"{side}_end", pos=[g.leg_m, 0, 0])
    end.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.005, 0, 0], contype=0, conaffinity=0, density=rho,
                 rgba=list(LINK_RGBA["ground"]))
    end.add_site(name=f"{side}_loop_b", pos=[0, 0, 0])
    spec.add_equality(name=f"{side}_loop", type=mujoco.mjtEq.mjEQ_CONNECT,
                      objtype=mujoco.mjtObj.mjOBJ_BODY, name1=f"{side}_ground", name2=f"{side}_end",
                      data=[g.ground_m / 2, 0, 0] + [0.0] * 7 + [1.0, 0.0],  # as MJCF fills it
                      solref=[sol.loop_timeconst_s, 1.0],
                      solimp=[sol.loop_dmin, sol.loop_dmax, 0.001, 0.5, 2.0])
    _loop_fold(spec, side, folds["loop"])
    act = spec.add_actuator(name=f"{side}_servo", target=f"{side}_servo",
                            trntype=mujoco.mjtTrn.mjTRN_JOINT)
    configure_servo(servo_joint, act, s, joint_damping_nms_per_rad=folds["servo"].damping_nms_per_rad,
                    trim_rad=trim, torque_cap_nm=servo_torque_cap_nm(values.servo, robot.power))
    act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    act.ctrlrange = [-math.radians(s.travel_deg), math.radians(s.travel_deg)]


def contact_solref(contact) -> list[float]:
    """MuJoCo's ``solref`` (time constant, damping ratio) for a contact of ``timeconst_s`` whose
    bounce has the coefficient of restitution ``restitution``: a damped spring loses
    ``exp(-zeta*pi/sqrt(1 - zeta^2))`` of its speed in one half-cycle, solved for zeta
    (restitution 0: critical damping, MuJoCo's default (0.02 s, 1)).

    Parameters
    ----------
    contact : Contact
        Its ``timeconst_s`` [s] and ``restitution`` (0..1, dimensionless).

    Returns
    -------
    list of float
        ``[time constant [s], damping ratio]``.
    """
    e = contact.restitution
    if e <= 0.0:
        return [contact.timeconst_s, 1.0]
    log_e = math.log(e)
    return [contact.timeconst_s, -log_e / math.sqrt(math.pi**2 + log_e**2)]


def _floor_pairs(spec: mujoco.MjSpec, contact) -> None:
    """Every robot part that can touch the floor gets an explicit ``pair`` with the floor that
    carries its own friction exactly: the plate ``contact.nose_friction``, the leg's links
    ``contact.foot_friction`` (MuJoCo's automatic contacts would take the larger of the two
    geoms' frictions). The softness is the drop test's (:func:`contact_solref`). The floor then
    takes no automatic contacts; with ``contact.self_collision`` the parts still collide with
    each other automatically.

    Listing the pairs also saves MuJoCo's broad phase (every collidable geom against every
    other, in each of the 4 evaluations of an rk4 step): a tenth of the step. Without
    ``contact.self_collision`` the pairs are every contact there is, so the parts take no
    automatic collisions at all (an explicit pair ignores ``contype``/``conaffinity``) and the
    broad phase, which still bounded every collidable body in every evaluation, has nothing
    to do: the same contacts, 9 % of a step less (docs/performance.md).
    """
    floor = spec.geom("floor")
    colliders = [g for g in spec.geoms if g is not floor and (
        g.contype & floor.conaffinity or g.conaffinity & floor.contype)]
    solref = contact_solref(contact)
    for i, geom in enumerate(colliders):
        if not geom.name:
            geom.name = f"floor_contact_{i}"
        mu = contact.nose_friction if geom.name == "plate" else contact.foot_friction
        spec.add_pair(name=f"floor_{geom.name}", geomname1=floor.name, geomname2=geom.name,
                      condim=max(floor.condim, geom.condim),
                      friction=[mu, mu, contact.torsional_friction, contact.rolling_friction,
                                contact.rolling_friction],
                      solref=solref, solimp=list(floor.solimp),
                      margin=max(floor.margin, geom.margin), gap=max(floor.gap, geom.gap))
    floor.contype = floor.conaffinity = 0
    if not contact.self_collision:
        for geom in colliders:
            geom.contype = geom.conaffinity = 0


def _hinge(body, name: str, fold: FoldValues) -> None:
    """A folded film hinge: a joint with the fold's spring, unloaded at its rest offset from
    the assembled pose (qpos 0)."""
    body.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0],
                   stiffness=fold.stiffness_nm_per_rad, damping=fold.damping_nms_per_rad,
                   springref=math.radians(fold.rest_offset_deg))


# The loop fold (leg end -> ground link's front pivot) has no joint: the connect equality
# closes the loop and leaves the leg's end free to turn. Its angle is the ground link's
# direction less the leg's, and the leg's is the crank's start angle plus the servo, knee and
# ankle joints' turns (each joint turns the links after it the same way), so the fold's
# deflection from the assembled pose is minus their sum: a fixed tendon of these coefficients
LOOP_FOLD_JOINTS = ("servo", "knee", "ankle")


def loop_fold_coefficients() -> dict[str, float]:
    """The loop fold's tendon: each joint's coefficient in the fold's deflection.

    Returns
    -------
    dict of str to float
        Joint (without its side's prefix) -> coefficient: the deflection [rad] is
        ``sum(coefficient * q)`` over the servo, knee and ankle joints.
    """
    return {joint: -1.0 for joint in LOOP_FOLD_JOINTS}


# MuJoCo reads a spring length of (-1, -1) as "the length at the spring pose", not -1 rad
_MUJOCO_UNSET_LENGTH = -1.0


def _loop_fold(spec: mujoco.MjSpec, side: str, fold: FoldValues) -> None:
    """The loop fold's spring: a fixed tendon whose length is the fold's deflection, its
    spring unloaded at the fold's rest offset."""
    rest = math.radians(fold.rest_offset_deg)
    if rest == _MUJOCO_UNSET_LENGTH:
        rest = math.nextafter(rest, 0.0)
    tendon = spec.add_tendon(name=f"{side}_loop_fold", stiffness=[fold.stiffness_nm_per_rad, 0.0, 0.0],
                             damping=[fold.damping_nms_per_rad, 0.0, 0.0], springlength=[rest, rest])
    for joint, coefficient in loop_fold_coefficients().items():
        tendon.wrap_joint(f"{side}_{joint}", coefficient)


# Collision bits: the floor collides with everything; robot parts collide with the floor and,
# when contact.self_collision is on (the notebook's model), with each other.
FLOOR_BITS = (1, 3)       # contype, conaffinity
ROBOT_BITS = {True: (1, 1), False: (2, 1)}


# group of the rounded contact edges: hidden in renders (the box is what the camera sees)
CONTACT_EDGE_GROUP = 3


def _link_box(body, length_m: float, half_w: float, half_t: float, rgba, friction,
              density: float, self_collision: bool, rounded_edges: bool) -> None:
    """A laminate link: a box that carries its mass and is drawn. It touches the floor with
    its box corners, or with ``rounded_edges`` through a massless capsule along the link of the
    laminate's thickness: in the plane of motion its profile is the link's (length by
    thickness, ends rounded), a rolling edge with one contact per end instead of four
    corners that the contact jumps between (docs/servo.md, "Contact and loop")."""
    contype, conaffinity = ROBOT_BITS[self_collision]
    box_bits = (0, 0) if rounded_edges else (contype, conaffinity)
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, pos=[length_m / 2, 0, 0],
                  size=[length_m / 2, half_w, half_t], rgba=list(rgba), friction=list(friction),
                  density=density, contype=box_bits[0], conaffinity=box_bits[1])
    if rounded_edges:
        body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[half_t, 0, 0, length_m - half_t, 0, 0],
                      size=[half_t, 0, 0], density=0.0, friction=list(friction), contype=contype,
                      conaffinity=conaffinity, group=CONTACT_EDGE_GROUP, rgba=list(rgba))


def _ghost_box(body, length_m: float, half_w: float, half_t: float, rgba, density: float) -> None:
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, pos=[0, 0, 0], size=[length_m / 2, half_w, half_t],
                  rgba=list(rgba), contype=0, conaffinity=0, density=density)


# where the dots sit, in dot radii: the foot dot up the leg from the foot; the nose dot back
# along the chassis from the nose edge and up from its plate (chassis -z is up)
MARKER_FOOT_UP = 2.5
MARKER_NOSE_BACK = 1.5
MARKER_NOSE_UP = 1.5


def _marker(body, name: str, face_pos) -> None:
    """A massless, non-colliding emissive disc for the video tracker.

    ``face_pos``: where the disc's back face touches the body (body frame); the disc's
    axis is the body's +y, so it faces the camera and stays parallel to the image plane
    while the body turns in the plane of motion.
    """
    x, y, z = face_pos
    body.add_geom(name=f"marker_{name}", type=mujoco.mjtGeom.mjGEOM_CYLINDER,
                  pos=[x, y + MARKER_HALF_THICKNESS_M, z], quat=_quat_euler_deg(-90.0, 0.0, 0.0),
                  size=[MARKER_RADIUS_M, MARKER_HALF_THICKNESS_M, 0], material=f"marker_{name}",
                  contype=0, conaffinity=0, mass=0.0, group=1)


def _add_sensors(spec: mujoco.MjSpec) -> None:
    def add(name, stype, objtype=None, objname="", **kw):
        sensor = spec.add_sensor(name=name, type=stype, **kw)
        if objtype is not None:
            sensor.objtype, sensor.objname = objtype, objname
        return sensor

    T, Obj = mujoco.mjtSensor, mujoco.mjtObj
    add("nose_pos", T.mjSENS_FRAMEPOS, Obj.mjOBJ_SITE, "nose")
    add("foot_pos", T.mjSENS_FRAMEPOS, Obj.mjOBJ_SITE, "L_foot")
    add("com_pos", T.mjSENS_SUBTREECOM, Obj.mjOBJ_BODY, "chassis")
    add("chassis_pos", T.mjSENS_FRAMEPOS, Obj.mjOBJ_BODY, "chassis")
    for side in SIDES:
        add(f"{side}_loop_a", T.mjSENS_FRAMEPOS, Obj.mjOBJ_SITE, f"{side}_loop_a")
        add(f"{side}_loop_b", T.mjSENS_FRAMEPOS, Obj.mjOBJ_SITE, f"{side}_loop_b")
    contact = add("floor_contact", T.mjSENS_CONTACT, Obj.mjOBJ_XBODY, "chassis",
                  reftype=Obj.mjOBJ_GEOM, refname="floor")
    contact.intprm = [1, 0, 1]  # data = found; one match is enough
    add("energy_potential", T.mjSENS_E_POTENTIAL)
    add("energy_kinetic", T.mjSENS_E_KINETIC)
    for side in SIDES:
        add(f"{side}_servo_force", T.mjSENS_ACTUATORFRC, Obj.mjOBJ_ACTUATOR, f"{side}_servo")
    for side in SIDES:
        add(f"{side}_servo_vel", T.mjSENS_ACTUATORVEL, Obj.mjOBJ_ACTUATOR, f"{side}_servo")


def _layout(model: mujoco.MjModel) -> SensorLayout:
    def sl(name: str) -> slice:
        sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
        adr, dim = int(model.sensor_adr[sid]), int(model.sensor_dim[sid])
        return slice(adr, adr + dim)

    def span(first: str, last: str) -> slice:
        return slice(sl(first).start, sl(last).stop)

    return SensorLayout(
        nose_pos=sl("nose_pos"), foot_pos=sl("foot_pos"), com_pos=sl("com_pos"),
        chassis_pos=sl("chassis_pos"),
        loop_a={side: sl(f"{side}_loop_a") for side in SIDES},
        loop_b={side: sl(f"{side}_loop_b") for side in SIDES},
        floor_contact=sl("floor_contact"),
        energy_potential=sl("energy_potential"), energy_kinetic=sl("energy_kinetic"),
        actuator_force=span("L_servo_force", "R_servo_force"),
        actuator_velocity=span("L_servo_vel", "R_servo_vel"),
    )


def build(robot: Robot) -> BuiltModel:
    """Compile the robot's model.

    Parameters
    ----------
    robot : Robot
        The robot's parameters.

    Returns
    -------
    BuiltModel
        The compiled model and its sensor layout.

    Raises
    ------
    GeometryError
        The linkage cannot close.
    SimError
        An unknown integrator, or MuJoCo's compiler refused a value.
    """
    spec, asms = build_spec(robot)
    return compile_spec(spec, asms, robot)


def compile_spec(spec: mujoco.MjSpec, asms: dict[str, Assembly], robot: Robot) -> BuiltModel:
    """Compile a spec of ``robot``'s model (:func:`build_spec`, perhaps with parts added: a
    still's stickers, a hand holding the plate) into a :class:`BuiltModel`.

    Parameters
    ----------
    spec : mujoco.MjSpec
        The specification, from :func:`build_spec`.
    asms : dict of str to Assembly
        The assemblies :func:`build_spec` returned with it.
    robot : Robot
        The robot it was built from (its link lengths).

    Returns
    -------
    BuiltModel
        The compiled model.

    Raises
    ------
    SimError
        MuJoCo's compiler refused a value.
    """
    try:
        model = spec.compile()
    except ValueError as exc:  # MuJoCo's compiler reports bad values this way
        raise SimError(f"MuJoCo could not compile the model: {exc}",
                       "check the robot parameters named in the message") from None
    ids = tuple(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{s}_servo") for s in SIDES)
    servos = tuple(side_values(robot, side).servo for side in SIDES)
    limiting = any(supply_limits(servo, robot.power) for servo in servos)
    return BuiltModel(model=model, assemblies=asms, sensors=_layout(model), servo_actuators=ids,
                      link_lengths_m=robot.link_lengths_m(),  # type: ignore[arg-type]
                      supply=ServoSupply(servos, robot.power) if limiting else None)


def loop_closure_error_m(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """Largest distance between the two anchors of any loop ``connect``, after ``mj_forward``.

    Parameters
    ----------
    model : mujoco.MjModel
        A model built here (its sites ``L_loop_a`` .. ``R_loop_b``).
    data : mujoco.MjData
        Its data, after ``mj_forward`` or a step.

    Returns
    -------
    float
        The larger of the two sides' anchor distances [m].
    """
    worst = 0.0
    for side in SIDES:
        a = data.site(f"{side}_loop_a").xpos
        b = data.site(f"{side}_loop_b").xpos
        worst = max(worst, float(np.linalg.norm(a - b)))
    return worst
