"""From drawing contours to a design: what is body, hinge, hole and slit.

Layers are given roles by name (case-insensitive shell patterns). The defaults cover the
seed's ``plate`` / ``hinge_N`` and the course files' ``body`` / ``joints`` /
``hinge_mountain`` / ``hinge_valley`` / ``holes`` / ``cuts``:

- body: closed outlines; nested loops alternate material and hole (even-odd), touching
  pieces are joined. An open body outline is an error that names the gap. Outlines that
  overlap without one holding the other are joined (their union, material once) and the
  summary names each overlap.
- hinge: a closed outline is a hinge slot, used as drawn; an open path is a fold line,
  cut out ``hinge_width_mm`` wide (flat ends) across the body. A fold line that misses the
  body or has no length is an error that names its position.
- holes: closed outlines cut through every layer.
- cuts: closed outlines cut through every layer; open paths are slits (a single pass of
  the beam, zero width as designed). One drawing reads them otherwise: the seed notebook's
  own combined cut pattern (its Part 4's ``combined_cut_pattern.dxf``) holds the outline on
  ``plate`` and the hinge slots on ``cuts``, with no hinge layer, and its ``flexible.dxf`` has
  none of them: in a drawing of that shape (:func:`seed_combined_pattern`) the closed
  outlines on ``cuts`` are hinge slots, cut from the rigid and adhesive layers only, and the
  summary says so.

A drawing with no hinge at all cuts the flexible layer as the others; the summary says that
too (a laminate's flexible layer is there to be its hinges).
"""

from __future__ import annotations

import fnmatch
from dataclasses import dataclass, field

import numpy as np
from shapely import STRtree, unary_union
from shapely.geometry import LineString, MultiPolygon, Polygon
from shapely.validation import explain_validity

from ..errors import FabError
from .dxf_read import Contour, Drawing

ROLES = ("body", "hinge", "holes", "cuts")

DEFAULT_LAYER_MAP: dict[str, tuple[str, ...]] = {
    "body": ("plate", "body", "outline"),
    "hinge": ("hinge", "hinge_*", "hinges", "joints", "joint", "joint_*", "hinge_mountain",
              "hinge_valley", "mountain", "valley", "fold", "folds"),
    "holes": ("holes", "hole", "hole_*"),
    "cuts": ("cuts", "cut", "cut_*", "slits"),
}


@dataclass(frozen=True)
class HingeCut:
    """One hinge: a slot cut out of the rigid and adhesive layers."""

    layer: str
    kind: str                      # "slot" (closed outline as drawn) or "fold" (fold line)
    polygon: Polygon               # the cut-out, mm, inside the body

    @property
    def area_mm2(self) -> float:
        """The cut-out's area [mm²]."""
        return float(self.polygon.area)

    def table_row(self) -> dict:
        """The hinge as a row of the manufacturing summary's hinge table.

        Returns
        -------
        dict
            ``layer``, ``kind``, and the cut-out's centre, extent and area, each in mm (mm²),
            rounded to 0.1 µm.
        """
        x0, y0, x1, y1 = self.polygon.bounds
        return {"layer": self.layer, "kind": self.kind,
                "center_x_mm": round((x0 + x1) / 2, 4), "center_y_mm": round((y0 + y1) / 2, 4),
                "y_min_mm": round(y0, 4), "y_max_mm": round(y1, 4),
                "width_mm": round(x1 - x0, 4), "height_mm": round(y1 - y0, 4),
                "area_mm2": round(self.area_mm2, 4)}


@dataclass(frozen=True)
class Design:
    """A flat part as designed, in millimetres."""

    body: Polygon | MultiPolygon
    hinges: tuple[HingeCut, ...] = ()
    holes: tuple[Polygon, ...] = ()                # through every layer
    slits: tuple[LineString, ...] = ()             # through every layer, zero width
    source: str = ""
    units: str = "mm"
    units_from: str = ""
    layer_roles: dict[str, str] = field(default_factory=dict)    # drawing layer -> role
    ignored_layers: tuple[str, ...] = ()
    joined: tuple[str, ...] = ()                   # overlapping body outlines joined, and where
    notes: tuple[str, ...] = ()                    # how the layers were read, where a person should know

    @property
    def bounds_mm(self) -> tuple[float, float, float, float]:
        """The body's bounding box, (x min, y min, x max, y max) [mm]."""
        return tuple(float(v) for v in self.body.bounds)

    def hinge_union(self):
        """Every hinge's cut-out as one shape.

        Returns
        -------
        shapely.geometry.base.BaseGeometry
            The union of the hinges' polygons [mm] (empty without hinges).
        """
        return unary_union([h.polygon for h in self.hinges])

    def hole_union(self):
        """Every hole as one shape.

        Returns
        -------
        shapely.geometry.base.BaseGeometry
            The union of the holes [mm] (empty without holes).
        """
        return unary_union(list(self.holes))


