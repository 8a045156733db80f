"""Why a robot goes over, and what would change it: ``locust sim --explain``.

Three parts, each from simulations of the robot itself:

- **The tip-over** (:class:`TipOver`, from :mod:`.support`): for a run that goes over, when and
  from which pose: the last stretch, before the plate turns past
  :data:`~.outcome.OVER_TURN_DEG`, in which the robot stands on the floor with its centre of mass
  behind every point it stands on (gravity turning it over backwards about the rearmost), the
  support points then, how far behind the centre of mass is and for how long, and the servos'
  torque. For a run that does not go over, :class:`Approach`: the closest its centre of mass came
  to being behind its supports (the margin to going over this way).
- **The thresholds** (:class:`Threshold`): for every value that carries an uncertainty and every
  design value (:data:`DESIGN_KEYS`), the nearest value on each side at which the outcome
  changes, each value moved alone: probed at :data:`PROBES` times its scale (its standard
  deviation, or :data:`DESIGN_STEP` of its unit for a design value without one), then bisected
  :data:`BISECTIONS` times. Its distance is given in the value's unit and in its sd.
- **The tornado** (:class:`TornadoBar`): each uncertain value alone at -/+ :data:`K_SD` sd, its
  effect on the first hop's nose rise and on the run's distance (these runs are probes of the
  threshold search).

All runs of one stage go in batched rollouts (:func:`.figures.run_figures`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..params import Provenance, Robot
from ..tables import label, quantity, split_unit
from .figures import RunFigures, run_figures
from .hops import plate_pitch_deg
from .outcome import GOES_OVER, OVER_TURN_DEG
from .rollout import Trajectory, servo_control
from .samples import MIN_FRACTION, uncertain_values
from .sensitivity import K_SD
from .support import Stance, stances

# what a student can change on the robot they build, beside what carries an uncertainty
DESIGN_KEYS = (
    "geometry.ground_m", "geometry.crank_m", "geometry.coupler_m", "geometry.leg_m",
    "geometry.crank_start_deg", "geometry.ground_angle_deg", "geometry.servo_axis_x_m",
    "schedule.push_deg", "schedule.push_s",
)
# a design value's scale when it has no uncertainty, by its unit: a step a student would try
DESIGN_STEP = {"m": 0.002, "deg": 2.0, "s": 0.05, "kg": 0.002}
PROBES = (1.0, 2.0, 4.0, 8.0)   # multiples of the scale probed on each side
BISECTIONS = 5                   # halvings of the bracket where the outcome changes


@dataclass(frozen=True)
class SupportPhase:
    """One part of a tip-over: the robot on one kind of support (its knees, its feet).

    Attributes
    ----------
    parts : tuple of str
        What it stands on, rearmost first.
    start_s, end_s : float
        From and to, from the cycle's push [s].
    com_behind_max_m : float
        The farthest its centre of mass was behind the rearmost of them [m].
    """

    parts: tuple[str, ...]
    start_s: float
    end_s: float
    com_behind_max_m: float


@dataclass(frozen=True)
class TipOver:
    """How a run went over (see the module docstring).

    Attributes
    ----------
    cycle : int
        The cycle it went over in, from 1.
    start_s : float
        When its centre of mass went behind its supports, from that cycle's push [s].
    duration_s : float
        How long it stood so, tipping over backwards, before it left the floor or landed on a
        part behind its centre of mass [s].
    support : tuple of str
        The parts it stood on then, rearmost first (``left knee``, ``right foot``, ...).
    support_after : tuple of str
        Every part it stood on while tipping, in the order it came to stand on them.
    phases : tuple of SupportPhase
        The stretch by what it stood on (its rearmost support's kind: knees, then feet).
    support_forward_m : tuple of float
        Their positions along the robot's forward direction from the centre of mass [m]
        (positive: in front of it).
    com_behind_m : float
        How far the centre of mass was behind the rearmost support as it went behind: the
        largest over the stretch [m].
    com_behind_start_m : float
        The same at the stretch's first step [m].
    servo_torque_nm : tuple of float
        Each servo's torque (left, right) as it starts [N·m].
    servo_torque_mean_nm : tuple of float
        Each servo's torque over the stretch, its magnitude's mean [N·m].
    pitch_deg : float
        The plate's pitch then, less its standing pitch, nose up positive [deg].
    """

    cycle: int
    start_s: float
    duration_s: float
    support: tuple[str, ...]
    support_after: tuple[str, ...]
    phases: tuple[SupportPhase, ...]
    support_forward_m: tuple[float, ...]
    com_behind_m: float
    com_behind_start_m: float
    servo_torque_nm: tuple[float, float]
    servo_torque_mean_nm: tuple[float, float]
    pitch_deg: float


@dataclass(frozen=True)
class Approach:
    """For a run that does not go over: the closest its centre of mass came to being behind
    its supports while it stood on the floor during the pushes.

    Attributes
    ----------
    cycle : int
        The cycle, from 1.
    at_s : float
        When, from that cycle's push [s].
    com_behind_m : float
        The centre of mass behind its rearmost support then [m] (negative: in front, the
        margin to going over that way).
    support : tuple of str
        The parts it stood on then, rearmost first.
    """

    cycle: int
    at_s: float
    com_behind_m: float
    support: tuple[str, ...]


@dataclass(frozen=True)
class Edge:
    """Where a value moved alone changes the outcome, on one side of the robot's own value.

    Attributes
    ----------
    value : float
        The value at the change (the middle of the last bracket), in the key's unit.
    resolution : float
        Half the last bracket's width, in the key's unit.
    outcome : str or None
        The outcome beyond it (None: no valid robot there: a linkage that does not close, a
        value outside the limits, a run that fails its audit).
    distance : float
        ``value`` less the robot's own [the key's unit].
    distance_sd : float or None
        The same in the value's standard deviations (None: it carries none).
    """

    value: float
    resolution: float
    outcome: str | None
    distance: float
    distance_sd: float | None


@dataclass(frozen=True)
class Threshold:
    """A value's nearest outcome changes below and above it (None: none within the probes).

    Attributes
    ----------
    key : str
        The robot-file key.
    value : float
        The robot's own value.
    sd : float or None
        Its standard deviation (None: a design value without one).
    scale : float
        The step the probes are multiples of (the sd, or :data:`DESIGN_STEP`).
    below, above : Edge or None
        The nearest change each way.
    """

    key: str
    value: float
    sd: float | None
    scale: float
    below: Edge | None
    above: Edge | None

    @property
    def nearest(self) -> Edge | None:
        """The nearer of the two changes (None: neither within the probes)."""
        edges = [e for e in (self.below, self.above) if e is not None]
        return min(edges, key=lambda e: abs(e.distance)) if edges else None


@dataclass(frozen=True)
class TornadoBar:
    """One uncertain value alone at -/+ ``k_sd`` sd: the nose rise and distance at each end.

    Attributes
    ----------
    key : str
        The robot-file key.
    sd : float
        Its standard deviation, in the key's unit.
    low_value, high_value : float
        The ends (a positive value kept above a tenth of itself).
    low, high : RunFigures or None
        The run at each end (None: not a valid run).
    """

    key: str
    sd: float
    low_value: float
    high_value: float
    low: RunFigures | None
    high: RunFigures | None

    def swing(self, figure: str) -> float:
        """|high - low| of ``figure`` (``nose_rise_m`` or ``distance_m``), nan where an end is invalid."""
        if self.low is None or self.high is None:
            return math.nan
        return abs(getattr(self.high, figure) - getattr(self.low, figure))


@dataclass(frozen=True)
class Explanation:
    """Why the robot does what it does (see the module docstring).

    Attributes
    ----------
    outcome : str
        The robot's own outcome.
    nominal : RunFigures
        Its own run's figures.
    tip_over : TipOver or None
        How it went over (None: it did not).
    approach : Approach or None
        For a run that did not go over, the closest it came (None: it went over, or never stood
        on the floor during a push).
    thresholds : list of Threshold
        Every uncertain and design value, nearest change first.
    tornado : list of TornadoBar
        Every uncertain value, largest nose-rise swing first.
    k_sd : float
        The tornado's ends, in sd.
    cycles : int
        The cycles every run simulated.
    runs : int
        Simulations the explanation took.
    words : list of str
        It in plain words, the reason first, then what to change.
    """

    outcome: str
    nominal: RunFigures
    tip_over: TipOver | None
    approach: Approach | None
    thresholds: list[Threshold]
    tornado: list[TornadoBar]
    k_sd: float
    cycles: int
    runs: int
    words: list[str]

    def to_json(self) -> dict:
        """The explanation as plain JSON-ready values (SI units, as the names say).

        Returns
        -------
        dict
        """
        return dataclasses.asdict(self)


def scale_of(key: str, sd: float | None) -> float:
    """The step a key's probes are multiples of: its sd, else :data:`DESIGN_STEP` of its unit.

    Parameters
    ----------
    key : str
        A robot-file key.
    sd : float or None
        Its standard deviation.

    Returns
    -------
    float
        In the key's unit.
    """
    if sd:
        return sd
    return DESIGN_STEP.get(split_unit(key)[1], 0.0)


def _moved(robot: Robot, key: str, value: float) -> float:
    centre = robot.get(key)
    return max(value, MIN_FRACTION * centre) if centre > 0 else value


# -- the tip-over --------------------------------------------------------------------------
def _cycle_of(traj: Trajectory, row: int) -> int:
    starts = traj.plan.cycle_start_steps
    return int(np.searchsorted(starts, row, side="right"))


def _pitch(traj: Trajectory) -> np.ndarray:
    s, sd, plan = traj.built.sensors, traj.sensordata, traj.plan
    turn = plate_pitch_deg(sd[:, s.nose_pos], sd[:, s.chassis_pos])
    stand = plan.settle_steps - 1 if plan.settle_steps > 0 else len(turn) - 1
    return turn - turn[stand]


def _stances(traj: Trajectory, first: int, last: int) -> list[Stance]:
    control = servo_control(traj.built, traj.plan)
    # state row i is the state after step i: the sensors' row i + 1
    return stances(traj.built, traj.states, control, range(first, last))


def tip_over(traj: Trajectory) -> TipOver | None:
    """How a kept rollout went over (None: it did not, or it went over in the air).

    The stretch is the one in which the plate turns past :data:`~.outcome.OVER_TURN_DEG`:
    every step of it on the floor, the nose off it, the plate turning nose up (its support may
    pass from one part to the next, the knees to the feet, as it turns); it starts at its first
    step with the centre of mass behind its rearmost support, and ends as the robot leaves the
    floor or lands on a part behind its centre of mass.

    Parameters
    ----------
    traj : Trajectory
        The rollout, with its states (``keep_states``).

    Returns
    -------
    TipOver or None
    """
    turn = _pitch(traj)
    plan = traj.plan
    over = np.flatnonzero(turn[plan.settle_steps:] > OVER_TURN_DEG)
    if over.size == 0:
        return None
    over_row = plan.settle_steps + int(over[0])
    cycle = _cycle_of(traj, over_row)
    push_row = int(plan.cycle_start_steps[cycle - 1])
    seen = _stances(traj, push_row, int(plan.cycle_start_steps[cycle]))
    behind = np.array([st.com_behind_m if st.support else np.nan for st in seen])
    # state row i is the state after step i: the sensors' row i + 1
    rows = np.minimum(np.arange(push_row + 1, push_row + 1 + len(seen)), len(turn) - 1)
    turning = turn[rows] >= turn[rows - 1]
    standing = np.array([bool(st.support) and "nose" not in st.parts and "plate" not in st.parts for st in seen])
    tipping = standing & turning
    o = over_row - push_row
    before = np.flatnonzero(tipping[:o + 1])
    if before.size == 0:
        return None
    end = int(before[-1])
    while end + 1 < len(tipping) and tipping[end + 1]:
        end += 1
    start = end
    while start > 0 and tipping[start - 1]:
        start -= 1
    strictly = np.flatnonzero(behind[start:end + 1] > 0)
    if strictly.size == 0:
        return None
    start += int(strictly[0])
    first = seen[start]
    parts: list[str] = []
    for st in seen[start:end + 1]:
        parts += [p for p in st.parts if p not in parts]
    dt = traj.timestep_s
    phases = _phases(seen, behind, start, end, dt)
    row = push_row + start + 1   # state row i is after step i: the sensors' row i + 1
    torque = traj.sensordata[row, traj.built.sensors.actuator_force]
    mean = np.abs(traj.sensordata[row:push_row + end + 2, traj.built.sensors.actuator_force]).mean(axis=0)
    return TipOver(
        cycle=cycle, start_s=(start + 1) * dt, duration_s=(end - start + 1) * dt, support=first.parts,
        support_after=tuple(parts), phases=phases,
        support_forward_m=tuple(p.forward_m - first.com_forward_m for p in first.support),
        com_behind_m=float(np.nanmax(behind[start:end + 1])), com_behind_start_m=first.com_behind_m,
        servo_torque_nm=(float(torque[0]), float(torque[1])),
        servo_torque_mean_nm=(float(mean[0]), float(mean[1])), pitch_deg=float(turn[row]))


def _kind(part: str) -> str:
    side, _, what = part.partition(" ")
    return what if side in ("left", "right") else part


def _phases(seen: list[Stance], behind: np.ndarray, start: int, end: int, dt: float) -> tuple[SupportPhase, ...]:
    """Steps ``start``..``end`` of ``seen`` cut where the rearmost support's kind changes."""
    out: list[SupportPhase] = []
    k = start
    while k <= end:
        kind = _kind(seen[k].support[0].part)
        j = k
        while j + 1 <= end and _kind(seen[j + 1].support[0].part) == kind:
            j += 1
        parts = tuple(p for p in seen[k].parts if _kind(p) == kind)
        out.append(SupportPhase(parts=parts, start_s=(k + 1) * dt, end_s=(j + 1) * dt,
                                com_behind_max_m=float(np.max(behind[k:j + 1]))))
        k = j + 1
    return tuple(out)


