"""The demo's virtual robot: the robot as built, with every uncertain value drawn once.

``locust demo`` hops, films and fits a robot nobody can see into, as a student does the one
on the desk. That robot is :data:`~locust.params.DEFAULT_PRESET` (the robot as built) with
each value that carries an uncertainty drawn from it (:func:`locust.sim.samples.draw`, the
draws of ``locust sim --samples``): a robot the as-built file could be. The draw is chosen, and
said to be chosen, for one property: its Medium and Large rear and come back down, as the
filmed robots did (README, "What the filmed record allows"), so their hops carry the
information the hop fit needs; as built, the robot goes over at its first push and a fit of
its hops finds nothing. Its hinge is the film hinge's (``fit:Damping_test.trk``, drawn about
1.46e-4 N*m/rad), never a cardstock beam's.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from ..fileio import atomic_write_json
from ..io.robot_toml import save_robot
from ..params import DEFAULT_PRESET, Provenance, Robot, preset
from ..sim.samples import draw

DRAW_SEED = 0        # the random generator's seed of the draws
# The draw taken: of the first 300 of seed 0, one whose Medium and Large rear and return with
# a margin (crank angle at rest +-1 deg and ground link +-1.5 deg about it rear them too); its
# Small stays low (tests/test_demo_truth.py holds these outcomes).
DRAW_INDEX = 59
HOP_FIT_SETS = ("medium", "large")   # the leg sets whose filmed hops the demo fits
NAME = "virtual"


def virtual_robot() -> Robot:
    """The hidden robot the demo's virtual board simulates (its Small leg set; ``hop
    --leg-set`` puts the others on).

    Returns
    -------
    locust.params.Robot
        Named ``virtual``; each drawn value's source ``demo-draw`` with the seed and index.
    """
    robot = draw(preset(DEFAULT_PRESET), DRAW_INDEX + 1, DRAW_SEED)[DRAW_INDEX]
    note = (f"the demo's virtual robot: draw {DRAW_INDEX} of seed {DRAW_SEED} of the robot as built's uncertainties, "
            "chosen as one whose Medium and Large rear and return (hidden from the calibration)")
    drawn = {k: Provenance("demo-draw", note=note) for k, p in robot.provenance.items() if p.source == "sample"}
    return dataclasses.replace(robot, provenance={**robot.provenance, **drawn}).renamed(NAME)


def hidden_values(robot: Robot) -> dict[str, float]:
    """The drawn values of ``robot`` (:func:`virtual_robot`), by dotted name.

    Parameters
    ----------
    robot : locust.params.Robot

    Returns
    -------
    dict of str to float
        Key -> value, in the unit its name says.
    """
    return {k: robot.get(k) for k, p in robot.provenance.items() if p.source == "demo-draw"}


def write_truth(folder: Path) -> tuple[Path, dict[str, float]]:
    """Write the virtual robot to ``folder/virtual/truth.toml``, and what it hides, with a note
    saying how it was drawn and chosen, to ``folder/virtual/truth.json``.

    Parameters
    ----------
    folder : pathlib.Path
        The demo's run folder.

    Returns
    -------
    path : pathlib.Path
        The robot file the virtual board reads.
    hidden : dict of str to float
        Its drawn values (:func:`hidden_values`).
    """
    robot = virtual_robot()
    path = save_robot(robot, folder / "virtual" / "truth.toml")
    hidden = hidden_values(robot)
    note = (f"the virtual robot: the robot as built with each uncertain value drawn (draw {DRAW_INDEX} of seed "
            f"{DRAW_SEED}), chosen as one whose {' and '.join(HOP_FIT_SETS)} rear and come back down; hidden from "
            "every stage but the virtual board")
    atomic_write_json(folder / "virtual" / "truth.json", {"note": note, "values": hidden,
                                                          "hop_fit_sets": list(HOP_FIT_SETS)})
    return path, hidden
