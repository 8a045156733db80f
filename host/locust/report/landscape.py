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
from ..sim.outcome import GOES_OVER
from ..sweep.design import SCALE
from ..trials.configs import Configuration


@dataclass(frozen=True)
class Landscape:
    """A sweep's designs and their outcomes, read from a ``locust sweep`` folder.

    Attributes
    ----------
    folder : Path
        The sweep folder.
    base : str
        The base robot's name.
    names : list of str
        The varied names, in order (``scale`` or dotted parameters).
    cycles : int
        Cycles each design was simulated.
    values : dict of str to ndarray
        Per varied name, one value per design, in that parameter's unit (``scale``: metres added
        to every link).
    valid : ndarray of bool
        Whether each design's simulation passed its audit.
    distance_m : ndarray
        ``locust sim``'s distance over the run of ``cycles`` [m] (nan when invalid).
    reason : list of str
        Per design, the ``reason`` column of ``results.csv`` (why an invalid one failed).
    finished : bool
        False for a sweep still running or interrupted, some designs missing.
    goes_over : ndarray of bool
        Whether each design's run goes over onto its back (its ``outcome``; a sweep with
        ``--samples``: the draws' most common outcome).
    planned : int or None
        The designs the sweep plans (None: its folder does not say).
    running : bool
        A sweep was writing the folder when it was read.
    """

    folder: Path
    base: str
    names: list[str]                  # varied names, in order
    cycles: int
    values: dict[str, np.ndarray]     # per varied name, one value per design
    valid: np.ndarray                 # bool per design
    distance_m: np.ndarray            # total over ``cycles`` (nan when invalid)
    reason: list[str]
    finished: bool = True             # False: an interrupted sweep, some designs missing
    goes_over: np.ndarray | None = None   # bool per design: its run goes over onto its back
    planned: int | None = None        # the designs the sweep plans
    running: bool = False             # a sweep was writing the folder when it was read

    def __post_init__(self):
        if self.goes_over is None:
            object.__setattr__(self, "goes_over", np.zeros_like(self.valid, dtype=bool))

    @property
    def distance_per_hop_m(self) -> np.ndarray:
        """Each design's distance over the run divided by its cycles [m]."""
        return self.distance_m / self.cycles

    @property
    def designs(self) -> int:
        """Number of designs read."""
        return len(self.valid)


def read_landscape(folder: Path) -> Landscape:
    """The landscape of a sweep folder, read by its owner (:mod:`locust.io.sweep_store`).

    Parameters
    ----------
    folder : Path
        A ``locust sweep --out`` folder.

    Returns
    -------
    Landscape
        Its designs.

    Raises
    ------
    ReportError
        The folder is not a sweep, or has no finished design.
    """
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
                     finished=res.finished, planned=res.planned, running=res.running,
                     goes_over=np.array([str(o) == GOES_OVER for o in res.column("outcome")], dtype=bool))


def design_value(config: Configuration, name: str) -> float:
    """Where ``config`` sits on the sweep axis ``name``.

    Parameters
    ----------
    config : Configuration
        A configuration of the report.
    name : str
        The axis: ``scale`` or a dotted parameter.

    Returns
    -------
    float
        On ``scale``, the length the configuration adds to every link [m]; otherwise that
        parameter's value in its robot, in its unit (nan when it is not a robot parameter).
    """
    if name == SCALE:
        return config.added_m
    try:
        return float(config.robot.get(name))
    except LocustError:  # not a robot parameter
        return math.nan
