"""How a run ended, said the same way for the simulation and for a filmed trial: on its feet
after every hop, or over onto its back at a given hop, and where it rests.

A simulated run's outcome is :mod:`locust.sim.outcome`'s (``goes_over``, ``rears_and_returns``,
``stays_low``), from the plate's pitch at the end of each cycle; the hop it goes over at is the
first whose cycle ends turned more than :data:`locust.sim.outcome.OVER_TURN_DEG`, and where it
rests is ``locust sim``'s distance (the chassis' travel over the run).

A camera that follows one marker does not see the plate's pitch, but it sees where the marker
rests: a robot back on its feet rests with the marker where it stood (the presets' returning
hops: within a millimetre, about the camera's noise), one on its back with the marker high above
it (87.5 mm on Small as built, 109 mm on Large). So a filmed cycle that ends with the marker at
rest more than :data:`OVER_REST_M` above where it stood has gone over; one whose every hop
lifts the marker more than :data:`locust.sim.outcome.REAR_M` rears and returns (the marker
rises less than the model's nose point does, so a rear near that height may read as staying
low). A run that went over is never a jump: its marker's height after that hop is where it
lies, not how high it hopped.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..sim.outcome import GOES_OVER, OVER_TURN_DEG, REAR_M, REARS_AND_RETURNS, STAYS_LOW
from ..tables import outcome_words
from ..trials.measure import MeasuredHop

OVER_REST_M = 0.03    # a marker at rest this far above where it stood: the robot lies on its back

ON_ITS_FEET, GOES_OVER_HERE, ON_ITS_BACK = "on its feet", "goes over", "on its back"


@dataclass(frozen=True)
class Ending:
    """How one run ended.

    Attributes
    ----------
    outcome : str
        ``goes_over``, ``rears_and_returns`` or ``stays_low``; "" when no hop is covered.
    over_hop : int or None
        The hop (from 1) in which it went over; None when it did not.
    travel_m : float
        The marker's travel from where it stood to where it rests at the end of the last hop
        covered [m] (nan when none is).
    rest_height_m : float
        The marker at that rest above where it stood [m].
    distance_m : float
        The robot's travel over the run as ``locust sim`` gives it (the chassis) [m]; nan for a
        filmed trial, whose chassis the camera does not follow.
    """

    outcome: str
    over_hop: int | None
    travel_m: float
    rest_height_m: float
    distance_m: float = math.nan

    def state(self, hop: int) -> str:
        """Where the robot is at the end of ``hop``: on its feet, going over in it, or on its back.

        Parameters
        ----------
        hop : int
            From 1.

        Returns
        -------
        str
            ``on its feet``, ``goes over`` or ``on its back``.
        """
        if self.over_hop is None or hop < self.over_hop:
            return ON_ITS_FEET
        return GOES_OVER_HERE if hop == self.over_hop else ON_ITS_BACK

    def came_down(self, hop: int) -> bool:
        """Whether ``hop`` ended back on the robot's feet (its apex is then a jump)."""
        return self.state(hop) == ON_ITS_FEET

    def to_json(self) -> dict:
        """The ending as ``report.json`` keeps it.

        Returns
        -------
        dict
            ``outcome``, ``over_hop``, ``travel_m``, ``rest_height_m``, ``distance_m`` and the words.
        """
        return {"outcome": self.outcome, "over_hop": self.over_hop, "travel_m": self.travel_m,
                "rest_height_m": self.rest_height_m, "distance_m": self.distance_m, "words": words(self)}


def marker_ending(hops: Sequence[MeasuredHop]) -> Ending:
    """How a run ended, from its marker's hops (a track's, or the simulated marker's).

    Parameters
    ----------
    hops : sequence of MeasuredHop
        The hops, in order, with their rest heights.

    Returns
    -------
    Ending
        Its outcome, the hop it went over in, and where its marker rests.
    """
    covered = [h for h in hops if math.isfinite(h.rest_height_m)]
    if not covered:
        return Ending("", None, math.nan, math.nan)
    over = next((h.hop for h in covered if h.rest_height_m > OVER_REST_M), None)
    last = covered[-1]
    travel = math.fsum(h.distance_m for h in hops if h.hop <= last.hop)
    if over is not None:
        outcome = GOES_OVER
    elif all(h.apex_m > REAR_M for h in covered):
        outcome = REARS_AND_RETURNS
    else:
        outcome = STAYS_LOW
    return Ending(outcome, over, travel, last.rest_height_m)


def simulated_ending(result, marker_hops: Sequence[MeasuredHop] = ()) -> Ending:
    """How a simulated run ended, by :mod:`locust.sim.outcome` and ``locust sim``'s distance.

    Parameters
    ----------
    result : SimResult
        A valid run (:func:`locust.sim.run.run`), its hops with their end pitch.
    marker_hops : sequence of MeasuredHop
        The simulated marker's hops, for where the marker rests.

    Returns
    -------
    Ending
        The run's outcome, the first hop whose cycle ends turned past
        :data:`~locust.sim.outcome.OVER_TURN_DEG`, the marker's rest, and the run's distance.
    """
    over = next((h.cycle for h in result.hops if h.end_turn_deg > OVER_TURN_DEG), None)
    seen = marker_ending(marker_hops)
    return Ending(result.outcome or "", over, seen.travel_m, seen.rest_height_m, float(result.distance_m))


def _behind(length_m: float) -> str:
    return f"{abs(length_m) * 1000:.1f} mm {'behind' if length_m < 0 else 'ahead of'}"


def words(e: Ending) -> str:
    """The ending as a sentence: ``goes over at hop 1, rests on its back 72.5 mm behind its start``.

    Parameters
    ----------
    e : Ending

    Returns
    -------
    str
        For a simulated run (``distance_m`` known) where the robot rests; for a filmed one where
        its marker does.
    """
    if not e.outcome:
        return "not seen (the track covers no hop)"
    if e.outcome != GOES_OVER:
        return outcome_words(e.outcome)
    said = f"goes over at hop {e.over_hop}"
    if math.isfinite(e.distance_m):
        return f"{said}, rests on its back {_behind(e.distance_m)} its start"
    if math.isfinite(e.travel_m):
        return (f"{said}, its marker at rest {e.rest_height_m * 1000:.1f} mm up and {_behind(e.travel_m)} "
                "where it stood")
    return said


def trials_words(endings: Sequence[Ending]) -> str:
    """How a configuration's filmed trials ended: one sentence when they agree (their marker's
    rest averaged), else each way with its count.

    Parameters
    ----------
    endings : sequence of Ending
        One per trial with a track.

    Returns
    -------
    str
        ``—`` without trials.
    """
    seen = [e for e in endings if e.outcome]
    if not seen:
        return "—"
    kinds: dict[tuple[str, int | None], list[Ending]] = {}
    for e in seen:
        kinds.setdefault((e.outcome, e.over_hop), []).append(e)
    if len(kinds) == 1:
        (outcome, hop), group = next(iter(kinds.items()))
        mean = Ending(outcome, hop, math.fsum(e.travel_m for e in group) / len(group),
                      math.fsum(e.rest_height_m for e in group) / len(group))
        return words(mean) + (f" (all {len(group)} trials)" if len(group) > 1 else "")
    parts = []
    for (outcome, hop), group in kinds.items():
        what = f"goes over at hop {hop}" if outcome == GOES_OVER else outcome_words(outcome)
        parts.append(f"{what} in {len(group)} of {len(seen)} trials")
    return "; ".join(parts)