def approach(traj: Trajectory) -> Approach | None:
    """For a kept rollout that did not go over: the closest its centre of mass came to being
    behind its supports in any cycle (None: it never stood on the floor after the settle).

    Parameters
    ----------
    traj : Trajectory
        The rollout, with its states.

    Returns
    -------
    Approach or None
    """
    starts = traj.plan.cycle_start_steps
    best: tuple[float, int, float, Stance] | None = None
    for c in range(len(starts) - 1):
        a, b = int(starts[c]), int(starts[c + 1])
        for k, st in enumerate(_stances(traj, a, b)):
            if st.support and (best is None or st.com_behind_m > best[0]):
                best = (st.com_behind_m, c + 1, (k + 1) * traj.timestep_s, st)
    if best is None:
        return None
    behind, cycle, at, st = best
    return Approach(cycle=cycle, at_s=at, com_behind_m=behind, support=st.parts)


# -- thresholds and tornado -------------------------------------------------------------------
def _keys(robot: Robot) -> dict[str, float | None]:
    sds: dict[str, float | None] = dict(uncertain_values(robot))
    for key in DESIGN_KEYS:
        sds.setdefault(key, None)
    return {k: v for k, v in sds.items() if scale_of(k, v) > 0}


def _edge(robot: Robot, key: str, sd: float | None, same: float, other: float, outcome: str | None,
          step: float) -> Edge:
    value = 0.5 * (same + other)
    distance = value - robot.get(key)
    return Edge(value=value, resolution=0.5 * abs(other - same), outcome=outcome, distance=distance,
                distance_sd=distance / sd if sd else None)


