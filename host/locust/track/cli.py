"""``locust track``: marker tracks from video, or from a Tracker project."""

from __future__ import annotations

import math
from pathlib import Path

import click
import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_json
from ..io import trk as trk_io
from ..io.camera_json import camera_json_beside
from ..io.importing import ImportOptions, import_options, import_tracks, is_project, span_warnings
from ..io.tracks_csv import tracks_csv_beside, write_tracks_csv
from ..progress import progress
from . import board, calib, camera, export, overlay, preview, trk
from .aruco import DEFAULT_DICTIONARY, side_px_in_video
from .board import DEFAULT_BOARD
from .runner import track_video
from .spec import ModelOptions, parse_markers
from .video import Clip, probe


def _outputs(base: Path, fmt: str, overlay_kind: str) -> dict[str, Path]:
    stem = base.name[: -len(base.suffix)] if base.suffix in (".csv", ".txt") else base.name
    folder = base.parent
    out = {"tracks": folder / f"{stem}{'.txt' if fmt == 'tracker' else '.csv'}", "sidecar": folder / f"{stem}.json"}
    if overlay_kind == "png":
        out["overlay"] = folder / f"{stem}.png"
    elif overlay_kind == "video":
        out["overlay"] = folder / f"{stem}.overlay.mp4"
    return out


def _refuse_overwrite(paths: dict[str, Path], force: bool) -> None:
    taken = [str(p) for p in paths.values() if p.exists()]
    if taken and not force:
        raise TrackError(f"output exists: {', '.join(taken)}", "choose another --out, or add --force to replace it")


def _refuse_inputs(paths: dict[str, Path], inputs: list[Path]) -> None:
    """No output may land on an input: the video, a Tracker project, or a sidecar beside them
    (``<video>.camera.json``, ``<video>.truth.csv``), ``--force`` or not."""
    guarded = set()
    for p in inputs:
        guarded |= {p.resolve(), camera_json_beside(p).resolve(), p.with_name(p.stem + ".truth.csv").resolve()}
    clash = [str(p) for p in paths.values() if p.resolve() in guarded]
    if clash:
        raise TrackError(f"--out would overwrite an input or its sidecar: {', '.join(clash)}",
                         "choose another --out (the default, <video>.tracks.csv, is always safe)")


def _base_path(out: Path | None, source: Path) -> Path:
    default_stem = tracks_csv_beside(source).with_suffix("").name   # hop.tracks (.csv, .json, .png)
    if out is None:
        return source.with_name(default_stem)
    if out.is_dir():
        return out / default_stem
    return out


@click.command(context_settings={"max_content_width": 100})
@click.argument("video", required=False, type=click.Path(path_type=Path))
@click.option("--marker", "markers", multiple=True, metavar="NAME=SPEC",
              help="A marker to track; repeatable. SPEC is color:#RRGGBB[@X,Y] (X,Y: where it is on the first "
                   "frame), template:X,Y@FRAME or aruco:ID[@DICT]. "
                   "Default: the robot's nose (#ff00ff) and foot (#00ffff) colours.")
@click.option("--color-tol", default=80, show_default=True, type=click.IntRange(1, 255),
              help="Colour markers: largest per-channel difference (0-255) still counted as the marker; "
                   "at 80 a pixel of the marker's hue (+-16 deg) also counts down to 0.3 of its saturation and "
                   "brightness (shadow, blur), and the bounds scale with it.")
@click.option("--search", "search_px", default=40, show_default=True, type=click.IntRange(4, 2000),
              help="Half-size (px) of the search window around each predicted position "
                   "(colour markers: at least five marker diameters, growing while the marker is lost).")
@click.option("--template-radius", default=8, show_default=True, type=click.IntRange(2, 200),
              help="Template markers: radius (px) of the circular template (Tracker's mask is 16 px across).")
