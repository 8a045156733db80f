"""The run record of a hop: what was commanded, what the firmware measured, how it ended.

``data/runs/<timestamp>/run.json`` (or ``--out DIR``): written when the hop starts and again
as phases arrive (at most every 0.25 s), atomically, so an interrupted run still leaves a readable record of
what happened. A record is never overwritten by another run.

This module owns the format both ways: :func:`write` puts a :class:`RunRecord` on disk and
:func:`read_run_record` gives it back, equal to what was written. Phase times are kept in
the firmware's native microseconds; the file also carries them in milliseconds for people,
converted by :func:`us_to_ms` alone. The schedule's limits and defaults are the protocol's
``hop`` command's (``locust.firmware.protocol.COMMANDS``), read here, never retyped.
"""

from __future__ import annotations

import json
import math
import os
import re
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

from ..errors import DeviceError
from ..fileio import atomic_write_json, claim_folder, make_folder, unique_dir
from ..firmware import protocol as P

COMPLETE = "complete"
INCOMPLETE = "incomplete"
ERROR = "error"
# every phase ran, but the board's config.json was unreadable or invalid and the firmware ran
# on its default config (pins, trims and pulse range that may not be this robot's)
DEFAULT_CONFIG = "default_config"
CONFIG_FIX_HINT = ("write a valid config: `locust config --port PORT --set left.trim_deg=0` (any key; the "
                   "board saves the whole config), or `locust flash --port PORT --reset-config`")
RECORD_NAME = "run.json"
# a board starts each phase within 2 ms of its time (its firmware spins the last 12 ms before
# one); a virtual robot's host that held the interpreter off longer than this while a phase
# was due, or long enough to make a phase late past it, says the run's timing is the host's
TIMING_BOUND_US = 2000
READ_HINT = "give the run.json that `locust hop` wrote"
DAMAGED_HINT = "the record is damaged; rerun the hop"

# the protocol's `hop` arguments: name -> (kind, lowest, highest, default)
HOP_ARGS = P.COMMANDS["hop"]


def hop_range(name: str) -> tuple[int | float, int | float]:
    """(lowest, highest) the firmware accepts for the ``hop`` argument ``name``.

    Parameters
    ----------
    name : str
        ``cycles``, ``push_deg``, ``push_ms``, ``wait_ms`` or ``heartbeat_ms``.

    Returns
    -------
    tuple
        In the argument's unit (its name's suffix).
    """
    return HOP_ARGS[name][1], HOP_ARGS[name][2]


def hop_default(name: str) -> int | float:
    """The value the firmware uses for the ``hop`` argument ``name`` when none is sent.

    Parameters
    ----------
    name : str

    Returns
    -------
    int or float
        In the argument's unit.
    """
    return HOP_ARGS[name][3]


def us_to_ms(us: int) -> float:
    """Microseconds (the firmware's clock) to milliseconds: the one conversion of phase times.

    Parameters
    ----------
    us : int
        [µs].

    Returns
    -------
    float
        [ms].
    """
    return us / 1000.0


@dataclass(frozen=True)
class HopSchedule:
    """What a hop commands; the defaults are the protocol's (:func:`hop_default`)."""

    cycles: int = hop_default("cycles")
    push_deg: float = float(hop_default("push_deg"))
    push_ms: int = hop_default("push_ms")
    wait_ms: int = hop_default("wait_ms")
    heartbeat_ms: int = hop_default("heartbeat_ms")

    @property
    def phases(self) -> int:
        """Phases commanded: a push and a wait per cycle."""
        return 2 * self.cycles

    @property
    def duration_s(self) -> float:
        """The schedule's length, (push + wait) per cycle [s]."""
        return self.cycles * (self.push_ms + self.wait_ms) / 1000.0


