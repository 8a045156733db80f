"""The report's figures (matplotlib, Agg), each drawn on given axes so the HTML page and the
PNG dashboard share them. Measured: solid, coloured by configuration; predicted: dashed or
hatched. An invalid simulation is written in its panel, never drawn as a prediction; a run that
went over onto its back is written as such where its jump would be, never drawn as a jump.
Lengths are in millimetres on every axis; legends stand outside the axes, never over the data.
"""

from __future__ import annotations

import math

import numpy as np

from ..plotting import png_bytes, pyplot
from ..sweep.design import axis_scale
from ..trials.configs import Configuration
from .compare import Comparison, ending_of, stat
from .landscape import Landscape, design_value

COLOURS = {"small": "#1f77b4", "medium": "#ff7f0e", "large": "#2ca02c"}   # the seed dashboard's
OTHER = ["#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"]
MM = 1000.0   # hop figures in mm, as every command prints them
OVER_COLOUR = "#6a3d9a"   # a run gone over onto its back: the sweep plot's colour for it


def colour(name: str, names: list[str]) -> str:
    """A configuration's colour: the seed dashboard's for small, medium and large, others in turn.

    Parameters
    ----------
    name : str
        The configuration.
    names : list of str
        Every configuration of the report, in order.

    Returns
    -------
    str
        A matplotlib colour (``#rrggbb``).
    """
    if name in COLOURS:
        return COLOURS[name]
    others = [n for n in names if n not in COLOURS]
    return OTHER[others.index(name) % len(OTHER)] if name in others else OTHER[0]


def legend_outside(ax, below: bool = False, **kw) -> None:
    """The axes' legend beside them on the right (or ``below`` them), off the data.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The axes whose labelled artists are listed.
    below : bool
        Under the axes in two columns instead of on the right.
    **kw
        Passed to ``Axes.legend`` (``fontsize`` defaults to 7).
    """
    place = (dict(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2) if below
             else dict(loc="upper left", bbox_to_anchor=(1.02, 1.0)))
    ax.legend(frameon=False, fontsize=kw.pop("fontsize", 7), borderaxespad=0.0, **place, **kw)


def _label(c: Comparison) -> str:
    return c.config[:1].upper() + c.config[1:]


def _invalid_note(ax, c: Comparison) -> None:
    reasons = "; ".join(c.prediction.result.reasons)[:90]
    ax.text(0.02, 0.04, f"simulation INVALID: {reasons}", transform=ax.transAxes, fontsize=7, color="#b00020",
            wrap=True)


def draw_traces(ax, c: Comparison, names: list[str], which: str, spread=None, before=None) -> None:
    """Nose forward travel (``which='x'``) or height (``'y'``) against time, one configuration;
    with a :class:`.spread.Spread` the draws' mean +- 1 sd as a band, with ``before`` (a
    :class:`.predict.Prediction` on the robot before a fit) its trace dotted.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw, in mm against seconds since the first push.
    c : Comparison
        The configuration's comparison.
    names : list of str
        Every configuration, for the colours.
    which : str
        ``x`` (forward) or ``y`` (up).
    spread : Spread, optional
        The prediction's spread over draws.
    before : Prediction, optional
        The prediction on the robot before a fit.
    """
    col = colour(c.config, names)
    for i, m in enumerate(c.trials):
        ax.plot(m.trace.t_s, getattr(m.trace, f"{which}_m") * MM, color=col, lw=1.4, alpha=0.85,
                label="measured" if i == 0 else None)
    p = c.prediction
    if spread is not None:
        mean, sd = getattr(spread, f"{which}_mean_m"), getattr(spread, f"{which}_sd_m")
        ax.fill_between(spread.t_s, (mean - sd) * MM, (mean + sd) * MM, color="0.55", alpha=0.35, lw=0,
                        label=f"predicted ±1 sd ({spread.n_valid} draws)")
    if before is not None and before.trace is not None:
        ax.plot(before.trace.t_s, getattr(before.trace, f"{which}_m") * MM, ":", color="#b00020", lw=1.2,
                label="predicted before the fit")
    if p.trace is not None:
        ax.plot(p.trace.t_s, getattr(p.trace, f"{which}_m") * MM, "--", color="black", lw=1.2, label="predicted")
    else:
        _invalid_note(ax, c)
    if which == "y":
        _say_over(ax, c)
    for k in range(c.cycles + 1):
        ax.axvline(k * c.period_s, color="#bbbbbb", lw=0.6, zorder=0)
    ax.grid(True, ls=":", alpha=0.5)