def _nearness(t: Threshold) -> tuple[int, float]:
    """Thresholds in order: those reaching another outcome (nearest in their scale first), then
    those reaching only invalid robots, then those with none probed."""
    edges = [e for e in (t.below, t.above) if e is not None]
    valid = [e for e in edges if e.outcome is not None]
    pick = valid or edges
    rank = 0 if valid else 1 if edges else 2
    return rank, min((abs(e.distance) / t.scale for e in pick), default=0.0)


def thresholds(robot: Robot, nominal: str, cycles: int | None,
               progress: Callable[[int], None] | None = None) -> tuple[list[Threshold], list[TornadoBar], int]:
    """Every uncertain and design value's nearest outcome changes, and the uncertain values'
    tornado (see the module docstring).

    Parameters
    ----------
    robot : Robot
        The robot.
    nominal : str
        Its own outcome.
    cycles : int or None
        Hop cycles of every run.
    progress : callable, optional
        ``progress(k)`` as each batch of ``k`` runs is done.

    Returns
    -------
    thresholds : list of Threshold
        Nearest change first (those with none last, in the robot file's order).
    tornado : list of TornadoBar
        Largest nose-rise swing first.
    runs : int
        Simulations made.
    """
    keys = _keys(robot)
    prov = Provenance(source="explain", note="one value moved alone")
    probes = [(key, side, m, _moved(robot, key, robot.get(key) + side * m * scale_of(key, sd)))
              for key, sd in keys.items() for side in (-1, 1) for m in PROBES]
    figures = run_figures([robot.with_values({k: v}, prov) for k, _, _, v in probes], cycles, progress)
    runs = len(probes)
    at = {(k, side, m): (v, f) for (k, side, m, v), f in zip(probes, figures)}
    brackets: dict[tuple[str, int], list] = {}
    for key in keys:
        for side in (-1, 1):
            same = robot.get(key)
            for m in PROBES:
                v, f = at[(key, side, m)]
                kind = f.outcome if f else None
                if kind != nominal:
                    brackets[(key, side)] = [same, v, kind]
                    break
                same = v
    for _ in range(BISECTIONS):
        todo = list(brackets)
        if not todo:
            break
        mids = [0.5 * (brackets[t][0] + brackets[t][1]) for t in todo]
        found = run_figures([robot.with_values({t[0]: v}, prov) for t, v in zip(todo, mids)], cycles, progress)
        runs += len(todo)
        for t, v, f in zip(todo, mids, found):
            kind = f.outcome if f else None
            if kind == nominal:
                brackets[t][0] = v
            else:
                brackets[t][1], brackets[t][2] = v, kind
    out = []
    for key, sd in keys.items():
        ends = {side: _edge(robot, key, sd, *brackets[(key, side)], step=scale_of(key, sd))
                for side in (-1, 1) if (key, side) in brackets}
        out.append(Threshold(key=key, value=robot.get(key), sd=sd, scale=scale_of(key, sd),
                             below=ends.get(-1), above=ends.get(1)))
    out.sort(key=_nearness)
    bars = [TornadoBar(key=key, sd=sd, low_value=at[(key, -1, K_SD)][0], high_value=at[(key, 1, K_SD)][0],
                       low=at[(key, -1, K_SD)][1], high=at[(key, 1, K_SD)][1])
            for key, sd in keys.items() if sd]
    bars.sort(key=lambda b: -(b.swing("nose_rise_m") if math.isfinite(b.swing("nose_rise_m")) else -1.0))
    return out, bars, runs


