"""Landscape plots of a sweep: 1-D curves and 2-D heat maps, invalid designs shown as such."""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..params import LEG_SETS, Robot, preset
from ..plotting import pyplot, save_png
from ..sim.outcome import GOES_OVER
from .design import SCALE, Axis, axis_scale

METRICS = (("distance_m", "distance over the run (mm)"),
           ("max_nose_height_m", "highest nose point above the floor (mm)"))   # as `locust sim` prints them
MM = 1000.0


def _leg_set_marks(axis: Axis, robot: Robot) -> list[tuple[str, float]]:
    """Where the physical Small/Medium/Large leg sets sit on a ``scale`` axis of the seed."""
    if axis.name != SCALE or robot.link_lengths_m() != preset("seed").link_lengths_m():
        return []
    lo, hi = sorted((axis.start, axis.stop))
    return [(name.capitalize(), leg.added_m) for name, leg in LEG_SETS.items()
            if lo - 1e-12 <= leg.added_m <= hi + 1e-12]


def _curve(rows: list[dict[str, Any]], axis: Axis, best: dict | None, robot: Robot, path: Path) -> Path:
    plt = pyplot()
    x_scale, label = axis_scale(axis.name)
    fig, panels = plt.subplots(1, 2, figsize=(11, 4.2))
    ok = [r for r in rows if r["valid"] and r["outcome"] != GOES_OVER]
    over = [r for r in rows if r["valid"] and r["outcome"] == GOES_OVER]
    bad = [r for r in rows if not r["valid"]]
    for ax, (key, ylab) in zip(panels, METRICS):
        # with several axes, each value's best over the others
        by_x: dict[float, float] = {}
        for r in ok:
            by_x[r[axis.name]] = max(by_x.get(r[axis.name], -math.inf), r[key])
        xs = sorted(by_x)
        ax.plot([x * x_scale for x in xs], [by_x[x] * MM for x in xs], "o-", ms=4, color="#1f77b4",
                label=f"valid, stays on its feet ({len(ok)})")
        if over:
            ax.plot([r[axis.name] * x_scale for r in over], [r[key] * MM for r in over], "v", ms=6, mfc="none",
                    color="#9467bd", label=f"goes over onto its back ({len(over)}): not a jump")
        if bad:
            ax.plot([r[axis.name] * x_scale for r in bad], [0.0] * len(bad), "x", color="#d62728",
                    label=f"invalid ({len(bad)}): not a result")
        if best is not None:
            ax.plot(best[axis.name] * x_scale, best[key] * MM, "*", ms=14, color="#ff7f0e",
                    label="best valid (distance)")
        for name, v in _leg_set_marks(axis, robot):
            ax.axvline(v * x_scale, color="0.4", ls=":", lw=1)
            ax.text(v * x_scale, ax.get_ylim()[1], f" {name}", rotation=90, va="top", fontsize=8, color="0.3")
        ax.set_xlabel(label)
        ax.set_ylabel(ylab)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    panels[0].set_title("distance over the run")
    panels[1].set_title("highest nose point above the floor")
    fig.suptitle(f"sweep of {robot.name}", fontsize=10)
    return save_png(fig, path)


def _heatmap(rows: list[dict[str, Any]], ax_a: Axis, ax_b: Axis, path: Path) -> Path:
    plt = pyplot()
    va, vb = ax_a.values(), ax_b.values()
    (ka, label_a), (kb, label_b) = axis_scale(ax_a.name), axis_scale(ax_b.name)
    fig, panels = plt.subplots(1, 2, figsize=(12, 4.8))
    for ax, (key, title) in zip(panels, METRICS):
        grid = np.full((len(vb), len(va)), np.nan)
        over = np.zeros_like(grid, dtype=bool)
        for r in rows:
            i, j = vb.index(r[ax_b.name]), va.index(r[ax_a.name])
            if r["valid"] and r["outcome"] != GOES_OVER:
                grid[i, j] = np.fmax(grid[i, j], r[key] * MM)
            elif r["valid"]:
                over[i, j] = True
        img = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis",
                        extent=_extent([v * ka for v in va]) + _extent([v * kb for v in vb]))
        fig.colorbar(img, ax=ax, label=title)
        jj, ii = np.meshgrid(np.asarray(va) * ka, np.asarray(vb) * kb)
        over &= np.isnan(grid)
        bad = np.isnan(grid) & ~over
        if over.any():
            ax.plot(jj[over], ii[over], "v", color="#9467bd", mfc="none", ms=5, label="goes over onto its back")
        if bad.any():
            ax.plot(jj[bad], ii[bad], "x", color="#d62728", ms=5, label="invalid (no valid design)")
        if bad.any() or over.any():
            ax.legend(fontsize=8, loc="upper right")
        ax.set_xlabel(label_a)
        ax.set_ylabel(label_b)
        ax.set_title(title + ("" if len(rows) == grid.size else ", best over the other axes"), fontsize=9)
    return save_png(fig, path)


def _extent(values: list[float]) -> list[float]:
    if len(values) == 1:
        return [values[0] - 0.5, values[0] + 0.5]
    step = (values[-1] - values[0]) / (len(values) - 1)
    return [values[0] - step / 2, values[-1] + step / 2]


def _safe(name: str) -> str:
    return name.replace(".", "_")


def plot_landscape(rows: list[dict[str, Any]], axes: list[Axis], best: dict | None, out: Path,
                   robot: Robot) -> list[Path]:
    """The sweep's landscape plots: a curve per axis of more than one value, a heat map per pair
    of them; invalid designs are shown as such.

    Parameters
    ----------
    rows : list of dict
        The sweep's rows.
    axes : list of Axis
        The sweep's axes.
    best : dict or None
        The best row, marked.
    out : Path
        The folder the PNG files go in.
    robot : Robot
        The robot the sweep starts from (its leg sets are marked on a ``scale`` axis of the seed).

    Returns
    -------
    list of Path
        The files written: ``curve_<name>.png`` and ``heatmap_<a>__<b>.png``.
    """
    out = Path(out)
    made = [_curve(rows, a, best, robot, out / f"curve_{_safe(a.name)}.png") for a in axes if a.n > 1]
    for a, b in itertools.combinations([a for a in axes if a.n > 1], 2):
        made.append(_heatmap(rows, a, b, out / f"heatmap_{_safe(a.name)}__{_safe(b.name)}.png"))
    return made
