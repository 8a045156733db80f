"""Whether a robot's draws are converged in the step: what the ensemble states, at dt and dt/2.

A draw that sits on the threshold between two outcomes flips under any change of the step, as
it would under any perturbation: its own figures are not converged at any step. What draws
state is their outcome shares and the quantiles of their figures, so that is what
``--check-convergence`` with ``--samples`` judges. The same draws (their seed) are run again
with every step halved (``Solver.steps_scaled``) and:

- each outcome's share at dt/2 is set against the 95 % binomial interval of its share at dt
  (Wilson's score interval over the valid draws);
- the 10th, 50th and 90th percentiles of the distance and of the highest nose point, over the
  draws valid at both steps, at dt/2 against the 95 % bootstrap interval of each at dt
  (:data:`BOOTSTRAP_DRAWS` resamples of the draws, seed 0);
- each draw whose outcome differs between the two steps is named, a flip on the threshold,
  not a failure of convergence by itself.

The ensemble is converged when every share and every percentile at dt/2 lies in its interval.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..params import Robot
from .outcome import OUTCOMES
from .samples import Samples, sample

Z_95 = 1.959963984540054
QUANTILES = (0.1, 0.5, 0.9)
BOOTSTRAP_DRAWS = 1000
FIGURES = ("distance_m", "max_nose_height_m")


def wilson_interval(k: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson's score interval of a share ``k / n`` (95 % at the default ``z``).

    Parameters
    ----------
    k, n : int
        Draws with the outcome, and valid draws.
    z : float
        The normal quantile of the interval.

    Returns
    -------
    low, high : float
        In 0..1; (nan, nan) for no draws.
    """
    if n <= 0:
        return math.nan, math.nan
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def bootstrap_interval(values: np.ndarray, q: float, draws: int = BOOTSTRAP_DRAWS,
                       seed: int = 0) -> tuple[float, float]:
    """The 95 % bootstrap interval of the ``q`` quantile of ``values``.

    Parameters
    ----------
    values : ndarray
        The draws' figure (finite).
    q : float
        The quantile, 0..1.
    draws : int
        Resamples.
    seed : int
        Seed of NumPy's default generator.

    Returns
    -------
    low, high : float
        The 2.5th and 97.5th percentiles of the resampled quantile; (nan, nan) for fewer than
        two values.
    """
    if values.size < 2:
        return math.nan, math.nan
    rng = np.random.default_rng(seed)
    resampled = np.quantile(values[rng.integers(0, values.size, (draws, values.size))], q, axis=1)
    return float(np.quantile(resampled, 0.025)), float(np.quantile(resampled, 0.975))


@dataclass(frozen=True)
class ShareChange:
    """One outcome's share of the draws at dt and at dt/2, and the interval of the first."""

    outcome: str
    share: float              # of the valid draws at dt
    half_share: float         # at dt/2
    low: float                # the 95 % binomial interval of the share at dt
    high: float

    @property
    def within(self) -> bool:
        """Whether the share at dt/2 lies in the interval of the share at dt."""
        return self.low - 1e-12 <= self.half_share <= self.high + 1e-12


@dataclass(frozen=True)
class QuantileChange:
    """A percentile of one figure over the draws at dt and dt/2, and its interval at dt [m]."""

    figure: str               # distance_m or max_nose_height_m
    q: float
    value_m: float
    half_value_m: float
    low_m: float              # the 95 % bootstrap interval of the percentile at dt
    high_m: float

    @property
    def within(self) -> bool:
        """Whether the percentile at dt/2 lies in the interval of the percentile at dt."""
        return self.low_m <= self.half_value_m <= self.high_m


@dataclass(frozen=True)
class Flip:
    """A draw whose outcome is another at dt/2 (``None``: not a valid run there)."""

    draw: int
    outcome: str | None
    half_outcome: str | None


