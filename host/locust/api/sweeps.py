"""``locust.sweep_designs``: a grid of designs, each checked, simulated and audited; the best valid one."""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..errors import SweepError
from ..params import Robot
from ..sweep.design import Axis, parse_axis
from ..sweep.run import SweepSummary, run_sweep

RANGE = tuple[float, float, int]


@dataclass
class SweepResults(SweepSummary):
    """What :func:`sweep_designs` returns: every design's row (``rows``), the best valid one (``best``,
    None when none is valid), the varied names (``names``) and, when written to a folder,
    ``folder`` and the landscape ``plots``.
    """

    names: tuple[str, ...] = ()

    def to_dataframe(self):
        """One row per design, in design order.

        Returns
        -------
        pandas.DataFrame
            ``design``, the varied values by name, ``valid``, ``reason``, ``distance_m``,
            ``max_nose_height_m``, ``nose_apex_max_m``, ``com_apex_max_m``, ``hops``,
            ``grashof``, ``transmission_deg``.
        """
        import pandas as pd

        return pd.DataFrame(self.rows)

    def plot(self, y: str = "distance_m"):
        """``y`` of each valid design against the first varied value, lengths in mm on both
        axes (as ``locust sweep``'s plots draw them); the best design ringed.

        Parameters
        ----------
        y : str, default "distance_m"
            A column of :meth:`to_dataframe`.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from matplotlib.figure import Figure

        from ..sweep.design import axis_scale
        from ..tables import for_person

        df = self.to_dataframe()
        ok = df[df["valid"].astype(bool)]
        name = self.names[0]
        kx, xlabel = axis_scale(name)
        stem, scale, unit = for_person(y)
        fig = Figure(figsize=(6, 3.5), layout="constrained")
        ax = fig.subplots()
        ax.plot(ok[name] * kx, ok[y] * scale, "o-", ms=4)
        if self.best is not None:
            ax.plot([self.best[name] * kx], [self.best[y] * scale], "o", mfc="none", mec="C3", ms=12, label="best")
            ax.legend(fontsize=8)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"{stem} ({unit})" if unit else y)
        return fig

    def __repr__(self) -> str:
        valid = sum(1 for r in self.rows if r["valid"])
        head = f"SweepResults: {len(self.rows)} designs of {', '.join(self.names)}, {valid} valid"
        if self.best is None:
            return head + "; no valid design"
        from ..sweep.design import design_text

        where = ", ".join(design_text(n, self.best[n]) for n in self.names)
        return (f"{head}\n  best: design {self.best['design']} ({where}): distance "
                f"{self.best['distance_m'] * 1000:.2f} mm over the run, highest nose "
                f"{self.best['max_nose_height_m'] * 1000:.2f} mm above the floor")


def varied(robot: Robot, vary: Mapping[str, tuple | str] | Sequence, parse: Callable, kind: type,
           example: str) -> list:
    """``vary`` as a dict (name -> a tuple of numbers or their ``"a:b"`` text) or as the command
    line's ``--vary NAME=...`` strings, each parsed by ``parse(text, base)`` unless it already is
    a ``kind``, and each name given once.

    Parameters
    ----------
    robot : locust.params.Robot
        The robot whose parameters are varied (names are checked against it).
    vary : mapping or sequence
        Name -> tuple of numbers or ``"a:b[:n]"`` text, or ``NAME=a:b[:n]`` strings or ``kind`` objects;
        values in the parameter's unit.
    parse : callable
        ``parse(text, base)`` -> a ``kind`` (:func:`locust.sweep.design.parse_axis` or ``parse_bound``).
    kind : type
        What ``parse`` makes (``Axis`` or ``Bound``).
    example : str
        The hint's example when nothing is varied.

    Returns
    -------
    list
        One ``kind`` per varied name, in the order given.

    Raises
    ------
    locust.errors.SweepError
        Nothing varied, a name given twice, or a value ``parse`` refuses.
    """
    parsed = [v if isinstance(v, kind) else parse(v, robot) for v in vary_texts(vary)]
    names = [p.name for p in parsed]
    if not names:
        raise SweepError("nothing to vary", f"e.g. vary={example}")
    if len(set(names)) != len(names):
        raise SweepError(f"--vary names a parameter twice: {', '.join(names)}", "give each parameter one --vary")
    return parsed


def vary_texts(vary: Mapping[str, tuple | str] | Sequence) -> list:
    """``vary`` as the command line's ``--vary NAME=...`` texts: a dict's items (name -> a tuple
    of numbers, written exactly, or their text) made ``NAME=a:b[:n]``; a sequence as it is.

    Parameters
    ----------
    vary : mapping or sequence
        Name -> tuple of numbers or text, or texts (and parsed objects) already.

    Returns
    -------
    list
        The texts (and any parsed objects), in the order given.
    """
    if not isinstance(vary, Mapping):
        return list(vary)
    items = [v if isinstance(v, str) else ":".join(repr(x) for x in v) for v in vary.values()]
    return [f"{name}={spec}" for name, spec in zip(vary, items)]


def sweep_axes(robot: Robot, vary: Mapping[str, RANGE | str] | Sequence[str | Axis]) -> list[Axis]:
    """The grid's axes: ``{"scale": (0.0, 0.05, 30)}``, ``{"geometry.leg_m": "0.04:0.1:7"}`` or
    ``["scale=0:0.05:30", ...]`` (the command line's ``--vary``), each name checked once.

    Parameters
    ----------
    robot : locust.params.Robot
        The robot swept.
    vary : mapping or sequence
        Name -> (low, high, count) in the parameter's unit, or the same as text.

    Returns
    -------
    list of locust.sweep.design.Axis

    Raises
    ------
    locust.errors.SweepError
        Nothing varied, a name given twice, or a range that cannot be read.
    """
    return varied(robot, vary, parse_axis, Axis, '{"scale": (0.0, 0.05, 30)}')


def sweep_designs(robot: Robot, vary: Mapping[str, RANGE | str] | Sequence[str | Axis], cycles: int = 3, *,
          out: str | Path | None = None, jobs: int | None = None, scheduler: str = "local", samples: int = 0,
          progress: Callable[[int], None] | None = None, say: Callable[[str], None] | None = None) -> SweepResults:
    """Simulate every combination of the varied values and find the best valid design.

    Each design is checked before it is simulated (the four-bar assembles and stays closed over
    the commanded crank range) and audited after; one that fails is a row with ``valid`` False
    and its ``reason``, never the best.

    Parameters
    ----------
    robot : Robot
        The base design (:func:`locust.robot`).
    vary : dict
        Name -> ``(start, stop, n)``: n values from start to stop inclusive. A name is a
        numeric parameter's dotted name or ``scale`` (metres added to all four links, the seed
        notebook's sweep variable). Several names make a grid.
    cycles : int, default 3
        Hop cycles per design.
    out : path-like, optional
        A folder for ``results.csv``, ``sweep.json`` and the landscape plots (rerunning into it
        resumes); default none: nothing is kept on disk.
    jobs : int, optional
        Worker processes (default every local core; 1 runs in this process).
    scheduler : str, default "local"
        ``local``, ``dask-local`` or ``tcp://HOST:PORT`` of a Dask scheduler.
    samples : int, default 0
        Rank designs by their mean over this many draws of the uncertain values.
    progress : callable, optional
        Called with 1 as each design finishes.
    say : callable, optional
        Told, as a line of text, when fewer workers start than ``jobs`` asked for.

    Returns
    -------
    SweepResults
        ``.rows``, ``.best``, ``.to_dataframe()``.

    Examples
    --------
    >>> import locust
    >>> res = locust.sweep_designs(locust.robot("seed"), vary={"scale": (0.0, 0.02, 3)}, cycles=1, jobs=1)
    >>> res.to_dataframe()[["scale", "valid"]].shape
    (3, 2)
    """
    axes = sweep_axes(robot, vary)
    if out is not None:
        summary = run_sweep(robot, axes, cycles, Path(out), scheduler=scheduler, jobs=jobs, progress=progress,
                            samples=samples, say=say)
        return SweepResults(**vars(summary), names=tuple(a.name for a in axes))
    with tempfile.TemporaryDirectory(prefix="locust-sweep-") as tmp:
        summary = run_sweep(robot, axes, cycles, Path(tmp), scheduler=scheduler, jobs=jobs, progress=progress,
                            plots=False, samples=samples, say=say)
    summary.folder = None
    return SweepResults(**vars(summary), names=tuple(a.name for a in axes))


__all__ = ["SweepResults", "sweep_designs", "sweep_axes"]
