"""What ``locust measure stroke`` writes: the crank's angle over time as CSV, and its plot.

The CSV is tidy, one row per clip frame: ``clip`` (``floor`` or ``held``), ``frame``,
``t_s`` (from the clip's first frame), ``t_from_onset_s`` (from the frame the crank left
rest), ``crank_deg`` and ``crank_sd_deg`` (the crank's angle from its ground link and its
standard deviation; empty where a sticker was not found) and ``model_crank_deg`` (the model's
for the same push at the same time from the onset). The plot draws the clip's angle from
rest against the model's, each clip in its own panel, with the extreme marked.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from ..fileio import atomic_write_text
from ..plotting import pyplot, save_png
from .stroke import KIND_WORDS, StrokeResult

COLUMNS = ("clip", "frame", "t_s", "t_from_onset_s", "crank_deg", "crank_sd_deg", "model_crank_deg")


def _cell(v: float) -> str:
    return "" if not np.isfinite(v) else f"{v:.6g}"


def angle_csv(result: StrokeResult) -> str:
    """The crank's angle over time, every clip's frames (module doc).

    Parameters
    ----------
    result : StrokeResult

    Returns
    -------
    str
        CSV text with a header line.
    """
    buf = io.StringIO()
    buf.write(",".join(COLUMNS) + "\n")
    for r in result.readings:
        s, model = r.series, r.model_at_frames_deg()
        for k in range(len(s.t_s)):
            cells = [r.kind, str(k), f"{s.t_s[k]:.6f}", f"{s.t_s[k] - r.swing.onset_s:.6f}",
                     _cell(s.angle_deg[k]), _cell(s.sd_deg[k]), _cell(model[k])]
            buf.write(",".join(cells) + "\n")
    return buf.getvalue()


def stroke_figure(result: StrokeResult):
    """The crank's excursion from rest over time, clip against model, a panel per clip.

    Parameters
    ----------
    result : StrokeResult

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    fig, axes = plt.subplots(1, len(result.readings), figsize=(5.5 * len(result.readings), 4.0), squeeze=False)
    for ax, r in zip(axes[0], result.readings):
        s, sw = r.series, r.swing
        t_ms = (s.t_s - sw.onset_s) * 1000.0
        ax.errorbar(t_ms, sw.direction * (s.angle_deg - sw.rest_deg), yerr=1.96 * s.sd_deg, fmt=".", ms=3,
                    color="C0", ecolor="0.7", label=f"{s.path.name} (95 %)")
        mt = (r.model_t_s - r.model.onset_s) * 1000.0
        keep = (mt >= t_ms[0]) & (mt <= t_ms[-1])
        ax.plot(mt[keep], r.model.direction * (r.model_angle_deg[keep] - r.model.rest_deg), color="C3",
                label=f"model {result.robot_name}")
        stroke = r.estimates["stroke_deg"]
        ax.axhline(stroke.value, color="C0", lw=0.8, ls="--")
        ax.axhspan(*stroke.ci95, color="C0", alpha=0.15, lw=0)
        ax.axhline(r.model.stroke_deg, color="C3", lw=0.8, ls="--")
        ax.axhline(abs(result.push_deg), color="0.4", lw=0.8, ls=":", label=f"command {abs(result.push_deg):g} deg")
        ax.set_title(f"push {KIND_WORDS[r.kind]}: stroke {stroke.value:.1f} deg, model {r.model.stroke_deg:.1f}")
        ax.set_xlabel("time from the crank's onset [ms]")
        ax.set_ylabel("crank from rest, the push's way [deg]")
        ax.legend(fontsize=8, loc="best")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def write_outputs(result: StrokeResult, csv_path: Path | None = None, plot_path: Path | None = None,
                  force: bool = False) -> list[Path]:
    """Write the CSV and the plot asked for.

    Parameters
    ----------
    result : StrokeResult
    csv_path, plot_path : Path, optional
        Where to write each (None: not written).
    force : bool
        Replace an existing plot that is not one of this toolkit's figures.

    Returns
    -------
    list of Path
        The files written, in order.
    """
    written = []
    if csv_path is not None:
        atomic_write_text(csv_path, angle_csv(result))
        written.append(csv_path)
    if plot_path is not None:
        written.append(save_png(stroke_figure(result), plot_path, force=force, option="--plot"))
    return written


__all__ = ["COLUMNS", "angle_csv", "stroke_figure", "write_outputs"]