# -- in plain words ---------------------------------------------------------------------------
# how a change of a design value reads (below / above its own value); others read "set X to V"
MOVES = {
    "geometry.servo_axis_x_m": ("move the servo axis {d} toward the nose", "move the servo axis {d} toward the tail"),
}
SUGGESTIONS = 2    # design changes named in the words


def _change(t: Threshold, edge: Edge) -> str:
    moves = MOVES.get(t.key)
    if moves:
        return moves[0 if edge.distance < 0 else 1].format(d=quantity(t.key, abs(edge.distance), 2))
    if t.key == "schedule.push_deg":
        return f"push to {quantity(t.key, edge.value, 3)}"
    return f"set {label(t.key)} to {quantity(t.key, edge.value, 3)} (now {quantity(t.key, t.value, 3)})"


def _toward(thresholds: list[Threshold], wanted: Callable[[str | None], bool]) -> list[tuple[Threshold, Edge]]:
    """Each value's nearest edge whose far outcome is ``wanted``, nearest (in its scale) first."""
    found = []
    for t in thresholds:
        edges = [e for e in (t.below, t.above) if e is not None and wanted(e.outcome)]
        if edges:
            found.append((t, min(edges, key=lambda e: abs(e.distance))))
    return sorted(found, key=lambda te: abs(te[1].distance) / te[0].scale)


