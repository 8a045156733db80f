"""What a design is judged by: objectives by name, per hop over the run, and their robust figure.

Each objective is a figure of one simulated run per hop, as its name and its column say (the
run's figure over its cycles; ``distance`` alone, in ``locust sim``, ``sweep`` and ``report``,
is the travel over the whole run):

- ``distance_per_hop``: ``distance_per_hop_m``, the chassis' travel over the run (``locust
  sim``'s and ``sweep``'s ``distance_m``) divided by the hop cycles (m a hop);
- ``nose_rise_per_hop``: ``nose_rise_per_hop_m``, the nose's highest point above its standing
  height in each hop (``locust sim``'s "nose rise"), the mean over the hops (m);
- ``flight_per_hop``: ``flight_per_hop_s``, the longest time with no part of the robot on the
  floor in each hop, the mean over the hops (s).

All three are maximised. A draw (or a nominal run) that goes over onto its back scores 0 on
every objective: a robot on its back does not hop again, and its nose resting high is not a
jump. Over ``N`` draws, the figure optimised is the ``quantile`` of the draws' figures (0.1:
the figure 9 draws in 10 beat); the mean is reported beside it. The flip share is the share of
the valid draws that go over; a draw that fails its audit is left out of every share and
figure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import SweepError
from ..sim.outcome import GOES_OVER, OUTCOMES


@dataclass(frozen=True)
class Objective:
    """One objective: its command-line name, its column (with unit) and what it measures.

    Attributes
    ----------
    name : str
        The ``--objective`` name: ``distance_per_hop``, ``nose_rise_per_hop`` or ``flight_per_hop``.
    column : str
        Its column in the trial rows, with its unit: ``distance_per_hop_m``, ``nose_rise_per_hop_m``,
        ``flight_per_hop_s``.
    label : str
        Axis label, in the unit the plots draw it in.
    plot_factor : float
        Factor from the column's unit to the plotted one (1000: m to mm, s to ms).
    """

    name: str
    column: str
    label: str          # axis label, in the unit the plots draw it in
    plot_factor: float  # column unit -> plotted unit


OBJECTIVES = {
    "distance_per_hop": Objective("distance_per_hop", "distance_per_hop_m", "distance per hop (mm)", 1000.0),
    "nose_rise_per_hop": Objective("nose_rise_per_hop", "nose_rise_per_hop_m", "nose rise per hop (mm)", 1000.0),
    "flight_per_hop": Objective("flight_per_hop", "flight_per_hop_s", "flight per hop (ms)", 1000.0),
}
DEFAULT = "distance_per_hop"
# the names before each said that it is a figure per hop: refused, with the name that is
RENAMED = {"distance": "distance_per_hop", "nose_rise": "nose_rise_per_hop", "flight": "flight_per_hop"}


def objectives_named(names: list[str] | tuple[str, ...]) -> list[Objective]:
    """The objectives ``names`` in the order given; ``distance_per_hop`` when none is given.

    Parameters
    ----------
    names : list or tuple of str
        ``--objective`` names.

    Returns
    -------
    list of Objective
        The objectives.

    Raises
    ------
    SweepError
        An unknown or repeated name, or a name without the ``_per_hop`` it now has (:data:`RENAMED`).
    """
    if not names:
        return [OBJECTIVES[DEFAULT]]
    out = []
    for name in names:
        if name in RENAMED:
            raise SweepError(f"--objective {name!r}: each objective is a figure per hop, and says so in its name "
                             f"(`{name}` alone is the figure over the whole run in locust sim, sweep and report)",
                             f"give --objective {RENAMED[name]}")
        if name not in OBJECTIVES:
            raise SweepError(f"--objective {name!r}: no such objective",
                             f"choose from {', '.join(OBJECTIVES)}")
        if OBJECTIVES[name] in out:
            raise SweepError(f"--objective {name} given twice", "give each objective once")
        out.append(OBJECTIVES[name])
    return out


@dataclass(frozen=True)
class DrawFigures:
    """One simulated run's outcome and its per-hop figures, by objective column.

    Attributes
    ----------
    outcome : str
        ``goes_over``, ``rears_and_returns`` or ``stays_low``.
    figures : dict of str to float
        Column (``distance_per_hop_m`` [m], ``nose_rise_per_hop_m`` [m], ``flight_per_hop_s`` [s]) to
        its per-hop figure.
    """

    outcome: str
    figures: dict[str, float]


@dataclass(frozen=True)
class Judgement:
    """A design judged over its draws (or its nominal run alone).

    ``figures`` holds each objective's figure optimised (the quantile over the draws, or the
    nominal run's figure), ``means`` its mean over the same draws; shares are of the valid draws.

    Attributes
    ----------
    valid : bool
        Enough draws passed their audit (and the design could be built).
    reason : str
        Why it is not valid ("" when it is).
    figures, means : dict of str to float
        Objective column to its figure optimised and its mean, in the column's unit.
    flip_share : float
        Share of the valid draws that go over.
    outcome_shares : dict of str to float
        Each outcome's share of the valid draws.
    draws, draws_valid : int
        Draws simulated, and those that passed their audit.
    """

    valid: bool
    reason: str
    figures: dict[str, float] = field(default_factory=dict)
    means: dict[str, float] = field(default_factory=dict)
    flip_share: float = math.nan
    outcome_shares: dict[str, float] = field(default_factory=dict)
    draws: int = 0
    draws_valid: int = 0


def per_hop_figures(distance_m: float, hops: list, cycles: int, outcome: str) -> DrawFigures:
    """A run's per-hop figures from its travel over the run and its hops
    (:class:`locust.sim.hops.Hop`); every figure 0 when the run went over.

    Parameters
    ----------
    distance_m : float
        Chassis travel over the run [m].
    hops : list of Hop
        The run's hops (nose apex [m], flight time [s]).
    cycles : int
        Hop cycles of the run.
    outcome : str
        The run's class.

    Returns
    -------
    DrawFigures
        ``distance_per_hop_m`` [m], the mean ``nose_rise_per_hop_m`` [m] and the mean
        ``flight_per_hop_s`` [s].
    """
    if outcome == GOES_OVER:
        return DrawFigures(outcome, {o.column: 0.0 for o in OBJECTIVES.values()})
    return DrawFigures(outcome, {
        "distance_per_hop_m": distance_m / cycles,
        "nose_rise_per_hop_m": float(np.mean([h.nose_apex_m for h in hops])) if hops else 0.0,
        "flight_per_hop_s": float(np.mean([h.flight_s for h in hops])) if hops else 0.0,
    })


def judge_draws(draws: list[DrawFigures | None], objectives: list[Objective], quantile: float | None,
                min_valid_share: float = 0.5) -> Judgement:
    """Aggregate the draws of one design (None: a draw that failed its audit).

    Parameters
    ----------
    draws : list of DrawFigures or None
        Every draw, the same draws for every design.
    objectives : list of Objective
        What the design is judged by.
    quantile : float or None
        The quantile of the draws' figures taken as the figure optimised (0.1: the figure 9 in
        10 draws beat); None for a single nominal run, whose figure is taken as it is.
    min_valid_share : float
        Fewer valid draws than this share make the design invalid.

    Returns
    -------
    Judgement
        Valid with its figures, means and shares; or invalid with the number of failed draws.
    """
    valid = [d for d in draws if d is not None]
    n = len(draws)
    if not valid or len(valid) < min_valid_share * n:
        return Judgement(False, f"{n - len(valid)} of {n} draws of the uncertain values fail their audit",
                         draws=n, draws_valid=len(valid))
    shares = {name: sum(d.outcome == name for d in valid) / len(valid) for name in OUTCOMES}
    figures, means = {}, {}
    for o in objectives:
        values = np.array([d.figures[o.column] for d in valid], dtype=float)
        means[o.column] = float(np.mean(values))
        figures[o.column] = float(np.quantile(values, quantile)) if quantile is not None else float(values[0])
    return Judgement(True, "", figures, means, shares[GOES_OVER], shares, n, len(valid))
