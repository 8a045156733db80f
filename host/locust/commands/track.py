"""``locust track``: marker tracks from video, or from a Tracker project or track file.

One subcommand per job (``video``, ``import``, ``from-trk``, ``board``, ``preview``), each
with only its options; ``locust track VIDEO ...`` is short for ``locust track video VIDEO ...``.
"""

from __future__ import annotations

import functools
from pathlib import Path

import click

from ..errors import TrackError
from ..io.importing import ImportOptions
from ..track.convert import convert_project, import_file
from ..track.export import report_lines
from ..track.pipeline import TrackOptions, progress_bars, track_job
from ..track.preview import preview_video
from .options import import_options
from .track_options import BOARD, FROM_TRK, IMPORT, OUTPUT, PREVIEW_FRAME, VIDEO, marker_options, stacked

SUBCOMMANDS = ("video", "import", "from-trk", "board", "preview")
# the options of the one-command `locust track` that became subcommands, and their new form
MOVED = {"--import": "locust track import FILE", "--from-trk": "locust track from-trk PROJECT",
         "--make-board": "locust track board BOARD.png", "--preview": "locust track preview VIDEO --frame N"}


class TrackGroup(click.Group):
    """A group whose first argument, when it is not a subcommand, is the VIDEO of ``video``."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        moved = [MOVED[a.split("=")[0]] for a in args if a.split("=")[0] in MOVED]
        if moved and (not args or args[0] not in SUBCOMMANDS):
            raise TrackError(f"`locust track {' '.join(args)}`: that option is a subcommand of its own",
                             f"{moved[0]} (see `locust track --help`)")
        if args and args[0] not in SUBCOMMANDS and args[0] not in ctx.help_option_names:
            args = ["video", *args]
        return super().parse_args(ctx, args)


@click.group(cls=TrackGroup, context_settings={"max_content_width": 100})
def track():
    """Marker tracks (nose, foot) from a video, as Tracker's autotracker would, in batch; or
    another program's tracks converted to locust's tracks CSV.

    \b
    Pixel positions you type (--marker, --origin, --scale) are Tracker's by default
    (--pixels tracker: origin at the image's top-left corner, as in Tracker's table) or
    OpenCV's (--pixels opencv: origin at the top-left pixel's centre, 0.5 px apart); the
    pixel columns written are OpenCV's, x right, y down.
    World columns are metres, y up. `locust track VIDEO ...` is short for
    `locust track video VIDEO ...`.

    \b
    Every subcommand writes into one output folder, named on the first line (stderr): --out
    (a folder, or the tracks file's path), else the run folder the input sits in (`locust hop
    --out` made it: run.json beside the input; calibrate hop and report read its track there),
    else the current folder; never beside an input in a folder of its own.

    \b
    Examples:
      locust track hop.mp4                                 nose + foot by colour (metres from hop.camera.json)
      locust track board board.png                         print at 100 %, lay it in the plane of the hop
      locust track board --check photo.jpg                 was it printed at 100 %? (a bank card beside it)
      locust track preview phone.mp4                       pick colours and start points from phone.preview.png
      locust track video phone.mp4 --marker nose=color:#e8308c@412,630 --board aruco:4X4_50:5x4:40:10
      locust track from-trk experiment.trz --format tracker
      locust track import tracker.txt --units cm --rename A=nose --out hop.tracks.csv
    """


@track.command("video", short_help="Track the markers of a video or image sequence.")
@click.argument("video", type=click.Path(path_type=Path))
@marker_options
@stacked(*VIDEO)
def video_command(video, **options):
    """Track the markers of VIDEO (a video file, an image sequence's folder or first file, or a
    Tracker project that opens one).

    \b
    World columns are metres once a scale is given (--scale, --scale-aruco, --board,
    --plane-points), or through the pinhole camera of a simulated video (its
    <video>.camera.json, found beside it). A marker not found in a frame is nan with
    <name>_ok = 0; it is never filled in. Writes <video>.tracks.csv, .json and .png into the
    output folder named on the first line: --out, else the run folder VIDEO sits in (run.json
    beside it), else the current folder.

    \b
    Examples:
      locust track video hop.mp4                           nose + foot by colour (metres from hop.camera.json)
      locust track video hop.mp4 --scale 100,400,500,400=0.30 --origin 100,400
      locust track video phone.mp4 --marker nose=color:#e8308c@412,630 --board aruco:4X4_50:5x4:40:10
      locust track video slowmo.mp4 --fps 240 --start 30 --end 400
      locust track video toss.mp4 --marker ball=template:131.28,207.86@2 --calibration-from toss.trk
      locust track video BallToss.trz --marker ball=template:131.28,207.86@2 --trk redo.trk
      locust track video frames/shot00.jpg --fps 10 --marker cup=template:203.4,34.5@0
    """
    _echo(report_lines(track_job(video, TrackOptions(**options), _say, progress_bars)))


@track.command("import", short_help="Convert a Tracker text export, t,x,y CSV or tracks CSV to metres.")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@import_options
@stacked(*IMPORT)
def import_command(file, imports: ImportOptions, trk_names, out, force):
    """Convert FILE, another program's tracks, into a tracks CSV in metres: a Tracker text
    export, a t,x,y CSV (one marker, the nose), a tracks CSV, or a Tracker project
    (.trk/.trz, through its own calibration).

    \b
    Times must increase from row to row; a file whose times repeat or go back is refused,
    naming the rows.

    \b
    Examples:
      locust track import tracker.txt --units cm --rename A=nose --out hop.tracks.csv
      locust track import cups.txt --units mm --rename "cup 3=nose" --rename "cup 7=foot" --mirror
      locust track import hop.csv --units cm
    """
    _echo(import_file(file, imports, list(trk_names), out, force, _say))


@track.command("from-trk", short_help="Convert a Tracker project's point tracks.")
@click.argument("project", type=click.Path(dir_okay=False, path_type=Path))
@stacked(*FROM_TRK)
def from_trk_command(project, trk_names, out, force, fmt):
    """Convert the point tracks of a Tracker PROJECT (.trk, or a .trz zip holding one) into a
    tracks CSV (or Tracker's text layout), in metres through the project's own calibration
    and times from its frame interval.

    \b
    Examples:
      locust track from-trk experiment.trz
      locust track from-trk BallToss.trz --track ball --format tracker --out toss.txt
    """
    _echo(report_lines(convert_project(project, list(trk_names), out, fmt, force, _say)))


@track.command("board", short_help="Write a printable ArUco board (PNG and PDF), or check a print of one.")
@click.argument("png", required=False, type=click.Path(dir_okay=False, path_type=Path))
@stacked(*BOARD)
def board_command(png, board_text, photo, force):
    """Write an ArUco grid board as PNG (300 DPI) and PDF (its page the sheet's size), to print
    at 100 % and lay flat in the plane of motion; `locust track video VIDEO --board SPEC` then
    gives metres with the perspective corrected. Beside the markers the sheet carries a 100 mm
    scale bar and the board's spec and sizes.

    \b
    --check PHOTO measures a photo of the print instead: lay a bank or ID card (ISO/IEC 7810
    ID-1, 85.60 x 53.98 mm) flat on the table beside the sheet, its whole outline in view, and
    photograph both from above. A photo alone cannot tell a smaller print from a farther
    camera: the card, at its true size, can. Or lay a ruler along the printed 100 mm bar.

    \b
    Examples:
      locust track board board.png                         also writes board.pdf
      locust track board small.png --board aruco:4X4_50:4x3:30:6
      locust track board --check photo.jpg                 the print's scale, from the card beside it
    """
    from ..track import board, boardcheck, boardsheet

    spec = board.parse_board(board_text)
    if photo is not None and png is not None:
        raise TrackError("give PNG (write a board) or --check PHOTO (measure a print), not both",
                         "e.g. locust track board --check photo.jpg")
    lines = (boardcheck.check_print(photo, spec).lines(spec) if photo is not None
             else [boardsheet.make_board(png, spec, force, _say)])
    for line in lines:
        click.echo(line, err=line.startswith("warning:"))


@track.command("preview", short_help="One frame with a pixel grid, its coloured blobs listed.")
@click.argument("video", type=click.Path(path_type=Path))
@PREVIEW_FRAME
@marker_options
@stacked(*OUTPUT)
def preview_command(video, frame, markers, model, out, force):
    """Write one FRAME of VIDEO with a pixel grid, the most saturated blobs listed (colour,
    position) and what the --marker specs find there, to <out>.preview.png in the output
    folder named on the first line: pick colours and start points for `locust track video`
    without a GUI.

    \b
    Examples:
      locust track preview phone.mp4                       -> phone.tracks.preview.png
      locust track preview phone.mp4 --frame 40 --marker nose=color:#e8308c@412,630
    """
    _echo(preview_video(video, frame, markers, model, out, force, _say))


_say = functools.partial(click.echo, err=True)   # a line for the person: the output folder, a warning


def _echo(lines: list[str]) -> None:
    for line in lines:
        click.echo(line)
