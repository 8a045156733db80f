"""Tracks to files: the CSV everyone reads, and a JSON sidecar with how they were made.

The CSV's layout, writer and reader are :mod:`locust.io.tracks_csv`'s (columns ``frame``, ``t_s``,
then per marker ``<name>_px``, ``<name>_py`` in pixels, OpenCV convention, ``<name>_x_m``,
``<name>_y_m`` in world metres, y up, ``nan`` without a scale, and ``<name>_ok`` 1/0; a
marker not found is ``nan`` with ok 0). A
:class:`~.runner.TrackResult` holds one (``result.tracks``); this module writes it, and the
sidecar beside it.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..fileio import atomic_write_json
from ..io.tracks_csv import write_tracks_csv
from ..version import __version__
from .runner import TrackResult
from .video import TIMES_FROM_FILE

SIDECAR_FORMAT = "locust.track/1"   # the JSON sidecar beside a tracks CSV
PIXEL_CONVENTION = "OpenCV: origin at the centre of the top-left pixel, x right, y down"


def sidecar(result: TrackResult, csv_path: Path) -> dict:
    """The JSON sidecar of a tracks CSV: source video, clip, calibration, and per marker its
    found frames, events and scores.

    Parameters
    ----------
    result : TrackResult
        The tracks.
    csv_path : Path
        The CSV it goes beside (its name is recorded).

    Returns
    -------
    dict
        The sidecar (format :data:`SIDECAR_FORMAT`).
    """
    clip, t = result.clip, result.tracks
    src: dict = {"kind": result.source}
    if result.video is not None:
        v = result.video
        # absolute: the sidecar lands in the output folder, seldom beside the video
        src.update(video=str(Path(v.path).resolve()), width_px=v.width_px, height_px=v.height_px,
                   frame_count=v.frame_count, file_fps=v.file_fps)
    return {
        "format": SIDECAR_FORMAT,
        "locust_version": __version__,
        "tracks": csv_path.name,
        "pixel_convention": PIXEL_CONVENTION,
        "source": src,
        "clip": {"start": clip.start, "end": clip.end, "step": clip.step, "fps": clip.fps, "time": result.times},
        "calibration": result.calibration.as_dict(),
        "markers": [{"name": m, "spec": result.specs[m], "frames": len(t.ok[m]), "found": result.found(m),
                     **asdict(track_events(t.px[m], t.py[m], t.ok[m])),
                     "missing_frames": [int(f) for f in t.frame[~t.ok[m]]]} for m in t.markers],
        "scores": {"frame": [int(f) for f in t.frame],
                   **{m: [float(s) for s in result.scores[m]] for m in t.markers}},
    }


def write_tracks(result: TrackResult, csv_path: Path) -> tuple[Path, Path]:
    """Write ``csv_path`` and its sidecar ``<stem>.json``, each atomically.

    Parameters
    ----------
    result : TrackResult
        The tracks.
    csv_path : Path
        The CSV to write.

    Returns
    -------
    csv_path, json_path : Path
        The files written.
    """
    json_path = csv_path.with_suffix(".json")
    write_tracks_csv(csv_path, result.tracks)
    atomic_write_json(json_path, sidecar(result, csv_path))
    return csv_path, json_path


def sidecar_video(csv_path: Path) -> Path | None:
    """The video a tracks CSV was tracked from, as its sidecar (``<stem>.json`` beside it,
    :func:`write_tracks`) records it: the sidecar often lies in an output folder away from
    the video.

    Parameters
    ----------
    csv_path : Path
        The tracks CSV.

    Returns
    -------
    Path or None
        The recorded video where it is still a file; None without a readable locust sidecar,
        or where the video has moved.
    """
    try:
        doc = json.loads(csv_path.with_suffix(".json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict) or doc.get("format") != SIDECAR_FORMAT:
        return None
    video = doc.get("source", {}).get("video")
    return Path(video) if isinstance(video, str) and Path(video).is_file() else None


JUMP_MIN_PX = 50.0


@dataclass(frozen=True)
class TrackEvents:
    """How a marker's track holds together: a tracker that jumps to a look-alike shows here."""

    gaps: int              # runs of frames not found, after the first sighting
    longest_gap: int       # frames
    reacquired: int        # sightings after a gap
    jumps: int             # frame-to-frame steps larger than 50 px and 5 times the median step


