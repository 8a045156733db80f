"""A ``locust optimize`` study in the report: its Pareto front and the designs it picks.

The folder is read by its owner (:func:`locust.io.study_store.read_study`); the front is drawn
as ``pareto.png`` draws it (:func:`locust.sweep.pareto.draw_front`).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ReportError, SweepError
from ..io.study_store import StudyResults, read_study
from ..plotting import png_bytes, pyplot
from ..sweep.objectives import OBJECTIVES, RENAMED
from ..sweep.pareto import describe, draw_front, picks_of
from . import page as H


def read_front(folder: Path) -> StudyResults:
    """The study in ``folder``; a folder that is not one is a :class:`ReportError`.

    Parameters
    ----------
    folder : Path
        A ``locust optimize`` folder.

    Returns
    -------
    StudyResults
        Its trials and Pareto front.

    Raises
    ------
    ReportError
        The folder is not a readable study, or one of objectives this locust does not know
        (a study from before the objectives said ``_per_hop``).
    """
    try:
        study = read_study(folder)
    except SweepError as exc:
        raise ReportError(f"--optimize {folder}: {exc.message}", exc.hint) from None
    unknown = [name for name in study.objectives if name not in OBJECTIVES]
    if unknown:
        raise ReportError(f"--optimize {folder}: its study maximises {', '.join(unknown)}, which is no objective of "
                          f"this locust ({', '.join(OBJECTIVES)})",
                          "rerun the study into a new --out with --objective "
                          + " --objective ".join(RENAMED.get(n, n) for n in study.objectives))
    return study


def study_figure(study: StudyResults) -> H.Figure:
    """The front, its ends and knee, with a caption saying how each design was judged.

    Parameters
    ----------
    study : StudyResults
        The study, from :func:`read_front`.

    Returns
    -------
    Figure
        The ``pareto`` figure of the page (PNG bytes and caption).
    """
    objectives = [OBJECTIVES[name] for name in study.objectives]
    chosen = picks_of(study.front)
    fig, ax = pyplot().subplots(figsize=(8, 5))
    draw_front(ax, study.trials, study.front, chosen, objectives, study.max_flip,
               f"{len(study.trials)} designs of {study.base}, {len(study.front)} on the front")
    fig.tight_layout()
    judged = (f"the {study.quantile:g} quantile over {study.robust} draws of the robot file's uncertain values "
              "(the same draws for every design)" if study.robust else "the nominal run")
    limit = f"; a design whose share of draws going over is above {study.max_flip:g} is infeasible" \
        if study.max_flip is not None else ""
    picked = "; ".join(f"{name}: {describe(r, study.names, objectives)}" for name, r in chosen.items())
    caption = (f"Pareto front of the study in {study.folder}: each objective per hop, {judged}{limit}; a run "
               f"that goes over onto its back scores 0. Grey: dominated designs; red crosses: over the flip "
               f"limit. {picked or 'No feasible design.'}")
    return H.Figure("pareto", "Designs that hop far and high without going over", caption, png_bytes(fig))
