"""The regime of a simulated run: whether the robot goes over, rears and returns, or stays low.

Each leg set of the robot as built sits near a threshold: a push that carries the centre of
mass behind the feet turns the robot over onto its back, where it stays; a weaker one rears
it up and it falls back onto its feet and moves on; a weaker one still barely lifts the
nose. A run is one of three outcomes (:data:`OUTCOMES`):

``goes_over``
    The plate ends a cycle turned more than :data:`OVER_TURN_DEG` nose up from its standing
    pitch: the robot is on its back (it does not right itself with the legs in the air).
``rears_and_returns``
    Not over, and every hop lifts the nose more than :data:`REAR_M` above its standing height
    and ends the cycle back down (each cycle ends within :data:`OVER_TURN_DEG` of standing).
``stays_low``
    Neither: it comes back down every cycle but at least one hop lifts the nose no more than
    :data:`REAR_M`.

What :func:`classify` reads, per hop (:class:`locust.sim.hops.Hop`, as ``summarise`` and
``SimResult.hops`` give them): ``nose_apex_m``, the nose's highest point in the cycle above
its standing height, and ``end_turn_deg``, the plate's pitch at the end of the cycle (after
its wait) less its standing pitch, nose up positive, counted through the vertical.

The thresholds and why:

- :data:`REAR_M` = 3 cm of nose rise: the height that counts as a rear; the filmed
  "several centimetres" of a hop are above it, a robot shuffling on its feet is well below.
- :data:`OVER_TURN_DEG` = 45 deg: a robot that has come back down stands within a degree
  of its start (0.0 deg measured on every returning hop of the presets' near-threshold
  settings), while one that went over rests on its leg-end edge and legs turned 91-107 deg
  (Small, Medium and Large as preset: 91.4, 99.1, 106.5 deg; nose 11-14 cm up), or right
  over onto the plate's top, 212 deg (Medium with the crank at -90 deg). 45 deg is far from
  both.

``classify(hops)`` is a stable interface (other packages call it): its name, its one
argument (a sequence of objects with ``nose_apex_m`` and ``end_turn_deg``) and its return
(one of :data:`OUTCOMES`) do not change.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

GOES_OVER = "goes_over"
REARS_AND_RETURNS = "rears_and_returns"
STAYS_LOW = "stays_low"
OUTCOMES = (GOES_OVER, REARS_AND_RETURNS, STAYS_LOW)

REAR_M = 0.03           # a hop rears when its nose rises more than this above standing
OVER_TURN_DEG = 45.0    # a cycle that ends turned more than this nose up has gone over


class HopFigures(Protocol):
    """What :func:`classify` reads of a hop: ``nose_apex_m`` [m] and ``end_turn_deg`` [deg]."""

    nose_apex_m: float
    end_turn_deg: float


def classify(hops: Sequence[HopFigures]) -> str:
    """The outcome of one run from its hops.

    Parameters
    ----------
    hops : sequence of Hop
        One per cycle, in order, each with ``nose_apex_m`` (nose's highest point above its
        standing height, m) and ``end_turn_deg`` (plate pitch at the cycle's end less its
        standing pitch, nose up positive, deg): :class:`locust.sim.hops.Hop`.

    Returns
    -------
    str
        ``"goes_over"``, ``"rears_and_returns"`` or ``"stays_low"`` (the module docstring
        gives the rules). A run with no hops stays low.

    Examples
    --------
    >>> from types import SimpleNamespace as H
    >>> classify([H(nose_apex_m=0.07, end_turn_deg=0.1), H(nose_apex_m=0.108, end_turn_deg=95.0)])
    'goes_over'
    >>> classify([H(nose_apex_m=0.07, end_turn_deg=0.1)] * 3)
    'rears_and_returns'
    >>> classify([H(nose_apex_m=0.07, end_turn_deg=0.1), H(nose_apex_m=0.012, end_turn_deg=0.0)])
    'stays_low'
    """
    if any(h.end_turn_deg > OVER_TURN_DEG for h in hops):
        return GOES_OVER
    if hops and all(h.nose_apex_m > REAR_M for h in hops):
        return REARS_AND_RETURNS
    return STAYS_LOW


@dataclass(frozen=True)
class MeanSd:
    """A figure's mean and spread over draws, in the figure's unit.

    Attributes
    ----------
    mean : float
        Mean (nan with no draws).
    sd : float
        Sample standard deviation (n - 1); nan with fewer than two draws.
    """

    mean: float      # nan with no draws
    sd: float        # sample standard deviation (n - 1); nan with fewer than two draws


@dataclass(frozen=True)
class OutcomeFigures:
    """One outcome over a set of draws: its share and its own figures' mean and sd."""

    share: float             # of the classified (valid) draws; the shares sum to 1
    n: int
    distance_m: MeanSd
    max_nose_height_m: MeanSd


def _mean_sd(values: list[float]) -> MeanSd:
    n = len(values)
    if n == 0:
        return MeanSd(math.nan, math.nan)
    mean = math.fsum(values) / n
    sd = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1)) if n > 1 else math.nan
    return MeanSd(mean, sd)


def outcome_shares(outcomes: Sequence[str | None], distance_m: Sequence[float],
                   max_nose_height_m: Sequence[float]) -> dict[str, OutcomeFigures]:
    """Each outcome's share of the draws and the mean and sd of its own draws' figures.

    Parameters
    ----------
    outcomes : sequence of str or None
        Per draw, one of :data:`OUTCOMES`, or None for a draw that is not a result (failed its
        audit); those are left out of the shares.
    distance_m, max_nose_height_m : sequence of float
        Per draw, the run's distance and highest nose point (m).

    Returns
    -------
    dict
        Every name of :data:`OUTCOMES` (in that order) -> :class:`OutcomeFigures`; the shares
        sum to 1 when any draw is classified (all 0 when none is).
    """
    n = sum(o is not None for o in outcomes)
    out = {}
    for name in OUTCOMES:
        picked = [i for i, o in enumerate(outcomes) if o == name]
        out[name] = OutcomeFigures(share=len(picked) / n if n else 0.0, n=len(picked),
                                   distance_m=_mean_sd([distance_m[i] for i in picked]),
                                   max_nose_height_m=_mean_sd([max_nose_height_m[i] for i in picked]))
    return out


__all__ = ["GOES_OVER", "REARS_AND_RETURNS", "STAYS_LOW", "OUTCOMES", "REAR_M", "OVER_TURN_DEG", "classify",
           "MeanSd", "OutcomeFigures", "outcome_shares"]
