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

# AutoCAD colour index per DXF layer
COLOURS = {"rigid": 1, "adhesive": 30, "flexible": 5, "outline": 7, "plate": 7, "cutouts": 1,
           "hinges": 1, "holes": 5, "slits": 6, "alignment": 3, "release": 4}


def polygons(geom) -> list:
    """The non-empty polygons of a shapely geometry.

    Parameters
    ----------
    geom : shapely geometry
        A Polygon, MultiPolygon or collection.

    Returns
    -------
    list of Polygon
        Its polygons (none for an empty geometry; lines and points are left out).
    """
    if geom.is_empty:
        return []
    if geom.geom_type == "Polygon":
        return [geom]
    return [g for g in getattr(geom, "geoms", []) if g.geom_type == "Polygon" and not g.is_empty]


def rings(geom, exteriors_only: bool = False) -> list[list[tuple[float, float]]]:
    """The rings of every polygon of ``geom``, each without its closing point.

    Parameters
    ----------
    geom : shapely geometry
        The geometry [mm].
    exteriors_only : bool, default False
        Leave out the polygons' holes.

    Returns
    -------
    list of list of (float, float)
        Each ring's vertices [mm].
    """
    out = []
    for poly in polygons(geom):
        out.append(list(poly.exterior.coords)[:-1])
        if not exteriors_only:
            out += [list(r.coords)[:-1] for r in poly.interiors]
    return out


class CutDocument:
    """A new R2010 drawing in millimetres with colour-coded layers (ezdxf).

    Attributes
    ----------
    doc : ezdxf.document.Drawing
        The drawing.
    msp : Modelspace
        Its model space.
    """

    def __init__(self):
        import ezdxf

        self.doc = ezdxf.new("R2010", units=4)
        self.doc.header["$MEASUREMENT"] = 1          # metric
        # ezdxf leaves the paper-space viewport scale at 0; LibreCAD prints with it and
        # draws every entity onto one point.
        self.doc.header["$PSVPSCALE"] = 1.0
        self.msp = self.doc.modelspace()

    def layer(self, name: str, colour: int | None = None) -> str:
        """Add layer ``name`` if it is not there yet.

        Parameters
        ----------
        name : str
            The layer's name.
        colour : int, optional
            AutoCAD colour index; by default the one ``COLOURS`` gives the name (7 if none).

        Returns
        -------
        str
            ``name``.
        """
        if name not in self.doc.layers:
            self.doc.layers.add(name, color=colour if colour is not None else COLOURS.get(name, 7))
        return name

    def contours(self, geom, layer: str, colour: int | None = None, exteriors_only: bool = False) -> int:
        """Draw every ring of ``geom`` with three or more vertices as a closed LWPOLYLINE on ``layer``.

        Parameters
        ----------
        geom : shapely geometry
            The geometry [mm].
        layer : str
            The DXF layer.
        colour : int, optional
            The layer's AutoCAD colour index, when the layer is new.
        exteriors_only : bool, default False
            Leave out the polygons' holes.

        Returns
        -------
        int
            The number of contours drawn.
        """
        self.layer(layer, colour)
        rs = [r for r in rings(geom, exteriors_only) if len(r) >= 3]
        for r in rs:
            self.msp.add_lwpolyline(r, close=True, dxfattribs={"layer": layer})
        return len(rs)

    def paths(self, lines, layer: str) -> int:
        """Draw each line as an open LWPOLYLINE on ``layer`` (slits: single beam passes).

        Parameters
        ----------
        lines : sequence of LineString
            The paths [mm].
        layer : str
            The DXF layer.

        Returns
        -------
        int
            The number of paths drawn.
        """
        self.layer(layer)
        for line in lines:
            self.msp.add_lwpolyline(list(line.coords), close=False, dxfattribs={"layer": layer})
        return len(lines)

    def to_bytes(self) -> bytes:
        """The drawing as DXF.

        Returns
        -------
        bytes
            The DXF file, UTF-8.
        """
        stream = io.StringIO()
        self.doc.write(stream)
        return stream.getvalue().encode("utf-8")


