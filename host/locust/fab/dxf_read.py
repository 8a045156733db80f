"""Read an outline drawing into contours in millimetres.

Every curve a drawing program writes for a cut outline is accepted: LINE, ARC,
LWPOLYLINE (bulges included), POLYLINE, CIRCLE, ELLIPSE and SPLINE, also inside block
references. Closed entities are loops as they stand; open pieces are chained into loops
with ezdxf's edge miner when their ends meet within ``gap_tol_mm``. What is left open is
returned open, with the entities it came from, so the caller can say where the gap is.

Units come from ``$INSUNITS`` (``units`` overrides them); a unitless drawing is read as
millimetres and says so. Geometry leaves this module in millimetres and nowhere else
is a unit converted. What a drawing may hold (block copies, spline points, arc chords, finite
numbers) is checked by :mod:`.dxf_limits` before it is expanded or flattened.
"""

from __future__ import annotations

import contextlib
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FabError
from .dxf_limits import (
    MAX_CURVE_VERTICES,
    MAX_INSERT_DEPTH,
    check_entity,
    check_expansion,
    check_spline,
    entity_label,
    reason,
)

# $INSUNITS code -> (name, millimetres per unit). Exact factors: ezdxf's own table
# carries float noise (25.4000000001 mm per inch).
INSUNITS: dict[int, tuple[str, float]] = {
    1: ("in", 25.4), 2: ("ft", 304.8), 3: ("mi", 1_609_344.0), 4: ("mm", 1.0),
    5: ("cm", 10.0), 6: ("m", 1000.0), 7: ("km", 1e6), 8: ("microinch", 25.4e-6),
    9: ("mil", 0.0254), 10: ("yd", 914.4), 11: ("angstrom", 1e-7), 12: ("nm", 1e-6),
    13: ("um", 1e-3), 14: ("dm", 100.0),
}
UNIT_BY_NAME: dict[str, tuple[int, float]] = {name: (code, mm) for code, (name, mm) in INSUNITS.items()}

CURVES = {"LINE", "ARC", "LWPOLYLINE", "POLYLINE", "CIRCLE", "ELLIPSE", "SPLINE"}

# The gap two ends may leave and still be joined: above 0 (0 joins nothing, below 0 is no
# distance) and at most 10 mm (a laminate part is millimetres to centimetres).
GAP_TOL_MM = (0.0, 10.0)


@dataclass(frozen=True)
class Contour:
    """One loop or open path of a drawing layer, in millimetres.

    Attributes
    ----------
    layer : str
        The DXF layer.
    points_mm : numpy.ndarray
        (n, 2) vertices [mm]; a loop does not repeat its first point.
    closed : bool
        A loop (three or more vertices).
    entities : tuple of str
        The entities it came from, e.g. ``("LINE #1F", "ARC #20")``.
    """

    layer: str
    points_mm: np.ndarray          # (n, 2); a loop does not repeat its first point
    closed: bool
    entities: tuple[str, ...]      # e.g. ("LINE #1F", "ARC #20"): where it came from

    @property
    def start_mm(self) -> tuple[float, float]:
        """The first vertex (x, y) [mm]."""
        return tuple(self.points_mm[0])

    @property
    def end_mm(self) -> tuple[float, float]:
        """The last vertex (x, y) [mm]."""
        return tuple(self.points_mm[-1])


@dataclass(frozen=True)
class Drawing:
    """Every curve of a DXF file as contours in millimetres.

    Attributes
    ----------
    path : Path
        The file read.
    units : str
        The drawing's unit: ``mm``, ``cm``, ``in``, ...
    mm_per_unit : float
        Millimetres per drawing unit.
    units_from : str
        ``$INSUNITS``, ``--units``, or ``assumed (no $INSUNITS)``.
    contours : tuple of Contour
        The loops and open paths, two vertices or more.
    skipped : dict of str to int
        Entity types that are not curves, and how many of each.
    recovered : int
        Problems fixed by ezdxf's recover mode.
    points : tuple of Contour
        Pieces shorter than the gap tolerance, one point each (for the caller to name).
    """

    path: Path
    units: str                     # "cm", "in", ...
    mm_per_unit: float
    units_from: str                # "$INSUNITS", "--units", or "assumed (no $INSUNITS)"
    contours: tuple[Contour, ...]
    skipped: dict[str, int] = field(default_factory=dict)   # entity type -> count, not curves
    recovered: int = 0             # problems fixed by ezdxf's recover mode
    points: tuple[Contour, ...] = ()   # pieces shorter than the gap tolerance: one point each

    def layers(self) -> list[str]:
        """The layers that hold contours.

        Returns
        -------
        list of str
            Layer names, sorted.
        """
        return sorted({c.layer for c in self.contours})


