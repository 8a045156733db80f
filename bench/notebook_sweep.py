"""The seed notebook's design sweep (its "Granular Sweep"), reconstructed as written.

Kept only as the reference that ``bench/sweep_speed.py`` times locust against; locust never
uses it. It keeps the notebook's units bug (``degrees(atan2(...)) - theta_rad`` subtracts
radians from degrees), so the knee starts a few tenths of a degree off and the linkage is
built open; the ``connect`` constraint then yanks it shut. It also has no torque limit and
MuJoCo's default solver settings. Serial, a Python loop over 60 Hz frames of
``int(1/60/dt)`` steps, ``data.site("nose")`` looked up every step.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

FRIC_FLOOR_VAL = "1.6 0.006 0.00005"
FRIC_FOOT_VAL = "1.7 0.006 0.00005"
OPTIMAL_STIFFNESS = 0.056375
OPTIMAL_DAMPING = OPTIMAL_STIFFNESS / 100.0
SERVO_KP = 20.0
SERVO_KV = 0.0069
L_BLUE, L_YELLOW, L_GREEN, L_RED = 0.04, 0.04, 0.02, 0.06


def sweep_xml(delta_L: float) -> str | None:
    """The notebook's ``xml_dynamic`` for one added length, or None where it refused."""
    L_BLUE_NEW = L_BLUE + delta_L
    L_YELLOW_NEW = L_YELLOW + delta_L
    L_GREEN_NEW = L_GREEN + delta_L
    L_RED_NEW = L_RED + delta_L
    try:
        theta_rad = math.radians(-90)
        P1, P4 = np.array([-L_BLUE_NEW / 2, 0]), np.array([L_BLUE_NEW / 2, 0])
        P2 = P1 + np.array([L_YELLOW_NEW * math.cos(theta_rad), L_YELLOW_NEW * math.sin(theta_rad)])
        d = np.linalg.norm(P4 - P2)
        a = (L_GREEN_NEW**2 - L_RED_NEW**2 + d**2) / (2 * d)
        arg = L_GREEN_NEW**2 - a**2
        if arg < 0:
            return None
        h = math.sqrt(arg)
        x3 = P2[0] + a * (P4[0] - P2[0]) / d + h * (P4[1] - P2[1]) / d
        z3 = P2[1] + a * (P4[1] - P2[1]) / d - h * (P4[0] - P2[0]) / d
        P3 = np.array([x3, z3])
        vec_green = P3 - P2
        deg_green = math.degrees(math.atan2(vec_green[1], vec_green[0])) - theta_rad  # the bug, kept
        vec_red = P4 - P3
        deg_red = (math.degrees(math.atan2(vec_red[1], vec_red[0]))
                   - math.degrees(math.atan2(vec_green[1], vec_green[0])))
    except Exception:
        return None

    def leg(side: str, y: str) -> str:
        return f"""
        <body name="{side}_A" pos="0.04 {y}0.045 0"><body name="{side}_D" pos="-{L_BLUE_NEW/2} 0 0" euler="0 -90 0">
            <joint name="{side}_Servo" axis="0 1 0" range="-45 45"/>
            <geom class="leg" type="box" pos="{L_YELLOW_NEW/2} 0 0" size="{L_YELLOW_NEW/2} 0.01 0.001"/>
            <body name="{side}_C" pos="{L_YELLOW_NEW} 0 0" euler="0 {deg_green} 0">
                <joint name="{side}_Knee" axis="0 1 0"/>
                <geom class="leg" type="box" pos="{L_GREEN_NEW/2} 0 0" size="{L_GREEN_NEW/2} 0.01 0.001"/>
                <body name="{side}_B" pos="{L_GREEN_NEW} 0 0" euler="0 {deg_red} 0">
                    <joint name="{side}_Ankle" axis="0 1 0"/>
                    <geom class="leg" type="box" pos="{L_RED_NEW/2} 0 0" size="{L_RED_NEW/2} 0.01 0.001"/>
                    <body name="{side}_E" pos="{L_RED_NEW} 0 0"><geom class="ghost" type="sphere" size="0.005"/></body>
                </body>
            </body>
        </body></body>"""

    return f"""
<mujoco>
    <compiler angle="degree"/>
    <option gravity="0 0 -9.81" timestep="0.0001"/>
    <default>
        <default class="ghost"><geom contype="0" conaffinity="0"/></default>
        <default class="leg"><geom contype="1" conaffinity="1" friction="{FRIC_FOOT_VAL}" /></default>
        <joint damping="{OPTIMAL_DAMPING}" stiffness="{OPTIMAL_STIFFNESS}" />
    </default>
    <worldbody>
        <body name="floor" pos="0 0 0"><geom type="plane" size="10 5 0.1" friction="{FRIC_FLOOR_VAL}" /></body>
        <body name="locust" pos="0 0 0.1" euler="180 -30 180">
            <freejoint/>
            <geom type="box" size="{L_BLUE_NEW/2} 0.06 0.001" mass="0.05"/>
            <site name="nose" pos="-0.06 0 0"/>
            {leg("L", "")}
            {leg("R", "-")}
        </body>
    </worldbody>
    <equality>
        <connect name="L_Loop" body1="L_A" body2="L_E" anchor="{L_BLUE_NEW/2} 0 0"/>
        <connect name="R_Loop" body1="R_A" body2="R_E" anchor="{L_BLUE_NEW/2} 0 0"/>
    </equality>
    <actuator>
        <position joint="L_Servo" kp="{SERVO_KP}" kv="{SERVO_KV}" ctrlrange="-45 45"/>
        <position joint="R_Servo" kp="{SERVO_KP}" kv="{SERVO_KV}" ctrlrange="-45 45"/>
    </actuator>
</mujoco>
"""


def run_optimization_sim(delta_L: float) -> tuple[float, float, bool]:
    """The notebook's function: (distance, max nose height, success), 3 hops."""
    xml = sweep_xml(delta_L)
    if xml is None:
        return 0, 0, False
    model_sweep = mujoco.MjModel.from_xml_string(xml)
    data_sweep = mujoco.MjData(model_sweep)
    NUM_HOPS = 3
    CYCLE_TIME = 1.3
    duration = NUM_HOPS * CYCLE_TIME
    steps = int(duration * 60)
    sim_steps = int(1.0 / 60 / model_sweep.opt.timestep)
    start_x_pos = data_sweep.qpos[0]
    max_h = 0.0
    for i in range(steps):
        cycle = (i / 60) % CYCLE_TIME
        ctrl = math.radians(-30) if cycle < 0.3 else 0.0
        data_sweep.ctrl[:] = ctrl
        for _ in range(sim_steps):
            mujoco.mj_step(model_sweep, data_sweep)
            current_h = data_sweep.site("nose").xpos[2]
            if current_h > max_h:
                max_h = current_h
    return (data_sweep.qpos[0] - start_x_pos), max_h, True


def notebook_sweep(delta_values) -> list[tuple[float, float, float, bool]]:
    """The notebook's serial loop: one (delta, distance, height, success) per design."""
    return [(d, *run_optimization_sim(d)) for d in delta_values]
