"""`locust fab` on the seed team's own combined cut pattern gives back the seed's own layer
files: the hinge slots (layer `cuts`) cut from the rigid and adhesive layers, the flexible
layer whole across them (that is what makes it a hinge).

The truth is ../shared/data/robot/cut_files: the files the seed's Part 4 notebook wrote from
its zz.dxf (`$INSUNITS` says metres, the numbers are centimetres: 0..18 x 0..3), read here
with plain ezdxf and shapely, none of locust.fab's reading.
"""

from __future__ import annotations

import json

import ezdxf
import pytest
from click.testing import CliRunner
from shapely.geometry import Polygon

from locust.commands import cli

KERF_MM = 0.05        # locust fab's default: each cut-out drawn kerf/2 inside the part as designed


def seed_layer(shared_data, name: str) -> tuple[Polygon, list[Polygon]]:
    """A seed layer file in mm: its outline and the cut-outs inside it."""
    loops = [Polygon([(10 * x, 10 * y) for x, y in e.get_points("xy")])
             for e in ezdxf.readfile(shared_data / "robot" / "cut_files" / f"{name}.dxf").modelspace()
             if e.dxftype() == "LWPOLYLINE"]
    loops.sort(key=lambda p: -p.area)
    return loops[0], loops[1:]


def cutouts(path) -> list[Polygon]:
    """The cut-outs a locust layer file holds (its `cutouts` layer), mm."""
    return [Polygon(list(e.get_points("xy"))) for e in ezdxf.readfile(path).modelspace()
            if e.dxftype() == "LWPOLYLINE" and e.dxf.layer == "cutouts"]


def test_the_seed_combined_pattern_makes_the_seeds_own_layers(shared_data, tmp_path):
    out = tmp_path / "cut"
    res = CliRunner().invoke(cli, ["fab", str(shared_data / "robot" / "cut_files" / "combined_cut_pattern.dxf"),
                                   "--units", "cm", "--out", str(out), "--no-preview", "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    for name in ("rigid_top", "adhesive_top", "flexible", "adhesive_bottom", "rigid_bottom"):
        outline, slots = seed_layer(shared_data, name)
        truth_mm2 = outline.area - sum(p.area for p in slots)
        # as designed, against the seed's own file: rigid and adhesive 5348.86 mm2, flexible 5400.00
        assert s["areas_mm2"][name] == pytest.approx(truth_mm2, abs=0.01), name
        ours = sorted(cutouts(out / f"{name}.dxf"), key=lambda p: p.centroid.x)
        assert len(ours) == len(slots), name                  # the flexible layer: none (was: the four slots)
        for mine, theirs in zip(ours, sorted(slots, key=lambda p: p.centroid.x)):
            assert mine.centroid.distance(theirs.centroid) < 1e-6, name
            # the seed's slot less half the kerf all round: inside it, and all of it but that band
            assert theirs.buffer(1e-6).contains(mine), name
            assert theirs.area - mine.area == pytest.approx(theirs.length * KERF_MM / 2, rel=0.02), name
    assert [row["center_x_mm"] for row in s["slots"]] == pytest.approx([40, 80, 100, 160])
    assert s["holes"] == 0 and s["layer_roles"]["cuts"] == "hinge"
    assert any("the seed's combined cut pattern" in note for note in s["notes"])


def test_a_cuts_layer_given_explicitly_cuts_through_every_layer_and_says_no_hinge(shared_data):
    """`--layer cuts=cuts` reads the layer as the course drawings use it, through every layer:
    the flexible layer then has the slots too, and the summary says the drawing has no hinge."""
    res = CliRunner().invoke(cli, ["fab", str(shared_data / "robot" / "cut_files" / "combined_cut_pattern.dxf"),
                                   "--units", "cm", "--layer", "cuts=cuts", "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["areas_mm2"]["flexible"] == pytest.approx(s["areas_mm2"]["rigid_top"]) and s["holes"] == 4
    assert any(note.startswith("no hinge in the drawing") for note in s["notes"])


@pytest.mark.parametrize("name, holes, slits", [("five_bar.dxf", 1, 1), ("laminate_leg_flat.dxf", 0, 2)])
def test_the_course_drawings_still_cut_their_cuts_through_every_layer(shared_data, name, holes, slits):
    """The course drawings keep `cuts` as cuts through the laminate (five_bar's open square,
    laminate_leg_flat's two slits along its links): their hinges are on `joints`, and nothing
    is read otherwise."""
    res = CliRunner().invoke(cli, ["fab", str(shared_data / "dxf" / name), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout)
    assert s["layer_roles"]["cuts"] == "cuts" and s["layer_roles"]["joints"] == "hinge" and s["notes"] == []
    assert (s["holes"], s["slits"]) == (holes, slits)
