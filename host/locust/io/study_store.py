"""A ``locust optimize`` folder's tables: ``trials.csv`` (one row per trial) and ``pareto.csv``
(the rows of the Pareto front, with the ``pick`` each is), written and read here.

Columns: ``trial``, ``state``, one per design variable by its dotted name, each objective's
figure and ``<figure>_mean``, ``flip_share``, ``share_<outcome>``, ``feasible``, ``draws``,
``draws_valid``, ``reason`` (and ``pick`` in ``pareto.csv``). Floats are written with ``repr``
and read back bit for bit; ``optimize.json`` beside them says which columns are the design
variables and which the objectives.
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import SweepError
from ..fileio import atomic_write_text

TRIALS = "trials.csv"
PARETO = "pareto.csv"
META = "optimize.json"
_INTS = {"trial", "draws", "draws_valid"}
_TEXT = {"state", "reason", "pick"}


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else "nan"
    return str(value)


def table_text(rows: list[dict[str, Any]], columns: list[str]) -> str:
    """The CSV text of ``rows`` under ``columns`` (floats by ``repr``).

    Parameters
    ----------
    rows : list of dict
        Column -> value.
    columns : list of str
        The header.

    Returns
    -------
    str
    """
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(columns)
    for r in rows:
        writer.writerow([_cell(r[c]) for c in columns])
    return out.getvalue()


def write_tables(folder: Path, rows: list[dict[str, Any]], front: list[dict[str, Any]]) -> None:
    """Write ``trials.csv`` (every row) and ``pareto.csv`` (the front, each with its ``pick``).

    Parameters
    ----------
    folder : pathlib.Path
    rows : list of dict
        Every trial's row.
    front : list of dict
        The Pareto front's rows.

    Raises
    ------
    locust.errors.WriteError
        A file cannot be written.
    """
    columns = list(rows[0]) if rows else ["trial", "state"]
    atomic_write_text(Path(folder) / TRIALS, table_text(rows, columns))
    atomic_write_text(Path(folder) / PARETO, table_text(front, [*columns, "pick"]))


def _parse(row: dict[str, str]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, raw in row.items():
        if key in _INTS:
            out[key] = int(raw)
        elif key in _TEXT:
            out[key] = raw
        elif key == "feasible":
            out[key] = raw == "True"
        else:
            out[key] = float(raw)
    return out


@dataclass(frozen=True)
class StudyResults:
    """A ``locust optimize --out`` folder, read back: its settings, trials and front."""

    folder: Path
    base: str
    names: list[str]                 # the design variables, by dotted name
    objectives: list[str]            # the objectives by name (distance_per_hop, ...)
    robust: int                      # draws a design (0: its nominal run)
    quantile: float | None
    max_flip: float | None
    trials: list[dict[str, Any]]
    front: list[dict[str, Any]]
    study: str = "locust"            # the study's name in its storage


def read_study(folder: Path) -> StudyResults:
    """Read a ``locust optimize --out`` folder (``optimize.json``, ``trials.csv``, ``pareto.csv``).

    Parameters
    ----------
    folder : pathlib.Path

    Returns
    -------
    StudyResults

    Raises
    ------
    locust.errors.SweepError
        A file missing, or not what ``locust optimize`` writes.
    """
    folder = Path(folder)
    hint = "give the --out folder of a `locust optimize` run"
    for name in (META, TRIALS, PARETO):
        if not (folder / name).is_file():
            raise SweepError(f"{folder}: no {name}", hint)
    try:
        meta = json.loads((folder / META).read_text(encoding="utf-8"))
        held = meta["settings"]
        names = [str(v["name"]) for v in held["vary"]]
        objectives = [str(o) for o in held["objectives"]]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise SweepError(f"{folder / META}: not a `locust optimize` summary ({exc})", hint) from None
    tables = []
    for name in (TRIALS, PARETO):
        try:
            with open(folder / name, newline="", encoding="utf-8") as fh:
                tables.append([_parse(r) for r in csv.DictReader(fh)])
        except (OSError, ValueError, TypeError) as exc:
            raise SweepError(f"{folder / name}: not a `locust optimize` table ({exc})", hint) from None
    return StudyResults(folder, str(held.get("base", "?")), names, objectives, int(held.get("robust") or 0),
                        held.get("quantile"), held.get("max_flip"), *tables, study=str(meta.get("study", "locust")))
