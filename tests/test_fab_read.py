"""The DXF reader on synthetic drawings of known area (written here with ezdxf), one per
entity kind it reads, plus units, chaining, gaps, layers and damaged files."""

from __future__ import annotations

import math

import ezdxf
import pytest
from ezdxf.math import rational_bspline_from_arc

from locust.errors import FabError
from locust.fab.design import LayerMap, design_from_drawing, parse_layer_options
from locust.fab.dxf_limits import MAX_EXPANDED_ENTITIES, expanded_count
from locust.fab.dxf_read import read_drawing
from probing import assert_refused_and_unchanged, invoke


def _doc(units=4):
    doc = ezdxf.new("R2010", units=units)
    return doc, doc.modelspace()


def _area(path, **kw):
    return design_from_drawing(read_drawing(path, **kw)).body.area


# Each part lies far from the others; its exact area is beside it.
def _every_kind(msp, layer="body"):
    a = {"layer": layer}
    parts = {}
    msp.add_circle((0, 0), 10, dxfattribs=a)                                      # CIRCLE
    parts["circle"] = math.pi * 100
    # LWPOLYLINE with bulges: a 20 x 10 mm stadium (two half circles, radius 5)
    msp.add_lwpolyline([(100, 0, 0), (120, 0, 1), (120, 10, 0), (100, 10, 1)], format="xyb", close=True, dxfattribs=a)
    parts["stadium"] = 20 * 10 + math.pi * 25
    msp.add_polyline2d([(200, 0), (210, 0), (210, 5), (200, 5)], close=True, dxfattribs=a)   # POLYLINE
    parts["polyline"] = 50.0
    spline = msp.add_spline(dxfattribs=a)                                         # SPLINE: exact circle
    spline.apply_construction_tool(rational_bspline_from_arc(center=(300, 0), radius=4, start_angle=0, end_angle=360))
    parts["spline"] = math.pi * 16
    msp.add_ellipse((400, 0), major_axis=(6, 0), ratio=0.5, dxfattribs=a)        # ELLIPSE 6 x 3
    parts["ellipse"] = math.pi * 18
    # a "D" from one LINE and one ARC, the LINE drawn against the ARC's direction
    msp.add_line((500, 10), (500, 0), dxfattribs=a)
    msp.add_arc((500, 5), 5, -90, 90, dxfattribs=a)
    parts["line+arc"] = math.pi * 25 / 2
    return parts


def test_every_entity_kind_gives_its_exact_area(tmp_path):
    doc, msp = _doc()
    parts = _every_kind(msp)
    doc.saveas(tmp_path / "kinds.dxf")
    design = design_from_drawing(read_drawing(tmp_path / "kinds.dxf"))
    got = sorted(p.area for p in design.body.geoms)
    want = sorted(parts.values())
    assert got == pytest.approx(want, rel=2e-4)          # flattened to 0.001 mm sagitta


@pytest.mark.parametrize("code,mm", [(1, 25.4), (5, 10.0), (6, 1000.0), (4, 1.0)])
def test_units_from_insunits(tmp_path, code, mm):
    doc, msp = _doc(units=code)
    msp.add_lwpolyline([(0, 0), (2, 0), (2, 1), (0, 1)], close=True, dxfattribs={"layer": "plate"})
    doc.saveas(tmp_path / "u.dxf")
    assert _area(tmp_path / "u.dxf") == pytest.approx(2 * mm * mm, rel=1e-12)


def test_unitless_is_read_as_mm_and_says_so_and_units_override(tmp_path):
    doc, msp = _doc(units=0)
    msp.add_lwpolyline([(0, 0), (2, 0), (2, 1), (0, 1)], close=True, dxfattribs={"layer": "plate"})
    doc.saveas(tmp_path / "u.dxf")
    drawing = read_drawing(tmp_path / "u.dxf")
    assert drawing.units == "mm" and drawing.units_from.startswith("assumed")
    assert _area(tmp_path / "u.dxf", units="cm") == pytest.approx(200.0)


def _square_of_lines(msp, x0, y0, side, gap=0.0, layer="body"):
    p = [(x0, y0), (x0 + side, y0), (x0 + side, y0 + side), (x0, y0 + side)]
    for i in range(4):
        a, b = p[i], p[(i + 1) % 4]
        if i == 3:
            b = (b[0], b[1] + gap)           # the last LINE stops short of the start
        msp.add_line(a, b, dxfattribs={"layer": layer})


def test_open_outline_names_the_gap_and_gap_tol_closes_it(tmp_path):
    doc, msp = _doc()
    _square_of_lines(msp, 0, 0, 50, gap=0.3)
    doc.saveas(tmp_path / "gap.dxf")
    with pytest.raises(FabError) as err:
        _area(tmp_path / "gap.dxf")
    msg = err.value.message
    assert "not closed" in msg and "gap of 0.3 mm" in msg
    assert "(0.000, 0.300)" in msg and "(0.000, 0.000)" in msg and "LINE #" in msg
    assert "--gap-tol-mm 0.45" in err.value.hint
    assert _area(tmp_path / "gap.dxf", gap_tol_mm=0.45) == pytest.approx(2500.0, rel=1e-9)


