"""Fit plots: data and model above, residuals below (one such pair per recording), written
atomically (PNG, SVG or PDF by the path's suffix); and a hop fit's run, its tracked markers
against the fitted simulation."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..fileio import storable
from ..plotting import save_png
from .curves import Curves

if TYPE_CHECKING:
    from .hopresidual import RunFit


def plot_fit(curves: Curves | list[Curves], path: str | Path, subtitle: str = "", force: bool = False) -> Path:
    """One recording's ``Curves``, or several stacked (each with its residuals below it); ``force``:
    replace an existing file that is not one of this toolkit's figures.

    Parameters
    ----------
    curves : Curves or list of Curves
        What to draw.
    path : path-like
        The figure's file; its suffix chooses PNG, SVG or PDF.
    subtitle : str
        A line under the title (the fit's RMS per recording).
    force : bool, default False
        Replace a file that is not one of this toolkit's figures.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    locust.errors.WriteError
        ``path`` cannot be written, or holds another file and ``force`` is False.
    """
    return save_png(fit_figure(curves, subtitle), path, dpi=110, force=force, option="--plot")


def fit_figure(curves: Curves | list[Curves], subtitle: str = ""):
    """The figure :func:`plot_fit` writes (a ``matplotlib.figure.Figure``, no display needed).

    Parameters
    ----------
    curves : Curves or list of Curves
        What to draw.
    subtitle : str
        A line under the title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    panels = [curves] if isinstance(curves, Curves) else list(curves)
    fig = Figure(figsize=(7.5, 5.5 * len(panels)))
    axes = fig.subplots(2 * len(panels), 1, squeeze=False, gridspec_kw={"height_ratios": [3, 1.2] * len(panels)})
    for k, c in enumerate(panels):
        top, bottom = axes[2 * k, 0], axes[2 * k + 1, 0]
        bottom.sharex(top)
        discrete = c.model_x is None
        top.plot(c.x, c.data, "o" if discrete else ".", ms=4, color="#1f77b4", label="data")
        if discrete:
            top.plot(c.x, c.model, "-", color="#d62728", label="fit")
        else:
            top.plot(c.model_x, c.model_fine, "-", lw=1.2, color="#d62728", label="model")
        top.set_ylabel(c.y_label)
        # (a recording's name may hold an undecodable byte, which no font can draw)
        top.set_title(storable(c.title + (f"\n{subtitle}" if subtitle and k == 0 else "")), fontsize=10)
        top.legend(loc="best", fontsize=8)
        top.grid(alpha=0.3)
        bottom.axhline(0, color="0.5", lw=0.8)
        bottom.plot(c.x, c.residual, "o" if discrete else ".", ms=3, color="#2ca02c")
        bottom.set_ylabel(c.residual_label)
        bottom.set_xlabel(c.x_label)
        if discrete:      # numbered trials (the ramp's): ticks on whole trials only
            bottom.xaxis.set_major_locator(MaxNLocator(integer=True))
        bottom.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_run(fit: RunFit, path: Path, subtitle: str = "") -> Path:
    """Tracked markers against the fitted simulation, x and y of each, on the schedule's clock."""
    return save_png(run_figure(fit, subtitle), path, dpi=110)


def run_figure(fit: RunFit, subtitle: str = ""):
    """The figure :func:`plot_run` writes (a ``matplotlib.figure.Figure``, no display needed)."""
    from matplotlib.figure import Figure

    markers = list(fit.curves)
    fig = Figure(figsize=(5.2 * max(len(markers), 1), 5.5))
    axes = fig.subplots(2, max(len(markers), 1), squeeze=False, sharex=True)
    for col, m in enumerate(markers):
        t, x, y, ts, xs, ys = fit.curves[m]
        lo, hi = float(t[0]), float(t[-1])
        keep = (ts >= lo) & (ts <= hi)
        for row, (data, model, label) in enumerate(((x, xs, "x forward"), (y, ys, "y up"))):
            ax = axes[row, col]
            ax.plot(t, 1000 * data, ".", ms=3, color="#1f77b4", label="tracked")
            ax.plot(ts[keep], 1000 * model[keep], "-", lw=1.2, color="#d62728", label="fitted simulation")
            ax.set_ylabel(f"{m} {label} [mm]")
            ax.grid(alpha=0.3)
        axes[0, col].set_title(f"{m}: RMS {1000 * fit.rms_by_marker_m[m]:.2f} mm", fontsize=10)
        axes[1, col].set_xlabel("t from the first push [s]")
    axes[0, 0].legend(loc="best", fontsize=8)
    fig.suptitle(f"{fit.config}: {Path(fit.source).name}" + (f"\n{subtitle}" if subtitle else ""), fontsize=10)
    fig.tight_layout()
    return fig
