"""``locust calibrate ramp``: static friction from critical ramp angles."""

from __future__ import annotations

from pathlib import Path

import click

from ...calibrate import jobs
from ...calibrate.ramp import READING_RESOLUTION_DEG
from ..options import POSITIVE, import_options, time_options
from .options import output_options
from .output import finish


@click.command()
@click.argument("data", nargs=-1, required=True, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--ramp-markers", default="ramp_a,ramp_b", show_default=True, metavar="A,B",
              help="For a ramp video track: markers at the two ends of the board.")
@click.option("--robot-marker", default="robot", show_default=True, help="For a ramp video track: the robot's marker.")
@click.option("--into", type=click.Choice(["foot", "nose"]), default="foot", show_default=True,
              help="Which friction the result is written to (contact.foot_friction or contact.nose_friction).")
@click.option("--resolution-deg", type=POSITIVE, default=READING_RESOLUTION_DEG, show_default=True,
              help="How finely each angle was read [deg] (a protractor's graduation); the trials' spread is "
                   "taken as at least resolution/sqrt(12), so trials read alike give an interval, not a point.")
@import_options
@time_options
@output_options
def ramp(data, ramp_markers, robot_marker, into, resolution_deg, imports, timing, write_path, as_json, plot_path,
         no_plot, force):
    """Static friction from critical ramp angles: mu = tan(mean angle), with a 95% interval.

    DATA: CSVs with an angle_deg column (one trial a row, degrees), and/or side-view
    tracks of a tilting ramp (one trial each; --units, --rename, --mirror act on them).
    """
    fit = jobs.ramp(list(data), into=into, ramp_markers=ramp_markers, robot_marker=robot_marker,
                    imports=imports, timing=timing, resolution_deg=resolution_deg)
    finish(fit, None if len(data) > 1 else Path(fit.source), write_path, as_json, plot_path, no_plot, force)