@click.option("--accept", default=0.5, show_default=True, type=float,
              help="Template markers: least peak height (mean / best square difference - 1 over the search "
                   "window) to accept a match; it must also look like the template (--likeness) and follow the "
                   "motion its track predicts.")
@click.option("--likeness", default=0.5, show_default=True, type=click.FloatRange(-1, 1),
              help="Template markers: least correlation (zero-mean, normalised) of a match with the template.")
@click.option("--evolve", default=20.0, show_default=True, type=click.FloatRange(0, 100),
              help="Template markers: percent of each accepted match blended into the template.")
@click.option("--scale", metavar="X1,Y1,X2,Y2=LENGTH_M",
              help="Calibration stick: two pixel points and the distance between them in metres.")
@click.option("--scale-aruco", metavar="ID=SIDE_M",
              help="Calibrate from an ArUco marker's printed side length (m), measured where it first appears.")
@click.option("--aruco-dict", default=DEFAULT_DICTIONARY, show_default=True,
              help="ArUco dictionary for --scale-aruco.")
@click.option("--board", "board_text", metavar="aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM",
              help="An ArUco grid board lying in the plane of motion (see --make-board): world x_m/y_m in that plane, "
                   "origin at the board's bottom-left corner, y up, with perspective corrected. "
                   "E.g. aruco:4X4_50:5x4:40:10.")
@click.option("--plane-points", metavar="PX,PY=X_M,Y_M;...",
              help="Instead of a board: four or more pixels with their measured plane coordinates (m, y up).")
@click.option("--make-board", type=click.Path(dir_okay=False, path_type=Path),
              help=f"Write the --board (default {DEFAULT_BOARD}) as a PNG at 300 DPI to print at 100 %, and stop.")
@click.option("--preview", "preview_frame", type=int, metavar="FRAME",
              help="Write FRAME with a pixel grid, the most saturated blobs listed (colour, position) and what the "
                   "--marker specs find there, to <out>.preview.png, and stop.")
@click.option("--camera-json", type=click.Path(dir_okay=False, path_type=Path),
              help="Pinhole camera of a simulated video (world metres through each marker's plane). "
                   "Default: <video>.camera.json beside the video, "
                   "used when no --scale/--scale-aruco/--origin is given.")
@click.option("--origin", metavar="X,Y", help="World origin in pixels. Default: centre of the bottom-left pixel.")
@click.option("--angle", default=0.0, show_default=True, type=float,
              help="Direction of the world x axis, degrees counter-clockwise from the image x axis (as Tracker).")
@click.option("--start", default=0, show_default=True, type=int, help="First frame of the clip.")
@click.option("--end", default=None, type=int, help="Last frame of the clip (inclusive). Default: the last frame.")
@click.option("--step", default=1, show_default=True, type=int, help="Track every STEP-th frame.")
@click.option("--fps", default=None, type=float,
              help="True frame rate, for slow-motion footage whose file rate is wrong. Default: the file's rate.")
@click.option("--out", type=click.Path(path_type=Path),
              help="Output file (or folder). Default: <video>.tracks.csv beside the video, with .json and .png.")
@click.option("--format", "fmt", type=click.Choice(["csv", "tracker"]), default="csv", show_default=True,
              help="csv: frame, t_s, <name>_px/_py/_x_m/_y_m/_ok. tracker: Tracker's text export layout.")
@click.option("--overlay", "overlay_kind", type=click.Choice(["png", "video", "none"]), default="png",
              show_default=True, help="Draw the tracks on the last frame (png) or on the whole clip (video).")
@click.option("--force", is_flag=True, help="Replace existing output files.")
@click.option("--trk", "trk_out", type=click.Path(dir_okay=False, path_type=Path),
              help="Also write the tracks as a Tracker project (.trk) that opens the video or image sequence with "
                   "the clip's timing and calibration, one point mass per marker: correct frames by hand in Tracker.")
@click.option("--calibration-from", type=click.Path(dir_okay=False, path_type=Path),
              help="Track in the coordinates of a Tracker project (.trk or .trz): its scale, origin and axes, and "
                   "its frame interval unless --fps is given. VIDEO may also be the project itself.")
