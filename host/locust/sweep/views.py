"""The study's own views, as Optuna draws them: its history, the parameter importances and an
interactive Pareto front, in one HTML page that opens offline (``study.html``).

Each view is ``optuna.visualization``'s plotly figure of the study: the history and the
importances one per objective, the front once (two or three objectives). Objectives are drawn
in the unit the plots use (:attr:`~locust.sweep.objectives.Objective.plot_factor`: mm, ms);
the study itself keeps SI. plotly's JavaScript is inlined once, so the page needs nothing
from outside (its Content-Security-Policy forbids any outside resource, so a browser proves
it).

Importances are Optuna's default evaluator (PED-ANOVA), which ranks the parameters by how
much they matter for reaching *low* values of the target it is given; every objective here is
maximised, so it is given each objective negated.
"""

from __future__ import annotations

import html
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from ..fileio import atomic_write_text
from .objectives import Objective

STUDY_PAGE = "study.html"
VIEWS = ("history", "importances", "front")
# no outside resource of any kind; the page's own inline script (plotly) and styles only, and
# images as data: (plotly's "download plot as png")
CSP = "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data: blob:"
STYLE = ("body{font:14px/1.45 system-ui,'DejaVu Sans',sans-serif;margin:2em auto;max-width:1180px;color:#222;"
         "padding:0 1em}h2{margin-top:1.6em;border-bottom:1px solid #ddd}.note{color:#555}"
         "section div.plot{height:480px}")
PLOT_CONFIG = {"displaylogo": False, "responsive": True}


@dataclass
class View:
    """One of the page's views: its plotly figures, or why it has none.

    Attributes
    ----------
    key : str
        ``history``, ``importances`` or ``front`` (the section's id).
    title : str
        The section's heading.
    figures : list of plotly.graph_objects.Figure
        The figures drawn.
    note : str
        Why a figure is missing ("" when none is).
    """

    key: str
    title: str
    figures: list = field(default_factory=list)
    note: str = ""


def _scaled(k: int, factor: float):
    return lambda t: t.values[k] * factor


def _negated(k: int):
    return lambda t: -t.values[k]


def study_views(study, objectives: list[Objective]) -> list[View]:
    """Optuna's history, importances and Pareto front of ``study``.

    Parameters
    ----------
    study : optuna.Study
        The study (all its objectives maximised, in the order of ``objectives``).
    objectives : list of Objective
        What it maximises.

    Returns
    -------
    list of View
        ``history`` (a figure per objective), ``importances`` (a figure per objective) and
        ``front`` (one figure, or a note with one objective); a view Optuna cannot draw yet
        (too few complete trials) carries its reason instead.
    """
    import optuna.visualization as vis

    history = View("history", "Optimization history")
    importances = View("importances", "Parameter importances")
    front = View("front", "Pareto front")
    for k, o in enumerate(objectives):
        fig = vis.plot_optimization_history(study, target=_scaled(k, o.plot_factor), target_name=o.label)
        fig.update_layout(title=f"Optimization history: {o.label}")
        history.figures.append(fig)
        try:
            with warnings.catch_warnings():
                # the evaluator's reminder that it ranks for low targets: the target is negated
                warnings.filterwarnings("ignore", message=".*importances of params to achieve low")
                fig = vis.plot_param_importances(study, target=_negated(k), target_name=o.label)
        except (ValueError, RuntimeError) as exc:
            importances.note = f"not drawn yet: {exc}"
            continue
        fig.update_layout(title=f"Parameter importances for {o.label}")
        importances.figures.append(fig)
    if len(objectives) < 2:
        front.note = ("one objective: the study has no front, only its best trial "
                      "(the highest point of the history above)")
    else:
        factors = [o.plot_factor for o in objectives]
        fig = vis.plot_pareto_front(study, targets=lambda t: [v * f for v, f in zip(t.values, factors)],
                                    target_names=[o.label for o in objectives])
        front.figures.append(fig)
    return [history, importances, front]


def page_html(views: list[View], title: str, lines: list[str]) -> str:
    """The views as one HTML page, plotly's JavaScript inlined once.

    Parameters
    ----------
    views : list of View
        From :func:`study_views`.
    title : str
        The page's title and heading.
    lines : list of str
        Paragraphs under the heading (plain text, escaped here).

    Returns
    -------
    str
        The document.
    """
    from plotly.offline import get_plotlyjs

    parts = []
    for view in views:
        body = "".join(f'<div class="plot" data-view="{view.key}">'
                       + fig.to_html(full_html=False, include_plotlyjs=False, config=PLOT_CONFIG,
                                     div_id=f"{view.key}-{n}", default_height="480px") + "</div>"
                       for n, fig in enumerate(view.figures))
        if view.note:
            body += f'<p class="note">{html.escape(view.note)}</p>'
        parts.append(f'<section id="{view.key}"><h2>{html.escape(view.title)}</h2>{body}</section>')
    intro = "".join(f"<p>{html.escape(line)}</p>" for line in lines)
    return ('<!DOCTYPE html><html lang="en"><head><meta charset="utf-8">'
            f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
            f"<title>{html.escape(title)}</title><style>{STYLE}</style>"
            f'<script type="text/javascript">{get_plotlyjs()}</script></head>'
            f"<body><h1>{html.escape(title)}</h1>{intro}{''.join(parts)}</body></html>")


def write_study_page(study, objectives: list[Objective], path: Path, lines: list[str] | None = None) -> Path:
    """Write ``study.html``: Optuna's views of ``study`` (:func:`study_views`), atomically.

    Parameters
    ----------
    study : optuna.Study
        The study.
    objectives : list of Objective
        What it maximises.
    path : Path
        The page to write.
    lines : list of str, optional
        Paragraphs under the heading; by default what the study holds.

    Returns
    -------
    Path
        The page written.
    """
    trials = study.get_trials(deepcopy=False)
    complete = sum(t.state.name == "COMPLETE" for t in trials)
    pruned = sum(t.state.name == "PRUNED" for t in trials)
    if lines is None:
        lines = [f"{len(trials)} trials: {complete} complete, {pruned} pruned as invalid designs; every objective "
                 "is maximised. Pruned trials are in no view; a design over the flip limit is drawn as "
                 "infeasible on the front."]
    title = f"Study {study.study_name}: Optuna's views"
    return atomic_write_text(path, page_html(study_views(study, objectives), title, lines))
