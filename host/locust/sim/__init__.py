"""The simulated robot in MuJoCo: build the model, roll out the hop schedule, audit, measure,
film.

:mod:`.fourbar` solves the leg linkage; :mod:`.servo` and :mod:`.model` build the MuJoCo model (MjSpec);
:mod:`.schedule` turns the hop schedule into a per-step command; :mod:`.rollout` and :mod:`.batching` run
it with ``mujoco.rollout`` (:mod:`.refine`: where ``solver.refine_timestep_s`` is set, a coarse
step with each floor-contact and command change taken again at a fine one); :mod:`.audit`
invalidates a run that breaks its own physics; :mod:`.hops`
and :mod:`.outcome` measure each hop and name the run's regime; :mod:`.run` does all of that for one
robot and returns :mod:`.result`'s :class:`~.result.SimResult` (:mod:`.job`: ``locust sim``'s whole run,
which :func:`locust.simulate` shares); :mod:`.samples` and :mod:`.sensitivity`
simulate draws and one-at-a-time moves of the uncertain values (:mod:`.figures`: many robots' runs
in batches, reduced to their figures; :mod:`.ensemble`: the draws' shares and percentiles at
dt/2); :mod:`.explain` says why a robot goes
over (from :mod:`.support`: what it stands on, where its centre of mass is) and where each value's
threshold lies; :mod:`.statics` finds the
standing robot's load on its nose; :mod:`.kinematics` poses the markers at kept states;
:mod:`.camera`, :mod:`.clip`, :mod:`.still` and :mod:`.stickers` render videos and stills with their
ground truth, :mod:`.foldrig` and :mod:`.foldphotos` the virtual fold test and its photos;
:mod:`.supply` the servos' supply as a circuit, and :mod:`.supply_rollout` the model stepped on it
where it limits them
(:mod:`.gl`: the OpenGL MuJoCo renders with, checked before MuJoCo is imported);
:mod:`.live` steps the model as the virtual robot's servo commands arrive; :mod:`.push` simulates one
push on the floor or held up, and :mod:`.pushclip` films it for ``locust measure stroke``.
"""

import os

# MuJoCo picks its GL backend when first imported: offscreen rendering needs no display.
# Set here, once, before any submodule imports MuJoCo (through .gl, which checks it first).
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")


def _quiet_mujoco() -> None:
    """MuJoCo imported (:mod:`.gl`: with rendering off where its OpenGL cannot be had), its own
    warnings (an unstable simulation: "Nan, Inf or huge value in QACC") going to
    this package's logger, not to stdout and a ``MUJOCO_LOG.TXT`` in the user's folder: each
    is counted in ``MjData.warning``, which the audit reads (:mod:`locust.sim.audit`)."""
    import logging

    from .gl import mujoco

    log = logging.getLogger("locust.sim")
    mujoco.set_mju_user_warning(lambda message: log.debug("MuJoCo: %s", message))


_quiet_mujoco()
