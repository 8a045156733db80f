"""``locust.fab``: the five-layer laminate cut files, from an outline DXF or a robot's links."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from ..fab import export, flat_pattern, laminate, preview
from ..fab.design import LayerMap, design_from_drawing
from ..fab.dxf_read import read_drawing
from ..fab.summary import summary
from ..fileio import json_text
from ..params import Robot


def make_cut_files(robot_or_dxf: Robot | str | Path, *, out: str | Path | None = None,
        layers: Mapping[str, Sequence[str]] | None = None, units: str | None = None, gap_tol_mm: float = 0.01,
        recover: bool = False, hinge_width_mm: float = 1.0, stack: Sequence[str] = laminate.SEED_STACK,
        mirror: Sequence[str] = (), kerf_mm: float = 0.05, support_width_mm: float = 2.0,
        jig_diameter_mm: float = 5.0, jig_spacing_mm: float = 10.0, glue_tab_mm: float = 20.0,
        slot_width_mm: float = 1.0, slot_length_mm: float = 13.0, previews: bool = True) -> dict:
    """Make the laminate's cut files, as ``locust fab`` does, and return its summary.

    Parameters
    ----------
    robot_or_dxf : Robot or path-like
        A robot (:func:`locust.robot`): the leg's flat pattern from its four link lengths; or
        an outline DXF (layers plate/body = outline, hinge_*/joints = hinges, holes, cuts).
    out : path-like, optional
        A new folder (refused if it holds files) for the DXF cut files, previews and
        ``summary.json``; default none: nothing is written, the summary is still made.
    layers : dict, optional
        Role (body, hinge, holes, cuts) -> the drawing's layer names for it (a DXF only).
    units : str, optional
        The drawing's units, overriding its $INSUNITS (a DXF only; unitless reads as mm).
    gap_tol_mm, recover, hinge_width_mm
        A DXF only: join outline ends this close; ezdxf's recover mode; the cut-out width
        made from a fold line.
    stack : sequence of str
        Layer materials, top to bottom.
    mirror : sequence of str
        Layers whose cut files are mirrored (e.g. ``["adhesive_bottom"]``).
    kerf_mm, support_width_mm, jig_diameter_mm, jig_spacing_mm : float
        The laser's cut width, the support web, the alignment holes' diameter and offset [mm].
    glue_tab_mm, slot_width_mm, slot_length_mm : float
        A robot only: the flat pattern's glue tab and hinge slots [mm].
    previews : bool, default True
        Write ``cut_pattern.png`` and ``laminate_layers.png`` with ``out``.

    Returns
    -------
    dict
        The manufacturing summary (``summary.json``'s content): the layer stack, areas in mm²,
        the hinges' positions in mm, the files written; from a robot also its ``assembly``
        (the crank's angle at rest, the servo axis, the push: what the cut files do not hold).

    Raises
    ------
    locust.errors.FabError
        A drawing that cannot be read or closed, a kerf that cannot be applied, an ``out``
        that holds files.

    Examples
    --------
    >>> import locust
    >>> summary = locust.make_cut_files(locust.robot("seed"))
    >>> [layer["name"] for layer in summary["stack"]]
    ['rigid_top', 'adhesive_top', 'flexible', 'adhesive_bottom', 'rigid_bottom']
    >>> summary["hinges_x_mm"]
    [40.0, 80.0, 100.0, 160.0]
    """
    out = Path(out) if out is not None else None
    if out is not None:
        export.check_out(out)
    fp = None
    if isinstance(robot_or_dxf, Robot):
        fp = flat_pattern.from_robot(robot_or_dxf, glue_tab_mm=glue_tab_mm, slot_width_mm=slot_width_mm,
                                     slot_length_mm=slot_length_mm)
        design = flat_pattern.design(fp)
    else:
        drawing = read_drawing(robot_or_dxf, units=units, gap_tol_mm=gap_tol_mm, recover=recover)
        layer_map = LayerMap().with_overrides({k: list(v) for k, v in (layers or {}).items()})
        design = design_from_drawing(drawing, layer_map, hinge_width_mm=hinge_width_mm, gap_tol_mm=gap_tol_mm)
    specs = laminate.stack_from_materials(list(stack), tuple(mirror))
    process = laminate.Process(kerf_mm=kerf_mm, support_width_mm=support_width_mm,
                               jig_diameter_mm=jig_diameter_mm, jig_spacing_mm=jig_spacing_mm)
    lam = laminate.build(design, specs, process)
    # the cut files are made with or without out: a kerf that cannot be applied is refused either way
    files: dict[str, bytes] = export.cut_files(lam)
    if out is None:
        files = {}
    else:
        if fp is not None:
            files["flat_pattern.dxf"] = flat_pattern.drawing_bytes(fp)
        if previews:
            files.update(preview.preview_files(lam))
    names = sorted(files) + (["summary.json"] if out is not None else [])
    result = summary(lam, hinges_x_mm=fp.hinges_x_mm if fp is not None else None, files=names,
                     out_dir=str(out) if out else None,
                     assembly=flat_pattern.assembly(robot_or_dxf) if fp is not None else None)
    if out is not None:
        files["summary.json"] = json_text(result).encode()
        export.publish(out, files)
    return result
