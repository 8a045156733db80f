"""``locust calibrate beam``: a cantilever's ring-down (or, with ``--static``, its deflection) fitted."""

from __future__ import annotations

from pathlib import Path

import click

from ...calibrate import jobs
from ...errors import CalibrationError
from ..options import FINITE, POSITIVE, import_options, time_options
from .options import output_options, static_writes_nothing, unwritten_static, window_option
from .output import finish


@click.command()
@click.argument("tracks", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--mass-kg", type=POSITIVE, required=True, help="Dropped tip mass [kg] (with --static: the tip load).")
@click.option("--marker", default=None, help="Marker of the beam tip in the track [default: the only one].")
@click.option("--length-m", type=POSITIVE, default=None,
              help="Free length of the beam, clamp to mass [m]; needed for the hinge values (k*L^2, b*L^2), "
                   "with --static for the bending stiffness E*I = k*L^3/3.")
@click.option("--beam-mass-kg", type=FINITE, default=0.0, show_default=True,
              help="The beam's own mass [kg]; 33/140 of it is added to the oscillating mass.")
@click.option("--start-s", type=FINITE, default=None,
              help="Fit from this time [default: the first swing after the drop].")
@click.option("--end-s", type=FINITE, default=None, help="Fit up to this time [default: end of the track].")
@click.option("--static", is_flag=True,
              help="A static deflection test, not a ring-down: the tip at rest, loaded, and settled; the "
                   "deflection from rest to settled, the stiffness m*g/deflection and (with --length-m) the "
                   "bending stiffness, each with a 95% interval. Nothing of it goes into robot.toml.")
@click.option("--rest-s", default=None, metavar="A,B",
              help="With --static: the rest window [s] [default: the start to where the loading begins].")
@click.option("--settled-s", default=None, metavar="A,B",
              help="With --static: the settled window [s] [default: where the loading ends to the end].")
@click.option("--scale-std-pct", type=FINITE, default=None, metavar="P",
              help="With --static: the scale's standard uncertainty [%] [default: a Tracker project's "
                   "calibration stick, its two ends placed to 0.25 px; else the scale taken as exact].")
@import_options
@time_options
@static_writes_nothing
@output_options
def beam(tracks, mass_kg, marker, length_m, beam_mass_kg, start_s, end_s, static, rest_s, settled_s, scale_std_pct,
         imports, timing, write_path, as_json, plot_path, no_plot, force):
    """Fit the beam tip's damped oscillation: stiffness, damping, and the model's hinge values.

    TRACKS is a `locust track` CSV, a Tracker project (.trk, .trz) or text export, or a
    t,x,y CSV of the beam tip (metres, or --units cm|mm). With --static, read the tip's
    static deflection under the load instead (the course's deflection test):

    \b
      locust calibrate beam Deflection_test.trk --static --mass-kg 0.095 --length-m 0.048
    """
    fit = jobs.beam(tracks, mass_kg, length_m=length_m, beam_mass_kg=beam_mass_kg, marker=marker,
                    start_s=start_s, end_s=end_s, imports=imports, timing=timing, static=static,
                    rest_s=window_option(rest_s, "--rest-s"), settled_s=window_option(settled_s, "--settled-s"),
                    scale_std_pct=scale_std_pct)
    if static:
        notes = fit.result.notes()
        unwritten = unwritten_static()
        if unwritten is not None:
            notes.append(f"nothing written to {unwritten}: no value of a robot file holds a cardstock beam's "
                         "stiffness (the model's links are rigid and its hinges are folds, whose stiffness "
                         "`locust calibrate hinge` measures: docs/servo.md, Hinges and links)")
        finish(fit, tracks, None, as_json, plot_path, no_plot, force, extra={"notes": notes})
        return
    if not fit.parameters and write_path:
        raise CalibrationError("--write needs --length-m: the hinge values are k*L^2 and b*L^2",
                               "measure the beam's free length from the clamp to the mass")
    finish(fit, tracks, write_path, as_json, plot_path, no_plot, force)

