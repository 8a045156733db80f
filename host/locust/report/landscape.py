"""A sweep's landscape (``locust sweep --out DIR``) and where the physical designs sit on it.

Reads ``DIR/sweep.json`` (``base``, ``vary`` [{name, start, stop, n}], ``cycles``) and
``DIR/results.csv`` (``design``, one column per varied name, ``valid``, ``reason``,
``distance_m``, ...). A configuration's position on a ``scale`` axis is the length it adds
to every link; on a dotted parameter's axis, that parameter's value in its robot.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import LocustError, ReportError
from .configs import Configuration

SCALE = "scale"
NEEDED = ("design", "valid", "distance_m")


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
    import pandas as pd

    folder = Path(folder)
    meta_path, csv_path = folder / "sweep.json", folder / "results.csv"
    hint = "give the --out folder of a finished `locust sweep`"
    for p in (meta_path, csv_path):
        if not p.is_file():
            raise ReportError(f"--sweep {folder}: no {p.name}", hint)
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
        req = meta.get("request", meta)   # what was asked; older folders keep it at the top
        names = [str(v["name"]) for v in req["vary"]]
        cycles = int(req["cycles"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        raise ReportError(f"{meta_path}: not a sweep description ({exc})", hint) from None
    if not names or cycles < 1:
        raise ReportError(f"{meta_path}: no varied parameter or no cycles", hint)
    try:
        table = pd.read_csv(csv_path)
    except (OSError, ValueError) as exc:
        raise ReportError(f"{csv_path}: cannot be read as CSV ({exc})", hint) from None
    missing = [c for c in (*NEEDED, *names) if c not in table.columns]
    if missing:
        raise ReportError(f"{csv_path}: missing columns {', '.join(missing)}", hint)
    if table.empty:
        raise ReportError(f"{csv_path}: no designs", "the sweep has not finished any design yet")
    valid = table["valid"].astype(str).str.lower().map({"true": True, "false": False})
    if valid.isna().any():
        line = int(valid.isna().to_numpy().argmax()) + 2
        raise ReportError(f"{csv_path}, line {line}: 'valid' is not True/False", hint)
    try:
        values = {n: table[n].to_numpy(dtype=float) for n in names}
        distance = table["distance_m"].to_numpy(dtype=float)
    except ValueError as exc:
        raise ReportError(f"{csv_path}: a non-number in a value column ({exc})", hint) from None
    valid_arr = valid.to_numpy(dtype=bool)
    distance = np.where(valid_arr, distance, np.nan)
    reasons = ["" if pd.isna(v) else str(v) for v in table["reason"]] if "reason" in table.columns else [""] * len(table)
    return Landscape(folder=folder, base=str(req.get("base", "?")), names=names, cycles=cycles,
                     values=values, valid=valid_arr, distance_m=distance, reason=reasons,
                     finished=bool(meta.get("finished", True)))


def design_value(config: Configuration, name: str) -> float:
    """Where ``config`` sits on the sweep axis ``name``."""
    if name == SCALE:
        return config.added_m
    try:
        return float(config.robot.get(name))
    except LocustError:  # not a robot parameter
        return math.nan
