"""The report's tornado: each uncertain value's -/+2 sd effect on a configuration's first hop's
nose rise and its distance (:mod:`locust.sim.explain`), largest first, one row of panels per
configuration; the explanation's words go in the caption.
"""

from __future__ import annotations

import math

from ..plotting import png_bytes, pyplot
from ..sim.explain import Explanation
from ..tables import label, quantity

MM = 1000.0
BARS = 8          # values drawn per panel (the JSON has every one)
LOW, HIGH = "#1f77b4", "#d62728"   # the value at -2 sd, at +2 sd


def _draw(ax, expl: Explanation, figure: str, title: str) -> None:
    bars = [b for b in expl.tornado if math.isfinite(b.swing(figure))]
    bars.sort(key=lambda b: b.swing(figure), reverse=True)
    bars = bars[:BARS][::-1]
    base = getattr(expl.nominal, figure) * MM
    for i, b in enumerate(bars):
        low = getattr(b.low, figure) * MM - base
        high = getattr(b.high, figure) * MM - base
        ax.barh(i, low, color=LOW, height=0.7)
        ax.barh(i, high, color=HIGH, height=0.7, alpha=0.8)
    ax.set_yticks(range(len(bars)), [f"{label(b.key)} (sd {quantity(b.key, b.sd, 2)})" for b in bars], fontsize=8)
    ax.axvline(0, color="k", lw=0.8)
    ax.set_xlabel(f"{title}: change from {base:.1f} mm, mm")
    if not bars:
        ax.text(0.5, 0.5, "no uncertain value", ha="center", va="center", transform=ax.transAxes)


def tornado_figure(explanations: dict[str, Explanation]) -> bytes:
    """One row per configuration: the nose-rise and the distance tornado.

    Parameters
    ----------
    explanations : dict of str to Explanation
        Per configuration's label, its explanation.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    plt = pyplot()
    n = max(1, len(explanations))
    fig, axes = plt.subplots(n, 2, figsize=(11, 3.2 * n), squeeze=False)
    for row, (name, expl) in zip(axes, explanations.items()):
        _draw(row[0], expl, "nose_rise_m", f"{name}, first hop's nose rise")
        _draw(row[1], expl, "distance_m", f"{name}, distance")
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in (LOW, HIGH)]
    fig.legend(handles, ["value at -2 sd", "value at +2 sd"], loc="lower center", ncol=2, frameon=False)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    return png_bytes(fig)


def tornado_caption(explanations: dict[str, Explanation]) -> str:
    """The figure's caption: what the bars are, and each configuration's explanation in words.

    Parameters
    ----------
    explanations : dict of str to Explanation

    Returns
    -------
    str
    """
    text = ("Each uncertain value of the robot file moved alone to -2 sd (blue) and +2 sd (red), the others "
            "held: the change of the first hop's nose rise and of the run's distance from the robot's own, in mm, "
            "largest first (locust sim --explain). ")
    return text + " ".join(f"{name}: {'; '.join(e.words)}." for name, e in explanations.items())


__all__ = ["tornado_caption", "tornado_figure"]