def open_document(path: str | Path, *, recover: bool = False):
    """Open a DXF strictly (or with ezdxf's recover mode); any failure is a FabError.

    Parameters
    ----------
    path : str or Path
        The DXF file.
    recover : bool, default False
        Read a damaged file with ezdxf's recover mode.

    Returns
    -------
    tuple
        (ezdxf document, number of problems the recover mode fixed).

    Raises
    ------
    FabError
        No such file, an empty file, or one ezdxf cannot read (or recover).
    """
    import ezdxf
    from ezdxf import recover as ezrecover

    path = Path(path)
    if not path.is_file():
        raise FabError(f"{path}: no such file", "give the path of a .dxf drawing")
    if path.stat().st_size == 0:
        raise FabError(f"{path}: the file is empty", "export the drawing again from the CAD program")
    fixed = 0
    try:
        if recover:
            doc, auditor = ezrecover.readfile(path)
            if auditor.has_errors:
                first = auditor.errors[0].message if auditor.errors else "unrecoverable"
                raise FabError(f"{path}: damaged beyond repair ({first})",
                               "export the drawing again from the CAD program")
            fixed = len(auditor.fixes)
        else:
            doc = ezdxf.readfile(path)
    except FabError:
        raise
    except Exception as exc:  # ezdxf raises many types on garbage (structure, decode, value)
        raise FabError(
            f"{path}: not a readable DXF ({type(exc).__name__}: {reason(exc)})",
            "export the drawing again; if it is truncated, --recover reads what is left",
        ) from None
    return doc, fixed


def drawing_units(doc, override: str | None) -> tuple[str, float, str]:
    """The drawing's unit: ``override`` if given, else ``$INSUNITS``, else millimetres assumed.

    Parameters
    ----------
    doc : ezdxf document
        The drawing.
    override : str or None
        A unit name from ``--units`` (``mm``, ``cm``, ``in``, ...).

    Returns
    -------
    tuple
        (unit name, millimetres per unit, where the unit came from).

    Raises
    ------
    FabError
        An unknown unit name, or an ``$INSUNITS`` code that is no length unit locust knows.
    """
    if override:
        if override not in UNIT_BY_NAME:
            raise FabError(f"unknown unit {override!r}", f"use one of {', '.join(UNIT_BY_NAME)}")
        return override, UNIT_BY_NAME[override][1], "--units"
    code = int(doc.header.get("$INSUNITS", 0) or 0)
    if code in INSUNITS:
        name, mm = INSUNITS[code]
        return name, mm, "$INSUNITS"
    if code != 0:   # 0 is "unitless"; any other code this table lacks is not a length unit it can read
        raise FabError(f"$INSUNITS = {code} is not a drawing unit locust knows "
                       f"({', '.join(f'{c} {n}' for c, (n, _) in sorted(INSUNITS.items()))})",
                       f"give the drawing's unit with --units ({', '.join(UNIT_BY_NAME)})")
    return "mm", 1.0, "assumed (no $INSUNITS)"


def _entities_by_layer(msp) -> tuple[dict[str, list], Counter]:
    """Model-space curves grouped by layer; block references are expanded in place."""
    by_layer: dict[str, list] = defaultdict(list)
    skipped: Counter = Counter()

    def visit(entity, inherited: str | None, depth: int) -> None:
        kind = entity.dxftype()
        layer = entity.dxf.get("layer", "0")
        if inherited is not None and layer == "0":
            layer = inherited                     # DXF rule: layer 0 in a block takes the insert's
        if kind == "INSERT" and depth < MAX_INSERT_DEPTH:
            for sub in entity.virtual_entities():
                visit(sub, layer, depth + 1)
        elif kind in CURVES:
            if kind == "SPLINE":
                check_spline(entity, layer)
            by_layer[layer].append(entity)
        else:
            skipped[kind] += 1

    for entity in msp:
        visit(entity, None, 0)
    return by_layer, skipped