def test_missing_body_layer_lists_the_layers(tmp_path):
    doc, msp = _doc()
    _square_of_lines(msp, 0, 0, 50, layer="Outline_A")
    doc.saveas(tmp_path / "m.dxf")
    with pytest.raises(FabError) as err:
        _area(tmp_path / "m.dxf")
    assert "no body outline" in err.value.message and "Outline_A" in err.value.message
    assert "--layer body=" in err.value.hint
    lm = LayerMap().with_overrides(parse_layer_options(["body=outline_*"]))
    assert design_from_drawing(read_drawing(tmp_path / "m.dxf"), lm).body.area == pytest.approx(2500.0)
    with pytest.raises(FabError):
        parse_layer_options(["body"])
    with pytest.raises(FabError):
        LayerMap().with_overrides({"bodies": ["x"]})


def test_nested_loops_alternate_material_and_hole(tmp_path):
    doc, msp = _doc()
    for side, off in ((100, 0), (40, 30), (10, 45)):
        msp.add_lwpolyline([(off, off), (off + side, off), (off + side, off + side), (off, off + side)],
                           close=True, dxfattribs={"layer": "plate"})
    doc.saveas(tmp_path / "n.dxf")
    assert _area(tmp_path / "n.dxf") == pytest.approx(100 * 100 - 40 * 40 + 10 * 10)


def test_block_reference_is_expanded_with_its_scale(tmp_path):
    doc, msp = _doc()
    blk = doc.blocks.new("PART")
    blk.add_lwpolyline([(0, 0), (10, 0), (10, 5), (0, 5)], close=True)   # layer 0: takes the insert's
    msp.add_blockref("PART", (100, 100), dxfattribs={"layer": "body", "xscale": 2, "yscale": 3})
    doc.saveas(tmp_path / "b.dxf")
    assert _area(tmp_path / "b.dxf") == pytest.approx(50 * 6)


def test_hinge_layers_slot_and_fold(tmp_path):
    doc, msp = _doc()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 30), (0, 30)], close=True, dxfattribs={"layer": "plate"})
    msp.add_line((40, -5), (40, 35), dxfattribs={"layer": "hinge_valley"})     # fold line, past the edges
    msp.add_lwpolyline([(69, 5), (71, 5), (71, 25), (69, 25)], close=True, dxfattribs={"layer": "hinge_2"})
    msp.add_circle((20, 15), 2, dxfattribs={"layer": "holes"})
    msp.add_line((85, 5), (85, 25), dxfattribs={"layer": "cuts"})
    doc.saveas(tmp_path / "h.dxf")
    design = design_from_drawing(read_drawing(tmp_path / "h.dxf"), hinge_width_mm=1.5)
    fold, slot = design.hinges
    assert (fold.kind, slot.kind) == ("fold", "slot")
    assert fold.area_mm2 == pytest.approx(1.5 * 30)          # clipped to the body
    assert slot.area_mm2 == pytest.approx(2 * 20)
    assert sum(h.area for h in design.holes) == pytest.approx(math.pi * 4, rel=2e-4)
    assert len(design.slits) == 1 and design.slits[0].length == pytest.approx(20)


