"""The laminate and its cut files, on the seed's zz.dxf (rebuilt from the notebook's
description by data/dxf/make_zz.py) and on the leg flat pattern from link lengths."""

from __future__ import annotations

import io
import math
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from shapely.geometry import Polygon

from locust import params
from locust.errors import FabError
from locust.fab import export, flat_pattern, laminate
from locust.fab.design import design_from_drawing
from locust.fab.dxf_read import read_drawing

ZZ = Path(__file__).resolve().parents[1] / "data" / "dxf" / "zz.dxf"
SLOT_MM2 = 1.0 * 12.0 + math.pi * 0.5 ** 2            # stadium 1 x 13 mm
SEED_FILES = ["rigid_top", "adhesive_top", "flexible", "adhesive_bottom", "rigid_bottom",
              "combined_cut_pattern", "first_pass_cuts", "final_perimeter"]


@pytest.fixture(scope="module")
def zz_lam():
    return laminate.build(design_from_drawing(read_drawing(ZZ)))


@pytest.fixture(scope="module")
def zz_files(zz_lam):
    return {name: ezdxf.read(io.StringIO(data.decode())) for name, data in export.cut_files(zz_lam).items()}


def _polys(doc, layer=None):
    return [Polygon(list(e.get_points("xy"))) for e in doc.modelspace().query("LWPOLYLINE")
            if layer is None or e.dxf.layer == layer]


def test_zz_areas_match_the_notebook(zz_lam):
    areas = {L.spec.name: L.area_mm2 for L in zz_lam.layers}
    # notebook Part 4: 53.4886 cm2 rigid and adhesive, 54.0000 cm2 flexible
    for name in ("rigid_top", "adhesive_top", "adhesive_bottom", "rigid_bottom"):
        assert areas[name] == pytest.approx(5348.86, rel=5e-4)
        assert areas[name] == pytest.approx(5400.0 - 4 * SLOT_MM2, rel=1e-6)   # exact stadiums
    assert areas["flexible"] == pytest.approx(5400.00, rel=1e-9)
    assert zz_lam.support_web.area == pytest.approx(184 * 34 - 180 * 30, rel=1e-9)   # mitred corners


def test_zz_all_eight_files_closed_in_mm(zz_files):
    assert sorted(zz_files) == sorted(f"{n}.dxf" for n in SEED_FILES)
    for name, doc in zz_files.items():
        assert doc.header["$INSUNITS"] == 4, name
        kinds = {e.dxftype() for e in doc.modelspace()}
        assert kinds == {"LWPOLYLINE"}, name
        assert all(e.closed for e in doc.modelspace()), name
        assert all(doc.layers.get(e.dxf.layer).color != 7 or e.dxf.layer in ("outline", "plate")
                   for e in doc.modelspace()), name
    top = zz_files["rigid_top.dxf"]
    assert {layer.dxf.name for layer in top.layers} >= {"outline", "cutouts", "alignment"}


def test_kerf_compensation_is_applied(zz_files):
    k = 0.05
    top = zz_files["rigid_top.dxf"]
    (outline,) = _polys(top, "outline")
    slots = _polys(top, "cutouts")
    assert outline.bounds == pytest.approx((-k / 2, -k / 2, 180 + k / 2, 30 + k / 2), abs=1e-9)
    assert len(slots) == 4
    # a 1 x 13 mm stadium cut in by k/2: 0.95 x 12.95 mm
    narrow = 0.95 * 12.0 + math.pi * 0.475 ** 2
    for s in slots:
        x0, y0, x1, y1 = s.bounds
        assert (x1 - x0, y1 - y0) == pytest.approx((1 - k, 13 - k), abs=1e-3)   # arcs to 0.001 mm
        assert s.area == pytest.approx(narrow, rel=2e-4)
    left = outline.area - sum(s.area for s in slots)
    assert left == pytest.approx((180 + k) * (30 + k) - 4 * narrow, abs=0.01)
    holes = _polys(top, "alignment")
    centres = sorted((round(h.centroid.x, 6), round(h.centroid.y, 6)) for h in holes)
    assert centres == [(-10, -10), (-10, 40), (190, -10), (190, 40)]
    for h in holes:
        r = np.hypot(*(np.array(h.exterior.coords) - h.centroid.coords[0]).T)
        assert r == pytest.approx(2.5 - k / 2, abs=1e-3)
    (release,) = _polys(zz_files["final_perimeter.dxf"], "release")
    assert release.bounds == pytest.approx((-2 - k / 2, -2 - k / 2, 182 + k / 2, 32 + k / 2), abs=1e-9)


