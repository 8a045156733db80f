"""The manufacturing summary: one dict (printed as text, or as ``--json``)."""

from __future__ import annotations

from dataclasses import asdict

from .laminate import Laminate


def _r(x: float, n: int = 4) -> float:
    return round(float(x), n)


def summary(lam: Laminate, *, hinges_x_mm: tuple[float, ...] | None = None,
            files: list[str] | None = None, out_dir: str | None = None, assembly: dict | None = None) -> dict:
    """The manufacturing summary of ``lam``, lengths rounded to 0.1 um.

    Parameters
    ----------
    lam : Laminate
        The laminate.
    hinges_x_mm : tuple of float, optional
        Hinge positions along the body [mm]; by default each hinge slot's centre from the
        body's left edge.
    files : list of str, optional
        The files written.
    out_dir : str, optional
        The folder they were written to.
    assembly : dict, optional
        From a robot: its design's figures the cut files do not hold
        (:func:`locust.fab.flat_pattern.assembly`).

    Returns
    -------
    dict
        Source and units, bounds [mm], layer stack with areas [mm^2], support web area
        [mm^2], hinge slots, hole and slit counts, alignment holes [mm], process settings,
        layer roles, ignored layers, joined overlaps, notes on how the layers were read and
        files.
    """
    d = lam.design
    x0, y0, x1, y1 = d.bounds_mm
    slots = [h.table_row() for h in d.hinges]
    if hinges_x_mm is None:
        hinges_x_mm = tuple(row["center_x_mm"] - x0 for row in slots)
    return {
        "source": d.source,
        "units": {"drawing": d.units, "from": d.units_from, "output": "mm"},
        "bounds_mm": {"min_x": _r(x0), "min_y": _r(y0), "max_x": _r(x1), "max_y": _r(y1),
                      "width": _r(x1 - x0), "height": _r(y1 - y0)},
        "stack": [{"name": L.spec.name, "material": L.spec.material, "mirror": L.spec.mirror} for L in lam.layers],
        "areas_mm2": {L.spec.name: _r(L.area_mm2) for L in lam.layers},
        "support_web_mm2": _r(lam.support_web.area),
        "slots": slots,
        "hinges_x_mm": [_r(x) for x in hinges_x_mm],
        "holes": len(d.holes),
        "slits": len(d.slits),
        "alignment_holes_mm": [[_r(h.centroid.x), _r(h.centroid.y)] for h in lam.alignment_holes],
        "process": asdict(lam.process),
        "layer_roles": d.layer_roles,
        "ignored_layers": list(d.ignored_layers),
        "joined_overlaps": list(d.joined),
        "notes": list(d.notes),
        "out": out_dir,
        "files": files or [],
        **({"assembly": assembly} if assembly is not None else {}),
    }


def summary_text(s: dict) -> str:
    """The summary as lines for people.

    Parameters
    ----------
    s : dict
        From :func:`summary`.

    Returns
    -------
    str
        The text, one fact a line.
    """
    b = s["bounds_mm"]
    p = s["process"]
    lines = [
        f"source: {s['source']}  (drawing units {s['units']['drawing']}, from {s['units']['from']}; output mm)",
        f"body: {b['width']:.3f} x {b['height']:.3f} mm  at ({b['min_x']:.3f}, {b['min_y']:.3f})",
        "layers (area as designed, before kerf compensation):",
    ]
    for layer in s["stack"]:
        mirror = "  mirrored" if layer["mirror"] else ""
        lines.append(f"  {layer['name']:18s} {layer['material']:9s} {s['areas_mm2'][layer['name']]:12.2f} mm2{mirror}")
    lines.append(f"support web: {s['support_web_mm2']:.2f} mm2 ({p['support_width_mm']:g} mm outside the outline)")
    if s["slots"]:
        lines.append("hinges:")
        lines.append(f"  {'layer':16s} {'kind':5s} {'x mm':>9s} {'y range mm':>19s} {'w x h mm':>15s}")
        for row in s["slots"]:
            lines.append(f"  {row['layer']:16s} {row['kind']:5s} {row['center_x_mm']:9.3f} "
                         f"{row['y_min_mm']:9.3f}-{row['y_max_mm']:<9.3f} "
                         f"{row['width_mm']:6.3f} x {row['height_mm']:<7.3f}")
    lines.append(f"holes: {s['holes']}   slits: {s['slits']}   alignment holes: {len(s['alignment_holes_mm'])} x "
                 f"{p['jig_diameter_mm']:g} mm, {p['jig_spacing_mm']:g} mm out from the corners")
    lines.append(f"kerf: {p['kerf_mm']:g} mm (outer contours out, holes in, by half)")
    if s["ignored_layers"]:
        lines.append(f"ignored layers (no role): {', '.join(s['ignored_layers'])}")
    for note in s["joined_overlaps"]:
        lines.append(f"overlapping outlines joined (union): {note}")
    for note in s.get("notes", []):
        lines.append(f"note: {note}")
    if "assembly" in s:
        a = s["assembly"]
        links = ", ".join(f"{k} {v:.1f}" for k, v in a["links_mm"].items())
        lines += [f"design: {a['robot']}: links {links} mm on a {a['link_width_mm']:.1f} mm strip",
                  f"assemble: the crank at rest at {a['crank_start_deg']:.1f} deg from the ground link (its servo "
                  f"horn on the spline there at the 0 deg command: docs/hardware.md), the servo axis "
                  f"{a['servo_axis_x_mm']:.1f} mm from the plate's centre",
                  f"hop: push {a['push_deg']:.1f} deg for {a['push_s'] * 1000:.0f} ms (`locust hop --config` with "
                  f"this robot file, or --push-deg {a['push_deg']:g} --push-ms {a['push_s'] * 1000:g})"]
    if s["files"]:
        lines.append(f"wrote {len(s['files'])} files to {s['out']}: {', '.join(s['files'])}")
    return "\n".join(lines)