@click.option("--from-trk", type=click.Path(dir_okay=False, path_type=Path),
              help="Convert the point tracks of a Tracker project (.trk or .trz) instead of tracking a video.")
@click.option("--track", "trk_names", multiple=True, metavar="NAME",
              help="With --from-trk: only these Tracker tracks (repeatable). Default: all point masses.")
@click.option("--import", "import_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Convert a track file instead of tracking a video: a Tracker text export, a t,x,y CSV or a "
                   "tracks CSV, in --units, with --rename and --mirror, into a tracks CSV in metres.")
@import_options
def track(video, markers, color_tol, search_px, template_radius, accept, likeness, evolve, scale, scale_aruco,
          aruco_dict, board_text, plane_points, make_board, preview_frame, camera_json, origin, angle, start, end,
          step, fps, out, fmt, overlay_kind, force, trk_out, calibration_from, from_trk, trk_names, import_path,
          imports):
    """Extract marker tracks (nose, foot) from VIDEO, as Tracker's autotracker would, in batch.

    \b
    Pixels follow OpenCV: origin at the centre of the top-left pixel, x right, y down.
    World columns are metres, y up, once a scale is given (--scale or --scale-aruco), or
    through the pinhole camera of a simulated video (its <video>.camera.json, found beside it).
    A marker not found in a frame is nan with <name>_ok = 0; it is never filled in.

    \b
    Examples:
      locust track hop.mp4                                  nose + foot by colour (metres from hop.camera.json)
      locust track hop.mp4 --scale 100,400,500,400=0.30 --origin 100,400
      locust track toss.mp4 --marker ball=template:131.28,207.86@2
      locust track toss.mp4 --marker ball=template:131.28,207.86@2 --calibration-from toss.trk
      locust track BallToss.trz --marker ball=template:131.28,207.86@2 --trk redo.trk
      locust track frames/shot00.jpg --fps 10 --marker cup=template:203.4,34.5@0   an image sequence
      locust track slowmo.mp4 --fps 240 --start 30 --end 400
      locust track --make-board board.png                   print at 100 %, lay it in the plane of the hop
      locust track phone.mp4 --preview 0                    pick colours and start points from phone.preview.png
      locust track phone.mp4 --marker nose=color:#e8308c@412,630 --board aruco:4X4_50:5x4:40:10
      locust track --from-trk experiment.trz --format tracker
      locust track --import tracker.txt --units cm --rename A=nose --out hop.tracks.csv
    """
    for name, value in (("--angle", angle), ("--accept", accept), ("--fps", fps)):
        if value is not None and not math.isfinite(value):
            raise TrackError(f"{name} {value}: not a finite number", f"give {name} as a plain number, see --help")
    if fps is not None and fps <= 0:
        raise TrackError(f"--fps {fps:g}: a frame rate must be above 0", "e.g. --fps 240 for slow-motion footage")
    if make_board is not None:
        spec = board.parse_board(board_text or DEFAULT_BOARD)
        _refuse_overwrite({"board": make_board}, force)
        board.write_board_png(make_board, spec)
        click.echo(f"wrote {make_board}: board {spec.text()}, {spec.width_mm:g} x {spec.height_mm:g} mm of markers "
                   f"at {board.BOARD_DPI} DPI; print at 100 % (no fit to page), check one marker is "
                   f"{spec.marker_mm:g} mm, lay it flat in the plane of motion")
        return
    if import_path is not None:
        if video is not None or from_trk is not None:
            raise TrackError("give one of VIDEO, --from-trk and --import", "one input per run")
        # a Tracker project carries its own units: converted as --from-trk does, or, renamed or
        # mirrored, through the import layer (which refuses --units for it)
        if is_project(import_path) and imports.identity:
            return _convert_trk(import_path, list(trk_names), out, fmt, force)
        if trk_names:
            raise TrackError("--track picks the tracks of a Tracker project converted as it is",
                             "leave out --rename and --mirror, or leave out --track")
        if fmt != "csv":
            raise TrackError("--import writes a tracks CSV only", "leave out --format, or use --format csv")
        return _import(import_path, imports, out, force)
    if not imports.identity:
        raise TrackError("--units, --rename and --mirror go with --import",
                         "locust track --import FILE --units cm --rename A=nose --out tracks.csv")
    if from_trk is not None:
        if video is not None:
            raise TrackError("give either VIDEO or --from-trk, not both", "track a video, or convert a Tracker project")
        return _convert_trk(from_trk, list(trk_names), out, fmt, force)
    if video is None:
        raise TrackError("no video given",
                         "usage: locust track VIDEO [--marker NAME=SPEC ...] or --import FILE; see --help")
    if trk_out is not None and trk_out.suffix.lower() != ".trk":
        raise TrackError(f"--trk {trk_out}: a Tracker project is written as a .trk file", "e.g. --trk redo.trk")
    project = None
    if is_project(video):
        if calibration_from is not None:
            raise TrackError("VIDEO is a Tracker project: its calibration is used, leave out --calibration-from",
                             "or give the video itself as VIDEO")
        project = trk_io.read_project(video)
    elif calibration_from is not None:
        project = trk_io.read_project(calibration_from)
    if project is not None and (scale or scale_aruco or origin or camera_json or board_text or plane_points):
        raise TrackError("a Tracker project's calibration, or --scale/--scale-aruco/--origin/--camera-json/--board, "
                         "not both", "one calibration per run")
    if project is not None and fps is None and math.isfinite(project.clip.fps):
        fps = project.clip.fps
    if project is not None and is_project(video):
        with trk_io.project_media(project) as media:
            return _track(media, video, project, markers, (color_tol, search_px, template_radius, accept, likeness,
                                                           evolve), board_text, plane_points, preview_frame,
                          camera_json, scale, scale_aruco, aruco_dict, origin, angle, Clip(start, end, step, fps),
                          out, fmt, overlay_kind, force, trk_out)
    return _track(video, video, project, markers, (color_tol, search_px, template_radius, accept, likeness, evolve),
                  board_text, plane_points, preview_frame, camera_json, scale, scale_aruco, aruco_dict, origin, angle,
                  Clip(start, end, step, fps), out, fmt, overlay_kind, force, trk_out)


