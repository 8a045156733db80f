"""A prediction's spread: the robot simulated at draws of its uncertain values.

Every value of the robot file that carries an uncertainty (one standard deviation, written
by ``locust calibrate`` beside the value) is drawn from a normal distribution about it,
independently; a positive value stays positive (draws below a tenth of it are put there).
All draws are simulated in one batched ``mujoco.rollout`` on every core and each is audited and summarised
like ``locust sim``'s own run; the spread of the valid ones is the prediction's uncertainty.
Each valid draw is also classified (:mod:`.outcome`): near the threshold the draws split
between going over and coming back, so each outcome's share and its own figures are the
prediction, not one mean and sd across both.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from ..params import Provenance, Robot, check_robot, problems, real_keys
from .audit import audit
from .batching import check_batch
from .figures import BATCH_PER_CORE, RunFigures, run_figures
from .model import build
from .outcome import OutcomeFigures, outcome_shares
from .rollout import Trajectory, available_cores, simulate_batch
from .schedule import control_plan

MIN_FRACTION = 0.1      # a positive value's draws are kept above this fraction of it


@dataclass(frozen=True)
class Samples:
    """The spread of ``n`` draws; figures over the valid ones (nan when fewer than two).

    Attributes
    ----------
    n : int
        Draws simulated.
    n_valid : int
        Draws that were built and passed their audit.
    seed : int
        The random generator's seed.
    uncertain : dict of str to float
        Robot-file key -> the standard deviation it was drawn with (in the key's own unit).
    distance_m : list of float
        Chassis x travelled from the start of the schedule to the end of the run, per draw
        (nan: invalid) [m].
    max_nose_height_m : list of float
        Highest nose point during the run, per draw (nan: invalid) [m].
    distance_m_mean, distance_m_sd : float
        Mean and sample standard deviation of the valid draws' distances [m].
    max_nose_height_m_mean, max_nose_height_m_sd : float
        Mean and sample standard deviation of the valid draws' nose heights [m].
    outcome : list of str or None
        Each draw's outcome (:func:`~locust.sim.outcome.classify`; None: invalid).
    outcomes : dict of str to OutcomeFigures
        Each outcome's share of the valid draws and its own figures.
    """

    n: int
    n_valid: int
    seed: int
    uncertain: dict[str, float]          # key -> one standard deviation drawn from
    distance_m: list[float]              # per draw (nan: failed its audit)
    max_nose_height_m: list[float]
    distance_m_mean: float
    distance_m_sd: float
    max_nose_height_m_mean: float
    max_nose_height_m_sd: float
    outcome: list[str | None] = dataclasses.field(default_factory=list)   # per draw (None: invalid)
    outcomes: dict[str, OutcomeFigures] = dataclasses.field(default_factory=dict)

    def to_json(self) -> dict:
        """Every field as plain JSON-ready values (nested dataclasses as dicts).

        Returns
        -------
        dict
            Field name -> value, units as the field names say.
        """
        return dataclasses.asdict(self)


def uncertain_values(robot: Robot) -> dict[str, float]:
    """Real-valued keys whose provenance gives a positive, finite uncertainty -> that uncertainty.

    Parameters
    ----------
    robot : Robot
        The robot, its values and their provenance.

    Returns
    -------
    dict of str to float
        Key -> one standard deviation, in the key's own unit (keys with a finite value only).
    """
    out = {}
    for key in real_keys():
        sd = robot.source_of(key).uncertainty
        if sd and math.isfinite(sd) and math.isfinite(robot.get(key)):
            out[key] = float(sd)
    return out


def draw(robot: Robot, n: int, seed: int = 0) -> list[Robot]:
    """``n`` robots with every uncertain value drawn about its own (see the module docstring).

    Parameters
    ----------
    robot : Robot
        The robot whose uncertain values are drawn.
    n : int
        Draws.
    seed : int
        Seed of NumPy's default generator.

    Returns
    -------
    list of Robot
        The draws, each value's provenance ``sample``; values without uncertainty unchanged.
    """
    sds = uncertain_values(robot)
    rng = np.random.default_rng(seed)
    keys = list(sds)
    centre = np.array([robot.get(k) for k in keys], dtype=float)
    values = centre + rng.standard_normal((n, len(keys))) * np.array([sds[k] for k in keys])
    values = np.where(centre > 0, np.maximum(values, MIN_FRACTION * centre), values)
    prov = Provenance(source="sample", note=f"drawn from the uncertainties, seed {seed}")
    return [robot.with_values(dict(zip(keys, row.tolist())), prov) for row in values]


def check_draws(robot: Robot, n: int, cycles: int | None = None, keep_states: bool = False):
    """The plan of ``n`` draws of ``robot``; refused (:class:`~locust.errors.SimError`) before
    any is drawn, built or run when their record would be over the batch's memory limit.

    Parameters
    ----------
    robot : Robot
        The robot at its own values.
    n : int
        Draws.
    cycles : int, optional
        Hop cycles instead of the schedule's.
    keep_states : bool
        Whether every step's state would be kept.

    Returns
    -------
    ControlPlan
        The servo command of every step, shared by all draws.

    Raises
    ------
    ParamsError
        ``robot`` is outside the parameter limits or its run too long.
    GeometryError, SimError
        ``robot``'s model cannot be built, or the draws' record would be over the memory limit.
    """
    check_robot(robot, cycles)
    plan = control_plan(robot.schedule, robot.solver, cycles)
    check_batch(build(robot).model, n, plan.nstep, keep_states)
    return plan


def simulate_draws(robot: Robot, n: int, cycles: int | None = None, seed: int = 0,
                   keep_states: bool = False, progress: Callable[[int], None] | None = None
                   ) -> list[Trajectory | None]:
    """``n`` draws of ``robot`` simulated in batches on every core, each audited: a draw's
    trajectory, or None for a draw outside the parameter limits, whose linkage cannot close,
    or that fails its audit (as a sweep's design would be an invalid row).

    With ``progress``, the draws go in batches of :data:`BATCH_PER_CORE` per core, and
    ``progress(k)`` is called as each batch of ``k`` draws is done (one call otherwise).

    Parameters
    ----------
    robot : Robot
        The robot at its own values.
    n : int
        Draws.
    cycles : int, optional
        Hop cycles instead of the schedule's.
    seed : int
        Seed of the draws (:func:`draw`).
    keep_states : bool
        Keep every step's state in the trajectories.
    progress : callable, optional
        Called with the number of draws just done (invalid ones first, in one call).

    Returns
    -------
    list of Trajectory or None
        One per draw, in order.

    Raises
    ------
    ParamsError, GeometryError, SimError
        As :func:`check_draws`, before anything is drawn.
    """
    plan = check_draws(robot, n, cycles, keep_states)
    builts = []
    for r in draw(robot, n, seed):
        try:
            builts.append(None if problems(r, cycles) else build(r))
        except GeometryError:
            builts.append(None)
    ok = [b for b in builts if b is not None]
    if progress and len(ok) < n:
        progress(n - len(ok))
    size = BATCH_PER_CORE * available_cores() if progress else max(len(ok), 1)
    done: list[Trajectory] = []
    for first in range(0, len(ok), size):
        done += simulate_batch(ok[first:first + size], plan, keep_states=keep_states)
        if progress:
            progress(len(ok[first:first + size]))
    trajs = iter(done)
    out: list[Trajectory | None] = []
    for b in builts:
        traj = next(trajs) if b is not None else None
        out.append(traj if traj is not None and audit(traj).valid else None)
    return out


def sample(robot: Robot, n: int, cycles: int | None = None, seed: int = 0,
           progress: Callable[[int], None] | None = None) -> Samples:
    """Simulate ``n`` draws of ``robot`` in one batch; their distances and nose heights.

    Parameters
    ----------
    robot : Robot
        The robot at its own values.
    n : int
        Draws.
    cycles : int, optional
        Hop cycles instead of the schedule's.
    seed : int
        Seed of the draws (:func:`draw`).
    progress : callable, optional
        As :func:`simulate_draws`.

    Returns
    -------
    Samples
        Each draw's figures and outcome, and their spread over the valid ones.

    Raises
    ------
    ParamsError, GeometryError, SimError
        As :func:`check_draws`, before anything is drawn.
    """
    check_draws(robot, n, cycles)
    return spread_of(robot, n, seed, run_figures(draw(robot, n, seed), cycles, progress))


def spread_of(robot: Robot, n: int, seed: int, figures: list[RunFigures | None]) -> Samples:
    """The spread of the draws ``draw(robot, n, seed)`` from each one's figures.

    Parameters
    ----------
    robot : Robot
        The robot drawn about.
    n : int
        Draws.
    seed : int
        Their seed.
    figures : list of RunFigures or None
        Each draw's figures, in order (None: outside the limits, not built, or not audited).

    Returns
    -------
    Samples
    """
    dist = [f.distance_m if f else math.nan for f in figures]
    nose = [f.max_nose_height_m if f else math.nan for f in figures]
    kind = [f.outcome if f else None for f in figures]
    d, h = np.array(dist), np.array(nose)
    valid = np.isfinite(d) & np.isfinite(h)

    def stats(a: np.ndarray) -> tuple[float, float]:
        if valid.sum() < 2:
            return math.nan, math.nan
        return float(np.mean(a[valid])), float(np.std(a[valid], ddof=1))

    (dm, ds), (hm, hs) = stats(d), stats(h)
    return Samples(n=n, n_valid=int(valid.sum()), seed=seed, uncertain=uncertain_values(robot), distance_m=dist,
                   max_nose_height_m=nose, distance_m_mean=dm, distance_m_sd=ds, max_nose_height_m_mean=hm,
                   max_nose_height_m_sd=hs, outcome=kind, outcomes=outcome_shares(kind, dist, nose))
