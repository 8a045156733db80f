"""Fit plots: data and model above, residuals below, written atomically as PNG."""

from __future__ import annotations

from pathlib import Path

from ..plotting import pyplot, save_png
from .curves import Curves


def plot_fit(curves: Curves, path: str | Path, subtitle: str = "") -> Path:
    plt = pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 1.2]})
    discrete = curves.model_x is None
    top.plot(curves.x, curves.data, "o" if discrete else ".", ms=4, color="#1f77b4", label="data")
    if discrete:
        top.plot(curves.x, curves.model, "-", color="#d62728", label="fit")
    else:
        top.plot(curves.model_x, curves.model_fine, "-", lw=1.2, color="#d62728", label="model")
    top.set_ylabel(curves.y_label)
    top.set_title(curves.title + (f"\n{subtitle}" if subtitle else ""), fontsize=10)
    top.legend(loc="best", fontsize=8)
    top.grid(alpha=0.3)
    bottom.axhline(0, color="0.5", lw=0.8)
    bottom.plot(curves.x, curves.residual, "o" if discrete else ".", ms=3, color="#2ca02c")
    bottom.set_ylabel("residual")
    bottom.set_xlabel(curves.x_label)
    bottom.grid(alpha=0.3)
    fig.tight_layout()
    return save_png(fig, path, dpi=110)
