"""Four-bar solver, MuJoCo model builder, audited hop rollout, marker kinematics, camera and
video clips, live simulation."""

import os

# MuJoCo picks its GL backend when first imported: offscreen rendering needs no display.
# Set here, once, before any submodule imports MuJoCo.
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
