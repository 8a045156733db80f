"""The options of ``locust track``'s subcommands, each defined once: the markers and their
settings, the calibration, the clip, the output. ``locust track video``'s are named as the
fields of :class:`locust.track.pipeline.TrackOptions`, which the command builds from them."""

from __future__ import annotations

import functools
from pathlib import Path

import click

from ..track.aruco import DEFAULT_DICTIONARY
from ..track.board import DEFAULT_BOARD
from ..track.calib import PIXEL_CONVENTIONS, PIXELS_HELP
from ..track.outputs import out_path
from ..track.spec import ModelOptions
from ..track.video import check_fps


def stacked(*options):
    """A decorator putting ``options`` (click options, in order) on a command."""

    def decorate(func):
        for option in reversed(options):
            func = option(func)
        return func

    return decorate


OUTPUT = [click.option("--out", type=click.Path(path_type=str), callback=lambda ctx, param, value: out_path(value),
                       help="Output file, or folder (ending in /: made if missing), its folder named on the first "
                            "line. Default: <input>.tracks.csv "
                            "(with .json) in the run folder the input sits in (run.json beside it), else in the "
                            "current folder; never beside an input in a folder of its own."),
          click.option("--force", is_flag=True, help="Replace existing output files.")]
FORMAT = [click.option("--format", "fmt", type=click.Choice(["csv", "tracker"]), default="csv", show_default=True,
                       help="csv: frame, t_s, <name>_px/_py/_x_m/_y_m/_ok. tracker: Tracker's text export layout.")]


def marker_options(func):
    """``--marker``, ``--pixels`` and the matching settings; the command gets the ``NAME=SPEC``
    strings as ``markers`` and the models' settings (the convention of typed pixel positions
    among them) as ``model``, a :class:`~locust.track.spec.ModelOptions`."""

    @functools.wraps(func)
    def wrapper(*args, markers, color_tol, search_px, template_radius, accept, likeness, evolve, pixels, **kwargs):
        model = ModelOptions(color_tol, search_px, template_radius, accept, evolve / 100.0, likeness, pixels)
        return func(*args, markers=tuple(markers), model=model, **kwargs)

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
    click.option("--board", metavar="aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM",
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
    click.option("--angle", "angle_deg", default=0.0, show_default=True, type=float,
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
VIDEO = [*CALIBRATION, *CLIP, *OUTPUT, *FORMAT,
    click.option("--overlay", type=click.Choice(["png", "video", "none"]), default="png", show_default=True,
                 help="Draw the tracks on the last frame (png) or on the whole clip (video)."),
    click.option("--trk", type=click.Path(dir_okay=False, path_type=Path),
                 help="Also write the tracks as a Tracker project (.trk) that opens the video or image sequence with "
                      "the clip's timing and calibration, one point mass per marker: correct frames by hand in "
                      "Tracker."),
]
IMPORT = [click.option("--track", "trk_names", multiple=True, metavar="NAME",
                       help="A Tracker project converted as it is: only these of its tracks (repeatable)."), *OUTPUT]
FROM_TRK = [click.option("--track", "trk_names", multiple=True, metavar="NAME",
                         help="Only these Tracker tracks (repeatable). Default: all point masses."), *OUTPUT, *FORMAT]
BOARD = [
    click.option("--board", "board_text", default=DEFAULT_BOARD, show_default=True,
                 metavar="aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM", help="The ArUco grid board."),
    click.option("--check", "photo", type=click.Path(dir_okay=False, path_type=Path), default=None,
                 help="Measure PHOTO, the printed board with an ID-1 card (a bank or ID card, 85.60 x 53.98 mm) lying "
                      "flat beside it, and say by how much the printer scaled the board."),
    click.option("--force", is_flag=True, help="Replace an existing PNG and PDF."),
]
PREVIEW_FRAME = click.option("--frame", default=0, show_default=True, type=int, help="The frame to show.")
