"""Laminates from the public course drawings (``../shared/data/dxf``) against an
independent truth: the shoelace formula, or point sampling on a grid with matplotlib's
point-in-polygon, from raw vertices read with plain ezdxf. The truth shares no code with
locust.fab (no shapely, no chaining, no unit table), so agreement means the reader and
the laminate got the geometry right."""

from __future__ import annotations

import ezdxf
import numpy as np
import pytest
from matplotlib.path import Path as MplPath

from locust.fab import laminate
from locust.fab.design import design_from_drawing
from locust.fab.dxf_read import read_drawing


def shoelace_mm2(points) -> float:
    p = np.asarray(points, float)
    x, y = p[:, 0], p[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2)


def sampled_area_mm2(include, exclude=(), strips=(), h_mm: float = 0.05) -> float:
    """Area inside any ``include`` polygon, outside every ``exclude`` polygon and outside
    every strip ``(a, b, width)`` (a segment widened with flat ends): one random point in
    each ``h_mm`` cell (stratified sampling, seeded)."""
    pts = np.vstack([np.asarray(p, float) for p in include])
    (x0, y0), (x1, y1) = pts.min(0), pts.max(0)
    # cells tile [x0, x0 + n h] >= [x0, x1]: the last row and column are never dropped
    xs = x0 + (np.arange(int(np.ceil((x1 - x0) / h_mm))) + 0.5) * h_mm
    ys_all = y0 + (np.arange(int(np.ceil((y1 - y0) / h_mm))) + 0.5) * h_mm
    inc = [MplPath(np.asarray(p, float)) for p in include]
    exc = [MplPath(np.asarray(p, float)) for p in exclude]
    count = 0
    rng = np.random.default_rng(8)
    for ys in np.array_split(ys_all, 16):
        gx, gy = np.meshgrid(xs, ys)
        # one point a cell, uniformly placed in it (stratified): a straight edge along a
        # grid row would otherwise gain or lose the whole row
        P = np.column_stack([gx.ravel(), gy.ravel()]) + rng.uniform(-h_mm / 2, h_mm / 2, (gx.size, 2))
        inside = np.zeros(len(P), bool)
        for path in inc:
            inside |= path.contains_points(P)
        for path in exc:
            inside &= ~path.contains_points(P)
        for a, b, width in strips:
            a, b = np.asarray(a, float), np.asarray(b, float)
            length = float(np.hypot(*(b - a)))
            u = (b - a) / length
            rel = P - a
            along, across = rel @ u, np.abs(rel @ np.array([-u[1], u[0]]))
            inside &= ~((along >= 0) & (along <= length) & (across <= width / 2))
        count += int(inside.sum())
    return count * h_mm * h_mm


# -- the drawings ------------------------------------------------------------------------
HINGE_W_MM = 1.0


def _raw(path, scale):
    """Raw vertices by layer, read with plain ezdxf: closed polylines as drawn, LINEs as
    segments (in file order)."""
    out = {"poly": {}, "lines": {}}
    for e in ezdxf.readfile(path).modelspace():
        if e.dxftype() == "LWPOLYLINE":
            pts = np.array(list(e.get_points("xy")), float) * scale
            out["poly"].setdefault(e.dxf.layer, []).append(pts)
        elif e.dxftype() == "LINE":
            seg = (np.array(e.dxf.start.vec2) * scale, np.array(e.dxf.end.vec2) * scale)
            out["lines"].setdefault(e.dxf.layer, []).append(seg)
    return out


def _areas(path, **kw):
    design = design_from_drawing(read_drawing(path, **kw), hinge_width_mm=HINGE_W_MM)
    lam = laminate.build(design)
    return design, {L.spec.name: L.area_mm2 for L in lam.layers}


def test_five_bar_mm_areas_match_the_drawing(shared_data):
    path = shared_data / "dxf" / "five_bar.dxf"
    raw = _raw(path, 1.0)
    body, hole = raw["poly"]["body"][0], raw["poly"]["holes"][0]
    flexible = shoelace_mm2(body) - shoelace_mm2(hole)
    assert flexible == pytest.approx(7600.0, abs=1e-6)          # by hand: 7950 - 350
    strips = [(a, b, HINGE_W_MM) for a, b in raw["lines"]["joints"]]
    rigid = sampled_area_mm2([body], [hole], strips, h_mm=0.05)
    design, areas = _areas(path)
    assert design.units == "mm"
    assert areas["flexible"] == pytest.approx(flexible, rel=1e-6)
    assert areas["rigid_top"] == pytest.approx(rigid, rel=5e-4)
    assert areas["rigid_top"] < flexible - 250                   # five 1 mm cut-outs, ~55 mm each
    assert len(design.hinges) == 5 and len(design.slits) == 1 and design.ignored_layers == ("bridge",)


def test_laminate_leg_flat_six_touching_outlines_join(shared_data):
    path = shared_data / "dxf" / "laminate_leg_flat.dxf"
    raw = _raw(path, 1.0)
    # the six body outlines tile a 105 x 30 mm strip; seven 10 mm fold lines inside it
    assert sum(shoelace_mm2(p) for p in raw["poly"]["body"]) == pytest.approx(105 * 30, abs=1e-3)
    design, areas = _areas(path)
    assert design.body.geom_type == "Polygon"
    assert areas["flexible"] == pytest.approx(3150.0, rel=1e-6)
    joints = raw["lines"]["joints"]
    removed = sum(float(np.hypot(*(b - a))) for a, b in joints) * HINGE_W_MM
    assert removed == pytest.approx(70.0, abs=1e-6)
    assert areas["rigid_top"] == pytest.approx(3150.0 - removed, rel=1e-6)
    assert len(design.slits) == 2


def test_flipper_inches_chained_lines(shared_data):
    path = shared_data / "dxf" / "flipper.dxf"
    raw = _raw(path, 25.4)
    # body: a pentagon and a quad (LWPOLYLINEs) and a pentagon of 5 loose LINEs, overlapping
    chained = np.array([a for a, _ in raw["lines"]["body"]])
    body = raw["poly"]["body"] + [chained]
    hole = raw["poly"]["holes"]
    folds = [(a, b, HINGE_W_MM) for layer in ("hinge_mountain", "hinge_valley") for a, b in raw["lines"][layer]]
    flexible = sampled_area_mm2(body, hole, h_mm=0.1)
    rigid = sampled_area_mm2(body, hole, folds, h_mm=0.1)
    design, areas = _areas(path)
    assert design.units == "in" and design.units_from == "$INSUNITS"
    assert (design.bounds_mm[2] - design.bounds_mm[0]) == pytest.approx((9.9175 - 2.0700) * 25.4, abs=0.01)
    assert areas["flexible"] == pytest.approx(flexible, rel=5e-4)
    assert areas["rigid_top"] == pytest.approx(rigid, rel=5e-4)
    assert [h.kind for h in design.hinges] == ["fold"] * 5
