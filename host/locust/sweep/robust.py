"""``DesignJudge``: one design judged on its nominal run or over draws of its uncertain values.

With ``draws`` N, the design is simulated at N draws of every value of the robot file that
carries an uncertainty (:func:`locust.sim.samples.simulate_draws`, one batched rollout), each
audited and classified (:mod:`locust.sim.outcome`). The draws are common random numbers: seed
``seed`` gives the same standard normal deviates to every design, and a value a design sets
keeps the uncertainty of the value it replaces (:func:`locust.sweep.design.design_robot`), so
every design meets the same draws of what is not known about the robot.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..errors import GeometryError, LocustError
from ..params import Robot, problems
from .design import design_robot, precheck
from .objectives import DrawFigures, Judgement, Objective, judge_draws, per_hop_figures


def draw_figures(traj, cycles: int, audited: bool = False) -> DrawFigures | None:
    """One trajectory -> its outcome (:func:`locust.sim.outcome.classify`) and per-hop figures.

    Parameters
    ----------
    traj : Trajectory or None
        A rollout.
    cycles : int
        Hop cycles it ran.
    audited : bool, default False
        It has passed its audit already (or is None): not audited again.

    Returns
    -------
    DrawFigures or None
        The figures; None when it is None or fails its audit.
    """
    from ..sim.audit import audit
    from ..sim.hops import summarise
    from ..sim.outcome import classify

    if traj is None or not (audited or audit(traj).valid):
        return None
    summary = summarise(traj)
    return per_hop_figures(summary.distance_m, summary.hops, cycles, classify(summary.hops))


@dataclass(frozen=True)
class DesignJudge:
    """Judge designs of ``base`` (a picklable callable: ``judge(values) -> Judgement``).

    ``draws`` 0 judges the nominal run alone (its outcome is the flip share, 0 or 1);
    otherwise each objective's figure is the ``quantile`` over the draws.

    Attributes
    ----------
    base : Robot
        The robot every design starts from.
    cycles : int
        Hop cycles each design runs.
    objectives : tuple of Objective
        What is judged.
    draws : int
        Draws of the uncertain values per design (0: the nominal run).
    quantile : float
        The quantile of the draws each figure is.
    seed : int
        Seed of the draws (the same deviates for every design).
    """

    base: Robot
    cycles: int
    objectives: tuple[Objective, ...]
    draws: int = 0
    quantile: float = 0.1
    seed: int = 0

    def __call__(self, values: dict[str, Any]) -> Judgement:
        """Judge the design with ``values``: build it, check it, simulate it (nominal run or draws).

        Parameters
        ----------
        values : dict
            Parameter name (or ``scale``) to value, in the parameter's unit.

        Returns
        -------
        Judgement
            Its figures, or invalid with the reason (it cannot be built or driven, a value out of
            range, the nominal run fails its audit, too few valid draws).
        """
        try:
            robot = design_robot(self.base, values)
        except LocustError as exc:
            return Judgement(False, str(exc))
        reason = "; ".join(problems(robot, self.cycles)) or precheck(robot)
        if reason:
            return Judgement(False, reason)
        try:
            figures = self._figures(robot)
        except (GeometryError, LocustError) as exc:
            return Judgement(False, str(exc))
        if self.draws == 0 and figures[0] is None:
            return Judgement(False, "the nominal run fails its audit", draws=1)
        return judge_draws(figures, list(self.objectives), self.quantile if self.draws else None)

    def _figures(self, robot: Robot) -> list[DrawFigures | None]:
        from ..sim.model import build
        from ..sim.rollout import roll_out
        from ..sim.samples import simulate_draws

        if self.draws == 0:
            return [draw_figures(roll_out(robot, cycles=self.cycles, built=build(robot)), self.cycles)]
        trajs = simulate_draws(robot, self.draws, cycles=self.cycles, seed=self.seed)
        # simulate_draws has audited each draw (None: outside the limits, or failed)
        return [draw_figures(t, self.cycles, audited=True) for t in trajs]