PLURALS = {"foot": "feet", "knee": "knees", "leg end": "leg ends", "servo axis": "servo axes"}


def _parts(parts: tuple[str, ...]) -> str:
    """``left foot``, ``right foot`` -> ``feet``: a part named on both sides once, in the plural."""
    named: list[str] = []
    for p in parts:
        side, _, what = p.partition(" ")
        other = ("right " if side == "left" else "left ") + what
        if other in parts and side in ("left", "right"):
            if PLURALS.get(what, what + "s") not in named:
                named.append(PLURALS.get(what, what + "s"))
        else:
            named.append(p)
    return " and ".join(named) if len(named) <= 2 else ", ".join(named[:-1]) + " and " + named[-1]


def words(outcome: str, tip: TipOver | None, near: Approach | None, found: list[Threshold]) -> list[str]:
    """The explanation in plain words: the reason, then the design changes that would change the
    outcome (the :data:`SUGGESTIONS` nearest), then the uncertain values it is within reach of.

    Parameters
    ----------
    outcome : str
        The robot's outcome.
    tip : TipOver or None
        How it went over.
    near : Approach or None
        How close it came, when it did not.
    found : list of Threshold
        The thresholds.

    Returns
    -------
    list of str
    """
    lines = []
    if outcome == GOES_OVER and tip is not None:
        torque = max(abs(v) for v in tip.servo_torque_mean_nm)
        first, *later = tip.phases
        then = "".join(f", then on its {_parts(ph.parts)} (up to {ph.com_behind_max_m * 1000:.0f} mm)" for ph in later)
        lines.append(f"goes over in push {tip.cycle}: {tip.start_s:.2f} s into it, it stands on its "
                     f"{_parts(first.parts)} with its centre of mass up to {first.com_behind_max_m * 1000:.0f} mm "
                     f"behind them{then}, the servos holding {torque:.3f} N·m on average, and falls over "
                     f"backwards about them in {tip.duration_s:.2f} s")
    elif outcome == GOES_OVER:
        lines.append("goes over in the air: no point on the floor to tip about (its momentum turns it over)")
    elif near is not None:
        where = "behind" if near.com_behind_m > 0 else "in front of"
        lines.append(f"does not go over: at its closest (push {near.cycle}, {near.at_s * 1000:.0f} ms into it) its "
                     f"centre of mass is {abs(near.com_behind_m) * 1000:.0f} mm {where} its {_parts(near.support)}")
    design = [te for te in _toward(found, lambda o: o is not None and (o != GOES_OVER) == (outcome == GOES_OVER))
              if te[0].key in DESIGN_KEYS]
    if outcome != GOES_OVER:
        design = [te for te in _toward(found, lambda o: o == GOES_OVER) if te[0].key in DESIGN_KEYS]
    if design:
        verb = "to stay on its feet" if outcome == GOES_OVER else "it would go over if you"
        changes = " or ".join(_change(t, e) for t, e in design[:SUGGESTIONS])
        lines.append(f"{verb}: {changes}" if outcome == GOES_OVER else f"{verb} {changes}")
    reach = [(t, e) for t, e in _toward(found, lambda o: o is not None)
             if t.sd and e.distance_sd is not None and abs(e.distance_sd) <= K_SD]
    if reach:
        named = ", ".join(f"{label(t.key)} ({abs(e.distance_sd):.1f} sd away)" for t, e in reach[:4])
        lines.append(f"within {K_SD:g} sd of a change: {named}; measuring these better settles the prediction "
                     "(docs/hardware.md, \"Measure your robot\")")
    return lines