def track_events(px: np.ndarray, py: np.ndarray, ok: np.ndarray) -> TrackEvents:
    """How a marker's track holds together: gaps, re-acquisitions and jumps.

    Parameters
    ----------
    px, py : ndarray
        Its positions per frame [px].
    ok : ndarray of bool
        Whether it was found on each frame.

    Returns
    -------
    TrackEvents
        Gaps (a trailing one counted), the longest [frames], re-acquisitions, and steps over
        50 px and 5 times the median step.
    """
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return TrackEvents(0, 0, 0, 0)
    apart = np.diff(idx)
    missing = apart[apart > 1] - 1
    steps = np.hypot(np.diff(px[idx]), np.diff(py[idx]))[apart == 1]
    typical = float(np.median(steps)) if steps.size else 0.0
    jumps = int(np.sum((steps > JUMP_MIN_PX) & (steps > 5 * typical)))
    tail = len(ok) - 1 - idx[-1]
    return TrackEvents(int(missing.size + (tail > 0)), int(max(missing.max(initial=0), tail)), int(missing.size),
                       jumps)


def summary_lines(result: TrackResult) -> list[str]:
    """What was tracked, one line per marker: frames found, median score, missing frames and events.

    Parameters
    ----------
    result : TrackResult
        The tracks.

    Returns
    -------
    list of str
        The lines to print.
    """
    lines = []
    t = result.tracks
    n = len(t.frame)
    for m in t.markers:
        line = f"{m:10s} {result.found(m):5d}/{n} frames found"
        score = result.scores[m]
        finite = score[np.isfinite(score) & t.ok[m]]
        if finite.size:
            line += f", score median {np.median(finite):.3g}"
        missing = t.frame[~t.ok[m]]
        if missing.size:
            shown = ", ".join(str(int(f)) for f in missing[:8]) + (" ..." if missing.size > 8 else "")
            line += f"; missing frames {shown}"
        ev = track_events(t.px[m], t.py[m], t.ok[m])
        line += (f"; {ev.gaps} gap(s), longest {ev.longest_gap} frames, {ev.reacquired} re-acquisition(s), "
                 f"{ev.jumps} jump(s)")
        lines.append(line)
    if result.times == TIMES_FROM_FILE and len(t.t_s) > 1:
        gaps_ms = np.diff(t.t_s) / np.diff(t.frame) * 1000
        lines.append(f"times: the video's own timestamps, its frames {gaps_ms.min():.1f} to {gaps_ms.max():.1f} ms "
                     f"apart (a variable frame rate), not frame / {result.clip.fps:g} frames/s")
    lines.append(result.calibration.summary())
    return lines



def report_lines(result: TrackResult) -> list[str]:
    """What a job that wrote ``result`` prints: :func:`summary_lines`, a hint where a template
    marker was lost after it was found, and each file written.

    Parameters
    ----------
    result : TrackResult
        The tracks, with the files written.

    Returns
    -------
    list of str
        The lines to print.
    """
    lines = summary_lines(result)
    ok = result.tracks.ok
    lost = [m for m in result.tracks.markers
            if result.specs[m].startswith("template:") and ok[m].any() and not ok[m][int(np.argmax(ok[m])):].all()]
    if lost:
        lines.append(f"hint: {', '.join(lost)}: lost (nan) where the match looked unlike the template (--likeness, "
                     "--accept) or left the path its track predicts, e.g. out of view; check the overlay, and pick "
                     "a point with texture that stays in view, or a --template-radius about the feature's size")
    return [*lines, *(f"wrote {p}" for p in result.written)]