def _track(video: Path, named: Path, project, markers, settings, board_text, plane_points, preview_frame, camera_json,
           scale, scale_aruco, aruco_dict, origin, angle, clip: Clip, out, fmt, overlay_kind, force, trk_out) -> None:
    """Track ``video`` (``named`` on the command line: the video, or a Tracker project that opens it)."""
    color_tol, search_px, template_radius, accept, likeness, evolve = settings
    info = probe(video)
    clip = clip.resolved(info)
    options = ModelOptions(color_tol, search_px, template_radius, accept, evolve / 100.0, likeness)
    models = parse_markers(list(markers), options)
    if preview_frame is not None:
        return _preview(info, preview_frame, models, _base_path(out, named), force)
    if board_text or plane_points:
        if scale or scale_aruco or origin or camera_json:
            raise TrackError("give --board/--plane-points or --scale/--scale-aruco/--origin/--camera-json, not both",
                             "one calibration per run")
        if board_text and plane_points:
            raise TrackError("give --board or --plane-points, not both", "one calibration per run")
        calibration = (board.parse_plane_points(plane_points) if plane_points
                       else board.board_homography(info, clip, board.parse_board(board_text)))
    elif project is not None:
        calibration = project.calibration
    else:
        calibration = _calibration(info, clip, scale, scale_aruco, aruco_dict, origin, angle, camera_json)
    paths = _outputs(_base_path(out, named), fmt, overlay_kind)
    if trk_out is not None:
        paths["trk"] = trk_out
    _refuse_inputs(paths, [p for p in (video, named, camera_json, project and project.path) if p])
    _refuse_overwrite(paths, force)

    n = len(clip.frames())
    with progress(length=n, label=f"tracking {video.name}") as bar:
        result = track_video(info, clip, models, calibration, progress=bar.update)
    if named != video:   # a Tracker project's video, unpacked from it for this run
        result.source = f"locust track of the video in {named}"
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