@dataclass(frozen=True)
class EnsembleConvergence:
    """The draws' shares and percentiles at dt and at dt/2 (see the module docstring).

    Attributes
    ----------
    n : int
        Draws.
    half_timestep_s : float
        The step of the rerun [s].
    shares : list of ShareChange
        Each outcome's.
    quantiles : list of QuantileChange
        The distance's and the highest nose's 10th, 50th and 90th percentiles.
    flips : list of Flip
        The draws whose outcome differs at dt/2.
    half : Samples
        The draws at dt/2.
    """

    n: int
    half_timestep_s: float
    shares: list[ShareChange]
    quantiles: list[QuantileChange]
    flips: list[Flip]
    half: Samples

    @property
    def converged(self) -> bool:
        """Every share and every percentile at dt/2 within its interval at dt."""
        return all(s.within for s in self.shares) and all(q.within for q in self.quantiles)

    def to_json(self) -> dict:
        """The comparison as JSON-ready values (the dt/2 draws' own figures under ``half``).

        Returns
        -------
        dict
        """
        out = {"n": self.n, "half_timestep_s": self.half_timestep_s, "converged": self.converged,
               "shares": [{**dataclasses.asdict(s), "within": s.within} for s in self.shares],
               "quantiles": [{**dataclasses.asdict(q), "within": q.within} for q in self.quantiles],
               "flips": [dataclasses.asdict(f) for f in self.flips]}
        out["half"] = self.half.to_json()
        return out


def compare(spread: Samples, half: Samples, half_timestep_s: float) -> EnsembleConvergence:
    """The draws ``spread`` at dt against the same draws ``half`` at dt/2.

    Parameters
    ----------
    spread, half : Samples
        The draws at the robot's steps and with every step halved (the same seed).
    half_timestep_s : float
        The rerun's step [s].

    Returns
    -------
    EnsembleConvergence
    """
    shares = []
    for name in OUTCOMES:
        a, b = spread.outcomes.get(name), half.outcomes.get(name)
        k = a.n if a else 0
        low, high = wilson_interval(k, spread.n_valid)
        shares.append(ShareChange(outcome=name, share=a.share if a else 0.0, half_share=b.share if b else 0.0,
                                  low=low, high=high))
    quantiles = []
    for figure in FIGURES:
        at, at_half = np.array(getattr(spread, figure)), np.array(getattr(half, figure))
        both = np.isfinite(at) & np.isfinite(at_half)
        for q in QUANTILES:
            low, high = bootstrap_interval(at[both], q)
            quantiles.append(QuantileChange(
                figure=figure, q=q, value_m=float(np.quantile(at[both], q)) if both.any() else math.nan,
                half_value_m=float(np.quantile(at_half[both], q)) if both.any() else math.nan, low_m=low, high_m=high))
    flips = [Flip(draw=i, outcome=a, half_outcome=b) for i, (a, b) in enumerate(zip(spread.outcome, half.outcome))
             if a != b]
    return EnsembleConvergence(n=spread.n, half_timestep_s=half_timestep_s, shares=shares, quantiles=quantiles,
                               flips=flips, half=half)


def ensemble_convergence(robot: Robot, spread: Samples, cycles: int | None = None,
                         progress: Callable[[int], None] | None = None) -> EnsembleConvergence:
    """Run ``spread``'s draws again with every step halved and compare (module docstring).

    Parameters
    ----------
    robot : Robot
        The robot the draws were drawn about.
    spread : Samples
        Its draws (``locust.sim.samples.sample`` or ``locust sim --samples``).
    cycles : int, optional
        Hop cycles, as for ``spread``.
    progress : callable, optional
        ``progress(k)`` as each batch of ``k`` draws is done.

    Returns
    -------
    EnsembleConvergence
    """
    half_robot = robot.with_values(robot.solver.steps_scaled(0.5))
    half = sample(half_robot, spread.n, cycles, spread.seed, progress)
    return compare(spread, half, half_robot.solver.timestep_s)


__all__ = ["BOOTSTRAP_DRAWS", "EnsembleConvergence", "Flip", "QUANTILES", "QuantileChange", "ShareChange",
           "bootstrap_interval", "compare", "ensemble_convergence", "wilson_interval"]