@dataclass(frozen=True)
class LayerMap:
    """Which drawing layers play which role (body, hinge, hole, slit, ignore).

    Attributes
    ----------
    patterns : dict of str to tuple of str
        Role -> the layer-name patterns (``fnmatch``, case-insensitive) that give it.
    """

    patterns: dict[str, tuple[str, ...]] = field(default_factory=lambda: dict(DEFAULT_LAYER_MAP))

    def with_overrides(self, items: dict[str, list[str]]) -> LayerMap:
        """The map with some roles' patterns replaced.

        Parameters
        ----------
        items : dict of str to list of str
            Role -> patterns, e.g. ``{"body": ["outline_a"]}``: these replace the role's defaults.

        Returns
        -------
        LayerMap
            The new map.

        Raises
        ------
        locust.errors.FabError
            An unknown role.
        """
        for role in items:
            if role not in ROLES:
                raise FabError(f"unknown layer role {role!r}", f"roles are {', '.join(ROLES)}")
        return LayerMap({**self.patterns, **{r: tuple(v) for r, v in items.items()}})

    def is_default(self, role: str) -> bool:
        """Whether ``role`` keeps its default layer names (no ``--layer`` for it).

        Parameters
        ----------
        role : str

        Returns
        -------
        bool
        """
        return self.patterns[role] == DEFAULT_LAYER_MAP[role]

    def role_of(self, layer: str) -> str | None:
        """The role of a drawing layer.

        Parameters
        ----------
        layer : str
            The layer's name in the drawing.

        Returns
        -------
        str or None
            The first role (in ``ROLES`` order) one of whose patterns matches, or None.
        """
        name = layer.lower()
        for role in ROLES:
            if any(fnmatch.fnmatchcase(name, p.lower()) for p in self.patterns[role]):
                return role
        return None


def parse_layer_options(items: tuple[str, ...] | list[str]) -> dict[str, list[str]]:
    """``("body=outline", "hinge=fold_*", "hinge=creases")`` -> ``{"body": [...], ...}``."""
    out: dict[str, list[str]] = {}
    for item in items:
        role, sep, pattern = item.partition("=")
        if not sep or not pattern.strip():
            raise FabError(f"--layer {item!r}: expected ROLE=NAME", "e.g. --layer body=outline --layer hinge=folds")
        out.setdefault(role.strip().lower(), []).append(pattern.strip())
    return out


def _fmt(p) -> str:
    return f"({p[0]:.3f}, {p[1]:.3f}) mm"


def open_outline_error(layer: str, opens: list[Contour], gap_tol_mm: float) -> FabError:
    """Name the smallest gap between the loose ends of an open outline."""
    ends = [(c, which, np.asarray(getattr(c, which))) for c in opens for which in ("start_mm", "end_mm")]
    best = None
    for i, (ci, _wi, pi) in enumerate(ends):
        for cj, _wj, pj in ends[i + 1:]:
            if ci is cj and len(opens) > 1:
                continue
            d = float(np.hypot(*(pi - pj)))
            if best is None or d < best[0]:
                best = (d, pi, pj, ci, cj)
    d, pa, pb, ca, cb = best
    pieces = ", ".join(dict.fromkeys(ca.entities + cb.entities))
    if len(pieces) > 120:
        pieces = pieces[:119] + "…"
    return FabError(
        f"layer {layer!r}: the outline is not closed: a gap of {d:.4g} mm between {_fmt(pa)} "
        f"and {_fmt(pb)} ({pieces})",
        f"close the outline in the CAD program, or join pieces this far apart with "
        f"--gap-tol-mm {d * 1.5:.3g} (now {gap_tol_mm:g})",
    )


def _polygon(contour: Contour) -> Polygon:
    poly = Polygon(contour.points_mm)
    if not poly.is_valid:
        raise FabError(
            f"layer {contour.layer!r}: outline {', '.join(contour.entities[:3])} crosses itself "
            f"({explain_validity(poly)})",
            "fix the outline in the CAD program so it does not cross itself",
        )
    return poly