def _say_over(ax, c: Comparison) -> None:
    """Write in the axes' lower right which side went over, and at which hop."""
    said = _over_words(c)
    if said:
        ax.text(0.98, 0.04, said, transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color=OVER_COLOUR,
                bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.85, "pad": 1.5})


def _over_words(c: Comparison) -> str:
    """Which side went over onto its back, and at which hop (empty when neither did)."""
    said = []
    end = c.predicted_ending
    if end is not None and end.over_hop is not None:
        said.append(f"predicted: goes over at hop {end.over_hop}")
    hops = sorted({ending_of(m).over_hop for m in c.trials if ending_of(m).over_hop is not None})
    if hops:
        n = sum(1 for m in c.trials if ending_of(m).over_hop is not None)
        said.append(f"measured: goes over at hop {', '.join(map(str, hops))}"
                    + (f" ({n} of {len(c.trials)} trials)" if len(c.trials) > 1 else ""))
    return "\n".join(said)


def overlay_figure(comps: list[Comparison], spreads: dict | None = None, befores: dict | None = None) -> bytes:
    """Displacement (top row) and height (bottom row) against time, one column per configuration.

    Parameters
    ----------
    comps : list of Comparison
        The configurations.
    spreads : dict of str to Spread, optional
        Per configuration, a band of the draws.
    befores : dict of str to Prediction, optional
        Per configuration, the prediction before a fit.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    plt = pyplot()
    names = [c.config for c in comps]
    spreads, befores = spreads or {}, befores or {}
    fig, axes = plt.subplots(2, len(comps), figsize=(4.2 * len(comps), 6.2), squeeze=False, sharex="col")
    for j, c in enumerate(comps):
        for row, which in enumerate("xy"):
            draw_traces(axes[row, j], c, names, which, spreads.get(c.config), befores.get(c.config))
        axes[0, j].set_title(f"{_label(c)}: marker forward travel", loc="left", fontsize=10)
        axes[1, j].set_title(f"{_label(c)}: marker height", loc="left", fontsize=10)
        axes[1, j].set_xlabel("time since first push (s)")
        legend_outside(axes[1, j], below=True, fontsize=8)
    axes[0, 0].set_ylabel("forward from where it stood (mm)")
    axes[1, 0].set_ylabel("above standing (mm)")
    fig.suptitle("Marker travel and height vs time: measured (solid) and predicted (dashed)", fontsize=11)
    fig.tight_layout()
    return png_bytes(fig)


def draw_bars(ax, comps: list[Comparison], what: str) -> None:
    """Measured (mean, +-1 sd across trials) beside predicted, per configuration. A jump is
    only a hop that came back down: where every trial (or the simulation) went over in its first
    hop, the bar's place says so instead of drawing its resting height.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw, in mm.
    comps : list of Comparison
        The configurations.
    what : str
        ``jump`` (highest marker apex in a hop that came back down) or anything else for the
        marker's travel per hop (both sides the marker's: like with like).
    """
    names = [c.config for c in comps]
    x = np.arange(len(comps))
    w = 0.38
    if what == "jump":
        meas = [c.jump for c in comps]
        pred = [c.predicted_jump_m for c in comps]
    else:
        meas = [c.marker_travel_per_hop for c in comps]
        pred = [c.predicted_marker_travel_per_hop_m for c in comps]
    cols = [colour(n, names) for n in names]
    heights = [s.mean * MM if s.n else 0.0 for s in meas]
    errs = [(s.std or 0.0) * MM for s in meas]
    ax.bar(x - w / 2, heights, w, color=cols, yerr=errs, capsize=4, label="measured (mean ± 1 sd)", zorder=3)
    pv = [p * MM if math.isfinite(p) else 0.0 for p in pred]
    ax.bar(x + w / 2, pv, w, color="white", edgecolor=cols, hatch="//", lw=1.2, label="predicted", zorder=3)
    for i, (c, s, p) in enumerate(zip(comps, meas, pred)):
        if s.n:
            ax.annotate(f"{s.mean * MM:.1f}" + (f"±{s.std * MM:.1f}" if s.std is not None else ""),
                        (x[i] - w / 2, heights[i]), xytext=(0, 3), textcoords="offset points",
                        ha="center", fontsize=7)
        elif what == "jump" and c.trials:
            ax.annotate(_over_first("measured", [ending_of(m).over_hop for m in c.trials]), (x[i] - w / 2, 0),
                        xytext=(0, 3), textcoords="offset points", ha="center", va="bottom", fontsize=7,
                        rotation=90, color=OVER_COLOUR)
        ending = c.predicted_ending
        if math.isfinite(p):
            text, colour_ = f"{p * MM:.1f}", "black"
        elif ending is None:
            text, colour_ = "invalid", "#b00020"
        else:
            text, colour_ = _over_first("predicted", [ending.over_hop]), OVER_COLOUR
        ax.annotate(text, (x[i] + w / 2, pv[i]), xytext=(0, 3), textcoords="offset points", ha="center",
                    va="bottom", fontsize=7, color=colour_, rotation=0 if math.isfinite(p) or ending is None else 90)
    ax.set_xticks(x, [_label(c) for c in comps])
    if not any(heights) and not any(pv):     # nothing to draw but words: give them room above zero
        ax.set_ylim(0.0, 10.0)
    ax.axhline(0, color="black", lw=0.6)
    ax.yaxis.grid(True, ls="--", alpha=0.5, zorder=0)
    legend_outside(ax, fontsize=8)


def _over_first(who: str, over_hops: list) -> str:
    """What stands where a jump bar would: the run went over in its first hop (no jump)."""
    return f"{who}: goes over at hop {min(h for h in over_hops if h is not None)}, no jump" \
        if any(h is not None for h in over_hops) else f"{who}: no hop covered"


def bars_figure(comps: list[Comparison], what: str) -> bytes:
    """Measured against predicted jump height or distance per hop, as bars.

    Parameters
    ----------
    comps : list of Comparison
        The configurations.
    what : str
        ``jump`` or ``distance``.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(max(5.0, 2.2 * len(comps)), 4.0))
    draw_bars(ax, comps, what)
    if what == "jump":
        ax.set_title("Jump: highest marker point above standing, in a hop that came back down", loc="left",
                     fontsize=10)
        ax.set_ylabel("height (mm)")
    else:
        ax.set_title("Marker travel per hop", loc="left", fontsize=10)
        ax.set_ylabel("marker travel per hop (mm)")
    fig.tight_layout()
    return png_bytes(fig)