def test_first_pass_cuts_each_layer_and_keeps_the_flexible_whole(zz_files):
    doc = zz_files["first_pass_cuts.dxf"]
    counts = {name: len(_polys(doc, name)) for name in SEED_FILES[:5]}
    assert counts == {"rigid_top": 4, "adhesive_top": 4, "flexible": 0, "adhesive_bottom": 4, "rigid_bottom": 4}
    assert len(_polys(doc, "alignment")) == 4
    assert len(_polys(zz_files["flexible.dxf"], "cutouts")) == 0


def test_mirrored_bottom_adhesive(tmp_path):
    design = design_from_drawing(read_drawing(ZZ))
    stack = laminate.stack_from_materials(laminate.SEED_STACK, mirror=("adhesive_bottom",))
    lam = laminate.build(design, stack)
    files = export.cut_files(lam)
    doc = ezdxf.read(io.StringIO(files["adhesive_bottom.dxf"].decode()))
    xs = sorted(round(p.centroid.x, 6) for p in _polys(doc, "cutouts"))
    assert xs == [20, 80, 100, 140]          # 40, 80, 100, 160 mirrored about x = 90
    top = ezdxf.read(io.StringIO(files["adhesive_top.dxf"].decode()))
    assert sorted(round(p.centroid.x, 6) for p in _polys(top, "cutouts")) == [40, 80, 100, 160]
    holes = sorted((round(h.centroid.x, 6), round(h.centroid.y, 6)) for h in _polys(doc, "alignment"))
    assert holes == [(-10, -10), (-10, 40), (190, -10), (190, 40)]   # the pins still fit


@pytest.mark.parametrize("name,hinges,length", [
    ("seed", [40, 80, 100, 160], 180), ("small", [40, 80, 100, 160], 180),
    ("medium", [50, 100, 130, 200], 220), ("large", [60, 120, 160, 240], 260)])
def test_flat_pattern_from_link_lengths(name, hinges, length):
    fp = flat_pattern.from_robot(params.preset(name))
    assert list(fp.hinges_x_mm) == pytest.approx(hinges, abs=1e-9)
    assert fp.length_mm == pytest.approx(length)
    design = flat_pattern.design(fp)
    lam = laminate.build(design)
    rigid = lam.layers[0].area_mm2
    assert rigid == pytest.approx(length * 30 - 4 * SLOT_MM2, rel=1e-5)


def test_seed_flat_pattern_is_zz(tmp_path):
    from_robot = flat_pattern.design(flat_pattern.from_robot(params.preset("seed")))
    from_dxf = design_from_drawing(read_drawing(ZZ))
    a = laminate.part_geometry(from_robot, "rigid")
    b = laminate.part_geometry(from_dxf, "rigid")
    assert a.symmetric_difference(b).area < 0.01          # mm2, of 5348.86
    # and its own drawing (LINE + ARC, mm) reads back to the same part
    path = tmp_path / "flat.dxf"
    flat_pattern.write_drawing(flat_pattern.from_robot(params.preset("seed")), path)
    back = design_from_drawing(read_drawing(path))
    assert back.units == "mm" and len(back.hinges) == 4
    assert laminate.part_geometry(back, "rigid").symmetric_difference(b).area < 0.01


def test_bad_stacks_and_processes():
    assert [s.name for s in laminate.stack_from_materials(["rigid", "flexible", "rigid", "rigid"])] == \
        ["rigid_1", "flexible", "rigid_2", "rigid_3"]
    with pytest.raises(FabError, match="unknown material"):
        laminate.stack_from_materials(["rigid", "paper"])
    with pytest.raises(FabError, match="no flexible layer"):
        laminate.stack_from_materials(["rigid", "adhesive", "rigid"])
    with pytest.raises(FabError, match="no such layer"):
        laminate.stack_from_materials(laminate.SEED_STACK, mirror=("bottom",))
    design = design_from_drawing(read_drawing(ZZ))
    with pytest.raises(FabError, match="narrower than"):
        export.cut_files(laminate.build(design, process=laminate.Process(kerf_mm=1.2)))
    with pytest.raises(FabError, match="must be >= 0"):
        laminate.build(design, process=laminate.Process(kerf_mm=-0.1))
    with pytest.raises(FabError, match="too short"):
        flat_pattern.from_robot(params.preset("seed").with_values({"geometry.coupler_m": 0.0005}))


def test_zz_is_the_notebook_description():
    doc = ezdxf.readfile(ZZ)
    assert doc.header["$INSUNITS"] == 5                          # centimetres
    kinds = {}
    for e in doc.modelspace():
        kinds.setdefault(e.dxf.layer, []).append(e.dxftype())
    assert sorted(kinds) == ["hinge_1", "hinge_2", "hinge_3", "hinge_4", "plate"]
    assert kinds["plate"] == ["LINE"] * 4
    assert all(sorted(kinds[f"hinge_{i}"]) == ["ARC", "ARC", "LINE", "LINE"] for i in range(1, 5))
    radii = {round(e.dxf.radius, 9) for e in doc.modelspace().query("ARC")}
    assert radii == {0.05}
