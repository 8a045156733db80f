"""``locust track``: marker tracks from video, or from a Tracker project or track file.

One subcommand per job (``video``, ``import``, ``from-trk``, ``board``, ``preview``), each
with only its options; ``locust track VIDEO ...`` is short for ``locust track video VIDEO ...``.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import replace
from pathlib import Path

import click
import numpy as np

from ..errors import TrackError, WriteError
from ..fileio import atomic_write_json, locked, refuse_read_only_folder, write_target
from ..io import trk as trk_io
from ..io.camera_json import camera_json_beside
from ..io.importing import ImportOptions, import_tracks, is_project, span_warnings
from ..io.run_record import RECORD_NAME
from ..io.tracks_csv import tracks_csv_in, write_tracks_csv
from ..progress import progress
from ..tables import mm
from ..track import board, calib, camera, export, overlay, preview, trk
from ..track.aruco import side_px_in_video
from ..track.board import DEFAULT_BOARD
from ..track.calib import PIXEL_CONVENTIONS, typed_px
from ..track.runner import track_video
from ..track.upright import upside_down_warnings
from ..track.video import Clip, VideoInfo, probe, read_as_frame
from .options import import_options
from .track_options import CALIBRATION, CLIP, FORMAT, OUTPUT, marker_options, stacked

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
@stacked(*CALIBRATION, *CLIP, *OUTPUT, *FORMAT)
@click.option("--overlay", "overlay_kind", type=click.Choice(["png", "video", "none"]), default="png",
              show_default=True, help="Draw the tracks on the last frame (png) or on the whole clip (video).")
@click.option("--trk", "trk_out", type=click.Path(dir_okay=False, path_type=Path),
              help="Also write the tracks as a Tracker project (.trk) that opens the video or image sequence with "
                   "the clip's timing and calibration, one point mass per marker: correct frames by hand in Tracker.")
def video_command(video, models, pixels, start, end, step, fps, out, force, fmt, overlay_kind, trk_out,
                  calibration_from, **calibration):
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
    if not math.isfinite(calibration["angle"]):
        raise TrackError(f"--angle {calibration['angle']}: not a finite number", "give --angle as a plain number")
    if trk_out is not None and trk_out.suffix.lower() != ".trk":
        raise TrackError(f"--trk {trk_out}: a Tracker project is written as a .trk file", "e.g. --trk redo.trk")
    video = _named(video)
    project = None
    if is_project(video):
        if calibration_from is not None:
            raise TrackError("VIDEO is a Tracker project: its calibration is used, leave out --calibration-from",
                             "or give the video itself as VIDEO")
        project = trk_io.read_project(video)
    elif calibration_from is not None:
        project = trk_io.read_project(calibration_from)
    if project is not None and any(calibration[k] for k in ("scale", "scale_aruco", "origin", "camera_json",
                                                            "board_text", "plane_points")):
        raise TrackError("a Tracker project's calibration, or --scale/--scale-aruco/--origin/--camera-json/--board, "
                         "not both", "one calibration per run")
    if project is not None and fps is None and math.isfinite(project.clip.fps):
        fps = project.clip.fps
    calibration["pixels"] = pixels
    with _media(video, project) as media:
        _track(media, video, project, models, calibration, Clip(start, end, step, fps), out, fmt, overlay_kind,
               force, trk_out)


@track.command("import", short_help="Convert a Tracker text export, t,x,y CSV or tracks CSV to metres.")
@click.argument("file", type=click.Path(dir_okay=False, path_type=Path))
@import_options
@click.option("--track", "trk_names", multiple=True, metavar="NAME",
              help="A Tracker project converted as it is: only these of its tracks (repeatable).")
@stacked(*OUTPUT)
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
    # a Tracker project carries its own units: converted as from-trk does, or, renamed or
    # mirrored, through the import layer (which refuses --units for it)
    if is_project(file) and imports.identity:
        return _convert_trk(file, list(trk_names), out, "csv", force)
    if trk_names:
        raise TrackError("--track picks the tracks of a Tracker project converted as it is",
                         "leave out --rename and --mirror, or leave out --track")
    target = _tracks_path(out, file)
    tracks = import_tracks(file, options=imports)
    if target.exists() and target.resolve() == file.resolve():
        raise TrackError(f"--out {target} is the file being imported", "write the tracks CSV to another --out")
    _refuse_overwrite({"tracks": target}, force)
    for warning in span_warnings(tracks, imports):
        click.echo(f"warning: {warning}", err=True)
    write_tracks_csv(target, tracks)
    click.echo(f"{file.name}: {tracks.n_rows} rows, {imports.describe()}")
    for name in tracks.markers_with_positions():
        x, y = tracks.positions(name)
        ok = np.isfinite(x) & np.isfinite(y)
        if ok.any():
            # the span a person checks the conversion by, in mm (the CSV keeps metres)
            click.echo(f"  {name}: {int(ok.sum())} rows with a position; x {mm(x[ok].min(), 1)} .. "
                       f"{mm(x[ok].max(), 1)} mm, y {mm(y[ok].min(), 1)} .. {mm(y[ok].max(), 1)} mm")
        else:
            click.echo(f"  {name}: no position")
    click.echo(f"wrote {target}")


@track.command("from-trk", short_help="Convert a Tracker project's point tracks.")
@click.argument("project", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--track", "trk_names", multiple=True, metavar="NAME",
              help="Only these Tracker tracks (repeatable). Default: all point masses.")
@stacked(*OUTPUT, *FORMAT)
def from_trk_command(project, trk_names, out, force, fmt):
    """Convert the point tracks of a Tracker PROJECT (.trk, or a .trz zip holding one) into a
    tracks CSV (or Tracker's text layout), in metres through the project's own calibration
    and times from its frame interval.

    \b
    Examples:
      locust track from-trk experiment.trz
      locust track from-trk BallToss.trz --track ball --format tracker --out toss.txt
    """
    _convert_trk(project, list(trk_names), out, fmt, force)


@track.command("board", short_help="Write a printable ArUco board (PNG and PDF), or check a print of one.")
@click.argument("png", required=False, type=click.Path(dir_okay=False, path_type=Path))
@click.option("--board", "board_text", default=DEFAULT_BOARD, show_default=True,
              metavar="aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM", help="The ArUco grid board.")
@click.option("--check", "photo", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Measure PHOTO, the printed board with an ID-1 card (a bank or ID card, 85.60 x 53.98 mm) lying "
                   "flat beside it, and say by how much the printer scaled the board.")
@click.option("--force", is_flag=True, help="Replace an existing PNG and PDF.")
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
    from ..track import boardcheck, boardsheet

    spec = board.parse_board(board_text)
    if photo is not None:
        if png is not None:
            raise TrackError("give PNG (write a board) or --check PHOTO (measure a print), not both",
                             "e.g. locust track board --check photo.jpg")
        result = boardcheck.check_print(photo, spec)
        for line in result.lines(spec):
            click.echo(line, err=line.startswith("warning:"))
        return
    if png is None:
        raise TrackError("give the PNG to write, or --check PHOTO", "e.g. locust track board board.png")
    if png.suffix.lower() not in (".png", ".pdf"):
        raise TrackError(f"{png}: the board is written as a .png, with a .pdf beside it",
                         f"e.g. locust track board {png.with_suffix('.png').name}")
    png = png.with_suffix(".png") if png.suffix.lower() == ".pdf" else png
    pdf = boardsheet.pdf_beside(png)
    _say_folder(png)
    _refuse_overwrite({"board": png, "pdf": pdf}, force)
    boardsheet.write_board_sheet(png, spec)
    lay = boardsheet.layout(spec)
    click.echo(f"wrote {png} ({boardsheet.SHEET_DPI} DPI) and {pdf} ({lay.width_mm:.1f} x {lay.height_mm:.1f} mm "
               f"page): board {spec.text()}, {spec.width_mm:g} x {spec.height_mm:g} mm of markers; print at 100 % "
               f"(no fit to page), check the scale bar is 100 mm (or `locust track board --check PHOTO`), lay it "
               f"flat in the plane of motion")


@track.command("preview", short_help="One frame with a pixel grid, its coloured blobs listed.")
@click.argument("video", type=click.Path(path_type=Path))
@click.option("--frame", default=0, show_default=True, type=int, help="The frame to show.")
@marker_options
@stacked(*OUTPUT)
def preview_command(video, frame, models, pixels, out, force):
    """Write one FRAME of VIDEO with a pixel grid, the most saturated blobs listed (colour,
    position) and what the --marker specs find there, to <out>.preview.png in the output
    folder named on the first line: pick colours and start points for `locust track video`
    without a GUI.

    \b
    Examples:
      locust track preview phone.mp4                       -> phone.tracks.preview.png
      locust track preview phone.mp4 --frame 40 --marker nose=color:#e8308c@412,630
    """
    video = _named(video)
    project = trk_io.read_project(video) if is_project(video) else None
    with _media(video, project) as media:
        path = _tracks_path(out, video)
        path = path.with_name(_stem(path) + ".preview.png")
        info = probe(media)
        _refuse_inputs({"preview": path}, [video, media])
        _refuse_overwrite({"preview": path}, force)
        blobs, found = preview.preview(info, frame, models, path)
    click.echo(f"frame {frame} of {info.path.name} ({info.width_px}x{info.height_px}): most saturated blobs")
    for k, b in enumerate(blobs, 1):
        click.echo(b.line(k))
    if not blobs:
        click.echo("  none (no strongly coloured patch in this frame)")
    if found:
        click.echo(f"markers ({pixels}'s pixels, as --marker takes them):")
    for name, p in found.items():
        if p:   # found in OpenCV's pixels: shown in the convention the specs are typed in
            p = (p[0] - PIXEL_CONVENTIONS[pixels], p[1] - PIXEL_CONVENTIONS[pixels])
        click.echo(f"  marker {name}: " + (f"found at {p[0]:.1f},{p[1]:.1f}" if p else "not found"))
    click.echo(f"wrote {path}")


def _named(video: Path) -> Path:
    """``.`` (an image sequence's folder, run from inside it) by its own name, which the
    outputs and sidecars are named after."""
    return video.resolve() if not video.name else video


@contextlib.contextmanager
def _media(video: Path, project):
    """The video to read: ``video`` itself, or the one the Tracker project ``video`` opens."""
    if project is not None and is_project(video):
        with trk_io.project_media(project) as media:
            yield media
    else:
        yield video


def _stem(path: Path) -> str:
    """``hop.tracks.csv`` -> ``hop.tracks``: the name the outputs share (a .csv or .txt suffix off)."""
    return path.name[: -len(path.suffix)] if path.suffix in (".csv", ".txt") else path.name


def _outputs(base: Path, fmt: str, overlay_kind: str) -> dict[str, Path]:
    stem = _stem(base)
    folder = base.parent
    out = {"tracks": folder / f"{stem}{'.txt' if fmt == 'tracker' else '.csv'}", "sidecar": folder / f"{stem}.json"}
    if overlay_kind == "png":
        out["overlay"] = folder / f"{stem}.png"
    elif overlay_kind == "video":
        out["overlay"] = folder / f"{stem}.overlay.mp4"
    return out


def _refuse_overwrite(paths: dict[str, Path], force: bool) -> None:
    for p in paths.values():   # before any work: what no write may replace, nor reach through a link
        write_target(p)
    taken = [str(p) for p in paths.values() if p.exists()]
    if taken and not force:
        raise TrackError(f"output exists: {', '.join(taken)}", "choose another --out, or add --force to replace it")


def _refuse_inputs(paths: dict[str, Path], inputs: list[Path], info: VideoInfo | None = None) -> None:
    """No output may land on an input: the video, a Tracker project, or a sidecar beside them
    (``<video>.camera.json``, ``<video>.truth.csv``), ``--force`` or not; nor on any frame of an
    image sequence, nor where the next run would read it as one of its frames."""
    guarded = set()
    for p in inputs:
        guarded |= {p.resolve(), camera_json_beside(p).resolve(), p.with_name(p.stem + ".truth.csv").resolve()}
    clash = [str(p) for p in paths.values() if p.resolve() in guarded]
    if clash:
        raise TrackError(f"--out would overwrite an input or its sidecar: {', '.join(clash)}",
                         "choose another --out (the default, <video>.tracks.csv, is always safe)")
    frames = [str(p) for p in paths.values() if info is not None and read_as_frame(info, p)]
    if frames:
        raise TrackError(f"--out would write {', '.join(frames)}, a frame of the image sequence {info.path} (or a "
                         "file the next run would read as one)", "choose an --out outside the sequence's folder")


def _tracks_path(out: Path | None, source: Path) -> Path:
    """The tracks file of ``source``: ``--out`` as given, or ``<stem>.tracks.csv`` in the ``--out``
    folder, else in :func:`_default_folder`; its folder is named on stderr as the first line."""
    if out is not None and not out.is_dir() and out.exists() and not out.is_file():
        raise TrackError(f"--out {out} is a device or pipe, not a folder or a file name",
                         "give a folder, or the path of the tracks file to write")
    path = out if out is not None and not out.is_dir() else tracks_csv_in(out or _default_folder(source), source)
    _say_folder(path)
    return path


def _default_folder(source: Path) -> Path:
    """Without --out: the run folder ``source`` sits in (``locust hop --out`` made it; ``run.json``
    beside ``source``), where ``locust calibrate hop`` and ``locust report`` read its track, unless
    its mode says it is read-only (someone else's); else the current folder, as ``locust
    calibrate``'s plots, never a data folder beside the input."""
    folder = source.parent
    if (folder / RECORD_NAME).is_file():
        with contextlib.suppress(WriteError):
            refuse_read_only_folder(folder)
            return folder
    return Path(".")


def _say_folder(path: Path) -> None:
    click.echo(f"output folder: {path.parent.resolve()}", err=True)


def _track(video: Path, named: Path, project, models: list, cal: dict, clip: Clip, out, fmt, overlay_kind, force,
           trk_out) -> None:
    """Track ``video`` (``named`` on the command line: the video, or a Tracker project that opens it)."""
    paths = _outputs(_tracks_path(out, named), fmt, overlay_kind)
    if trk_out is not None:
        paths["trk"] = trk_out
    info = probe(video)
    clip = clip.resolved(info)
    if cal["board_text"] or cal["plane_points"]:
        if cal["scale"] or cal["scale_aruco"] or cal["origin"] or cal["camera_json"]:
            raise TrackError("give --board/--plane-points or --scale/--scale-aruco/--origin/--camera-json, not both",
                             "one calibration per run")
        if cal["board_text"] and cal["plane_points"]:
            raise TrackError("give --board or --plane-points, not both", "one calibration per run")
        calibration = (board.parse_plane_points(cal["plane_points"], cal["pixels"]) if cal["plane_points"]
                       else board.board_homography(info, clip, board.parse_board(cal["board_text"])))
    elif project is not None:
        calibration = project.calibration
    else:
        calibration = _calibration(info, clip, cal["scale"], cal["scale_aruco"], cal["aruco_dict"], cal["origin"],
                                   cal["angle"], cal["camera_json"], cal["pixels"])
    _refuse_inputs(paths, [p for p in (video, named, cal["camera_json"], project and project.path) if p], info)
    try:        # the outputs' names claimed for this run: a second `locust track` onto them now is refused
        with locked(paths["tracks"], wait_s=0):
            _refuse_overwrite(paths, force)
            _track_and_write(video, named, project, models, calibration, info, clip, paths, fmt, overlay_kind,
                             trk_out)
    except WriteError as exc:
        if ".lock beside" not in exc.message:
            raise
        raise TrackError(f"{paths['tracks']} is being written by another `locust track` now",
                         "wait for it to finish (then --force replaces what it wrote), or give this run another "
                         "--out") from None


def _track_and_write(video, named, project, models, calibration, info, clip, paths, fmt, overlay_kind,
                     trk_out) -> None:
    """Track ``video`` and write ``paths``: what :func:`_track` runs once the names are its own."""
    n = len(clip.frames())
    with progress(length=n, label=f"tracking {video.name}") as bar:
        result = track_video(info, clip, models, calibration, progress=bar.update)
    if named != video:   # a Tracker project's video, unpacked from it for this run
        result = replace(result, source=f"locust track of the video in {named}")
    for warning in upside_down_warnings(result):
        click.echo(f"warning: {warning}", err=True)
    if trk_out is not None:
        trk.check_even_times(result)   # before anything is written
    written = _write(result, paths, fmt)
    if trk_out is not None:
        media = trk_io.media_in_zip(project, trk_out) if project is not None and is_project(named) else None
        written.append(trk.write_project(result, trk_out, media))
    if "overlay" in paths:
        if overlay_kind == "png":
            written.append(overlay.write_png(result, paths["overlay"]))
        else:
            with progress(length=n, label="overlay video") as bar:
                written.append(overlay.write_video(result, paths["overlay"], bar.update))
    _report(result, written)


def _calibration(info, clip, scale, scale_aruco, aruco_dict, origin, angle, camera_json=None, pixels="tracker"):
    if scale and scale_aruco:
        raise TrackError("give --scale or --scale-aruco, not both", "one calibration per run")
    by_hand = bool(scale or scale_aruco or origin)
    if camera_json is not None:
        if by_hand:
            raise TrackError("give --camera-json or --scale/--scale-aruco/--origin, not both",
                             "one calibration per run")
        return camera.load(camera_json, info.width_px, info.height_px)
    beside = camera_json_beside(info.path)
    if not by_hand and beside.is_file():
        return camera.load(beside, info.width_px, info.height_px)
    m_per_px, source = math.nan, "none"
    if scale:
        x1, y1, x2, y2, length = calib.parse_scale(scale)
        m_per_px, source = calib.m_per_px_from_stick(x1, y1, x2, y2, length), f"stick {scale}"
    elif scale_aruco:
        marker_id, side_m = calib.parse_aruco_scale(scale_aruco)
        frame, side = side_px_in_video(info, clip, marker_id, aruco_dict)
        m_per_px, source = side_m / side, f"aruco {marker_id} side {side_m} m = {side:.3f} px on frame {frame}"
    point = typed_px(*calib.parse_point(origin, "--origin"), pixels) if origin else None
    return calib.build(info.height_px, m_per_px, point, angle, source)


def _write(result, paths: dict[str, Path], fmt: str) -> list[Path]:
    if fmt == "tracker":
        trk.write_tracker_text(result, paths["tracks"])
        atomic_write_json(paths["sidecar"], export.sidecar(result, paths["tracks"]))
        return [paths["tracks"], paths["sidecar"]]
    return list(export.write_tracks(result, paths["tracks"]))


def _convert_trk(path: Path, names: list[str], out, fmt: str, force: bool) -> None:
    paths = _outputs(_tracks_path(out, path), fmt, "none")
    project = trk_io.read_project(path)
    result = trk.project_result(project, names or None)
    _refuse_inputs(paths, [path])
    _refuse_overwrite(paths, force)
    _report(result, _write(result, paths, fmt))


def _report(result, written: list[Path]) -> None:
    for line in export.summary_lines(result):
        click.echo(line)
    ok = result.tracks.ok
    lost = [m for m in result.tracks.markers
            if result.specs[m].startswith("template:") and ok[m].any() and not ok[m][int(np.argmax(ok[m])):].all()]
    if lost:
        click.echo(f"hint: {', '.join(lost)}: lost (nan) where the match looked unlike the template (--likeness, "
                   "--accept) or left the path its track predicts, e.g. out of view; check the overlay, and pick "
                   "a point with texture that stays in view, or a --template-radius about the feature's size")
    for p in written:
        click.echo(f"wrote {p}")