def _preview(info, frame: int, models: list, base: Path, force: bool) -> None:
    path = base.with_name(base.name + ".preview.png")
    _refuse_overwrite({"preview": path}, force)
    blobs, found = preview.preview(info, frame, models, path)
    click.echo(f"frame {frame} of {info.path.name} ({info.width_px}x{info.height_px}): most saturated blobs")
    for k, b in enumerate(blobs, 1):
        click.echo(b.line(k))
    if not blobs:
        click.echo("  none (no strongly coloured patch in this frame)")
    for name, p in found.items():
        click.echo(f"  marker {name}: " + (f"found at {p[0]:.1f},{p[1]:.1f}" if p else "not found"))
    click.echo(f"wrote {path}")


def _calibration(info, clip, scale, scale_aruco, aruco_dict, origin, angle, camera_json=None):
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
    point = calib.parse_point(origin, "--origin") if origin else None
    return calib.build(info.height_px, m_per_px, point, angle, source)


def _write(result, paths: dict[str, Path], fmt: str) -> list[Path]:
    if fmt == "tracker":
        trk.write_tracker_text(result, paths["tracks"])
        atomic_write_json(paths["sidecar"], export.sidecar(result, paths["tracks"]))
        return [paths["tracks"], paths["sidecar"]]
    return list(export.write_tracks(result, paths["tracks"]))


def _convert_trk(path: Path, names: list[str], out, fmt: str, force: bool) -> None:
    project = trk_io.read_project(path)
    result = trk.project_result(project, names or None)
    paths = _outputs(_base_path(out, path), fmt, "none")
    _refuse_inputs(paths, [path])
    _refuse_overwrite(paths, force)
    _report(result, _write(result, paths, fmt))


def _import(path: Path, imports: ImportOptions, out: Path | None, force: bool) -> None:
    tracks = import_tracks(path, options=imports)
    target = out if out is not None and not out.is_dir() else tracks_csv_beside(out / path.name if out else path)
    if target.exists() and target.resolve() == path.resolve():
        raise TrackError(f"--out {target} is the file being imported", "write the tracks CSV to another --out")
    _refuse_overwrite({"tracks": target}, force)
    for warning in span_warnings(tracks, imports):
        click.echo(f"warning: {warning}", err=True)
    write_tracks_csv(target, tracks)
    click.echo(f"{path.name}: {tracks.n_rows} rows, {imports.describe()}")
    for name in tracks.markers_with_positions():
        x, y = tracks.positions(name)
        ok = np.isfinite(x) & np.isfinite(y)
        if ok.any():
            click.echo(f"  {name}: {int(ok.sum())} rows with a position; x {x[ok].min():.6g} .. {x[ok].max():.6g} m, "
                       f"y {y[ok].min():.6g} .. {y[ok].max():.6g} m")
        else:
            click.echo(f"  {name}: no position")
    click.echo(f"wrote {target}")


def _report(result, written: list[Path]) -> None:
    for line in export.summary_lines(result):
        click.echo(line)
    lost = [t.name for t in result.markers
            if t.spec.startswith("template:") and t.ok.any() and not t.ok[int(np.argmax(t.ok)):].all()]
    if lost:
        click.echo(f"hint: {', '.join(lost)}: lost (nan) where the match looked unlike the template (--likeness, "
                   "--accept) or left the path its track predicts, e.g. out of view; check the overlay, and pick "
                   "a point with texture that stays in view, or a --template-radius about the feature's size")
    for p in written:
        click.echo(f"wrote {p}")
