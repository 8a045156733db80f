"""The options of ``locust track``'s subcommands, each defined once: the markers and their
settings, the calibration, the clip, the output."""

from __future__ import annotations

import functools
import math
import os
from pathlib import Path

import click

from ..errors import TrackError
from ..track.aruco import DEFAULT_DICTIONARY
from ..track.calib import PIXEL_CONVENTIONS, PIXELS_HELP
from ..track.spec import ModelOptions, parse_markers
from ..track.video import check_fps


def stacked(*options):
    """A decorator putting ``options`` (click options, in order) on a command."""

    def decorate(func):
        for option in reversed(options):
            func = option(func)
        return func

    return decorate


def _out_path(ctx, param, value: str | None) -> Path | None:
    """``--out``: a name ending in ``/`` is a folder, made if it is not there yet (a ``Path``
    would drop the slash and name a file ``newdir.csv`` here instead)."""
    if value is None:
        return None
    path = Path(value)
    if value.endswith(("/", os.sep)) and not path.exists():
        from ..fileio import make_folder

        make_folder(path)
    return path


OUTPUT = [click.option("--out", type=click.Path(path_type=str), callback=_out_path,
                       help="Output file, or folder (ending in /: made if missing), its folder named on the first "
                            "line. Default: <input>.tracks.csv "
                            "(with .json) in the run folder the input sits in (run.json beside it), else in the "
                            "current folder; never beside an input in a folder of its own."),
          click.option("--force", is_flag=True, help="Replace existing output files.")]
FORMAT = [click.option("--format", "fmt", type=click.Choice(["csv", "tracker"]), default="csv", show_default=True,
                       help="csv: frame, t_s, <name>_px/_py/_x_m/_y_m/_ok. tracker: Tracker's text export layout.")]


def marker_options(func):
    """``--marker``, ``--pixels`` and the matching settings; the command gets the markers as
    ``models`` and the convention of typed pixel positions as ``pixels``."""

    @functools.wraps(func)
    def wrapper(*args, markers, color_tol, search_px, template_radius, accept, likeness, evolve, pixels, **kwargs):
        if not math.isfinite(accept):
            raise TrackError(f"--accept {accept}: not a finite number", "give --accept as a plain number, see --help")
        options = ModelOptions(color_tol, search_px, template_radius, accept, evolve / 100.0, likeness, pixels)
        return func(*args, models=parse_markers(list(markers), options), pixels=pixels, **kwargs)

    return stacked(
        click.option("--marker", "markers", multiple=True, metavar="NAME=SPEC",
                     help="A marker to track; repeatable. SPEC is color:#RRGGBB[@X,Y] (X,Y: where it is on the "
                          "first frame), template:X,Y@FRAME or aruco:ID[@DICT]. "
                          "Default: the robot's nose (#ff00ff) and foot (#00ffff) colours."),
        click.option("--pixels", type=click.Choice(list(PIXEL_CONVENTIONS)), default="tracker", show_default=True,
                     help=PIXELS_HELP),
        click.option("--color-tol", default=80, show_default=True, type=click.IntRange(1, 255),
                     help="Colour markers: largest per-channel difference (0-255) still counted as the marker; "
                          "at 80 a pixel of the marker's hue (+-16 deg) also counts down to 0.3 of its saturation "
                          "and brightness (shadow, blur), and the bounds scale with it."),
        click.option("--search", "search_px", default=40, show_default=True, type=click.IntRange(4, 2000),
                     help="Half-size (px) of the search window around each predicted position "
                          "(colour markers: at least five marker diameters, growing while the marker is lost)."),
        click.option("--template-radius", default=8, show_default=True, type=click.IntRange(2, 200),
                     help="Template markers: radius (px) of the circular template (Tracker's mask is 16 px across)."),
        click.option("--accept", default=0.5, show_default=True, type=float,
                     help="Template markers: least peak height (mean / best square difference - 1 over the search "
                          "window) to accept a match; it must also look like the template (--likeness) and follow "
                          "the motion its track predicts."),
        click.option("--likeness", default=0.5, show_default=True, type=click.FloatRange(-1, 1),
                     help="Template markers: least correlation (zero-mean, normalised) of a match with the template."),
        click.option("--evolve", default=20.0, show_default=True, type=click.FloatRange(0, 100),
                     help="Template markers: percent of each accepted match blended into the template."),
    )(wrapper)


CALIBRATION = [
    click.option("--scale", metavar="X1,Y1,X2,Y2=LENGTH_M",
                 help="Calibration stick: two pixel points and the distance between them in metres."),
    click.option("--scale-aruco", metavar="ID=SIDE_M",
                 help="Calibrate from an ArUco marker's printed side length (m), measured where it first appears."),
    click.option("--aruco-dict", default=DEFAULT_DICTIONARY, show_default=True,
                 help="ArUco dictionary for --scale-aruco."),
    click.option("--board", "board_text", metavar="aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM",
                 help="An ArUco grid board lying in the plane of motion (see `locust track board`): world x_m/y_m "
                      "in that plane, origin at the board's bottom-left corner, y up, with perspective corrected. "
                      "E.g. aruco:4X4_50:5x4:40:10."),
    click.option("--plane-points", metavar="PX,PY=X_M,Y_M;...",
                 help="Instead of a board: four or more pixels with their measured plane coordinates (m, y up)."),
    click.option("--camera-json", type=click.Path(dir_okay=False, path_type=Path),
                 help="Pinhole camera of a simulated video (world metres through each marker's plane). "
                      "Default: <video>.camera.json beside the video, "
                      "used when no --scale/--scale-aruco/--origin is given."),
    click.option("--origin", metavar="X,Y", help="World origin in pixels. Default: centre of the bottom-left pixel."),
    click.option("--angle", default=0.0, show_default=True, type=float,
                 help="Direction of the world x axis, degrees counter-clockwise from the image x axis (as Tracker)."),
    click.option("--calibration-from", type=click.Path(dir_okay=False, path_type=Path),
                 help="Track in the coordinates of a Tracker project (.trk or .trz): its scale, origin and axes, and "
                      "its frame interval unless --fps is given. VIDEO may also be the project itself."),
]
CLIP = [
    click.option("--start", default=0, show_default=True, type=int, help="First frame of the clip."),
    click.option("--end", default=None, type=int, help="Last frame of the clip (inclusive). Default: the last frame."),
    click.option("--step", default=1, show_default=True, type=int, help="Track every STEP-th frame."),
    click.option("--fps", default=None, type=float, callback=lambda ctx, param, value: check_fps(value),
                 help="True frame rate (1 to 10000 frames/s), for slow-motion footage whose file rate is wrong. "
                      "Default: the file's rate."),
]
