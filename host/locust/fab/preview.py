"""PNG previews: the cut pattern, and each layer of the stack (as designed, in mm)."""

from __future__ import annotations

from ..plotting import png_bytes, pyplot
from .export import polygons
from .laminate import Laminate

MATERIAL_COLOURS = {"rigid": "#e74c3c", "adhesive": "#f39c12", "flexible": "#3498db"}


def _fill(ax, geom, colour, alpha=0.6, edge="black", label=None):
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MplPath

    for i, poly in enumerate(polygons(geom)):
        verts, codes = [], []
        for ring in [poly.exterior, *poly.interiors]:
            pts = list(ring.coords)
            verts += pts
            codes += [MplPath.MOVETO] + [MplPath.LINETO] * (len(pts) - 2) + [MplPath.CLOSEPOLY]
        ax.add_patch(PathPatch(MplPath(verts, codes), facecolor=colour, edgecolor=edge, lw=0.6,
                               alpha=alpha, label=label if i == 0 else None))


def _frame(ax, lam: Laminate, title: str) -> None:
    from .laminate import sheet_bounds

    x0, y0, x1, y1 = sheet_bounds(lam)
    pad = 0.03 * max(x1 - x0, y1 - y0)
    ax.set_xlim(x0 - pad, x1 + pad)
    ax.set_ylim(y0 - pad, y1 + pad)
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")


def cut_pattern_png(lam: Laminate) -> bytes:
    """The cut pattern as a PNG: body, hinge cut-outs, holes, slits, support web and alignment holes [mm].

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    bytes
        The PNG file.
    """
    plt = pyplot()

    d = lam.design
    fig, ax = plt.subplots(figsize=(10, 4))
    _fill(ax, lam.support_web, "#bbbbbb", 0.5, label="support web")
    _fill(ax, d.body, "#3498db", 0.25, edge="#1f4e79", label="body")
    _fill(ax, d.hinge_union(), "#e74c3c", 0.8, label="hinge cut-outs")
    _fill(ax, d.hole_union(), "white", 1.0, label="holes")
    for hole in lam.alignment_holes:
        _fill(ax, hole, "black", 0.8)
    ax.plot([], [], "ko", label="alignment holes")
    for i, s in enumerate(d.slits):
        xs, ys = s.xy
        ax.plot(xs, ys, color="#8e44ad", lw=1.2, label="slits" if i == 0 else None)
    _frame(ax, lam, f"cut pattern: {d.source}")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    return png_bytes(fig, dpi=130)


def layers_png(lam: Laminate) -> bytes:
    """Each layer of the stack as a PNG panel, oriented as cut, with its material and area [mm^2].

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    bytes
        The PNG file.
    """
    plt = pyplot()

    from .laminate import sheet_bounds

    n = len(lam.layers)
    x0, y0, x1, y1 = sheet_bounds(lam)
    cols = 1 if (x1 - x0) > 2.5 * (y1 - y0) else min(3, n)      # long strips one above another
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(9 if cols == 1 else 4 * cols, (2.2 if cols == 1 else 4) * rows),
                             squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax, layer in zip(axes.flat, lam.layers):
        _fill(ax, lam.oriented(layer.part, layer), MATERIAL_COLOURS[layer.spec.material], 0.7)
        for hole in lam.alignment_holes:
            _fill(ax, hole, "black", 0.8)
        mirror = ", mirrored" if layer.spec.mirror else ""
        _frame(ax, lam, f"{layer.spec.name} ({layer.spec.material}{mirror}): {layer.area_mm2:.2f} mm²")
    fig.tight_layout()
    return png_bytes(fig, dpi=130)


def preview_files(lam: Laminate) -> dict[str, bytes]:
    """Both previews by file name.

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    dict of str to bytes
        ``cut_pattern.png`` and ``laminate_layers.png``.
    """
    return {"cut_pattern.png": cut_pattern_png(lam), "laminate_layers.png": layers_png(lam)}
