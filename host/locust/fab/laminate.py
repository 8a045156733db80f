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

from dataclasses import dataclass

from shapely import affinity, unary_union
from shapely.geometry import MultiPolygon, Point, Polygon, box

from ..errors import FabError
from .design import Design

MATERIALS = ("rigid", "adhesive", "flexible")


@dataclass(frozen=True)
class LayerSpec:
    name: str            # file stem: rigid_top, adhesive_top, ...
    material: str        # rigid | adhesive | flexible
    mirror: bool = False


@dataclass(frozen=True)
class Process:
    """Cutting parameters (the seed's Config, in millimetres)."""

    kerf_mm: float = 0.05
    support_width_mm: float = 2.0
    jig_diameter_mm: float = 5.0
    jig_spacing_mm: float = 10.0

    def check(self) -> None:
        for name in ("kerf_mm", "support_width_mm", "jig_diameter_mm", "jig_spacing_mm"):
            if not getattr(self, name) >= 0:
                raise FabError(f"process: {name} = {getattr(self, name)!r} must be >= 0",
                               f"give --{name.replace('_', '-')} >= 0")
        if self.jig_diameter_mm / 2 >= self.jig_spacing_mm:
            raise FabError(
                f"process: alignment holes ({self.jig_diameter_mm:g} mm) would cut into the body "
                f"at {self.jig_spacing_mm:g} mm spacing", "make --jig-spacing-mm more than half the diameter")


SEED_STACK = ("rigid", "adhesive", "flexible", "adhesive", "rigid")


def stack_from_materials(materials: tuple[str, ...] | list[str], mirror: tuple[str, ...] = ()) -> tuple[LayerSpec, ...]:
    """Name the layers of a stack: a material used once is named by it, twice gets
    ``_top``/``_bottom``, more get ``_1``, ``_2``...; ``mirror`` lists names to mirror."""
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
    spec: LayerSpec
    part: Polygon | MultiPolygon          # as designed, mm

    @property
    def area_mm2(self) -> float:
        return float(self.part.area)


@dataclass(frozen=True)
class Laminate:
    design: Design
    process: Process
    layers: tuple[LaminateLayer, ...]
    alignment_holes: tuple[Polygon, ...]
    release: Polygon | MultiPolygon       # the part plus its support web
    mirror_x_mm: float                    # mirror line of mirrored layers

    @property
    def support_web(self):
        return self.release.difference(self.design.body)

    def cutouts(self, layer: LaminateLayer):
        """What the first pass removes from this layer inside the body, as designed."""
        return self.design.body.difference(layer.part)

    def oriented(self, geom, layer: LaminateLayer):
        return affinity.scale(geom, -1.0, 1.0, origin=(self.mirror_x_mm, 0.0)) if layer.spec.mirror else geom


def part_geometry(design: Design, material: str):
    """Rigid and adhesive layers lose the hinge slots; every layer loses the holes."""
    geom = design.body
    if material != "flexible" and design.hinges:
        geom = geom.difference(design.hinge_union())
    if design.holes:
        geom = geom.difference(design.hole_union())
    return geom


def alignment_holes(bounds_mm, process: Process) -> tuple[Polygon, ...]:
    x0, y0, x1, y1 = bounds_mm
    s, r = process.jig_spacing_mm, process.jig_diameter_mm / 2
    corners = [(x0 - s, y0 - s), (x1 + s, y0 - s), (x1 + s, y1 + s), (x0 - s, y1 + s)]
    return tuple(Point(x, y).buffer(r, quad_segs=32) for x, y in corners)


def build(design: Design, stack: tuple[LayerSpec, ...] | None = None, process: Process | None = None) -> Laminate:
    stack = stack or stack_from_materials(SEED_STACK)
    process = process or Process()
    process.check()
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
    """Cut path around material: outer contours out by kerf/2, its holes in by kerf/2."""
    return geom.buffer(kerf_mm / 2, join_style="mitre") if kerf_mm else geom


def compensate_cutout(geom, kerf_mm: float):
    """Cut path of a hole (material removed inside): in by kerf/2. A hole narrower than
    the kerf cannot be compensated and is an error rather than silently lost."""
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
    return unary_union(list(geoms))


def sheet_bounds(lam: Laminate) -> tuple[float, float, float, float]:
    """Everything the laser touches: release cut and alignment holes."""
    return union([lam.release, *lam.alignment_holes, box(*lam.design.bounds_mm)]).bounds