@dataclass(frozen=True)
class Phase:
    """One phase's start as commanded and as the firmware measured it (its clock, microseconds).

    Attributes
    ----------
    cycle : int
        The cycle it belongs to, from 0.
    phase : str
        ``push`` or ``wait``.
    """

    cycle: int
    phase: str            # "push" or "wait"
    commanded_us: int     # commanded start, from the start of the hop (firmware clock)
    measured_us: int      # measured start: when the new PWM duty was written
    # a virtual robot's: how long its host held the interpreter off the CPU between the
    # commanded and the measured start (None: not watched, a real board)
    host_stall_us: int | None = None

    @property
    def error_us(self) -> int:
        """Measured minus commanded start [µs]: positive late."""
        return self.measured_us - self.commanded_us

    @property
    def commanded_ms(self) -> float:
        """The commanded start from the start of the hop [ms]."""
        return us_to_ms(self.commanded_us)

    @property
    def measured_ms(self) -> float:
        """The measured start (the new PWM duty written) [ms]."""
        return us_to_ms(self.measured_us)

    @property
    def error_ms(self) -> float:
        """Measured minus commanded start [ms]: positive late."""
        return us_to_ms(self.error_us)

    def to_dict(self) -> dict:
        """The phase as ``run.json`` holds it, times in ms and µs.

        Returns
        -------
        dict
        """
        return {
            "cycle": self.cycle,
            "phase": self.phase,
            "commanded_ms": self.commanded_ms,
            "measured_ms": self.measured_ms,
            "error_ms": self.error_ms,
            "commanded_us": self.commanded_us,
            "measured_us": self.measured_us,
            "host_stall_ms": None if self.host_stall_us is None else us_to_ms(self.host_stall_us),
            "host_stall_us": self.host_stall_us,
        }


@dataclass(frozen=True)
class Jitter:
    """Start-time errors (measured - commanded) over the phases of a run, in ms."""

    n: int
    mean_ms: float
    std_ms: float
    max_abs_ms: float
    max_late_ms: float
    max_early_ms: float


def jitter(phases: list[Phase]) -> Jitter | None:
    """The start-time errors' statistics over ``phases``.

    Parameters
    ----------
    phases : list of Phase

    Returns
    -------
    Jitter or None
        Mean, population standard deviation and extremes [ms], to 0.1 µs; None without phases.
    """
    if not phases:
        return None
    errs = [p.error_ms for p in phases]
    mean = sum(errs) / len(errs)
    std = math.sqrt(sum((e - mean) ** 2 for e in errs) / len(errs))
    return Jitter(n=len(errs), mean_ms=round(mean, 4), std_ms=round(std, 4),
                  max_abs_ms=round(max(abs(e) for e in errs), 4),
                  max_late_ms=round(max(max(errs), 0.0), 4), max_early_ms=round(max(-min(errs), 0.0), 4))


def host_stall_max_s(phases: list[Phase]) -> float | None:
    """The longest a virtual robot's host held its interpreter off while a phase was due.

    Parameters
    ----------
    phases : list of Phase

    Returns
    -------
    float or None
        [s]; None when no phase was watched (a real board: not applicable).
    """
    stalls = [p.host_stall_us for p in phases if p.host_stall_us is not None]
    return max(stalls) / 1e6 if stalls else None


def timing_note(phases: list[Phase]) -> str | None:
    """Why the phases' start errors are not the firmware's own, in plain words, or None.

    A phase is held up by the host when the host held the interpreter off longer than
    :data:`TIMING_BOUND_US` while it was due, or long enough that without it the phase would
    have started within the bound.

    Parameters
    ----------
    phases : list of Phase

    Returns
    -------
    str or None
        ``timing not representative: the host stalled ...``, naming the phase held up longest;
        None when no phase was held up (and for a real board).
    """
    held = [p for p in phases if p.host_stall_us is not None and (
        p.host_stall_us > TIMING_BOUND_US
        or (p.error_us > TIMING_BOUND_US and p.error_us - p.host_stall_us <= TIMING_BOUND_US))]
    if not held:
        return None
    worst = max(held, key=lambda p: p.host_stall_us)
    note = (f"timing not representative: the host stalled {us_to_ms(worst.host_stall_us):.1f} ms while "
            f"cycle {worst.cycle}'s {worst.phase} was due (it started {worst.error_ms:.1f} ms late)")
    if len(held) > 1:
        note += f"; {len(held)} phases were held up by the host"
    return note


_LEG_SET_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_+-]*$")


