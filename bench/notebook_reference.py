"""The seed notebook's Part 2 simulation, reconstructed as written (f-string MJCF, a Python
loop over 60 Hz frames of ``int(1/60/dt)`` steps, ``data.site(name)`` looked up every step).

Kept only as the reference that benchmarks and tests measure locust against; locust itself
never uses it. Text-extraction artefacts of the notebook (``range="-[CTRL_LIMIT] ..."``, the
right leg printed after ``</worldbody>``) are repaired the only way that compiles: the right leg
hangs from the chassis like the left one.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np


def notebook_xml(dt: float = 1e-4, L_BLUE=0.04, L_YELLOW=0.04, L_GREEN=0.02, L_RED=0.06) -> str:
    OPTIMAL_STIFFNESS = 0.056375
    OPTIMAL_DAMPING = OPTIMAL_STIFFNESS / 100.0
    SERVO_KP, SERVO_KV, TORQUE_LIMIT = 20.0, 0.0069, 0.15
    theta_yellow_deg = -90
    theta_yellow_rad = math.radians(theta_yellow_deg)
    P1 = np.array([-L_BLUE / 2, 0.0])
    P4 = np.array([L_BLUE / 2, 0.0])
    P2 = P1 + np.array([L_YELLOW * math.cos(theta_yellow_rad), L_YELLOW * math.sin(theta_yellow_rad)])
    d_vec = P4 - P2
    d = np.linalg.norm(d_vec)
    a = (L_GREEN**2 - L_RED**2 + d**2) / (2 * d)
    h = math.sqrt(max(0, L_GREEN**2 - a**2))
    x2, z2 = P2
    x4, z4 = P4
    x3 = x2 + a * (x4 - x2) / d + h * (z4 - z2) / d
    z3 = z2 + a * (z4 - z2) / d - h * (x4 - x2) / d
    P3 = np.array([x3, z3])
    vec_green = P3 - P2
    angle_green_global = math.atan2(vec_green[1], vec_green[0])
    deg_green = math.degrees(angle_green_global - theta_yellow_rad)
    vec_red = P4 - P3
    angle_red_global = math.atan2(vec_red[1], vec_red[0])
    deg_red = math.degrees(angle_red_global - angle_green_global)

    BODY_LEN, BODY_WID, BODY_THICK = 0.12, 0.12, 0.001
    POS_X, POS_Y, POS_Z = 0.04, 0.045, 0.08
    LINK_WIDTH, LINK_THICK = 0.03, 0.001
    LINK_A_LEN, LINK_B_LEN, LINK_C_LEN, LINK_D_LEN = L_BLUE, L_RED, L_GREEN, L_YELLOW
    FRIC_FLOOR = "1.6 0.006 0.00005"
    FRIC_FOOT = "1.7 0.006 0.00005"
    CTRL_LIMIT = 45.0

    def leg(side: str, y: str) -> str:
        return f"""
            <body name="{side}_LinkA" pos="{POS_X} {y}{POS_Y} 0" euler="0 0 0">
                <geom class="ghost_part" type="box" size="{LINK_A_LEN/2} {LINK_WIDTH/2} {LINK_THICK/2}" rgba="0.2 0.6 1 1"/>
                <body name="{side}_LinkD" pos="-{LINK_A_LEN/2} 0 0" euler="0 {theta_yellow_deg} 0">
                    <joint name="{side}_Servo_Joint" axis="0 1 0" range="-{CTRL_LIMIT} {CTRL_LIMIT}" limited="true"/>
                    <geom class="leg_part" type="box" pos="{LINK_D_LEN/2} 0 0" size="{LINK_D_LEN/2} {LINK_WIDTH/2} {LINK_THICK/2}" rgba="0.8 0.8 0 1"/>
                    <body name="{side}_LinkC" pos="{LINK_D_LEN} 0 0" euler="0 {deg_green} 0">
                        <joint name="{side}_Knee" axis="0 1 0"/>
                        <geom class="leg_part" type="box" pos="{LINK_C_LEN/2} 0 0" size="{LINK_C_LEN/2} {LINK_WIDTH/2} {LINK_THICK/2}" rgba="0 1 0 1"/>
                        <body name="{side}_LinkB" pos="{LINK_C_LEN} 0 0" euler="0 {deg_red} 0">
                            <joint name="{side}_Ankle" axis="0 1 0"/>
                            <geom class="leg_part" type="box" pos="{LINK_B_LEN/2} 0 0" size="{LINK_B_LEN/2} {LINK_WIDTH/2} {LINK_THICK/2}" rgba="1 0 0 1"/>
                            <body name="{side}_LinkE" pos="{LINK_B_LEN} 0 0">
                                <geom class="ghost_part" type="sphere" size="0.005" rgba="1 0 1 1"/>
                            </body>
                        </body>
                    </body>
                </body>
            </body>"""

    return f"""