def test_garbage_and_truncated_files_are_clear_errors(tmp_path):
    (tmp_path / "g.dxf").write_bytes(bytes(range(256)) * 8)
    with pytest.raises(FabError, match="not a readable DXF"):
        read_drawing(tmp_path / "g.dxf")
    doc, msp = _doc()
    _square_of_lines(msp, 0, 0, 50)
    doc.saveas(tmp_path / "full.dxf")
    text = (tmp_path / "full.dxf").read_text()
    (tmp_path / "t.dxf").write_text(text[: len(text) // 2])
    with pytest.raises(FabError, match="not a readable DXF") as err:
        read_drawing(tmp_path / "t.dxf")
    assert "--recover" in err.value.hint
    (tmp_path / "e.dxf").write_bytes(b"")
    with pytest.raises(FabError, match="empty"):
        read_drawing(tmp_path / "e.dxf")
    with pytest.raises(FabError, match="no such file"):
        read_drawing(tmp_path / "missing.dxf")


def test_self_crossing_outline_is_an_error(tmp_path):
    doc, msp = _doc()
    msp.add_lwpolyline([(0, 0), (10, 10), (10, 0), (0, 10)], close=True, dxfattribs={"layer": "body"})
    doc.saveas(tmp_path / "x.dxf")
    with pytest.raises(FabError, match="crosses itself"):
        _area(tmp_path / "x.dxf")


def test_nested_block_references_are_counted_and_refused_before_expanding(tmp_path):
    """8 levels of 10 references to a block of one LINE would be 10^8 lines (the expansion ran
    for hours); they are counted from the block table first, so the refusal is immediate."""
    doc, msp = _doc()
    doc.blocks.new("L0").add_line((0, 0), (1, 0))
    for level in range(1, 9):
        blk = doc.blocks.new(f"L{level}")
        for i in range(10):
            blk.add_blockref(f"L{level - 1}", (2 * i, 0))
    msp.add_blockref("L8", (0, 0), dxfattribs={"layer": "plate"})
    msp.add_blockref("L2", (0, 0), dxfattribs={"layer": "plate"})
    doc.saveas(tmp_path / "nest.dxf")
    doc = ezdxf.readfile(tmp_path / "nest.dxf")
    # L2 alone: itself, 10 L1 references, 100 L0 references, 100 lines = 211 entities
    assert expanded_count(doc, [e for e in doc.modelspace() if e.dxf.name == "L2"]) == 211
    assert expanded_count(doc, doc.modelspace()) > MAX_EXPANDED_ENTITIES
    assert_refused_and_unchanged(tmp_path, ["fab", tmp_path / "nest.dxf"], "more than 50,000 entities")


def _plate_with(tmp_path, draw):
    doc, msp = _doc()
    msp.add_lwpolyline([(0, 0), (100, 0), (100, 30), (0, 30)], close=True, dxfattribs={"layer": "plate"})
    draw(msp)
    doc.saveas(tmp_path / "p.dxf")
    return tmp_path / "p.dxf"


def test_a_hinge_outside_the_body_or_of_no_length_is_refused_with_its_position(tmp_path):
    outside = _plate_with(tmp_path, lambda m: m.add_line((150, -5), (150, 35), dxfattribs={"layer": "hinge_1"}))
    assert_refused_and_unchanged(tmp_path, ["fab", outside], "hinge LINE #", "(150.000, -5.000) mm",
                                 "does not cross the body", "x 0.000 to 100.000")
    point = _plate_with(tmp_path, lambda m: m.add_line((40, 10), (40, 10), dxfattribs={"layer": "hinge_1"}))
    assert_refused_and_unchanged(tmp_path, ["fab", point], "(40.000, 10.000) mm", "has no length")
    dot = _plate_with(tmp_path, lambda m: m.add_circle((60, 20), 0, dxfattribs={"layer": "hinge_1"}))
    assert_refused_and_unchanged(tmp_path, ["fab", dot], "CIRCLE #", "(60.000, 20.000) mm", "has no length")
    # a closed hinge "loop" of two vertices is a fold line there and back, used as one
    design = design_from_drawing(read_drawing(_plate_with(
        tmp_path, lambda m: m.add_lwpolyline([(40, -5), (40, 35)], close=True, dxfattribs={"layer": "hinge_1"}))))
    assert [h.kind for h in design.hinges] == ["fold"] and design.hinges[0].area_mm2 == pytest.approx(30.0)


def test_overlapping_outlines_are_joined_and_said_so_a_hole_in_the_overlap_stays_a_hole(tmp_path):
    """Two 100 mm squares overlapping by half, a 30 mm square hole inside the overlap: the
    material is their union (15000 mm2) less the hole (900 mm2); counted by nesting alone the
    hole lies inside two outlines and would be material again."""
    doc, msp = _doc()
    for x0, y0, side in ((0, 0, 100), (50, 0, 100), (60, 30, 30)):
        msp.add_lwpolyline([(x0, y0), (x0 + side, y0), (x0 + side, y0 + side), (x0, y0 + side)],
                           close=True, dxfattribs={"layer": "plate"})
    doc.saveas(tmp_path / "o.dxf")
    design = design_from_drawing(read_drawing(tmp_path / "o.dxf"))
    assert design.body.area == pytest.approx(15000 - 900)
    assert len(design.joined) == 1 and "overlap by 5000 mm2 at x 50.000 to 100.000, y 0.000 to 100.000" \
        in design.joined[0]
    res = invoke(["fab", tmp_path / "o.dxf"])
    assert res.exit_code == 0 and "overlapping outlines joined (union)" in res.output


def test_an_outline_drawn_many_times_over_itself_is_cut_once(tmp_path):
    """200 copies of one 50 mm square of LINEs, stacked (a block inserted 200 times at one
    place, as a careless copy leaves it), and a circle of two half ARCs with the same ends: the
    square is one loop of 2500 mm2, the arcs are not taken for copies of each other."""
    doc, msp = _doc()
    blk = doc.blocks.new("SQ")
    _square_of_lines(blk, 0, 0, 50, layer="0")
    for _ in range(200):
        msp.add_blockref("SQ", (0, 0), dxfattribs={"layer": "plate"})
    msp.add_arc((100, 25), 10, 0, 180, dxfattribs={"layer": "plate"})
    msp.add_arc((100, 25), 10, 180, 360, dxfattribs={"layer": "plate"})
    doc.saveas(tmp_path / "stack.dxf")
    drawing = read_drawing(tmp_path / "stack.dxf")
    assert len(drawing.contours) == 2
    areas = sorted(p.area for p in design_from_drawing(drawing).body.geoms)
    assert areas == pytest.approx([math.pi * 100, 2500.0], rel=2e-4)
