"""Cut files: every contour a closed LWPOLYLINE, in millimetres ($INSUNITS 4), on named
layers with colours. Slits (single beam passes) are the one open path, on layer ``slits``.

Files (the seed's names):

- ``rigid_top.dxf`` ... ``rigid_bottom.dxf``, one per layer of the stack: ``outline``
  (the part's outer contour, for reference or for cutting that layer alone), ``cutouts``
  (its first-pass cut-outs), ``alignment``, ``slits``. Mirrored layers are mirrored here.
- ``combined_cut_pattern.dxf``: the design overlaid: ``plate``, ``hinges``, ``holes``,
  ``slits``, ``alignment``, ``release``.
- ``first_pass_cuts.dxf``: what is cut in each sheet before lamination, one DXF layer per
  laminate layer (switch on the one for the sheet in the cutter), plus ``alignment`` and
  ``slits``.
- ``final_perimeter.dxf``: the release cut (``release``).

Every cut path is kerf-compensated (see :mod:`.laminate`).
"""

from __future__ import annotations

import io
import os
import shutil
import tempfile
from pathlib import Path

from ..errors import FabError
from ..fileio import make_folder
from .laminate import Laminate, compensate_cutout, compensate_part, union

DXF_NAMES = ("combined_cut_pattern", "first_pass_cuts", "final_perimeter")

# AutoCAD colour index per DXF layer
COLOURS = {"rigid": 1, "adhesive": 30, "flexible": 5, "outline": 7, "plate": 7, "cutouts": 1,
           "hinges": 1, "holes": 5, "slits": 6, "alignment": 3, "release": 4}


def polygons(geom) -> list:
    if geom.is_empty:
        return []
    if geom.geom_type == "Polygon":
        return [geom]
    return [g for g in getattr(geom, "geoms", []) if g.geom_type == "Polygon" and not g.is_empty]


def rings(geom, exteriors_only: bool = False) -> list[list[tuple[float, float]]]:
    out = []
    for poly in polygons(geom):
        out.append(list(poly.exterior.coords)[:-1])
        if not exteriors_only:
            out += [list(r.coords)[:-1] for r in poly.interiors]
    return out


class CutDocument:
    """A new R2010 drawing in millimetres with colour-coded layers."""

    def __init__(self):
        import ezdxf

        self.doc = ezdxf.new("R2010", units=4)
        self.doc.header["$MEASUREMENT"] = 1          # metric
        # ezdxf leaves the paper-space viewport scale at 0; LibreCAD prints with it and
        # draws every entity onto one point.
        self.doc.header["$PSVPSCALE"] = 1.0
        self.msp = self.doc.modelspace()

    def layer(self, name: str, colour: int | None = None) -> str:
        if name not in self.doc.layers:
            self.doc.layers.add(name, color=colour if colour is not None else COLOURS.get(name, 7))
        return name

    def contours(self, geom, layer: str, colour: int | None = None, exteriors_only: bool = False) -> int:
        self.layer(layer, colour)
        rs = [r for r in rings(geom, exteriors_only) if len(r) >= 3]
        for r in rs:
            self.msp.add_lwpolyline(r, close=True, dxfattribs={"layer": layer})
        return len(rs)

    def paths(self, lines, layer: str) -> int:
        self.layer(layer)
        for line in lines:
            self.msp.add_lwpolyline(list(line.coords), close=False, dxfattribs={"layer": layer})
        return len(lines)

    def to_bytes(self) -> bytes:
        stream = io.StringIO()
        self.doc.write(stream)
        return stream.getvalue().encode("utf-8")


def _mirror_lines(lam: Laminate, lines, layer):
    return [lam.oriented(s, layer) for s in lines]


def layer_file(lam: Laminate, layer) -> bytes:
    k = lam.process.kerf_mm
    doc = CutDocument()
    doc.contours(lam.oriented(compensate_part(lam.design.body, k), layer), "outline", exteriors_only=True)
    doc.contours(lam.oriented(compensate_cutout(lam.cutouts(layer), k), layer), "cutouts",
                 COLOURS[layer.spec.material])
    doc.contours(lam.oriented(compensate_cutout(union(lam.alignment_holes), k), layer), "alignment")
    doc.paths(_mirror_lines(lam, lam.design.slits, layer), "slits")
    return doc.to_bytes()


def combined_file(lam: Laminate) -> bytes:
    d, k = lam.design, lam.process.kerf_mm
    doc = CutDocument()
    doc.contours(compensate_part(d.body, k), "plate", exteriors_only=True)
    doc.contours(compensate_cutout(d.hinge_union(), k), "hinges")
    doc.contours(compensate_cutout(d.hole_union(), k), "holes")
    doc.paths(list(d.slits), "slits")
    doc.contours(compensate_cutout(union(lam.alignment_holes), k), "alignment")
    doc.contours(compensate_part(lam.release, k), "release", exteriors_only=True)
    return doc.to_bytes()


def first_pass_file(lam: Laminate) -> bytes:
    k = lam.process.kerf_mm
    doc = CutDocument()
    for layer in lam.layers:
        doc.contours(lam.oriented(compensate_cutout(lam.cutouts(layer), k), layer), layer.spec.name,
                     COLOURS[layer.spec.material])
    doc.contours(compensate_cutout(union(lam.alignment_holes), k), "alignment")
    doc.paths(list(lam.design.slits), "slits")
    return doc.to_bytes()


def perimeter_file(lam: Laminate) -> bytes:
    doc = CutDocument()
    doc.contours(compensate_part(lam.release, lam.process.kerf_mm), "release", exteriors_only=True)
    return doc.to_bytes()


def cut_files(lam: Laminate) -> dict[str, bytes]:
    """File name -> DXF bytes, every file of the job, built in memory before any is written."""
    files = {f"{layer.spec.name}.dxf": layer_file(lam, layer) for layer in lam.layers}
    files["combined_cut_pattern.dxf"] = combined_file(lam)
    files["first_pass_cuts.dxf"] = first_pass_file(lam)
    files["final_perimeter.dxf"] = perimeter_file(lam)
    return files


def check_out(out_dir: str | os.PathLike) -> Path:
    """Refuse, before any work, a destination that holds files."""
    out = Path(out_dir)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise FabError(f"{out} already exists and is not an empty folder",
                       "choose a new --out folder; results are never overwritten")
    return out


def publish(out_dir: str | os.PathLike, files: dict[str, bytes]) -> Path:
    """Write ``files`` into ``out_dir`` all at once: staged in a hidden sibling folder and
    renamed into place, so a failure leaves nothing behind. Never writes into a folder
    that already holds files."""
    out = check_out(out_dir)
    make_folder(out.parent)
    stage = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        for name, data in files.items():
            with open(stage / name, "wb") as fh:
                fh.write(data)
                fh.flush()
                os.fsync(fh.fileno())
        os.replace(stage, out)   # onto a missing or empty folder: atomic
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    return out
