"""``locust calibrate hinge``: a link's free swing on a flexure hinge fitted."""

from __future__ import annotations

from pathlib import Path

import click

from ...calibrate import jobs
from ...calibrate.hingeswing import GRAVITY_CHOICES
from ...calibrate.inputs import parse_floats
from ...progress import progress
from ..options import FINITE, POSITIVE, import_options, time_options
from .options import output_options
from .output import finish, interruptible

HINGE_LABEL = "fitting hinge swing ({stage}): evaluations of the swing"


@click.command()
@click.argument("tracks", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--inertia-kgm2", type=POSITIVE, required=True,
              help="The swinging link's moment of inertia about the hinge axis [kg*m^2], marker included "
                   "(calibration/protocols/hinge.md: a bar of mass m and length L hinged at one end: m*L^2/3).")
@click.option("--gravity", type=click.Choice(GRAVITY_CHOICES), required=True,
              help="in-plane: the link swings in a vertical plane (its weight pulls it down, -M*g*D*cos(angle), "
                   "straight down being the track's -y); out-of-plane: the hinge axis is vertical (no moment).")
@click.option("--mass-kg", type=POSITIVE, default=None, help="With --gravity in-plane: the swinging link's mass [kg].")
@click.option("--com-m", type=POSITIVE, default=None,
              help="With --gravity in-plane: hinge to the link's centre of mass [m], taken on the line from the "
                   "hinge to the marker.")
@click.option("--pivot", default=None, metavar="X,Y",
              help="The hinge's position in the track [m, after --units], held fixed [default: fitted with the "
                   "swing, from the centre of the circle through the marker's arc].")
@click.option("--marker", default=None, help="Marker on the swinging link [default: the only one].")
@click.option("--start-s", type=FINITE, default=None,
              help="Fit from this time [s] [default: the first turning point after the release, the end of "
                   "the first free swing].")
@click.option("--end-s", type=FINITE, default=None, help="Fit up to this time [s] [default: end of the track].")
@click.option("--coulomb", type=click.Choice(["auto", "off", "on"]), default="auto", show_default=True,
              help="Coulomb friction torque [N*m]: auto fits it only when the swing shows it (score test "
                   "p < 0.001, and its 95% interval excludes zero).")
@import_options
@time_options
@output_options
def hinge(tracks, inertia_kgm2, gravity, mass_kg, com_m, pivot, marker, start_s, end_s, coulomb, imports, timing,
          write_path, as_json, plot_path, no_plot, force):
    """Fit a link's free swing on a flexure hinge: stiffness, damping, neutral angle.

    TRACKS is a track of one marker on the swinging link: a Tracker project (.trk, .trz;
    its own calibration gives metres), a Tracker text export (a title line such as mass_A
    accepted), a `locust track` CSV or a t,x,y CSV (--units for cm or mm). The angle about
    the hinge is taken from the marker's x, y, at any size of swing; the model is
    I*theta'' = -k*(theta - theta0) - b*theta' [- M*g*D*cos(theta)] [- tau_c*sign(theta')].
    Prints k [N*m/rad], b [N*m*s/rad] with 95% intervals, the RMS residual of the marker
    position [m]; --write sets compliance.hinge_stiffness_nm_per_rad and
    compliance.hinge_damping_nms_per_rad, those the swing determines (a value NOT
    IDENTIFIABLE, or any where the model does not follow the swing, is never written). With
    --gravity in-plane, --inertia-kgm2 is at least --mass-kg x --com-m^2.

    \b
    Example (the course's film hinge, the link clamped with its hinge axis vertical):
      locust calibrate hinge Damping_test.trk --inertia-kgm2 8.5e-7 --gravity out-of-plane
    """
    centre = tuple(parse_floats(pivot, 2, "--pivot", "X,Y in metres, e.g. --pivot 0.0,0.0")) if pivot else None
    with (progress(label=HINGE_LABEL.format(stage="reading")) as bar,
          interruptible("the hinge fit", "run it again; a long recording fits sooner in a window of it "
                                         "(--start-s, --end-s)")):
        def told(stage: str, evaluations: int) -> None:
            bar.label = HINGE_LABEL.format(stage=stage)
            bar.update(evaluations - bar.pos)

        fit = jobs.hinge(tracks, inertia_kgm2, gravity, mass_kg=mass_kg, com_m=com_m, pivot=centre, marker=marker,
                         start_s=start_s, end_s=end_s, coulomb=coulomb, imports=imports, timing=timing, progress=told)
    finish(fit, tracks, write_path, as_json, plot_path, no_plot, force)

