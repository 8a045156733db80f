"""Four-bar solver, MuJoCo model builder, audited hop rollout, video, live simulation."""

import os

# MuJoCo picks its GL backend when first imported: offscreen rendering needs no display.
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")
