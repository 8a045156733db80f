"""How sure a prediction is: the marker trace and the hops at draws of the uncertain values.

The robot's values that carry an uncertainty are drawn as ``locust sim --samples`` draws
them (:func:`locust.sim.samples.draw`), all draws of a configuration are simulated in one
batched rollout, and each valid draw's marker trace is taken like the prediction's own
(:func:`.predict.marker_trace`, the same rows, so the draws share one clock). The band is
the draws' mean +- one standard deviation at every instant; each hop's marker distance and
apex (cut as the prediction's own are) get their standard deviation over the draws.
Each valid draw is classified (:mod:`locust.sim.outcome`), and each outcome's share and its
own distance and highest nose are kept, as ``locust sim --samples`` reports them.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..params import Robot
from ..sim.hops import summarise
from ..sim.outcome import OutcomeFigures, classify, outcome_shares
from ..sim.samples import simulate_draws
from ..trials.measure import measure_hops
from .predict import marker_trace


@dataclass(frozen=True)
class Spread:
    """The prediction's spread over draws of the robot's uncertain values.

    Attributes
    ----------
    n : int
        Draws simulated.
    n_valid : int
        Draws that passed their audit.
    t_s : ndarray
        The schedule's clock [s].
    x_mean_m, x_sd_m, y_mean_m, y_sd_m : ndarray
        Mean and sample standard deviation over the valid draws of the marker's forward and
        vertical position at every instant [m].
    hop_distance_sd_m, hop_apex_sd_m : list of float
        Per hop, the standard deviation of the marker's distance and apex [m] (nan with fewer
        than two finite values).
    outcomes : dict of str to OutcomeFigures
        Each outcome's share of the valid draws and its distance and highest nose.
    """

    n: int                         # draws
    n_valid: int
    t_s: np.ndarray                # the schedule's clock
    x_mean_m: np.ndarray
    x_sd_m: np.ndarray
    y_mean_m: np.ndarray
    y_sd_m: np.ndarray
    hop_distance_sd_m: list[float]     # per hop (nan with fewer than two valid draws)
    hop_apex_sd_m: list[float]
    outcomes: dict[str, OutcomeFigures] = field(default_factory=dict)   # each outcome's share and figures

    def to_json(self) -> dict:
        """The spread as ``report.json`` keeps it (no traces).

        Returns
        -------
        dict
            ``n``, ``n_valid``, per-hop ``hop_distance_sd_m`` and ``hop_apex_sd_m`` [m], and each
            outcome's share and figures.
        """
        return {"n": self.n, "n_valid": self.n_valid, "hop_distance_sd_m": self.hop_distance_sd_m,
                "hop_apex_sd_m": self.hop_apex_sd_m,
                "outcomes": {k: dataclasses.asdict(v) for k, v in self.outcomes.items()}}


def spread(robot: Robot, cycles: int, marker: str, n: int, seed: int = 0) -> Spread | None:
    """``n`` draws of ``robot`` over ``cycles``, simulated in one batch.

    Parameters
    ----------
    robot : Robot
        The robot; its values with an uncertainty are drawn.
    cycles : int
        Cycles to simulate.
    marker : str
        The model's marker to follow.
    n : int
        Number of draws.
    seed : int
        Seed of the draws.

    Returns
    -------
    Spread or None
        None when fewer than two draws are valid.
    """
    period = robot.schedule.push_s + robot.schedule.wait_s
    traces, dist, apex, kinds, run_dist, run_nose = [], [], [], [], [], []
    for traj in simulate_draws(robot, n, cycles, seed, keep_states=True):
        if traj is None:
            continue
        trace = marker_trace(traj, marker)
        traces.append(trace)
        hops = measure_hops(trace, period, cycles)
        summary = summarise(traj)
        kinds.append(classify(summary.hops))
        run_dist.append(summary.distance_m)
        run_nose.append(summary.max_nose_height_m)
        dist.append([h.distance_m for h in hops])
        apex.append([h.apex_m for h in hops])
    if len(traces) < 2:
        return None
    xs = np.array([t.x_m for t in traces])
    ys = np.array([t.y_m for t in traces])

    def sd(rows: list[list[float]]) -> list[float]:
        a = np.array(rows, dtype=float)
        return [float(v) if math.isfinite(v) else math.nan for v in np.std(a, axis=0, ddof=1)]

    return Spread(n=n, n_valid=len(traces), t_s=traces[0].t_s, x_mean_m=xs.mean(0), x_sd_m=xs.std(0, ddof=1),
                  y_mean_m=ys.mean(0), y_sd_m=ys.std(0, ddof=1), hop_distance_sd_m=sd(dist), hop_apex_sd_m=sd(apex),
                  outcomes=outcome_shares(kinds, run_dist, run_nose))