def check_leg_set(name: str) -> str:
    """A leg set's name as recorded: a plain name, lower case (``report`` groups trials by it).

    Parameters
    ----------
    name : str

    Returns
    -------
    str

    Raises
    ------
    locust.errors.DeviceError
        Not a plain name.
    """
    key = str(name).strip().lower()
    if not _LEG_SET_NAME.match(key):
        raise DeviceError(f"leg set {name!r} is not a plain name",
                          "use letters, digits, - or _, e.g. small, medium, large, v2")
    return key


@dataclass(frozen=True)
class RobotSource:
    """Which robot was hopped: the parameter set named on the command line and the leg set on it."""

    preset: str | None = None        # --preset, when no robot file was given
    robot_file: str | None = None    # --config: the robot.toml's path as given
    leg_set: str | None = None       # small / medium / large, or the user's own name (--leg-set)


@dataclass(frozen=True)
class ServoConfig:
    """One servo's entry of the board's config.json (``locust.firmware.config``)."""

    pin: int
    trim_deg: float
    direction: int
    pulse_min_us: float
    pulse_max_us: float
    range_deg: float
    travel_deg: float


@dataclass(frozen=True)
class BoardConfig:
    """The config the firmware was running on, read back from the board at the start of a hop."""

    chip: str | None
    machine: str | None
    left: ServoConfig
    right: ServoConfig
    problems: tuple[str, ...] = ()   # why the firmware did not use config.json (empty: it did)

    @property
    def on_defaults(self) -> bool:
        """Whether the firmware ran on its defaults (its config.json had problems)."""
        return bool(self.problems)

    def to_dict(self) -> dict:
        """The config as the run record's ``board`` holds it.

        Returns
        -------
        dict
        """
        return {"chip": self.chip, "machine": self.machine, "left": asdict(self.left),
                "right": asdict(self.right), "config_problems": list(self.problems)}


def board_config(doc, where: str = "the board") -> BoardConfig:
    """A :class:`BoardConfig` from ``{"chip", "machine", "left", "right", "config_problems"}``
    (the run record's ``board``, or the board's hello and config replies put together).

    Parameters
    ----------
    doc : dict
        The config as read (pins, trims [deg], pulse widths [µs], ranges [deg]).
    where : str
        Where it came from, for messages.

    Returns
    -------
    BoardConfig

    Raises
    ------
    locust.errors.DeviceError
        Not an object, a servo missing, a field missing or not a number.
    """
    if not isinstance(doc, dict):
        raise DeviceError(f"{where}: the board config is not an object", DAMAGED_HINT)
    servos = {}
    for name in ("left", "right"):
        entry = doc.get(name)
        if not isinstance(entry, dict):
            raise DeviceError(f"{where}: the board config has no {name!r} servo", DAMAGED_HINT)
        values = {}
        for f in ServoConfig.__dataclass_fields__:
            value = entry.get(f)
            if not _is_number(value) or (f in ("pin", "direction") and value != int(value)):
                raise DeviceError(f"{where}: board {name}.{f} is missing or not a number", DAMAGED_HINT)
            values[f] = int(value) if f in ("pin", "direction") else float(value)
        servos[name] = ServoConfig(**values)
    problems = doc.get("config_problems") or []
    if not isinstance(problems, list):
        raise DeviceError(f"{where}: board config_problems is not a list", DAMAGED_HINT)
    return BoardConfig(_text(doc.get("chip")), _text(doc.get("machine")), servos["left"], servos["right"],
                       tuple(str(p) for p in problems))


