"""A study's results a person reads: the Pareto front, its ends and knee, ``pareto.png``.

Rows are the tidy trial rows of :mod:`locust.sweep.optimize` (one per design, the design's
values by dotted name, each objective's figure by its column, ``flip_share``, ``feasible``).
Every objective is maximised.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .design import design_text
from .objectives import Objective


def dominates(a: dict[str, Any], b: dict[str, Any], columns: list[str]) -> bool:
    """Whether row ``a`` is at least as good as ``b`` on every column and better on one.

    Parameters
    ----------
    a, b : dict
        Trial rows.
    columns : list of str
        The objectives' columns (all maximised).

    Returns
    -------
    bool
        True when ``a`` dominates ``b``.
    """
    return all(a[c] >= b[c] for c in columns) and any(a[c] > b[c] for c in columns)


def knee(front: list[dict[str, Any]], columns: list[str]) -> dict[str, Any]:
    """The front's knee: each objective scaled to 0..1 over the front, the row nearest the
    point best in all (ties: the lower trial number).

    Parameters
    ----------
    front : list of dict
        The front's rows.
    columns : list of str
        The objectives' columns.

    Returns
    -------
    dict
        The knee's row.
    """
    values = np.array([[r[c] for c in columns] for r in front], dtype=float)
    low, high = values.min(axis=0), values.max(axis=0)
    span = np.where(high > low, high - low, 1.0)
    gap = np.linalg.norm((high - values) / span, axis=1)
    return min(zip(gap, front), key=lambda gr: (gr[0], gr[1]["trial"]))[1]


def picks(front: list[dict[str, Any]], objectives: list[Objective]) -> dict[str, dict[str, Any]]:
    """``best-<objective>`` for each end of the front, and ``knee`` with two objectives or more.

    Parameters
    ----------
    front : list of dict
        The front's rows (not empty).
    objectives : list of Objective
        What is maximised.

    Returns
    -------
    dict of str to dict
        Pick name to its row (ties: the lower trial number).
    """
    out = {f"best-{o.name}": max(front, key=lambda r, c=o.column: (r[c], -r["trial"])) for o in objectives}
    if len(objectives) > 1:
        out["knee"] = knee(front, [o.column for o in objectives])
    return out


def plot_front(rows: list[dict[str, Any]], front: list[dict[str, Any]], chosen: dict[str, dict[str, Any]],
               objectives: list[Objective], max_flip: float | None, path: Path, title: str) -> Path:
    """``pareto.png``: :func:`draw_front` on a figure of its own.

    Parameters
    ----------
    rows : list of dict
        Every trial's row.
    front : list of dict
        The front's rows.
    chosen : dict of str to dict
        The picks (:func:`picks`).
    objectives : list of Objective
        What is maximised.
    max_flip : float or None
        The largest share of draws that may go over.
    path : Path
        The PNG file to write.
    title : str
        The plot's title.

    Returns
    -------
    Path
        The file written.
    """
    from ..plotting import pyplot, save_png

    fig, ax = pyplot().subplots(figsize=(7.5, 5))
    draw_front(ax, rows, front, chosen, objectives, max_flip, title)
    return save_png(fig, path)


def picks_of(front: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """The picks of a front read back from ``pareto.csv`` (its ``pick`` column).

    Parameters
    ----------
    front : list of dict
        The rows of pareto.csv.

    Returns
    -------
    dict of str to dict
        Pick name to its row.
    """
    return {name: r for r in front for name in r["pick"].split()}


def draw_front(ax, rows: list[dict[str, Any]], front: list[dict[str, Any]], chosen: dict[str, dict[str, Any]],
               objectives: list[Objective], max_flip: float | None, title: str) -> None:
    """The front against its first two objectives (one objective: against the trial number):
    dominated trials grey, trials that go over too often marked, the front and its picks named.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes drawn on.
    rows : list of dict
        Every trial's row.
    front : list of dict
        The front's rows.
    chosen : dict of str to dict
        The picks.
    objectives : list of Objective
        What is maximised; figures drawn in each one's plot unit.
    max_flip : float or None
        The largest share of draws that may go over (for the legend).
    title : str
        The plot's title.
    """
    done = [r for r in rows if r["state"] == "complete"]
    flipped = [r for r in done if not r["feasible"]]
    front_ids = {r["trial"] for r in front}
    if len(objectives) > 1:
        (ox, oy) = objectives[:2]
        fx = lambda r: r[ox.column] * ox.plot_factor   # noqa: E731
        xlabel = ox.label
    else:
        oy = objectives[0]
        fx = lambda r: r["trial"]   # noqa: E731
        xlabel = "trial"
    fy = lambda r: r[oy.column] * oy.plot_factor   # noqa: E731
    grey = [r for r in done if r["feasible"] and r["trial"] not in front_ids]
    ax.plot([fx(r) for r in grey], [fy(r) for r in grey], "o", ms=5, color="0.7", label=f"dominated ({len(grey)})")
    feasible = grey + list(front)
    box = _box([fx(r) for r in feasible], [fy(r) for r in feasible]) if len(feasible) > 1 else None
    if flipped:
        why = f"flip share over {max_flip:g}" if max_flip is not None else "goes over"
        outside = sum(1 for r in flipped if box and not _inside(box, fx(r), fy(r)))
        more = f", {outside} outside the axes" if outside else ""
        ax.plot([fx(r) for r in flipped], [fy(r) for r in flipped], "x", ms=7, color="#d62728",
                label=f"{why} ({len(flipped)}{more})")
    ordered = sorted(front, key=fx)
    ax.plot([fx(r) for r in ordered], [fy(r) for r in ordered], "o-", ms=6, color="#1f77b4",
            label=f"Pareto front ({len(front)})")
    named: dict[int, list[str]] = {}
    for name, r in chosen.items():
        named.setdefault(r["trial"], []).append(name)
    for k, (trial, names) in enumerate(named.items()):
        r = chosen[names[0]]
        ax.plot(fx(r), fy(r), "*", ms=13, color="#ff7f0e")
        ax.annotate(f"{', '.join(names)} (trial {trial})", (fx(r), fy(r)), textcoords="offset points",
                    xytext=(-8, -14 - 12 * k), ha="right", fontsize=8, color="#c05800",
                    arrowprops={"arrowstyle": "-", "color": "#c05800", "lw": 0.5})
    if box:   # the feasible designs fill the axes; a design far over the flip limit is counted above
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(oy.label)
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")


def _box(xs: list[float], ys: list[float], margin: float = 0.15) -> tuple[float, float, float, float]:
    """Axis limits around the points, ``margin`` of their span (or of the value) on each side."""
    def pad(lo: float, hi: float) -> tuple[float, float]:
        m = margin * ((hi - lo) or abs(hi) or 1.0)
        return lo - m, hi + m
    return (*pad(min(xs), max(xs)), *pad(min(ys), max(ys)))


def _inside(box: tuple[float, float, float, float], x: float, y: float) -> bool:
    return box[0] <= x <= box[1] and box[2] <= y <= box[3]


def describe(row: dict[str, Any], names: list[str], objectives: list[Objective]) -> str:
    """One line: the design's values and its figures, in the units the plots use.

    Parameters
    ----------
    row : dict
        A trial's row.
    names : list of str
        The design variables (:func:`locust.sweep.design.design_text`: lengths in mm, each with its
        unit).
    objectives : list of Objective
        The figures shown.

    Returns
    -------
    str
        The line.
    """
    where = ", ".join(design_text(n, row[n]) for n in names)
    figs = ", ".join(f"{o.label.rsplit(' (', 1)[0]} {row[o.column] * o.plot_factor:.2f} "
                     f"{o.label.rsplit('(', 1)[-1].rstrip(')')}" for o in objectives)
    return f"trial {row['trial']} ({where}): {figs}, flip share {row['flip_share']:.2f}"
