"""Read an outline drawing into contours in millimetres.

Every curve a drawing program writes for a cut outline is accepted: LINE, ARC,
LWPOLYLINE (bulges included), POLYLINE, CIRCLE, ELLIPSE and SPLINE, also inside block
references. Closed entities are loops as they stand; open pieces are chained into loops
with ezdxf's edge miner when their ends meet within ``gap_tol_mm``. What is left open is
returned open, with the entities it came from, so the caller can say where the gap is.

Units come from ``$INSUNITS`` (``units`` overrides them); a unitless drawing is read as
millimetres and says so. Geometry leaves this module in millimetres and nowhere else
is a unit converted.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FabError

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


@dataclass(frozen=True)
class Contour:
    """One loop or open path of a drawing layer, in millimetres."""

    layer: str
    points_mm: np.ndarray          # (n, 2); a loop does not repeat its first point
    closed: bool
    entities: tuple[str, ...]      # e.g. ("LINE #1F", "ARC #20"): where it came from

    @property
    def start_mm(self) -> tuple[float, float]:
        return tuple(self.points_mm[0])

    @property
    def end_mm(self) -> tuple[float, float]:
        return tuple(self.points_mm[-1])


@dataclass(frozen=True)
class Drawing:
    path: Path
    units: str                     # "cm", "in", ...
    mm_per_unit: float
    units_from: str                # "$INSUNITS", "--units", or "assumed (no $INSUNITS)"
    contours: tuple[Contour, ...]
    skipped: dict[str, int] = field(default_factory=dict)   # entity type -> count, not curves
    recovered: int = 0             # problems fixed by ezdxf's recover mode

    def layers(self) -> list[str]:
        return sorted({c.layer for c in self.contours})


def open_document(path: str | Path, *, recover: bool = False):
    """Open a DXF strictly (or with ezdxf's recover mode); any failure is a FabError."""
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
            f"{path}: not a readable DXF ({type(exc).__name__}: {_short(exc)})",
            "export the drawing again; if it is truncated, --recover reads what is left",
        ) from None
    return doc, fixed


def _short(exc: Exception, n: int = 160) -> str:
    text = " ".join(str(exc).split()).removeprefix(f"{type(exc).__name__}: ")
    return text if len(text) <= n else text[: n - 1] + "…"


def drawing_units(doc, override: str | None) -> tuple[str, float, str]:
    if override:
        if override not in UNIT_BY_NAME:
            raise FabError(f"unknown unit {override!r}", f"use one of {', '.join(UNIT_BY_NAME)}")
        return override, UNIT_BY_NAME[override][1], "--units"
    code = int(doc.header.get("$INSUNITS", 0) or 0)
    if code in INSUNITS:
        name, mm = INSUNITS[code]
        return name, mm, "$INSUNITS"
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
        if kind == "INSERT" and depth < 8:
            for sub in entity.virtual_entities():
                visit(sub, layer, depth + 1)
        elif kind in CURVES:
            by_layer[layer].append(entity)
        else:
            skipped[kind] += 1

    for entity in msp:
        visit(entity, None, 0)
    return by_layer, skipped


def _label(entity) -> str:
    handle = entity.dxf.get("handle")
    return f"{entity.dxftype()} #{handle}" if handle else entity.dxftype()


def _flat(path, sagitta: float) -> np.ndarray:
    pts = np.array([(v.x, v.y) for v in path.flattening(distance=sagitta)], dtype=float)
    if len(pts) > 1:   # drop repeated vertices (segment joints)
        keep = np.r_[True, np.any(np.abs(np.diff(pts, axis=0)) > 1e-12, axis=1)]
        pts = pts[keep]
    return pts


def layer_contours(entities: list, layer: str, *, mm_per_unit: float, gap_tol_mm: float,
                   sagitta_mm: float) -> list[Contour]:
    """The loops and open paths of one layer's curves."""
    from ezdxf import edgeminer as em
    from ezdxf import edgesmith as es
    from ezdxf import path as ezpath

    gap = gap_tol_mm / mm_per_unit
    sag = sagitta_mm / mm_per_unit
    out: list[Contour] = []

    def emit(pts: np.ndarray, closed: bool, labels: tuple[str, ...]) -> None:
        if closed and len(pts) > 2 and np.hypot(*(pts[0] - pts[-1])) <= gap:
            pts = pts[:-1]
        if len(pts) >= 2:
            out.append(Contour(layer, pts * mm_per_unit, closed, labels))

    open_pieces = []
    for entity in entities:
        try:
            closed = es.is_closed_entity(entity)
        except Exception:  # degenerate entity (zero radius, no vertices)
            continue
        if closed:
            emit(_flat(ezpath.make_path(entity), sag), True, (_label(entity),))
        else:
            open_pieces.append(entity)

    edges = [e for e in (es.make_edge_2d(ent, gap_tol=gap) for ent in open_pieces) if e is not None]
    if not edges:
        return out
    deposit = em.Deposit(edges, gap_tol=gap)
    for chain in em.find_all_simple_chains(deposit):
        labels = tuple(_label(e.payload) for e in chain)
        pts = _flat(es.path2d_from_chain(chain), sag)
        emit(pts, em.is_loop(chain, gap_tol=gap), labels)
    return out


def read_drawing(path: str | Path, *, units: str | None = None, gap_tol_mm: float = 0.01,
                 sagitta_mm: float = 0.001, recover: bool = False) -> Drawing:
    """Read every curve of ``path`` into contours in millimetres (see the module doc)."""
    doc, fixed = open_document(path, recover=recover)
    unit_name, mm_per_unit, units_from = drawing_units(doc, units)
    by_layer, skipped = _entities_by_layer(doc.modelspace())
    contours: list[Contour] = []
    for layer in sorted(by_layer):
        contours += layer_contours(by_layer[layer], layer, mm_per_unit=mm_per_unit,
                                   gap_tol_mm=gap_tol_mm, sagitta_mm=sagitta_mm)
    for c in contours:
        if not np.isfinite(c.points_mm).all():
            raise FabError(f"{path}: layer {c.layer!r}: {', '.join(c.entities)} has a vertex that is not a "
                           "finite number (NaN or inf)", "fix the drawing in the CAD program, or redraw that entity")
    return Drawing(Path(path), unit_name, mm_per_unit, units_from, tuple(contours),
                   dict(skipped), fixed)