@dataclass
class RunRecord:
    """One hop's ``run.json``: the schedule, the firmware, the phases as they arrived, the verdict."""

    schedule: HopSchedule
    port: str
    status: str = INCOMPLETE
    firmware_version: str | None = None
    firmware_status: str | None = None   # the firmware's own verdict: complete/stopped/heartbeat_lost
    message: str | None = None           # why it is not complete
    started_at: str = field(default_factory=lambda: time.strftime("%Y-%m-%dT%H:%M:%S%z"))
    phases: list[Phase] = field(default_factory=list)
    # the board's raw ticks_us at the hop's start and end (30-bit: wrapped if end < start)
    firmware_ticks_us: list[int] | None = None
    robot: RobotSource = field(default_factory=RobotSource)
    board: BoardConfig | None = None     # pins, trims and chip read from the board before the hop

    def add_phase(self, phase: Phase) -> None:
        """Record a phase once (a repeated report is dropped), keeping commanded order.

        Parameters
        ----------
        phase : Phase
        """
        if all((p.cycle, p.phase) != (phase.cycle, phase.phase) for p in self.phases):
            self.phases.append(phase)
            self.phases.sort(key=lambda p: p.commanded_us)

    def set_host_stalls(self, stalls_us: list[int]) -> None:
        """Give each phase, in order, its host stall (a virtual robot's).

        Parameters
        ----------
        stalls_us : list of int
            [us], one per phase of :attr:`phases`.
        """
        self.phases = [replace(p, host_stall_us=s) for p, s in zip(self.phases, stalls_us, strict=True)]

    def order_problem(self) -> str | None:
        """Where the measured starts contradict the commanded order (a push measured after the
        wait commanded after it): a board's clock or a damaged record, never a hop.

        Returns
        -------
        str or None
            The first pair of phases out of order, in words; None when every measured start
            follows the one commanded before it.
        """
        ordered = sorted(self.phases, key=lambda p: p.commanded_us)
        for before, after in zip(ordered, ordered[1:]):
            if after.measured_us <= before.measured_us:
                return (f"cycle {after.cycle}'s {after.phase} is measured at {after.measured_ms:.3f} ms, not after "
                        f"cycle {before.cycle}'s {before.phase} (commanded before it) at {before.measured_ms:.3f} ms")
        return None

    def to_dict(self) -> dict:
        """The record as ``run.json`` holds it, with the phases' jitter and the host's stalls.

        Returns
        -------
        dict
        """
        j = jitter(self.phases)
        return {
            "status": self.status,
            "message": self.message,
            "firmware_version": self.firmware_version,
            "firmware_status": self.firmware_status,
            "port": self.port,
            "started_at": self.started_at,
            "robot": asdict(self.robot),
            "board": self.board.to_dict() if self.board else None,
            "schedule": asdict(self.schedule),
            "phases_expected": self.schedule.phases,
            "phases": [p.to_dict() for p in self.phases],
            "jitter": asdict(j) if j else None,
            "host_stall_max_s": host_stall_max_s(self.phases),
            "timing_note": timing_note(self.phases),
            "firmware_ticks_us": self.firmware_ticks_us,
            "ticks_wrapped": (None if not self.firmware_ticks_us
                              else self.firmware_ticks_us[1] < self.firmware_ticks_us[0]),
        }


RUNS_ROOT = Path("data/runs")   # where a run without --out goes, under the current folder


def run_dir(out: Path | None, root: Path = RUNS_ROOT) -> Path:
    """The directory of a new run record: ``out`` (must not hold one yet) or a fresh timestamped one.

    Parameters
    ----------
    out : pathlib.Path or None
        The folder asked for (``--out``); None: a new ``<root>/<timestamp>/``.
    root : pathlib.Path
        Where timestamped folders go.

    Returns
    -------
    pathlib.Path
        The folder, made.

    Raises
    ------
    locust.errors.DeviceError
        ``out`` is a file, or already holds a run record.
    """
    if out is None:
        return unique_dir(root, time.strftime("%Y%m%d-%H%M%S"))
    out = Path(out)
    _refuse_record(out)
    if out.exists() and not out.is_dir():
        raise DeviceError(f"--out {out} is a file, not a directory", "pass a directory path")
    make_folder(out)
    return out


def _refuse_record(directory: Path) -> None:
    if (directory / RECORD_NAME).exists():
        raise DeviceError(f"{directory / RECORD_NAME} already exists; a run record is never overwritten",
                          "pass another --out directory, or leave --out off for a new data/runs/<timestamp>/")


def claim(directory: Path) -> int:
    """Hold ``directory`` (from :func:`run_dir`) for one run: an exclusive lock on the folder,
    refused at once while another process holds it, then the check that it holds no record yet
    (another run may have finished there since :func:`run_dir` looked). Close the returned
    descriptor when the run's record is final.

    Parameters
    ----------
    directory : pathlib.Path

    Returns
    -------
    int
        The lock's file descriptor.

    Raises
    ------
    locust.errors.DeviceError
        The folder holds a run record already.
    locust.errors.WriteError
        Another process holds the folder.
    """
    fd = claim_folder(directory)
    try:
        _refuse_record(directory)
    except BaseException:
        os.close(fd)
        raise
    return fd


