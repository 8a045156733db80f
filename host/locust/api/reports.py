"""``locust.report``: the model against measured hops, one self-contained HTML page."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from ..io.importing import AS_IS, ImportOptions
from ..params import Robot


def make_report(robot: Robot, measured: Mapping[str, str | Path | Sequence[str | Path]] | Sequence[str], *,
           out: str | Path = "reports", cycles: int | None = None, sweep: str | Path | None = None,
           added: Mapping[str, float] | None = None, marker: str = "nose", samples: int = 0,
           side_by_side: bool = False, before: Robot | None = None, robot_source: str | None = None,
           imports: ImportOptions = AS_IS, progress: Callable[[str], None] | None = None,
           study: str | Path | None = None, explain: bool = False):
    """Simulate each leg set and compare it with its measured trials, in one HTML page.

    Parameters
    ----------
    robot : Robot
        The base robot (:func:`locust.robot`); each configuration adds its length to every link
        (small/medium/large: 0/1/2 cm, or ``added``).
    measured : dict or list
        Configuration name -> a trial or list of trials: a folder (``*.tracks.csv`` and/or
        ``run.json``), a track file or a ``run.json``. Or the command line's
        ``["small=a.tracks.csv,b.tracks.csv", ...]``.
    out : path-like, default "reports"
        Parent folder: the report goes into a new ``report/`` (``report-2/`` ...) inside it.
    cycles : int, optional
        Hop cycles to simulate and measure (default: the run records', else the robot's).
    sweep : path-like, optional
        A sweep folder (:func:`locust.sweep_designs` with ``out``): its landscape, the designs
        marked.
    added : dict of str to float, optional
        Configuration -> the length added to every link [m], for names that are not leg sets.
    marker : str, default "nose"
        The marker compared.
    samples : int, default 0
        Draws of the uncertain values per configuration: bands on the predictions.
    side_by_side : bool, default False
        Also write, per trial, its video beside the simulation's.
    robot_source : str, optional
        What the page says the robot is (default its name).
    imports : locust.io.importing.ImportOptions
        How each track is converted (``--units``, ``--rename``, ``--mirror``).
    progress : callable, optional
        Called with each progress line.
    before : Robot, optional
        The robot before a fit: its predictions drawn too.
    study : path-like, optional
        A ``locust optimize --out`` folder: its Pareto front and picked designs.
    explain : bool, default False
        Explain each configuration (``locust sim --explain``): the tornado figure of its
        uncertain values' -/+2 sd effects, why it goes over (or how close it comes) in words.

    Returns
    -------
    locust.report.build.ReportResult
        ``html_path``, ``dashboard_path``, ``json_path``, ``comparisons`` (per configuration:
        ``prediction.result`` the simulation, ``predicted_distance_m`` its distance as ``locust sim``
        gives it, ``predicted_ending`` how it ended, ``marker_travel`` and ``jump`` the measured
        means and sds, each trial's ``ending``).
    """
    from ..report.build import build_report
    from ..trials.measured import parse_measured

    if isinstance(measured, Mapping):
        measured = [f"{name}={','.join(str(p) for p in ([v] if isinstance(v, (str, Path)) else v))}"
                    for name, v in measured.items()]
    groups = parse_measured(list(measured), marker=marker, imports=imports)
    return build_report(robot, groups, Path(out), robot_source=robot_source or robot.name, cycles=cycles,
                        sweep=Path(sweep) if sweep is not None else None, added=dict(added or {}), marker=marker,
                        progress=progress, side_by_side=side_by_side, samples=samples, before=before,
                        study=Path(study) if study is not None else None, explain=explain)


__all__ = ["make_report"]