def _flat(path, sagitta: float, layer: str, labels: tuple[str, ...]) -> np.ndarray:
    """``path`` as vertices ``sagitta`` from the curve, at most MAX_CURVE_VERTICES of them."""
    vertices = []
    for v in path.flattening(distance=sagitta):
        vertices.append((v.x, v.y))
        if len(vertices) > MAX_CURVE_VERTICES:
            raise FabError(f"layer {layer!r}: {', '.join(labels[:3])} flattens into more than "
                           f"{MAX_CURVE_VERTICES:,} vertices (refused before the rest)",
                           "simplify the curve in the CAD program, or split it into shorter pieces")
    pts = np.array(vertices, dtype=float).reshape(-1, 2)
    if not np.isfinite(pts).all():   # (before the repeats are dropped: NaN is never "repeated")
        raise FabError(f"layer {layer!r}: {', '.join(labels[:3])} has a vertex that is not a finite number "
                       "(NaN or inf)", "fix the drawing in the CAD program, or redraw that entity")
    if len(pts) > 1:   # drop repeated vertices (segment joints)
        keep = np.r_[True, np.any(np.abs(np.diff(pts, axis=0)) > 1e-12, axis=1)]
        pts = pts[keep]
    return pts


def _trace_key(entity, edge, gap: float) -> tuple:
    """Where an open piece runs, to ``gap``: its two ends (either way round) and its middle."""
    from ezdxf import path as ezpath

    def q(v) -> tuple[int, int]:
        return round(v[0] / gap), round(v[1] / gap)

    try:
        pts = list(ezpath.make_path(entity).flattening(distance=gap))
        middle = q(pts[len(pts) // 2]) if len(pts) > 2 else None
    except Exception:  # a path ezdxf cannot make: keep the piece (an entity key of its own)
        middle = id(entity)
    ends = tuple(sorted((q(edge.start), q(edge.end))))
    return ends, middle


def _anchor(entity) -> np.ndarray | None:
    """Where a degenerate entity (no length, zero radius) lies: its centre, start or first vertex."""
    for attr in ("center", "start"):
        value = entity.dxf.get(attr) if entity.dxf.is_supported(attr) else None
        if value is not None:
            return np.array([[value[0], value[1]]], dtype=float)
    with contextlib.suppress(Exception):
        first = next(iter(entity.vertices()))
        return np.array([[first[0], first[1]]], dtype=float)
    return None


def layer_contours(entities: list, layer: str, *, mm_per_unit: float, gap_tol_mm: float,
                   sagitta_mm: float) -> list[Contour]:
    """The loops and open paths of one layer's curves: closed entities as they stand, open ones
    chained with ezdxf's edge miner where their ends meet within the gap tolerance.

    Parameters
    ----------
    entities : list of DXF entities
        The layer's curves.
    layer : str
        The layer's name.
    mm_per_unit : float
        Millimetres per drawing unit.
    gap_tol_mm : float
        The gap two ends may leave and still be joined [mm].
    sagitta_mm : float
        The largest distance of a chord from its curve when flattening [mm].

    Returns
    -------
    list of Contour
        The contours [mm]; a piece that collapses to a point is one of a single vertex.

    Raises
    ------
    FabError
        An entity that cannot be read, is not finite, or is too large to flatten.
    """
    gap, sag = gap_tol_mm / mm_per_unit, sagitta_mm / mm_per_unit
    pieces, open_entities = _closed_pieces(entities, layer, sag)
    edges, points = _open_edges(open_entities, gap)
    pieces += points + _chains(edges, layer, gap, sag)
    contours = (_contour(layer, piece, gap, mm_per_unit) for piece in pieces)
    return [c for c in contours if c is not None]


# a piece of a layer before it is a Contour: vertices [drawing units], closed, where it came from
_Piece = tuple[np.ndarray, bool, tuple[str, ...]]


def _closed_pieces(entities: list, layer: str, sag: float) -> tuple[list[_Piece], list]:
    """Each closed entity flattened, and each degenerate one (zero radius, no vertices) as its
    point, in the layer's order; the open entities apart, for the edge miner."""
    from ezdxf import edgesmith as es
    from ezdxf import path as ezpath

    pieces, open_entities = [], []
    for entity in entities:
        check_entity(entity, layer, sag)
        labels = (entity_label(entity),)
        try:
            closed = es.is_closed_entity(entity)
        except MemoryError:
            raise FabError(f"layer {layer!r}: {labels[0]} is too large to read",
                           "simplify it in the CAD program") from None
        except Exception:  # degenerate entity (zero radius, no vertices): a point the caller names
            point = _anchor(entity)
            if point is not None:
                pieces.append((point, False, labels))
            continue
        if closed:
            pieces.append((_flat(ezpath.make_path(entity), sag, layer, labels), True, labels))
        else:
            open_entities.append(entity)
    return pieces, open_entities


def _open_edges(open_entities: list, gap: float) -> tuple[list, list[_Piece]]:
    """The open entities as the edge miner's edges, each trace once, and those shorter than the
    gap tolerance (or of zero radius) as their points."""
    from ezdxf import edgesmith as es

    edges, points, seen = [], [], set()
    for entity in open_entities:
        edge = es.make_edge_2d(entity, gap_tol=gap)
        if edge is None:                  # shorter than the gap tolerance (or of zero radius)
            point = _anchor(entity)
            if point is not None:
                points.append((point, False, (entity_label(entity),)))
            continue
        # an entity drawn twice over itself (same ends, same middle) is one cut: chaining every
        # copy multiplies the chains the edge miner tries (10,000 stacked lines ran for minutes)
        key = _trace_key(entity, edge, gap)
        if key not in seen:
            seen.add(key)
            edges.append(edge)
    return edges, points


def _chains(edges: list, layer: str, gap: float, sag: float) -> list[_Piece]:
    """The edges chained where their ends meet within ``gap``, each chain flattened."""
    from ezdxf import edgeminer as em
    from ezdxf import edgesmith as es

    if not edges:
        return []
    chains = []
    for chain in em.find_all_simple_chains(em.Deposit(edges, gap_tol=gap)):
        labels = tuple(entity_label(e.payload) for e in chain)
        chains.append((_flat(es.path2d_from_chain(chain), sag, layer, labels), em.is_loop(chain, gap_tol=gap), labels))
    return chains


def _contour(layer: str, piece: _Piece, gap: float, mm_per_unit: float) -> Contour | None:
    """A piece in millimetres: a loop without its closing repeat; a "loop" of two points is a
    line there and back, open; a piece collapsed to a point is kept for the caller to name."""
    pts, closed, labels = piece
    if closed and len(pts) > 2 and np.hypot(*(pts[0] - pts[-1])) <= gap:
        pts = pts[:-1]
    closed = closed and len(pts) >= 3
    if len(pts) >= 2:
        return Contour(layer, pts * mm_per_unit, closed, labels)
    if len(pts):
        return Contour(layer, pts[:1] * mm_per_unit, False, labels)
    return None


def read_drawing(path: str | Path, *, units: str | None = None, gap_tol_mm: float = 0.01,
                 sagitta_mm: float = 0.001, recover: bool = False) -> Drawing:
    """Read every curve of ``path`` into contours in millimetres (see the module's description).

    Parameters
    ----------
    path : str or Path
        The DXF file.
    units : str, optional
        The drawing's unit, overriding ``$INSUNITS``.
    gap_tol_mm : float, default 0.01
        The gap two ends may leave and still be joined, above 0 and at most 10 [mm].
    sagitta_mm : float, default 0.001
        The largest distance of a chord from its curve when flattening [mm].
    recover : bool, default False
        Read a damaged file with ezdxf's recover mode.

    Returns
    -------
    Drawing
        The contours by layer, the units and where they came from, what was skipped.

    Raises
    ------
    FabError
        A gap tolerance out of range, a file that cannot be read, an unknown unit, too many
        block copies, or a curve that is not finite or too large.
    """
    low, high = GAP_TOL_MM
    if not low < gap_tol_mm <= high:
        raise FabError(f"--gap-tol-mm {gap_tol_mm:g} must be above {low:g} and at most {high:g} mm: the gap two "
                       "ends may leave and still be joined", "the default, 0.01 mm, joins what a CAD program "
                       "drew as meeting; give at most the gap you see in the drawing")
    doc, fixed = open_document(path, recover=recover)
    unit_name, mm_per_unit, units_from = drawing_units(doc, units)
    check_expansion(doc, path)
    by_layer, skipped = _entities_by_layer(doc.modelspace())
    contours: list[Contour] = []
    for layer in sorted(by_layer):
        try:
            contours += layer_contours(by_layer[layer], layer, mm_per_unit=mm_per_unit,
                                       gap_tol_mm=gap_tol_mm, sagitta_mm=sagitta_mm)
        except FabError as exc:
            raise FabError(f"{path}: {exc.message}", exc.hint) from None
    for c in contours:
        if not np.isfinite(c.points_mm).all():
            raise FabError(f"{path}: layer {c.layer!r}: {', '.join(c.entities)} has a vertex that is not a "
                           "finite number (NaN or inf)", "fix the drawing in the CAD program, or redraw that entity")
    return Drawing(Path(path), unit_name, mm_per_unit, units_from,
                   tuple(c for c in contours if len(c.points_mm) >= 2), dict(skipped), fixed,
                   tuple(c for c in contours if len(c.points_mm) < 2))