def explain(robot: Robot, cycles: int | None = None, progress: Callable[[int], None] | None = None,
            trajectory: Trajectory | None = None, figures: RunFigures | None = None) -> Explanation:
    """Why ``robot`` does what it does (see the module docstring).

    Parameters
    ----------
    robot : Robot
        The robot.
    cycles : int, optional
        Hop cycles of every run (default the robot's ``schedule.cycles``).
    progress : callable, optional
        ``progress(k)`` as each batch of ``k`` runs is done.
    trajectory : Trajectory, optional
        The robot's own rollout with its states, when already run (else it is run here).
    figures : RunFigures, optional
        Its figures, with ``trajectory``.

    Returns
    -------
    Explanation

    Raises
    ------
    SimError
        The robot's own run is not valid: there is nothing to explain.
    """
    from ..errors import SimError
    from .run import run

    if trajectory is None or figures is None:
        result = run(robot, cycles=cycles, keep_states=True)
        if not result.valid or result.trajectory is None:
            raise SimError(f"cannot explain an invalid simulation: {'; '.join(result.reasons)}",
                           "fix the reasons first")
        trajectory = result.trajectory
        figures = RunFigures(outcome=result.outcome or "", nose_rise_m=result.hops[0].nose_apex_m,
                             distance_m=result.distance_m)
    tip = tip_over(trajectory) if figures.outcome == GOES_OVER else None
    near = approach(trajectory) if figures.outcome != GOES_OVER else None
    found, bars, runs = thresholds(robot, figures.outcome, cycles, progress)
    if progress and explain_runs(robot) > runs:
        progress(explain_runs(robot) - runs)   # the bisections not needed: the bar ends full
    n_cycles = len(trajectory.plan.cycle_start_steps) - 1
    return Explanation(outcome=figures.outcome, nominal=figures, tip_over=tip, approach=near, thresholds=found,
                       tornado=bars, k_sd=K_SD, cycles=n_cycles, runs=runs + 1,
                       words=words(figures.outcome, tip, near, found))


def explain_runs(robot: Robot) -> int:
    """The most simulations :func:`explain` makes of ``robot`` (for a progress bar's length).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    int
    """
    n = len(_keys(robot))
    return n * 2 * (len(PROBES) + BISECTIONS)


assert K_SD in PROBES, "the tornado's ends are probes of the threshold search"

__all__ = ["Approach", "DESIGN_KEYS", "Edge", "Explanation", "SupportPhase", "Threshold", "TipOver", "TornadoBar",
           "approach", "explain", "explain_runs", "thresholds", "tip_over", "words"]
