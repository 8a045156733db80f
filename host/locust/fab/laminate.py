"""The laminate: a layer stack cut from one design, and the cuts that make it.

Process (the seed's Part 4, made explicit):

1. First pass, each sheet before lamination: the layer's inner cut-outs (hinge slots in
   rigid and adhesive layers, holes, slits) and the four alignment holes, ``jig_spacing_mm``
   outside the body's corners. The outline is not cut, so every sheet stays whole and
   registers on the pins.
2. Laminate the sheets on the pins.
3. Release: one cut through the whole laminate around the part, ``support_width_mm``
   outside its outline (mitred corners). The strip between outline and release cut is the
   support web: the laminate the part keeps round its edge.

Kerf compensation (``kerf_mm``, the width the beam removes) is applied to every cut path:
outer contours move out by kerf/2, holes and slots move in by kerf/2, so what is left is
the part as designed. Areas are reported as designed (before compensation).

A layer marked ``mirror`` (the bottom adhesive, when its sheet is cut liner side up) is
mirrored about the vertical line through the centre of the body; the alignment holes sit
symmetrically about it, so they register either way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shapely import affinity, unary_union
from shapely.geometry import MultiPolygon, Point, Polygon, box

from ..errors import FabError
from .design import Design

MATERIALS = ("rigid", "adhesive", "flexible")


@dataclass(frozen=True)
class LayerSpec:
    """One sheet of the stack.

    Attributes
    ----------
    name : str
        Its name and file stem: ``rigid_top``, ``adhesive_top``, ...
    material : str
        ``rigid``, ``adhesive`` or ``flexible``.
    mirror : bool
        Cut mirrored about the body's vertical centre line (an adhesive cut liner side up).
    """

    name: str            # file stem: rigid_top, adhesive_top, ...
    material: str        # rigid | adhesive | flexible
    mirror: bool = False


# the smallest and largest part a laser cutter can make: below 0.01 mm is a drawing in the wrong
# unit or a stray point, above 10 m no sheet holds it
PART_LIMITS_MM = (0.01, 10_000.0)
# process setting -> (lowest, lowest allowed?, highest), mm
PROCESS_LIMITS_MM = {"kerf_mm": (0.0, True, 10.0), "support_width_mm": (0.0, True, 1000.0),
                     "jig_diameter_mm": (0.0, False, 1000.0), "jig_spacing_mm": (0.0, False, 10_000.0)}


def check_design(design) -> None:
    """Refuse a part no cutter can make (size, non-finite vertices) and cut-outs that are not in it.

    Parameters
    ----------
    design : Design
        The part, in mm.

    Raises
    ------
    FabError
        Non-finite vertices, a size outside ``PART_LIMITS_MM``, or a hole, slit or hinge slot
        outside the body.
    """
    bounds = design.body.bounds
    if design.body.is_empty or not all(math.isfinite(v) for v in bounds):
        raise FabError(f"{design.source or 'the part'}: its outline has no finite vertices (NaN or inf)",
                       "check the drawing's coordinates, or redraw the outline")
    x0, y0, x1, y1 = bounds
    low, high = PART_LIMITS_MM
    size = max(x1 - x0, y1 - y0)
    if size > high or min(x1 - x0, y1 - y0) < low:
        raise FabError(f"{design.source or 'the part'}: {x1 - x0:.4g} x {y1 - y0:.4g} mm is outside the "
                       f"{low:g} mm to {high / 1000:g} m a cutter can make",
                       "check the drawing units (--units) or the robot's lengths (metres in robot.toml)")
    inside = design.body.buffer(1e-6)
    cuts = [("hole", h) for h in design.holes] + [("slit", s) for s in design.slits] + \
        [(f"hinge {h.layer}", h.polygon) for h in design.hinges]
    for what, geom in cuts:
        if geom.is_empty or not all(math.isfinite(v) for v in geom.bounds) or not geom.intersects(inside):
            gx0, gy0, gx1, gy1 = geom.bounds if not geom.is_empty else (math.nan,) * 4
            raise FabError(f"{what} at ({(gx0 + gx1) / 2:.3f}, {(gy0 + gy1) / 2:.3f}) mm lies outside the body",
                           "move it inside the outline, or put it on another layer")


@dataclass(frozen=True)
class Process:
    """Cutting parameters (the seed's Config, in millimetres).

    Attributes
    ----------
    kerf_mm : float
        Width the beam removes.
    support_width_mm : float
        Width of the support web the release cut leaves round the outline.
    jig_diameter_mm : float
        Diameter of the four alignment holes.
    jig_spacing_mm : float
        Distance of the alignment holes out from the body's corners, in x and in y.
    """

    kerf_mm: float = 0.05
    support_width_mm: float = 2.0
    jig_diameter_mm: float = 5.0
    jig_spacing_mm: float = 10.0

    def check(self) -> None:
        """Refuse settings outside ``PROCESS_LIMITS_MM``, or alignment holes that would cut into the body.

        Raises
        ------
        FabError
            A setting out of range, naming the option to change.
        """
        for name, (low, low_ok, high) in PROCESS_LIMITS_MM.items():
            value = getattr(self, name)
            if not (value > low or (low_ok and value == low)) or not value <= high:
                raise FabError(f"process: {name} = {value!r} must be {'>=' if low_ok else '>'} {low:g} "
                               f"and <= {high:g} mm", f"give --{name.replace('_', '-')} in that range")
        if self.jig_diameter_mm / 2 >= self.jig_spacing_mm:
            raise FabError(
                f"process: alignment holes ({self.jig_diameter_mm:g} mm) would cut into the body "
                f"at {self.jig_spacing_mm:g} mm spacing", "make --jig-spacing-mm more than half the diameter")


SEED_STACK = ("rigid", "adhesive", "flexible", "adhesive", "rigid")


def stack_from_materials(materials: tuple[str, ...] | list[str], mirror: tuple[str, ...] = ()) -> tuple[LayerSpec, ...]:
    """Name the layers of a stack: a material used once is named by it, twice gets
    ``_top``/``_bottom``, more get ``_1``, ``_2``...

    Parameters
    ----------
    materials : sequence of str
        Materials top to bottom (``rigid``, ``adhesive``, ``flexible``; case and blanks ignored).
    mirror : tuple of str, optional
        Names of the layers to cut mirrored.

    Returns
    -------
    tuple of LayerSpec
        The stack, top to bottom.

    Raises
    ------
    FabError
        An empty stack, an unknown material, no flexible layer, or a mirrored name that is no layer.
    """
    materials = [m.strip().lower() for m in materials if m.strip()]
    bad = [m for m in materials if m not in MATERIALS]
    if bad or not materials:
        raise FabError(f"layer stack {','.join(materials) or '(empty)'}: "
                       f"unknown material {', '.join(bad) or ''}".rstrip(),
                       f"list materials top to bottom from {', '.join(MATERIALS)}, e.g. --stack {','.join(SEED_STACK)}")
    if "flexible" not in materials:
        raise FabError("layer stack has no flexible layer: the hinges would not hold together",
                       f"e.g. --stack {','.join(SEED_STACK)}")
    names = []
    for i, m in enumerate(materials):
        n, k = materials.count(m), materials[:i + 1].count(m)
        names.append(m if n == 1 else (f"{m}_{'top' if k == 1 else 'bottom'}" if n == 2 else f"{m}_{k}"))
    unknown = [m for m in mirror if m not in names]
    if unknown:
        raise FabError(f"--mirror {', '.join(unknown)}: no such layer", f"layers are {', '.join(names)}")
    return tuple(LayerSpec(n, m, n in mirror) for n, m in zip(names, materials))


@dataclass(frozen=True)
class LaminateLayer:
    """One layer of the laminate as designed.

    Attributes
    ----------
    spec : LayerSpec
        Its name, material and mirroring.
    part : Polygon or MultiPolygon
        What is left of the sheet inside the body [mm], before mirroring and kerf compensation.
    """

    spec: LayerSpec
    part: Polygon | MultiPolygon          # as designed, mm

    @property
    def area_mm2(self) -> float:
        """The layer's area as designed [mm^2]."""
        return float(self.part.area)


@dataclass(frozen=True)
class Laminate:
    """The layer stack cut from one design, with the cuts that make it (see the module's description).

    Attributes
    ----------
    design : Design
        The part.
    process : Process
        The cutting parameters.
    layers : tuple of LaminateLayer
        The stack, top to bottom.
    alignment_holes : tuple of Polygon
        The four alignment holes [mm].
    release : Polygon or MultiPolygon
        The part plus its support web: inside the release cut [mm].
    mirror_x_mm : float
        The vertical line mirrored layers are mirrored about: the body's centre [mm].
    """

    design: Design
    process: Process
    layers: tuple[LaminateLayer, ...]
    alignment_holes: tuple[Polygon, ...]
    release: Polygon | MultiPolygon       # the part plus its support web
    mirror_x_mm: float                    # mirror line of mirrored layers

    @property
    def support_web(self):
        """The strip between the outline and the release cut [mm] (shapely geometry)."""
        return self.release.difference(self.design.body)

    def cutouts(self, layer: LaminateLayer):
        """What the first pass removes from this layer inside the body, as designed.

        Parameters
        ----------
        layer : LaminateLayer
            One of :attr:`layers`.

        Returns
        -------
        shapely geometry
            The cut-outs [mm].
        """
        return self.design.body.difference(layer.part)

    def oriented(self, geom, layer: LaminateLayer):
        """``geom`` as cut on ``layer``'s sheet: mirrored about :attr:`mirror_x_mm` if the layer is.

        Parameters
        ----------
        geom : shapely geometry
            Geometry in design coordinates [mm].
        layer : LaminateLayer
            The layer it is cut on.

        Returns
        -------
        shapely geometry
            The geometry on the sheet [mm].
        """
        return affinity.scale(geom, -1.0, 1.0, origin=(self.mirror_x_mm, 0.0)) if layer.spec.mirror else geom


def part_geometry(design: Design, material: str):
    """A layer's part: rigid and adhesive layers lose the hinge slots; every layer loses the holes.

    Parameters
    ----------
    design : Design
        The part.
    material : str
        The layer's material.

    Returns
    -------
    shapely geometry
        What is left of the body [mm].
    """
    geom = design.body
    if material != "flexible" and design.hinges:
        geom = geom.difference(design.hinge_union())
    if design.holes:
        geom = geom.difference(design.hole_union())
    return geom


def alignment_holes(bounds_mm, process: Process) -> tuple[Polygon, ...]:
    """The four alignment holes, ``jig_spacing_mm`` out from each corner of the bounds.

    Parameters
    ----------
    bounds_mm : tuple of float
        (x0, y0, x1, y1) of the body [mm].
    process : Process
        Gives the holes' diameter and spacing.

    Returns
    -------
    tuple of Polygon
        Circles [mm], counter-clockwise from the lower left corner.
    """
    x0, y0, x1, y1 = bounds_mm
    s, r = process.jig_spacing_mm, process.jig_diameter_mm / 2
    corners = [(x0 - s, y0 - s), (x1 + s, y0 - s), (x1 + s, y1 + s), (x0 - s, y1 + s)]
    return tuple(Point(x, y).buffer(r, quad_segs=32) for x, y in corners)


def build(design: Design, stack: tuple[LayerSpec, ...] | None = None, process: Process | None = None) -> Laminate:
    """The laminate of ``design``: each layer's part, the alignment holes and the release cut.

    Parameters
    ----------
    design : Design
        The part [mm].
    stack : tuple of LayerSpec, optional
        The layers top to bottom; the seed's rigid, adhesive, flexible, adhesive, rigid when None.
    process : Process, optional
        Cutting parameters; the defaults when None.

    Returns
    -------
    Laminate
        The laminate.

    Raises
    ------
    FabError
        Process settings out of range, a part no cutter can make, cut-outs outside the body,
        or a layer with nothing left.
    """
    stack = stack or stack_from_materials(SEED_STACK)
    process = process or Process()
    process.check()
    check_design(design)
    layers = tuple(LaminateLayer(spec, part_geometry(design, spec.material)) for spec in stack)
    for layer in layers:
        if layer.part.is_empty:
            raise FabError(f"layer {layer.spec.name}: nothing left after the cut-outs",
                           "check that hinge slots and holes lie inside the body, not over it")
    release = (design.body.buffer(process.support_width_mm, join_style="mitre") if process.support_width_mm
               else design.body)
    x0, _, x1, _ = design.bounds_mm
    return Laminate(design, process, layers, alignment_holes(design.bounds_mm, process), release, (x0 + x1) / 2)


# -- kerf compensation ----------------------------------------------------------------
def compensate_part(geom, kerf_mm: float):
    """Cut path around material: outer contours out by kerf/2, its holes in by kerf/2.

    Parameters
    ----------
    geom : shapely geometry
        The material as designed [mm].
    kerf_mm : float
        Width the beam removes.

    Returns
    -------
    shapely geometry
        The cut path [mm] (mitred corners).
    """
    return geom.buffer(kerf_mm / 2, join_style="mitre") if kerf_mm else geom


def compensate_cutout(geom, kerf_mm: float):
    """Cut path of a hole (material removed inside): in by kerf/2. A hole narrower than
    the kerf cannot be compensated and is an error rather than silently lost.

    Parameters
    ----------
    geom : shapely geometry
        The cut-outs as designed [mm].
    kerf_mm : float
        Width the beam removes.

    Returns
    -------
    shapely geometry
        The cut path [mm].

    Raises
    ------
    FabError
        A cut-out narrower than the kerf.
    """
    if not kerf_mm or geom.is_empty:
        return geom
    out = geom.buffer(-kerf_mm / 2, join_style="mitre")
    pieces = list(getattr(geom, "geoms", [geom]))
    kept = list(getattr(out, "geoms", [out])) if not out.is_empty else []
    if len(kept) < len(pieces):
        lost = next(p for p in pieces if p.buffer(-kerf_mm / 2, join_style="mitre").is_empty)
        x0, y0, x1, y1 = lost.bounds
        raise FabError(f"a cut-out at ({(x0 + x1) / 2:.3f}, {(y0 + y1) / 2:.3f}) mm is narrower than the "
                       f"{kerf_mm:g} mm kerf", "widen it, draw it as a slit on the cuts layer, or lower --kerf-mm")
    return out


def union(geoms):
    """The union of shapely geometries.

    Parameters
    ----------
    geoms : iterable of shapely geometry
        The geometries.

    Returns
    -------
    shapely geometry
        Their union.
    """
    return unary_union(list(geoms))


def sheet_bounds(lam: Laminate) -> tuple[float, float, float, float]:
    """Everything the laser touches: release cut and alignment holes.

    Parameters
    ----------
    lam : Laminate
        The laminate.

    Returns
    -------
    tuple of float
        (x0, y0, x1, y1) [mm].
    """
    return union([lam.release, *lam.alignment_holes, box(*lam.design.bounds_mm)]).bounds
