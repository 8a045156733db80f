"""``locust fab``: laminate cut files from an outline DXF or from the robot's link lengths."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

import click

from ..errors import FabError
from ..fab import laminate
from ..fab.design import parse_layer_options
from ..fab.dxf_read import UNIT_BY_NAME
from ..fab.summary import summary_text
from ..fileio import json_text
from ..io import robot_toml
from .options import FINITE, FiniteFloat

# a fold's cut-out is a millimetre or two wide (the seed's 1 mm); one of 50 mm takes a whole link away
MAX_HINGE_WIDTH_MM = 50.0


def _robot(spec: str):
    from .. import params
    from ..errors import GeometryError
    from ..sim.fourbar import assemble

    if spec in params.PRESETS:
        robot = params.preset(spec)
    elif Path(spec).suffix.lower() == ".toml" or Path(spec).exists():
        robot = robot_toml.load_robot(Path(spec))
        if robot.name in params.PRESETS and robot != params.preset(robot.name):
            robot = robot.renamed(Path(spec).stem)   # a changed preset keeps its name: say which file it is
    else:
        robot = None
    if robot is not None:
        g = robot.geometry
        try:
            assemble(g.ground_m, g.crank_m, g.coupler_m, g.leg_m, g.crank_start_deg)
        except GeometryError as exc:
            raise FabError(f"--from-robot {spec}: the linkage cannot close, so its flat pattern would fold into "
                           f"nothing: {exc.message}", exc.hint or "check geometry.*_m in the robot.toml") from None
        return robot
    raise FabError(f"--from-robot {spec!r}: neither a preset nor a robot.toml",
                   f"give one of {', '.join(params.PRESETS)} or the path of a robot.toml")


def _cad_check(out: Path, names: list[str]) -> dict:
    from ..fab import cadcheck

    bar = (click.progressbar(names, label="LibreCAD", file=sys.stderr, show_pos=True)
           if sys.stderr.isatty() else contextlib.nullcontext(names))
    results = {}
    with bar as items:
        for name in items:
            d = cadcheck.check_dxf(out / name)
            results[name] = {"painted_paths": d.painted_paths, "segments": d.segments}
    return results


@click.command()
@click.argument("dxf", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--from-robot", "from_robot", metavar="PRESET_OR_TOML", default=None,
              help="Draw the leg's flat pattern from a robot's four link lengths (a preset such as "
                   "seed/medium/large, or a robot.toml) instead of reading a DXF.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Write the cut files, previews and summary.json into this new folder "
                   "(refused if it holds files). Without it nothing is written.")
@click.option("--json", "as_json", is_flag=True, help="Print the manufacturing summary as JSON.")
@click.option("--layer", "layers", multiple=True, metavar="ROLE=NAME",
              help="Map a drawing layer (shell pattern) to a role: body, hinge, holes or cuts. "
                   "Replaces that role's defaults; repeatable.")
@click.option("--units", type=click.Choice(list(UNIT_BY_NAME)), default=None,
              help="Drawing units, overriding $INSUNITS (a unitless drawing is read as mm).")
@click.option("--gap-tol-mm", type=FINITE, default=0.01, show_default=True,
              help="Join open outline pieces whose ends are this close.")
@click.option("--recover", is_flag=True, help="Read a damaged DXF with ezdxf's recover mode.")
@click.option("--hinge-width-mm", type=FiniteFloat(positive=True, high=MAX_HINGE_WIDTH_MM), default=1.0,
              show_default=True,
              help="Width of the cut-out made from a fold line on a hinge layer.")
@click.option("--stack", default=",".join(laminate.SEED_STACK), show_default=True,
              help="Layer materials, top to bottom (rigid, adhesive, flexible).")
@click.option("--mirror", multiple=True, metavar="LAYER",
              help="Mirror this layer's cut files (e.g. adhesive_bottom, cut liner side up). Repeatable.")
@click.option("--kerf-mm", type=FINITE, default=0.05, show_default=True, help="Laser kerf (cut width).")
@click.option("--support-width-mm", type=FINITE, default=2.0, show_default=True,
              help="Support web: release cut this far outside the outline.")
@click.option("--jig-diameter-mm", type=FINITE, default=5.0, show_default=True, help="Alignment hole diameter.")
@click.option("--jig-spacing-mm", type=FINITE, default=10.0, show_default=True,
              help="Alignment holes this far out from the body's corners.")
@click.option("--glue-tab-mm", type=FINITE, default=20.0, show_default=True, help="With --from-robot: glue tab length.")
@click.option("--slot-width-mm", type=FINITE, default=1.0, show_default=True,
              help="With --from-robot: hinge slot width.")
@click.option("--slot-length-mm", type=FINITE, default=13.0, show_default=True,
              help="With --from-robot: hinge slot length.")
@click.option("--no-preview", is_flag=True, help="Skip the PNG previews.")
@click.option("--cad-check", is_flag=True, help="Open every written DXF in LibreCAD (headless) and check it draws.")
def fab(dxf, from_robot, out, as_json, layers, units, gap_tol_mm, recover, hinge_width_mm, stack, mirror,
        kerf_mm, support_width_mm, jig_diameter_mm, jig_spacing_mm, glue_tab_mm, slot_width_mm,
        slot_length_mm, no_preview, cad_check):
    """Generate the five-layer laminate cut files (DXF, mm).

    \b
    From a drawing (layers plate/body = outline, hinge_*/joints = hinges, holes, cuts):
      locust fab zz.dxf --out cut/
      locust fab part.dxf --layer body=outline --mirror adhesive_bottom --out cut/
    From the robot's link lengths (the leg's flat pattern; hinges at the running sums of
    ground, crank, coupler, leg):
      locust fab --from-robot seed --json
      locust fab --from-robot calibration/robot.toml --out cut/

    Writes rigid_top, adhesive_top, flexible, adhesive_bottom, rigid_bottom,
    combined_cut_pattern, first_pass_cuts and final_perimeter (.dxf), cut_pattern.png,
    laminate_layers.png and summary.json. Areas are as designed; cut paths are
    kerf-compensated. Nothing is written unless every file could be made.
    """
    if (dxf is None) == (from_robot is None):
        raise FabError("give a DXF drawing or --from-robot, not both" if dxf else "nothing to draw",
                       "e.g. `locust fab zz.dxf --out cut/` or `locust fab --from-robot seed --json`")
    from ..api.fabrication import make_cut_files

    result = make_cut_files(_robot(from_robot) if from_robot else dxf, out=out, layers=parse_layer_options(layers),
                            units=units, gap_tol_mm=gap_tol_mm, recover=recover, hinge_width_mm=hinge_width_mm,
                            stack=stack.split(","), mirror=tuple(mirror), kerf_mm=kerf_mm,
                            support_width_mm=support_width_mm, jig_diameter_mm=jig_diameter_mm,
                            jig_spacing_mm=jig_spacing_mm, glue_tab_mm=glue_tab_mm, slot_width_mm=slot_width_mm,
                            slot_length_mm=slot_length_mm, previews=not no_preview)
    if out is not None and cad_check:
        result["cad_check"] = _cad_check(out, [n for n in result["files"] if n.endswith(".dxf")])
    if as_json:
        click.echo(json_text(result), nl=False)
    else:
        click.echo(summary_text(result))
        if out is None:
            click.echo("(no --out: nothing written)")
        if "cad_check" in result:
            click.echo(f"LibreCAD drew every file: {sum(v['segments'] for v in result['cad_check'].values())} segments")