def write(record: RunRecord, directory: Path) -> Path:
    """Write ``record`` as ``directory/run.json`` (atomically); the path written.

    Parameters
    ----------
    record : RunRecord
    directory : pathlib.Path

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
        The file cannot be written.
    """
    return atomic_write_json(Path(directory) / RECORD_NAME, record.to_dict())


def read_run_record(path: Path) -> RunRecord:
    """A ``run.json`` back as the :class:`RunRecord` that :func:`write` wrote.

    Phase times and host stalls are read in their native microseconds; the derived fields (each
    phase's milliseconds, ``phases_expected``, ``jitter``, ``host_stall_max_s``, ``timing_note``)
    are not read, they follow from the rest.
    A file that is not a run record, or a damaged one, raises :class:`DeviceError` naming
    the file and the field.

    Parameters
    ----------
    path : pathlib.Path
        A ``run.json``.

    Returns
    -------
    RunRecord

    Raises
    ------
    locust.errors.DeviceError
        No such file, not JSON, not a run record, or a damaged field.
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DeviceError(f"{path}: no such file", READ_HINT) from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DeviceError(f"{path}: not a readable JSON run record ({exc})", READ_HINT) from None
    if (not isinstance(doc, dict) or not isinstance(doc.get("phases"), list)
            or not isinstance(doc.get("schedule"), dict)):
        raise DeviceError(f"{path}: not a run record (no 'schedule' and 'phases')", READ_HINT)
    sched = doc["schedule"]
    values = {}
    for key in ("cycles", "push_deg", "push_ms", "wait_ms", "heartbeat_ms"):
        value = sched.get(key, hop_default(key) if key == "heartbeat_ms" else None)
        if not _is_number(value):
            raise DeviceError(f"{path}: schedule.{key} is missing or not a number", DAMAGED_HINT)
        if key == "push_deg":
            values[key] = float(value)
        elif value == int(value):
            values[key] = int(value)
        else:
            raise DeviceError(f"{path}: schedule.{key} = {value} is not a whole number", DAMAGED_HINT)
    phases = []
    for i, ph in enumerate(doc["phases"]):
        if not isinstance(ph, dict) or not all(_is_int(ph.get(k)) for k in ("commanded_us", "measured_us")):
            raise DeviceError(f"{path}: phase {i + 1} has no commanded_us/measured_us integers", DAMAGED_HINT)
        cycle, stall = ph.get("cycle"), ph.get("host_stall_us")
        if stall is not None and not (_is_int(stall) and stall >= 0):
            raise DeviceError(f"{path}: phase {i + 1}'s host_stall_us is not a whole number of us", DAMAGED_HINT)
        phases.append(Phase(cycle if _is_int(cycle) else 0, str(ph.get("phase", "?")),
                            ph["commanded_us"], ph["measured_us"], stall))
    return RunRecord(
        schedule=HopSchedule(**values), port=str(doc.get("port") or ""), status=str(doc.get("status") or INCOMPLETE),
        firmware_version=_text(doc.get("firmware_version")), firmware_status=_text(doc.get("firmware_status")),
        message=_text(doc.get("message")), started_at=str(doc.get("started_at") or ""), phases=phases,
        firmware_ticks_us=_ticks(doc.get("firmware_ticks_us")), robot=_robot_source(path, doc.get("robot")),
        board=None if doc.get("board") is None else board_config(doc["board"], str(path)),
    )


def _robot_source(path: Path, value) -> RobotSource:
    if value is None:
        return RobotSource()       # a record from before the robot was recorded
    if not isinstance(value, dict) or not all(value.get(k) is None or isinstance(value.get(k), str)
                                               for k in ("preset", "robot_file", "leg_set")):
        raise DeviceError(f"{path}: robot is not an object of preset/robot_file/leg_set names", DAMAGED_HINT)
    return RobotSource(value.get("preset"), value.get("robot_file"), value.get("leg_set"))


def _ticks(value) -> list[int] | None:
    return list(value) if isinstance(value, list) and len(value) == 2 and all(_is_int(v) for v in value) else None


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _text(value) -> str | None:
    return None if value is None else str(value)
