"""What an outline drawing may hold, checked before it is expanded or flattened.

A laser outline is thousands of curves of millimetres to centimetres; a drawing far beyond that
(blocks nested in blocks, a spline of 200,000 points, an arc of a radius of 10^12 mm, a NaN)
would take hours or all the memory to read, so it is refused by a count made first, with the
entity named (:func:`entity_label`). :mod:`.dxf_read` reads the drawing through these checks.
"""

from __future__ import annotations

import math

from ..errors import FabError

# Block references are expanded this many levels deep, into at most this many entities: an
# outline for a laser is thousands of curves (50,000 circles read in about 9 s), and nested
# blocks multiply (8 levels of 10 references each are 10^8 copies, hours of expansion), so
# they are counted before any is expanded.
MAX_INSERT_DEPTH = 8
MAX_EXPANDED_ENTITIES = 50_000
# A SPLINE of more control or fit points than this is refused before it is flattened, and no
# curve is flattened into more vertices than MAX_CURVE_VERTICES: a laser outline's spline has
# tens to hundreds of points (500 flatten into about 2,000 vertices), while one of 200,000
# control points grew memory by 300 MB/s for minutes.
MAX_SPLINE_POINTS = 20_000
MAX_CURVE_VERTICES = 200_000


# An arc is flattened into chords no further than the sagitta from it: a circle of 10 m at
# 1 um is 7,000 chords. An arc needing more (a radius of 10^12 mm, a bulge of 1e300) is no
# outline for a laser and would take hours, so it is refused by its count before flattening.
MAX_ARC_SEGMENTS = 100_000


def reason(exc: Exception, n: int = 160) -> str:
    """What ``exc`` says, on one line, without its type's name, cut to ``n`` characters.

    Parameters
    ----------
    exc : Exception
    n : int, default 160
        The most characters kept.

    Returns
    -------
    str
    """
    text = " ".join(str(exc).split()).removeprefix(f"{type(exc).__name__}: ")
    return text if len(text) <= n else text[: n - 1] + "…"


def entity_label(entity) -> str:
    """An entity as a message names it: its type and handle, ``"LINE #1F"``.

    Parameters
    ----------
    entity : DXF entity

    Returns
    -------
    str
    """
    handle = entity.dxf.get("handle")
    return f"{entity.dxftype()} #{handle}" if handle else entity.dxftype()


def check_spline(entity, layer: str) -> None:
    """Refuse a SPLINE of more control or fit points than :data:`MAX_SPLINE_POINTS`, before it
    is flattened.

    Parameters
    ----------
    entity : DXF entity
        The SPLINE.
    layer : str
        Its layer, for the message.

    Raises
    ------
    FabError
    """
    n = max(entity.control_point_count(), entity.fit_point_count())
    if n > MAX_SPLINE_POINTS:
        raise FabError(f"layer {layer!r}: {entity_label(entity)} has {n:,} points, over the "
                       f"{MAX_SPLINE_POINTS:,} a cut outline's spline may have (refused before flattening it)",
                       "simplify the curve in the CAD program (fewer control points), or draw it as a polyline")


def _copies(entity) -> int:
    """How many times an INSERT places its block (a MINSERT is rows x columns)."""
    rows = max(int(entity.dxf.get("row_count", 1) or 1), 1)
    cols = max(int(entity.dxf.get("column_count", 1) or 1), 1)
    return rows * cols


def expanded_count(doc, entities, depth: int = 0, memo: dict | None = None) -> int:
    """How many entities ``entities`` become once their block references are expanded (as
    :func:`locust.fab.dxf_read.read_drawing` expands them), counted from the block definitions
    without expanding.

    Parameters
    ----------
    doc : ezdxf document
        The drawing (its block definitions).
    entities : iterable of DXF entities
        The entities, e.g. the model space.
    depth : int, default 0
        The nesting level of ``entities``.
    memo : dict, optional
        Counts of blocks already counted, by (name, depth).

    Returns
    -------
    int
        The count; it stops early once over ``MAX_EXPANDED_ENTITIES``.
    """
    memo = {} if memo is None else memo
    total = 0
    for entity in entities:
        total += 1
        if entity.dxftype() != "INSERT" or depth >= MAX_INSERT_DEPTH:
            continue
        name = entity.dxf.get("name")
        key = (name, depth + 1)
        if key not in memo:
            block = doc.blocks.get(name) if name else None
            memo[key] = 0 if block is None else expanded_count(doc, block, depth + 1, memo)
        total += _copies(entity) * memo[key]
        if total > MAX_EXPANDED_ENTITIES:
            return total
    return total


