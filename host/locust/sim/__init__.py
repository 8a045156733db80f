"""Four-bar solver, MuJoCo model builder, audited hop rollout, marker kinematics, camera and
video clips, live simulation."""

import os

# MuJoCo picks its GL backend when first imported: offscreen rendering needs no display.
# Set here, once, before any submodule imports MuJoCo.
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")


def _quiet_mujoco() -> None:
    """MuJoCo's own warnings (an unstable simulation: "Nan, Inf or huge value in QACC") go to
    this package's logger, not to stdout and a ``MUJOCO_LOG.TXT`` in the user's folder: each
    is counted in ``MjData.warning``, which the audit reads (:mod:`locust.sim.audit`)."""
    import logging

    import mujoco

    log = logging.getLogger("locust.sim")
    mujoco.set_mju_user_warning(lambda message: log.debug("MuJoCo: %s", message))


_quiet_mujoco()
