"""A sweep's landscape (``locust sweep --out DIR``) and where the physical designs sit on it.

``DIR/sweep.json`` and ``DIR/results.csv`` are read by their owner,
:func:`locust.io.sweep_store.read_results`. A configuration's position on a ``scale`` axis is the length it adds
to every link; on a dotted parameter's axis, that parameter's value in its robot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import LocustError, ReportError, SweepError
from ..io.sweep_store import read_results
from ..sweep.design import SCALE
from ..trials.configs import Configuration


@dataclass(frozen=True)
class Landscape:
    folder: Path
    base: str
    names: list[str]                  # varied names, in order
    cycles: int
    values: dict[str, np.ndarray]     # per varied name, one value per design
    valid: np.ndarray                 # bool per design
    distance_m: np.ndarray            # total over ``cycles`` (nan when invalid)
    reason: list[str]
    finished: bool = True             # False: an interrupted sweep, some designs missing

    @property
    def hop_distance_m(self) -> np.ndarray:
        return self.distance_m / self.cycles

    @property
    def designs(self) -> int:
        return len(self.valid)


def read_landscape(folder: Path) -> Landscape:
    """The landscape of a sweep folder, read by its owner (:mod:`locust.io.sweep_store`)."""
    try:
        res = read_results(Path(folder))
    except SweepError as exc:
        raise ReportError(f"--sweep {folder}: {exc.message}", exc.hint) from None
    if not res.rows:
        raise ReportError(f"--sweep {folder}: no designs in results.csv", "the sweep has not finished any design yet")
    valid = np.array(res.column("valid"), dtype=bool)
    distance = np.where(valid, np.array(res.column("distance_m"), dtype=float), np.nan)
    return Landscape(folder=res.folder, base=res.base, names=res.axis_names, cycles=res.cycles,
                     values={n: np.array(res.column(n), dtype=float) for n in res.axis_names},
                     valid=valid, distance_m=distance, reason=[str(r) for r in res.column("reason")],
                     finished=res.finished)


def design_value(config: Configuration, name: str) -> float:
    """Where ``config`` sits on the sweep axis ``name``."""
    if name == SCALE:
        return config.added_m
    try:
        return float(config.robot.get(name))
    except LocustError:  # not a robot parameter
        return math.nan
