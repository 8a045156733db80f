"""Where one physics step's time goes, by MuJoCo's own timers, for each preset's 3-hop run.

    python bench/step_profile.py [--presets seed,medium] [--cycles 3]

Each preset's hop schedule is stepped with ``mujoco.mj_step`` (the physics ``mujoco.rollout``
runs, one step at a time so that MuJoCo's timers can be read), and the time of each stage of
its model evaluations (rk4: 4 a step) is printed as a share of the step: kinematics, inertia,
collision (broad and narrow phase), making the constraint rows, velocity terms, the
constraint solver. With them: contacts, constraint rows and solver iterations a step.
The timers are wall-clock and add a little of their own; the shares are what counts.

Last line: ``step profile: <preset> <us> us a step, collision <c> %, constraints <k> %`` for
the last preset (collision: broad and narrow phase; constraints: making the rows and solving).
"""

from __future__ import annotations

import argparse
import os
import time

import mujoco
import numpy as np

from locust.params import preset
from locust.sim.model import build
from locust.sim.schedule import control_plan

T = mujoco.mjtTimer
STAGES = [   # (label, timer): the position stage's parts, then the rest of a model evaluation
    ("kinematics", T.mjTIMER_POS_KINEMATICS),
    ("inertia", T.mjTIMER_POS_INERTIA),
    ("collision: broad phase", T.mjTIMER_COL_BROAD),
    ("collision: narrow phase", T.mjTIMER_COL_NARROW),
    ("constraint rows (make)", T.mjTIMER_POS_MAKE),
    ("velocity terms", T.mjTIMER_VELOCITY),
    ("actuation", T.mjTIMER_ACTUATION),
    ("constraint solver", T.mjTIMER_CONSTRAINT),
]


def profile(name: str, cycles: int) -> dict:
    robot = preset(name)
    model = build(robot).model
    plan = control_plan(robot.schedule, robot.solver, cycles)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for timer in data.timer:
        timer.duration, timer.number = 0.0, 0
    ncon, nefc, niter = (np.empty(plan.nstep) for _ in range(3))
    t0 = time.process_time()
    for i in range(plan.nstep):
        data.ctrl[:] = plan.ctrl_rad[i]
        mujoco.mj_step(model, data)
        ncon[i], nefc[i], niter[i] = data.ncon, data.nefc, data.solver_niter[0]
    cpu = time.process_time() - t0
    step = data.timer[T.mjTIMER_STEP].duration
    shares = {label: data.timer[timer].duration / step * 100 for label, timer in STAGES}
    return {"preset": name, "integrator": robot.solver.integrator, "dt": robot.solver.timestep_s,
            "nstep": plan.nstep, "us_per_step": cpu / plan.nstep * 1e6, "shares": shares,
            "ncon": ncon.mean(), "ncon_max": ncon.max(), "nefc": nefc.mean(), "niter": niter.mean()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--presets", default="seed,small,medium,large")
    ap.add_argument("--cycles", type=int, default=3)
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; shares of MuJoCo's step time")
    rows = [profile(name, args.cycles) for name in args.presets.split(",")]
    print(f"{'':26s}" + "".join(f"{r['preset']:>9s}" for r in rows))
    print(f"{'us a step (CPU)':26s}" + "".join(f"{r['us_per_step']:9.1f}" for r in rows))
    for label, _ in STAGES:
        print(f"{label + ' %':26s}" + "".join(f"{r['shares'][label]:9.1f}" for r in rows))
    print(f"{'contacts (mean / max)':26s}" + "".join(f"{r['ncon']:5.1f}/{r['ncon_max']:<3.0f}" for r in rows))
    print(f"{'constraint rows (mean)':26s}" + "".join(f"{r['nefc']:9.1f}" for r in rows))
    print(f"{'solver iterations (mean)':26s}" + "".join(f"{r['niter']:9.2f}" for r in rows))
    last = rows[-1]
    s = last["shares"]
    collision = s["collision: broad phase"] + s["collision: narrow phase"]
    constraints = s["constraint rows (make)"] + s["constraint solver"]
    print(f"step profile: {last['preset']} {last['us_per_step']:.1f} us a step, collision {collision:.0f} %, "
          f"constraints {constraints:.0f} %")


if __name__ == "__main__":
    main()