def hops_figure(comps: list[Comparison], spreads: dict | None = None) -> bytes:
    """Per-hop marker travel and apex, every trial, against the prediction (with ±1 sd error
    bars over the draws of a :class:`.spread.Spread`); an apex only for a hop that came back
    down (a hop that went over, and each one after it, is no jump).

    Parameters
    ----------
    comps : list of Comparison
        The configurations.
    spreads : dict of str to Spread, optional
        Per configuration, the error bars of the prediction.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    plt = pyplot()
    names = [c.config for c in comps]
    spreads = spreads or {}
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for c in comps:
        col = colour(c.config, names)
        ending = c.predicted_ending
        for key, field, ax in (("distance", "marker_travel", axes[0]), ("apex", "apex", axes[1])):
            xs = [r.hop for r in c.rows]
            ys = [getattr(r, f"measured_{field}_m") * MM for r in c.rows]
            ax.plot(xs, ys, "o", color=col, ms=5, alpha=0.8, label=f"{_label(c)} measured")
            if ending is not None:
                # the simulated marker's hops, cut as the track's are; an apex only where it came back down
                shown = [h for h in c.prediction.hops if key == "distance" or ending.came_down(h.hop)]
                px, pv = [h.hop for h in shown], [getattr(h, f"{key}_m") for h in shown]
                sp = spreads.get(c.config)
                err = None if sp is None else [getattr(sp, f"hop_{key}_sd_m")[h.hop - 1] * MM for h in shown]
                ax.errorbar(px, [v * MM for v in pv], yerr=err, fmt="--", color=col, lw=1.2, capsize=3,
                            label=f"{_label(c)} predicted" + (" ±1 sd" if err else ""))
        _say_over(axes[1], c)
    axes[0].set_title("Marker travel in each hop", loc="left", fontsize=10)
    axes[1].set_title("Marker apex of each hop that came back down", loc="left", fontsize=10)
    if not axes[1].lines:    # no hop came back down: the axes still read as hops and mm
        axes[1].set_xlim(0.5, max(c.cycles for c in comps) + 0.5)
        axes[1].set_ylim(0.0, 10.0)
    for ax, unit in zip(axes, ("marker travel (mm)", "apex above standing (mm)")):
        ax.set_xlabel("hop")
        ax.set_ylabel(unit)
        ax.grid(True, ls=":", alpha=0.5)
        ax.xaxis.get_major_locator().set_params(integer=True)
    legend_outside(axes[1])
    fig.tight_layout()
    return png_bytes(fig)


def draw_landscape(ax, land: Landscape, comps: list[Comparison], configs: dict[str, Configuration]) -> None:
    """The sweep's distance per hop (``locust sim``'s distance over the cycles) over its first
    axis (a line) or first two axes (colour), designs that go over onto their backs marked as
    such, with each configuration's prediction (the same figure) and measurement (its marker's
    travel per hop, where every trial ended on its feet: then the two are the robot's travel)
    where it sits.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw, distances in mm.
    land : Landscape
        The sweep.
    comps : list of Comparison
        The configurations.
    configs : dict of str to Configuration
        The configurations by name, for their place on the axes.
    """
    names = [c.config for c in comps]
    first = land.names[0]
    k, xlabel = axis_scale(first)
    xs = land.values[first] * k
    hop = land.distance_per_hop_m * MM
    over = land.valid & land.goes_over
    if len(land.names) == 1:
        order = np.argsort(xs)
        ok = (land.valid & ~land.goes_over)[order]
        ax.plot(xs[order][ok], hop[order][ok], "o-", color="#555555", ms=3.5, lw=1.0,
                label=f"simulated designs on their feet ({int(ok.sum())})")
        if over.any():
            ax.plot(xs[over], hop[over], "v", color=OVER_COLOUR, mfc="none", ms=6,
                    label=f"goes over onto its back ({int(over.sum())}): not a hop")
        bad = ~land.valid
        if bad.any():
            ax.plot(xs[bad], np.zeros(bad.sum()), "x", color="#b00020", ms=7, label="invalid (failed audit)")
        for c in comps:
            cfg = configs[c.config]
            xv = design_value(cfg, first) * k
            col = colour(c.config, names)
            ax.axvline(xv, color=col, ls=":", lw=1.0)
            ending = c.predicted_ending
            if ending is not None:   # as the sweep's designs: a run gone over is a triangle, not a hop
                ax.plot([xv], [c.predicted_distance_per_hop_m * MM], "v" if ending.over_hop else "o", mfc="white",
                        mec=col, mew=2, ms=8)
            on_feet = stat([m.marker_travel_per_hop_m for m in c.trials if ending_of(m).over_hop is None])
            if on_feet.n:
                ax.errorbar([xv], [on_feet.mean * MM], yerr=[(on_feet.std or 0.0) * MM], fmt="s",
                            color=col, ms=7, capsize=4,
                            label=f"{_label(c)}: measured ■, predicted {'▽' if ending and ending.over_hop else '○'}")
            else:
                went = " (measured: goes over)" if c.trials else ""
                mark = "▽" if ending is not None and ending.over_hop else "○"
                ax.plot([], [], "v" if mark == "▽" else "o", mfc="white", mec=col,
                        label=f"{_label(c)}: predicted {mark}{went}")
        ax.set_ylabel("distance per hop (mm)")
    else:
        second = land.names[1]
        k2, ylabel = axis_scale(second)
        ys = land.values[second] * k2
        feet = land.valid & ~land.goes_over
        sc = ax.scatter(xs[feet], ys[feet], c=hop[feet], cmap="viridis", s=28)
        ax.figure.colorbar(sc, ax=ax, label="distance per hop (mm)")
        if over.any():
            ax.plot(xs[over], ys[over], "v", color=OVER_COLOUR, mfc="none", ms=6, label="goes over onto its back")
        bad = ~land.valid
        if bad.any():
            ax.plot(xs[bad], ys[bad], "x", color="#b00020", ms=6, label="invalid (failed audit)")
        for c in comps:
            cfg = configs[c.config]
            ax.plot([design_value(cfg, first) * k], [design_value(cfg, second) * k2], "*", ms=14,
                    color=colour(c.config, names), mec="black", label=_label(c))
        ax.set_ylabel(ylabel)
    ax.set_xlabel(xlabel)
    ax.set_title(f"Sweep landscape ({land.designs} designs, {land.cycles} cycles, base {land.base}) "
                 "with the physical designs", loc="left", fontsize=9)
    ax.grid(True, ls=":", alpha=0.5)
    legend_outside(ax)


def landscape_caption(land: Landscape, comps: list[Comparison]) -> str:
    """What :func:`draw_landscape` draws, in words: only marks that are drawn are named.

    Parameters
    ----------
    land : Landscape
        The sweep.
    comps : list of Comparison
        The configurations.

    Returns
    -------
    str
        The caption.
    """
    bad = int((~land.valid).sum())
    over = int((land.valid & land.goes_over).sum())
    went = (f"; {over} design{'s' if over != 1 else ''} going over onto {'their' if over != 1 else 'its'} "
            f"back{'s' if over != 1 else ''}: open triangles" if over else "")
    if len(land.names) == 1:
        text = (f"Simulated distance per hop (locust sim's distance over the {land.cycles} cycles) over the sweep "
                f"in {land.folder}")
        text += (f" ({bad} invalid design{'s' if bad != 1 else ''}, failed audit: red crosses at zero{went})" if bad
                 else f" (every design valid{went})")
        marks = []
        if any(c.prediction.valid for c in comps):
            marks.append("its prediction (open circle)")
        if any(ending_of(m).over_hop is None for c in comps for m in c.trials):
            marks.append("its measurement where every trial ended on its feet (the marker's travel per hop, "
                         "filled square, ±1 sd)")
        text += ", with each physical design's position (dotted line)"
        return text + (", " + " and ".join(marks) if marks else "") + "."
    text = f"Simulated distance per hop (colour) over the sweep in {land.folder}"
    text += (f" ({bad} invalid design{'s' if bad != 1 else ''}, failed audit: red crosses{went})" if bad
             else f" (every design valid{went})")
    return text + ", with each physical design marked by a star."


def landscape_figure(land: Landscape, comps: list[Comparison], configs: dict[str, Configuration]) -> bytes:
    """The sweep landscape with the configurations marked (:func:`draw_landscape`).

    Parameters
    ----------
    land : Landscape
        The sweep.
    comps : list of Comparison
        The configurations.
    configs : dict of str to Configuration
        The configurations by name.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    draw_landscape(ax, land, comps, configs)
    fig.tight_layout()
    return png_bytes(fig)


