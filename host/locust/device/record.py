"""The run record of a hop: what was commanded, what the firmware measured, how it ended.

``data/runs/<timestamp>/run.json`` (or ``--out DIR``): written when the hop starts and again
as every phase arrives, atomically, so an interrupted run still leaves a readable record of
what happened. A record is never overwritten by another run.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..errors import DeviceError
from ..fileio import atomic_write_json, unique_dir

COMPLETE = "complete"
INCOMPLETE = "incomplete"
ERROR = "error"
RECORD_NAME = "run.json"


@dataclass(frozen=True)
class HopSchedule:
    cycles: int = 6
    push_deg: float = -30.0
    push_ms: int = 300
    wait_ms: int = 1000
    heartbeat_ms: int = 500

    @property
    def phases(self) -> int:
        return 2 * self.cycles

    @property
    def duration_s(self) -> float:
        return self.cycles * (self.push_ms + self.wait_ms) / 1000.0


@dataclass(frozen=True)
class Phase:
    cycle: int
    phase: str            # "push" or "wait"
    commanded_us: int     # commanded start, from the start of the hop (firmware clock)
    measured_us: int      # measured start: when the new PWM duty was written

    @property
    def error_us(self) -> int:
        return self.measured_us - self.commanded_us

    def to_dict(self) -> dict:
        return {
            "cycle": self.cycle,
            "phase": self.phase,
            "commanded_ms": self.commanded_us / 1000.0,
            "measured_ms": self.measured_us / 1000.0,
            "error_ms": self.error_us / 1000.0,
            "commanded_us": self.commanded_us,
            "measured_us": self.measured_us,
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
    if not phases:
        return None
    errs = [p.error_us / 1000.0 for p in phases]
    mean = sum(errs) / len(errs)
    std = math.sqrt(sum((e - mean) ** 2 for e in errs) / len(errs))
    return Jitter(n=len(errs), mean_ms=round(mean, 4), std_ms=round(std, 4),
                  max_abs_ms=round(max(abs(e) for e in errs), 4),
                  max_late_ms=round(max(max(errs), 0.0), 4), max_early_ms=round(max(-min(errs), 0.0), 4))


@dataclass
class RunRecord:
    schedule: HopSchedule
    port: str
    status: str = INCOMPLETE
    firmware_version: str | None = None
    firmware_status: str | None = None   # the firmware's own verdict: complete/stopped/heartbeat_lost
    message: str | None = None           # why it is not complete
    started_at: str = field(default_factory=lambda: time.strftime("%Y-%m-%dT%H:%M:%S%z"))
    phases: list[Phase] = field(default_factory=list)

    def add_phase(self, phase: Phase) -> None:
        if all((p.cycle, p.phase) != (phase.cycle, phase.phase) for p in self.phases):
            self.phases.append(phase)
            self.phases.sort(key=lambda p: p.commanded_us)

    def to_dict(self) -> dict:
        j = jitter(self.phases)
        return {
            "status": self.status,
            "message": self.message,
            "firmware_version": self.firmware_version,
            "firmware_status": self.firmware_status,
            "port": self.port,
            "started_at": self.started_at,
            "schedule": asdict(self.schedule),
            "phases_expected": self.schedule.phases,
            "phases": [p.to_dict() for p in self.phases],
            "jitter": asdict(j) if j else None,
        }


def run_dir(out: Path | None, root: Path = Path("data/runs")) -> Path:
    """The directory of a new run record: ``out`` (must not hold one yet) or a fresh timestamped one."""
    if out is None:
        return unique_dir(root, time.strftime("%Y%m%d-%H%M%S"))
    out = Path(out)
    if (out / RECORD_NAME).exists():
        raise DeviceError(f"{out / RECORD_NAME} already exists; a run record is never overwritten",
                          "pass another --out directory, or leave --out off for a new data/runs/<timestamp>/")
    if out.exists() and not out.is_dir():
        raise DeviceError(f"--out {out} is a file, not a directory", "pass a directory path")
    out.mkdir(parents=True, exist_ok=True)
    return out


def write(record: RunRecord, directory: Path) -> Path:
    return atomic_write_json(Path(directory) / RECORD_NAME, record.to_dict())
