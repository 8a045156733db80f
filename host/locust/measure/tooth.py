"""Which spline tooth a side's crank sits on: ``locust measure stance --side left|right``.

A servo horn goes onto its shaft's spline in whole teeth (``360 / servo.spline_teeth`` deg
each): a crank put on a tooth off sits that many teeth off ``geometry.crank_start_deg``
(``left.crank_tooth``, ``right.crank_tooth``; +: turned the way a + command turns it). From
the side's crank angle at the 0 deg command, measured from photos of that side, the tooth is
the nearest whole number of teeth from ``geometry.crank_start_deg``:

    offset = (crank - crank_start_deg) / tooth_deg,    tooth = round(offset)

Its probability is the chance, under a normal error of the offset, that the offset lies
within half a tooth of that whole number; the sd combines the measured crank's, the robot
file's own uncertainty of ``geometry.crank_start_deg`` (measure the stance of the other side
first, without ``--side``, so that the reference is itself measured) and :data:`ROLL_SD_DEG`:
a crank a tooth off rolls the standing robot a few degrees (3 deg for Medium), its stickers
leave the board's plane, and the planar fit reads each side's crank off by as much as 1.5 deg
(the two sides the opposite ways), which the photo's own scatter does not show. The margin is
how far the offset lies inside its tooth's half-tooth band, in standard deviations.
"""

from __future__ import annotations

import datetime
import math
from dataclasses import dataclass
from pathlib import Path

from scipy.stats import norm

from ..calibrate.fitstats import Estimate
from ..params import Provenance, Robot, tooth_deg
from ..params.model import SIDE_SECTIONS

SIDE_WORDS = {"L": "left", "R": "right"}
# the planar fit's error in one side's crank less the other's on a rolled robot: ten virtual
# robots a tooth off on the right, read from the left then the right (rms 1.4 deg, largest 2.9;
# tests/test_measure_stance_sides.py)
ROLL_SD_DEG = 1.5


@dataclass(frozen=True)
class ToothEstimate:
    """A side's crank tooth, from its measured crank angle.

    Attributes
    ----------
    side : str
        ``L`` or ``R``.
    tooth : int
        The nearest whole tooth.
    offset_teeth : float
        The measured crank's offset from ``geometry.crank_start_deg``, in teeth.
    sd_teeth : float
        Its standard deviation, in teeth.
    probability : float
        The chance the offset lies within half a tooth of ``tooth``.
    margin_sd : float
        How far inside that band the offset lies, in standard deviations.
    tooth_deg : float
        One tooth [deg].
    reference_deg : float
        ``geometry.crank_start_deg`` [deg], the reference.
    reference_sd_deg : float
        Its uncertainty in the robot file [deg] (0: none given).
    file_tooth : int
        The side's tooth in the robot file.
    """

    side: str
    tooth: int
    offset_teeth: float
    sd_teeth: float
    probability: float
    margin_sd: float
    tooth_deg: float
    reference_deg: float
    reference_sd_deg: float
    file_tooth: int

    @property
    def key(self) -> str:
        """The robot value: ``left.crank_tooth`` or ``right.crank_tooth``."""
        return f"{SIDE_SECTIONS[self.side]}.crank_tooth"

    def to_json(self) -> dict:
        """As ``--json`` prints it.

        Returns
        -------
        dict
        """
        return {"side": SIDE_WORDS[self.side], "key": self.key, "tooth": self.tooth, "offset_teeth": self.offset_teeth,
                "sd_teeth": self.sd_teeth, "probability": self.probability, "margin_sd": self.margin_sd,
                "tooth_deg": self.tooth_deg, "reference_deg": self.reference_deg,
                "reference_sd_deg": self.reference_sd_deg, "file_tooth": self.file_tooth}


def crank_tooth(robot: Robot, side: str, crank: Estimate) -> ToothEstimate:
    """The side's tooth from its crank angle at the 0 deg command (module doc).

    Parameters
    ----------
    robot : Robot
        The robot file measured against (its ``geometry.crank_start_deg`` and spline).
    side : str
        ``L`` or ``R``.
    crank : Estimate
        The side's crank from its ground link at the 0 deg command [deg].

    Returns
    -------
    ToothEstimate
    """
    step = tooth_deg(robot)
    reference = robot.geometry.crank_start_deg
    ref_sd = robot.source_of("geometry.crank_start_deg").uncertainty or 0.0
    offset = (crank.value - reference) / step
    sd = math.sqrt(crank.std ** 2 + ref_sd ** 2 + ROLL_SD_DEG ** 2) / step
    tooth = int(round(offset))
    if sd > 0:
        probability = float(norm.cdf((tooth + 0.5 - offset) / sd) - norm.cdf((tooth - 0.5 - offset) / sd))
        margin = (0.5 - abs(offset - tooth)) / sd
    else:
        probability, margin = 1.0, math.inf
    return ToothEstimate(side, tooth, offset, sd, probability, margin, step, reference, ref_sd,
                         int(robot.get(f"{SIDE_SECTIONS[side]}.crank_tooth")))


def with_tooth(robot: Robot, est: ToothEstimate, photo: Path) -> Robot:
    """``robot`` with the side's crank tooth measured in place, its source the photo.

    Parameters
    ----------
    robot : Robot
    est : ToothEstimate
    photo : Path
        The rest photo it was measured from.

    Returns
    -------
    Robot
    """
    return robot.with_values({est.key: est.tooth}, Provenance(
        source=f"measured:{photo.name}", uncertainty=est.sd_teeth, date=datetime.date.today().isoformat(),
        note=f"nearest tooth to {est.offset_teeth:+.3f} teeth off geometry.crank_start_deg "
             f"({est.reference_deg:g} deg, one tooth {est.tooth_deg:.4g} deg): probability {est.probability:.4f}, "
             f"{est.margin_sd:.1f} sd inside its half-tooth band; locust measure stance --side"))


__all__ = ["ROLL_SD_DEG", "ToothEstimate", "crank_tooth", "with_tooth"]
