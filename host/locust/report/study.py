"""A ``locust optimize`` study in the report: its Pareto front and the designs it picks, and
Optuna's own views of it.

The folder is read by its owner (:func:`locust.io.study_store.read_study`); the front is drawn
as ``pareto.png`` draws it (:func:`locust.sweep.pareto.draw_front`). Optuna's views (history,
importances, interactive front: :mod:`locust.sweep.views`) are drawn from the study's journal
in that folder, as it is when the report is made, into ``study.html`` beside the report; a
study kept in a database (``--storage``) is shown by the ``study.html`` its folder holds.
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ReportError, SweepError
from ..io.study_store import StudyResults, read_study
from ..plotting import png_bytes, pyplot
from ..sweep.objectives import OBJECTIVES, RENAMED
from ..sweep.pareto import describe, draw_front, picks_of
from ..sweep.views import STUDY_PAGE
from .page import Figure

JOURNAL = "study.journal"


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


def views_page(study: StudyResults) -> str | None:
    """``study.html``'s text: Optuna's views of the study, from the journal in its folder (else
    the page its folder holds; None when it holds neither).

    Parameters
    ----------
    study : StudyResults
        The study, from :func:`read_front`.

    Returns
    -------
    str or None
        The page.

    Raises
    ------
    ReportError
        The journal is not one, or holds no study of the folder's name.
    """
    import optuna

    from ..sweep.storage import check_journal_file, open_storage
    from ..sweep.views import page_html, study_views

    journal = study.folder / JOURNAL
    if not journal.is_file():
        page = study.folder / STUDY_PAGE
        return page.read_text(encoding="utf-8") if page.is_file() else None
    try:
        check_journal_file(journal)
        optuna.logging.set_verbosity(optuna.logging.ERROR)
        held = optuna.load_study(study_name=study.study, storage=open_storage(None, study.folder))
    except SweepError as exc:
        raise ReportError(f"--optimize {study.folder}: {exc.message}", exc.hint) from None
    except KeyError:
        raise ReportError(f"--optimize {study.folder}: its journal holds no study {study.study!r}, which its "
                          "optimize.json names", "give the --out folder of one `locust optimize` run") from None
    trials = held.get_trials(deepcopy=False)
    lines = [f"{len(trials)} trials in {journal} when this report was made: "
             f"{sum(t.state.name == 'COMPLETE' for t in trials)} complete, "
             f"{sum(t.state.name == 'PRUNED' for t in trials)} pruned as invalid designs; every objective is "
             "maximised. Pruned trials are in no view; a design over the flip limit is drawn as infeasible on "
             "the front."]
    return page_html(study_views(held, [OBJECTIVES[n] for n in study.objectives]),
                     f"Study {held.study_name}: Optuna's views", lines)


def study_figure(study: StudyResults, views: bool = False) -> Figure:
    """The front, its ends and knee, with a caption saying how each design was judged.

    Parameters
    ----------
    study : StudyResults
        The study, from :func:`read_front`.
    views : bool
        ``study.html`` (:func:`views_page`) is written beside the report: the caption links it.

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
    link = (STUDY_PAGE, "Optuna's own views of the study: history, importances, interactive front.") if views \
        else None
    return Figure("pareto", "Designs that hop far and high without going over", caption, png_bytes(fig), link)