def check_expansion(doc, path) -> None:
    """Refuse a drawing whose block references expand into more than ``MAX_EXPANDED_ENTITIES``.

    Parameters
    ----------
    doc : ezdxf document
        The drawing.
    path : str or Path
        Its file, for the message.

    Raises
    ------
    FabError
        Too many entities once expanded.
    """
    n = expanded_count(doc, doc.modelspace())
    if n > MAX_EXPANDED_ENTITIES:
        raise FabError(
            f"{path}: its block references expand into more than {MAX_EXPANDED_ENTITIES:,} entities "
            f"(blocks nested in blocks multiply; counted before expanding)",
            "explode the blocks in the CAD program and keep only the outline for the laser, "
            "or remove the repeated blocks",
        )


def _numbers(entity) -> list[float]:
    """Every coordinate, radius, bulge, ratio and knot ``entity`` is drawn from, as stored."""
    dxf, kind = entity.dxf, entity.dxftype()
    out: list[float] = []
    for attr in ("start", "end", "center", "major_axis", "radius", "ratio", "start_angle", "end_angle",
                 "start_param", "end_param"):
        value = dxf.get(attr) if dxf.is_supported(attr) else None
        if value is not None:
            out += list(value) if hasattr(value, "__iter__") else [value]
    if kind == "LWPOLYLINE":
        out += [v for point in entity.get_points("xyb") for v in point]
    elif kind == "POLYLINE":
        for v in entity.vertices:
            out += [*v.dxf.location, v.dxf.get("bulge", 0.0)]
    elif kind == "SPLINE":
        out += [c for p in (*entity.control_points, *entity.fit_points) for c in p] + list(entity.knots)
    return [float(v) for v in out]


def _arc_segments(radius: float, angle_rad: float, sagitta: float) -> float:
    """Chords an arc of ``radius`` through ``angle_rad`` takes to stay within ``sagitta``."""
    if not radius > sagitta:
        return 1.0
    x = sagitta / radius
    step = 2.0 * (math.acos(1.0 - x) if x > 1e-8 else math.sqrt(2.0 * x))   # acos(1 - x) ~ sqrt(2x)
    return abs(angle_rad) / step if step > 0 else math.inf


def _bulge_segments(entity, sagitta: float) -> float:
    """The most chords any bulged segment of a polyline takes."""
    if entity.dxftype() == "LWPOLYLINE":
        pts = [(x, y, b) for x, y, b in entity.get_points("xyb")]
    else:
        pts = [(v.dxf.location[0], v.dxf.location[1], v.dxf.get("bulge", 0.0)) for v in entity.vertices]
    most = 0.0
    for (x0, y0, b), (x1, y1, _) in zip(pts, pts[1:] + pts[:1]):
        chord = math.hypot(x1 - x0, y1 - y0)
        if b and chord > 0:
            angle = 4.0 * math.atan(abs(b))
            radius = chord / (2.0 * math.sin(angle / 2.0)) if math.sin(angle / 2.0) > 0 else math.inf
            most = max(most, _arc_segments(radius, angle, sagitta) if math.isfinite(radius) else math.inf)
    return most


def check_entity(entity, layer: str, sagitta: float) -> None:
    """Refuse an entity that holds a number that is not finite, or an arc that would flatten into
    more than :data:`MAX_ARC_SEGMENTS` chords.

    Parameters
    ----------
    entity : DXF entity
        The curve.
    layer : str
        Its layer, for the message.
    sagitta : float
        The largest distance of a chord from its arc [drawing units].

    Raises
    ------
    FabError
        The entity cannot be read, holds NaN or inf, or flattens into too many chords.
    """
    try:
        numbers = _numbers(entity)
    except (TypeError, ValueError, AttributeError) as exc:
        raise FabError(f"layer {layer!r}: {entity_label(entity)} cannot be read ({reason(exc)})",
                       "fix the drawing in the CAD program, or redraw that entity") from None
    if not all(math.isfinite(v) for v in numbers):
        raise FabError(f"layer {layer!r}: {entity_label(entity)} has a coordinate, radius or bulge that is not a "
                       "finite number (NaN or inf)", "fix the drawing in the CAD program, or redraw that entity")
    kind = entity.dxftype()
    if kind in ("ARC", "CIRCLE"):
        segments = _arc_segments(abs(entity.dxf.radius), 2 * math.pi, sagitta)
    elif kind == "ELLIPSE":
        axis = entity.dxf.major_axis
        segments = _arc_segments(math.hypot(axis[0], axis[1]), 2 * math.pi, sagitta)
    elif kind in ("LWPOLYLINE", "POLYLINE"):
        segments = _bulge_segments(entity, sagitta)
    else:
        segments = 0.0
    if segments > MAX_ARC_SEGMENTS:
        raise FabError(f"layer {layer!r}: {entity_label(entity)} is an arc that flattens into {segments:.3g} chords, "
                       f"over the limit of {MAX_ARC_SEGMENTS:,} (a radius or bulge far beyond a laminate part's)",
                       "check the drawing's units and that arc's radius (or the polyline's bulge), and redraw it")
