"""The cut files opened by a real CAD program: LibreCAD (``librecad dxf2pdf``, headless)
draws each into a PDF, and the PDF's page content is read back to count what it drew."""

from __future__ import annotations

from pathlib import Path

import ezdxf
import pytest

from locust.errors import FabError
from locust.fab import cadcheck, export, laminate
from locust.fab.design import design_from_drawing
from locust.fab.dxf_read import read_drawing

ZZ = Path(__file__).resolve().parents[1] / "data" / "dxf" / "zz.dxf"

pytestmark = pytest.mark.skipif(not cadcheck.librecad_available(),
                                reason="LibreCAD not installed (apt-get install -y librecad)")


@pytest.fixture(scope="module")
def zz_out(tmp_path_factory):
    lam = laminate.build(design_from_drawing(read_drawing(ZZ)))
    return export.publish(tmp_path_factory.mktemp("fab") / "cut", export.cut_files(lam))


def _edges(path) -> int:
    return sum(len(e) for e in ezdxf.readfile(path).modelspace().query("LWPOLYLINE"))


@pytest.mark.parametrize("stem", ["rigid_top", "adhesive_top", "flexible", "adhesive_bottom", "rigid_bottom",
                                  "combined_cut_pattern", "first_pass_cuts", "final_perimeter"])
def test_librecad_draws_every_segment(zz_out, stem):
    drawing = cadcheck.check_dxf(zz_out / f"{stem}.dxf", timeout_s=60)
    assert drawing.segments >= _edges(zz_out / f"{stem}.dxf")      # every polyline edge stroked


def test_librecad_draws_the_release_cut_to_shape(zz_out):
    drawing = cadcheck.check_dxf(zz_out / "final_perimeter.dxf", timeout_s=60)
    assert drawing.painted_paths >= 1
    assert drawing.aspect == pytest.approx(184.05 / 34.05, rel=0.01)   # the 184 x 34 mm release cut


def test_librecad_on_garbage_times_out_as_an_error(tmp_path):
    bad = tmp_path / "garbage.dxf"
    bad.write_text("0\nSECTION\n2\nENTITIES\n0\nLINE\n8\nx\n10\nabc\n")
    with pytest.raises(FabError):          # LibreCAD hangs on this: the time limit ends it
        cadcheck.check_dxf(bad, timeout_s=3)


def test_pdf_reader_ignores_clip_paths():
    stream = b"0 0 m 10 0 l 10 10 l h W* n 1 1 m 5 1 l S 0 0 3 4 re f"
    import zlib
    pdf = b"%PDF-1.4\nstream\n" + zlib.compress(stream) + b"\nendstream\n"
    d = cadcheck.pdf_drawing(pdf)
    assert (d.painted_paths, d.segments) == (2, 5)
    assert d.bbox == (0.0, 0.0, 5.0, 4.0)