<mujoco>
    <compiler angle="degree"/>
    <visual><global offwidth="1280" offheight="720"/></visual>
    <default>
        <default class="ghost_part"><geom contype="0" conaffinity="0"/></default>
        <default class="leg_part"><geom contype="1" conaffinity="1" friction="{FRIC_FOOT}" /></default>
        <joint damping="{OPTIMAL_DAMPING}" stiffness="{OPTIMAL_STIFFNESS}" />
    </default>
    <option gravity="0 0 -9.81" timestep="{dt}" iterations="50" tolerance="1e-8"/>
    <worldbody>
        <body name="floor" pos="0 0 0">
            <geom type="plane" size="10 5 0.1" friction="{FRIC_FLOOR}" />
        </body>
        <body name="locust" pos="0 0 {POS_Z}" euler="180 -30 180">
            <geom type="box" size="{BODY_LEN/2} {BODY_WID/2} {BODY_THICK/2}" rgba="0.1 0.1 0.1 1" mass="0.05"/>
            <site name="nose_sensor" pos="-0.06 0 0" size="0.005" rgba="1 0 0 1"/>
            <freejoint/>
            {leg("L", "")}
            {leg("R", "-")}
        </body>
    </worldbody>
    <equality>
        <connect name="Loop_L" active="true" body1="L_LinkA" body2="L_LinkE" anchor="{L_BLUE/2} 0 0" solimp=".9 .95 .001" solref=".02 1"/>
        <connect name="Loop_R" active="true" body1="R_LinkA" body2="R_LinkE" anchor="{L_BLUE/2} 0 0" solimp=".9 .95 .001" solref=".02 1"/>
    </equality>
    <actuator>
        <position name="L_Servo" joint="L_Servo_Joint" kp="{SERVO_KP}" kv="{SERVO_KV}" ctrlrange="-{CTRL_LIMIT} {CTRL_LIMIT}" forcerange="-{TORQUE_LIMIT} {TORQUE_LIMIT}"/>
        <position name="R_Servo" joint="R_Servo_Joint" kp="{SERVO_KP}" kv="{SERVO_KV}" ctrlrange="-{CTRL_LIMIT} {CTRL_LIMIT}" forcerange="-{TORQUE_LIMIT} {TORQUE_LIMIT}"/>
    </actuator>
</mujoco>
"""


def notebook_run(dt: float = 1e-4, num_hops: int = 6) -> tuple[float, float]:
    """The notebook's loop, unchanged: returns (distance_m, max_nose_height_m)."""
    model = mujoco.MjModel.from_xml_string(notebook_xml(dt))
    data = mujoco.MjData(model)
    fps = 60
    PUSH_TIME, WAIT_TIME = 0.3, 1.0
    CYCLE_TIME = PUSH_TIME + WAIT_TIME
    duration = num_hops * CYCLE_TIME
    sim_steps = int(1.0 / fps / model.opt.timestep)
    start_x = data.qpos[0]
    TARGET_ANGLE_RAD = math.radians(-30)
    max_nose_height = 0.0
    for i in range(int(duration * fps)):
        current_time = i / fps
        cycle_pos = current_time % CYCLE_TIME
        ctrl = TARGET_ANGLE_RAD if cycle_pos < PUSH_TIME else 0.0
        data.ctrl[0] = ctrl
        data.ctrl[1] = ctrl
        for _ in range(sim_steps):
            mujoco.mj_step(model, data)
            current_nose_z = data.site("nose_sensor").xpos[2]
            if current_nose_z > max_nose_height:
                max_nose_height = current_nose_z
    return float(data.qpos[0] - start_x), float(max_nose_height)


if __name__ == "__main__":
    import sys
    import time

    dt = float(sys.argv[1]) if len(sys.argv) > 1 else 1e-4
    t0 = time.perf_counter()
    dist, h = notebook_run(dt)
    print(f"notebook model dt={dt:g}: distance {dist * 100:.2f} cm, max nose height {h * 100:.2f} cm "
          f"({time.perf_counter() - t0:.1f} s)")