def join_overlaps(contours: list[Contour], polys: list[Polygon],
                  tol_mm2: float = 1e-6) -> tuple[list[Polygon], tuple[str, ...]]:
    """Outlines that overlap without one holding the other are joined into one (their union),
    before even-odd nesting, so an overlap is material once, never cut out. Returns the
    outlines and, for each overlap joined, where it is."""
    parent = list(range(len(polys)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    notes = []
    pairs = STRtree(polys).query(polys, predicate="intersects")     # (2, n): candidate pairs
    for i, j in sorted((int(i), int(j)) for i, j in pairs.T if i < j):
        p, q = polys[i], polys[j]
        if p.contains(q) or q.contains(p):
            continue
        common = p.intersection(q)
        if common.area <= tol_mm2:
            continue                       # touching pieces are joined by the union anyway
        x0, y0, x1, y1 = common.bounds
        notes.append(f"layer {contours[i].layer!r}: {', '.join(contours[i].entities[:2])} and "
                     f"{', '.join(contours[j].entities[:2])} overlap by {common.area:.4g} mm2 at "
                     f"x {x0:.3f} to {x1:.3f}, y {y0:.3f} to {y1:.3f} mm")
        parent[root(i)] = root(j)
    groups: dict[int, list[Polygon]] = {}
    for i, p in enumerate(polys):
        groups.setdefault(root(i), []).append(p)
    joined = [g[0] if len(g) == 1 else unary_union(g) for g in groups.values()]
    return [g for part in joined for g in getattr(part, "geoms", [part])], tuple(notes)


def even_odd(polys: list[Polygon]):
    """Material of nested loops: inside an even number of others is material, odd is a hole."""
    depth = [sum(1 for j, q in enumerate(polys) if j != i and q.contains(p)) for i, p in enumerate(polys)]
    geom = Polygon()
    for d, p in sorted(zip(depth, polys), key=lambda t: t[0]):
        geom = geom.union(p) if d % 2 == 0 else geom.difference(p)
    return geom


def fold_cutout(line: LineString, width_mm: float, body) -> Polygon | MultiPolygon:
    """The slot a fold line makes: the line widened to ``width_mm``, flat at its ends, inside the body.

    Parameters
    ----------
    line : shapely.geometry.LineString
        The fold line [mm].
    width_mm : float
        The slot's width [mm].
    body : shapely.geometry.Polygon or MultiPolygon
        The part's body [mm].

    Returns
    -------
    shapely.geometry.Polygon or MultiPolygon
        The cut-out [mm].
    """
    return line.buffer(width_mm / 2, cap_style="flat", join_style="mitre").intersection(body)


def _contours_by_role(drawing: Drawing, roles: dict[str, str | None]) -> dict[str, list[Contour]]:
    """The drawing's contours under their layer's role (those of layers without one left out)."""
    by_role: dict[str, list[Contour]] = {r: [] for r in ROLES}
    for c in drawing.contours:
        if roles[c.layer]:
            by_role[roles[c.layer]].append(c)
    return by_role


def _check_closed_body_and_holes(drawing: Drawing, layer_map: LayerMap, by_role: dict[str, list[Contour]],
                                 gap_tol_mm: float) -> None:
    """Refuse a drawing without a body outline, or with an open body or hole outline."""
    if not by_role["body"]:
        found = ", ".join(drawing.layers()) or "none with curves"
        raise FabError(
            f"{drawing.path}: no body outline: no layer named like {', '.join(layer_map.patterns['body'])} "
            f"(layers with curves: {found})",
            "name the outline's layer with --layer body=NAME",
        )
    for role in ("body", "holes"):
        opens = [c for c in by_role[role] if not c.closed]
        for layer in dict.fromkeys(c.layer for c in opens):
            raise open_outline_error(layer, [c for c in opens if c.layer == layer], gap_tol_mm)


def _check_no_zero_length_cut(drawing: Drawing, layer_map: LayerMap, gap_tol_mm: float) -> None:
    """A cut that cannot be made is an error, never a cut file without it."""
    for c in drawing.points:
        role = layer_map.role_of(c.layer)
        if role in ("hinge", "cuts", "holes"):
            what = {"hinge": "hinge", "cuts": "cut", "holes": "hole"}[role]
            raise FabError(f"layer {c.layer!r}: {what} {', '.join(c.entities)} at {_fmt(c.start_mm)} has no length "
                           f"(shorter than --gap-tol-mm {gap_tol_mm:g}, or of zero radius)",
                           "draw the fold line across the body, or delete it" if role == "hinge"
                           else "draw it to its size, or delete it")


def _hinge_cuts(contours: list[Contour], body, hinge_width_mm: float) -> list[HingeCut]:
    """Each hinge contour as a cut: a closed one is a slot, an open one a fold line's cut-out
    across the body (refused if it misses the body); ordered by position."""
    hinges: list[HingeCut] = []
    for c in contours:
        if c.closed:
            hinges.append(HingeCut(c.layer, "slot", _polygon(c)))
            continue
        cut = fold_cutout(LineString(c.points_mm), hinge_width_mm, body)
        if cut.is_empty or cut.area <= 0:
            raise FabError(f"layer {c.layer!r}: hinge {', '.join(c.entities[:3])} from {_fmt(c.start_mm)} "
                           f"to {_fmt(c.end_mm)} does not cross the body "
                           f"(x {body.bounds[0]:.3f} to {body.bounds[2]:.3f}, "
                           f"y {body.bounds[1]:.3f} to {body.bounds[3]:.3f} mm)",
                           "draw the fold line across the body, or put it on another layer")
        hinges.append(HingeCut(c.layer, "fold", cut))
    hinges.sort(key=lambda h: (round(h.polygon.bounds[0], 6), round(h.polygon.bounds[1], 6)))
    return hinges


def seed_combined_pattern(drawing: Drawing, layer_map: LayerMap, roles: dict[str, str | None]) -> list[str]:
    """The ``cuts`` layers that hold hinge slots, in the seed notebook's combined cut pattern:
    a drawing whose body is on ``plate`` (the seed's name for it), with no hinge layer, whose
    ``cuts`` layers hold closed outlines only, read with the default layer names (a
    ``--layer`` for hinge or cuts reads it as given).

    Parameters
    ----------
    drawing : Drawing
    layer_map : LayerMap
    roles : dict of str to str or None
        Each layer's role by its name.

    Returns
    -------
    list of str
        Those layers (none when the drawing is not of that shape).
    """
    if not (layer_map.is_default("hinge") and layer_map.is_default("cuts")) or "hinge" in roles.values():
        return []
    if not any(role == "body" and layer.lower() == "plate" for layer, role in roles.items()):
        return []
    cuts = [layer for layer, role in roles.items() if role == "cuts"]
    if not cuts or any(not c.closed for c in drawing.contours if c.layer in cuts):
        return []
    return cuts


def design_from_drawing(drawing: Drawing, layer_map: LayerMap | None = None, *,
                        hinge_width_mm: float = 1.0, gap_tol_mm: float = 0.01) -> Design:
    """The design a drawing gives: its body, hinges, holes and slits, by each layer's role.

    Parameters
    ----------
    drawing : Drawing
        The contours read from a DXF (:func:`locust.fab.dxf_read.read_drawing`).
    layer_map : LayerMap, optional
        Which layer names play which role (default: :class:`LayerMap`'s patterns).
    hinge_width_mm : float
        The width [mm] of the cut-out a fold line becomes.
    gap_tol_mm : float
        The gap [mm] the reader closed ends within (said in the errors).

    Returns
    -------
    Design

    Raises
    ------
    FabError
        No body; an open outline; a body of no area; a cut of no length; a hinge off the body.
    """
    layer_map = layer_map or LayerMap()
    roles = {layer: layer_map.role_of(layer) for layer in drawing.layers()}
    notes = []
    seed_slots = seed_combined_pattern(drawing, layer_map, roles)
    for layer in seed_slots:
        roles[layer] = "hinge"
        notes.append(f"layer {layer!r} read as the hinge slots, cut from the rigid and adhesive layers only: the "
                     "seed's combined cut pattern (outline on 'plate', slots on 'cuts', no hinge layer; its own "
                     "flexible.dxf has none of them); give --layer cuts=cuts to cut them through every layer")
    by_role = _contours_by_role(drawing, roles)
    _check_closed_body_and_holes(drawing, layer_map, by_role, gap_tol_mm)
    body_polys, joined = join_overlaps(by_role["body"], [_polygon(c) for c in by_role["body"]])
    body = even_odd(body_polys)
    if body.is_empty or body.area <= 0:
        raise FabError(f"{drawing.path}: the body outline encloses no area", "check the body layer")
    _check_no_zero_length_cut(drawing, layer_map, gap_tol_mm)
    hinges = _hinge_cuts(by_role["hinge"], body, hinge_width_mm)
    holes = tuple(_polygon(c) for c in by_role["holes"] + by_role["cuts"] if c.closed)
    slits = tuple(LineString(c.points_mm) for c in by_role["cuts"] if not c.closed)
    if not hinges:
        notes.append("no hinge in the drawing (no layer named like "
                     f"{', '.join(layer_map.patterns['hinge'][:4])}, ...): the flexible layer is cut as the others; "
                     "give --layer hinge=NAME for the layer that holds the hinges")
    return Design(
        body=body, hinges=tuple(hinges), holes=holes, slits=slits, source=str(drawing.path),
        units=drawing.units, units_from=drawing.units_from,
        layer_roles={k: v for k, v in roles.items() if v},
        ignored_layers=tuple(k for k, v in roles.items() if not v), joined=joined, notes=tuple(notes),
    )
