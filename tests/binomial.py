"""How many of n independent intervals must cover the truth for a coverage test to mean something.

An interval that covers with probability ``level`` covers a Binomial(n, level) number of times
in n independent draws. The floor is the largest count that the stated level reaches with
probability above ``pass_probability`` (0.999 by default: a correct fit fails the test at most
once in a thousand seeds' choices). Whether an interval too narrow fails it depends on n: at
n = 150 the floor is 133 and an 80 % interval reaches it with probability 0.0035; at n = 40 the
floor is 33 and an 80 % interval reaches it 44 % of the time (a smoke test, not a proof).
Several intervals per draw (one per fitted parameter) each held to the floor lower it a little
(150 draws, five intervals: 132).
"""

from __future__ import annotations

from scipy.stats import binom


def coverage_floor(draws: int, level: float = 0.95, pass_probability: float = 0.999, intervals: int = 1) -> int:
    """The least number of covering intervals out of ``draws`` that a test should demand.

    Parameters
    ----------
    draws : int
        Independent draws (seeds), one interval each.
    level : float
        The intervals' nominal coverage (0.95 for a 95 % interval).
    pass_probability : float
        The probability with which intervals of exactly ``level`` reach the floor.
    intervals : int
        Intervals per draw, each held to the floor (several parameters of one fit): each must
        then reach it with probability ``1 - (1 - pass_probability) / intervals`` (Bonferroni),
        so that all do with ``pass_probability`` or more.

    Returns
    -------
    int
        The largest ``k`` with ``P(Binomial(draws, level) >= k)`` above that probability.
    """
    each = 1.0 - (1.0 - pass_probability) / intervals
    k = draws
    while binom.sf(k - 1, draws, level) <= each:
        k -= 1
    return k


def chance_to_pass(draws: int, floor: int, level: float) -> float:
    """The probability that intervals covering with probability ``level`` reach ``floor`` of
    ``draws`` (to say in a test how weak a narrower interval's chance is)."""
    return float(binom.sf(floor - 1, draws, level))