def _mirror_lines(lam: Laminate, lines, layer):
    return [lam.oriented(s, layer) for s in lines]


def layer_file(lam: Laminate, layer) -> bytes:
    """The DXF of one layer's sheet: ``outline``, ``cutouts``, ``alignment`` and ``slits``,
    kerf-compensated and mirrored if the layer is.

    Parameters
    ----------
    lam : Laminate
        The laminate.
    layer : LaminateLayer
        One of its layers.

    Returns
    -------
    bytes
        The DXF file.
    """
    k = lam.process.kerf_mm
    doc = CutDocument()
    doc.contours(lam.oriented(compensate_part(lam.design.body, k), layer), "outline", exteriors_only=True)
    doc.contours(lam.oriented(compensate_cutout(lam.cutouts(layer), k), layer), "cutouts",
                 COLOURS[layer.spec.material])
    doc.contours(lam.oriented(compensate_cutout(union(lam.alignment_holes), k), layer), "alignment")
    doc.paths(_mirror_lines(lam, lam.design.slits, layer), "slits")
    return doc.to_bytes()


def combined_file(lam: Laminate) -> bytes:
    """``combined_cut_pattern.dxf``: the design overlaid on ``plate``, ``hinges``, ``holes``,
    ``slits``, ``alignment`` and ``release``, kerf-compensated.

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    bytes
        The DXF file.
    """
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
    """``first_pass_cuts.dxf``: each sheet's cuts before lamination, one DXF layer per laminate
    layer, plus ``alignment`` and ``slits``.

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    bytes
        The DXF file.
    """
    k = lam.process.kerf_mm
    doc = CutDocument()
    for layer in lam.layers:
        doc.contours(lam.oriented(compensate_cutout(lam.cutouts(layer), k), layer), layer.spec.name,
                     COLOURS[layer.spec.material])
    doc.contours(compensate_cutout(union(lam.alignment_holes), k), "alignment")
    doc.paths(list(lam.design.slits), "slits")
    return doc.to_bytes()


def perimeter_file(lam: Laminate) -> bytes:
    """``final_perimeter.dxf``: the release cut, kerf-compensated.

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    bytes
        The DXF file.
    """
    doc = CutDocument()
    doc.contours(compensate_part(lam.release, lam.process.kerf_mm), "release", exteriors_only=True)
    return doc.to_bytes()


def cut_files(lam: Laminate) -> dict[str, bytes]:
    """Every DXF file of the job, built in memory before any is written.

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    dict of str to bytes
        File name to DXF bytes: one per layer, then the combined, first-pass and perimeter files.
    """
    files = {f"{layer.spec.name}.dxf": layer_file(lam, layer) for layer in lam.layers}
    files["combined_cut_pattern.dxf"] = combined_file(lam)
    files["first_pass_cuts.dxf"] = first_pass_file(lam)
    files["final_perimeter.dxf"] = perimeter_file(lam)
    return files


def check_out(out_dir: str | os.PathLike) -> Path:
    """Refuse, before any work, a destination that holds files.

    Parameters
    ----------
    out_dir : str or PathLike
        The output folder (may not exist yet).

    Returns
    -------
    Path
        ``out_dir`` as a Path.

    Raises
    ------
    FabError
        It exists and is not an empty folder.
    """
    out = Path(out_dir)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise FabError(f"{out} already exists and is not an empty folder",
                       "choose a new --out folder; results are never overwritten")
    return out


def publish(out_dir: str | os.PathLike, files: dict[str, bytes]) -> Path:
    """Write ``files`` into ``out_dir`` all at once: staged in a hidden sibling folder and
    renamed into place, so a failure leaves nothing behind. Never writes into a folder
    that already holds files.

    Parameters
    ----------
    out_dir : str or PathLike
        The output folder, missing or empty.
    files : dict of str to bytes
        File name to contents.

    Returns
    -------
    Path
        The output folder.

    Raises
    ------
    FabError
        ``out_dir`` exists and is not an empty folder.
    """
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