def draw_timing(ax, comps: list[Comparison]) -> None:
    """Phase start error (measured - commanded, firmware clock) of every run, per phase.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Where to draw, errors in ms.
    comps : list of Comparison
        The configurations; trials without a run record are left out.
    """
    names = [c.config for c in comps]
    drawn = False
    for c in comps:
        for m in (t for t in c.all_trials if t.record is not None):
            errs = [p.error_ms for p in m.record.phases]
            ax.plot(np.arange(1, len(errs) + 1), errs, "o-", ms=3, lw=1, color=colour(c.config, names),
                    label=f"{_label(c)} {m.label}")
            drawn = True
    if not drawn:
        ax.text(0.5, 0.5, "no run records given", transform=ax.transAxes, ha="center", va="center")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.set_xlabel("phase (push, wait, push, ...)")
    ax.set_ylabel("start error (ms)")
    ax.set_title("Firmware timing: phase start, measured - commanded", loc="left", fontsize=10)
    ax.grid(True, ls=":", alpha=0.5)
    if drawn:
        legend_outside(ax)


def timing_figure(comps: list[Comparison]) -> bytes:
    """The firmware timing of every run (:func:`draw_timing`).

    Parameters
    ----------
    comps : list of Comparison
        The configurations.

    Returns
    -------
    bytes
        The figure as PNG.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 3.6))
    draw_timing(ax, comps)
    fig.tight_layout()
    return png_bytes(fig)


def dashboard(comps: list[Comparison], land: Landscape | None, configs: dict[str, Configuration]) -> bytes:
    """One PNG like the seed's dashboard, measured and predicted together.

    Parameters
    ----------
    comps : list of Comparison
        The configurations.
    land : Landscape or None
        The sweep; without one, the distance per hop as bars takes its panel.
    configs : dict of str to Configuration
        The configurations by name.

    Returns
    -------
    bytes
        The dashboard as PNG (100 dpi).
    """
    plt = pyplot()
    names = [c.config for c in comps]
    fig, axes = plt.subplots(2, 2, figsize=(14, 9.5))
    ax = axes[0, 0]
    for c in comps:
        col = colour(c.config, names)
        for i, m in enumerate(c.trials):
            ax.plot(m.trace.t_s, m.trace.x_m * MM, color=col, lw=1.6, alpha=0.85,
                    label=f"{_label(c)} measured" if i == 0 else None)
        if c.prediction.trace is not None:
            ax.plot(c.prediction.trace.t_s, c.prediction.trace.x_m * MM, "--", color=col, lw=1.2,
                    label=f"{_label(c)} predicted")
    ax.set_title("Forward travel of the nose marker", loc="left", fontsize=11)
    ax.set_xlabel("time since first push (s)")
    ax.set_ylabel("forward from where it stood (mm)")
    ax.grid(True, ls=":", alpha=0.5)
    legend_outside(ax, fontsize=8)
    draw_bars(axes[0, 1], comps, "jump")
    axes[0, 1].set_title("Jump: highest marker point above standing, hops that came back down", loc="left",
                         fontsize=11)
    axes[0, 1].set_ylabel("height (mm)")
    if land is not None:
        draw_landscape(axes[1, 0], land, comps, configs)
    else:
        draw_bars(axes[1, 0], comps, "travel")
        axes[1, 0].set_title("Marker travel per hop", loc="left", fontsize=11)
        axes[1, 0].set_ylabel("marker travel per hop (mm)")
    draw_timing(axes[1, 1], comps)
    fig.suptitle("locust: simulation against measurement, " + ", ".join(_label(c) for c in comps), fontsize=13)
    fig.tight_layout()
    return png_bytes(fig, dpi=100)
