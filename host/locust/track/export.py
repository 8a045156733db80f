"""Tracks to files: the CSV everyone reads, and a JSON sidecar with how they were made.

CSV columns: ``frame``, ``t_s``, then per marker ``<name>_px``, ``<name>_py`` (pixels,
OpenCV convention), ``<name>_x_m``, ``<name>_y_m`` (world, y up; ``nan`` without a
scale), ``<name>_ok`` (1/0). A marker not found is ``nan`` with ok 0.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np

from .. import __version__
from ..fileio import atomic_write_json, atomic_write_text
from .runner import TrackResult

PIXEL_CONVENTION = "OpenCV: origin at the centre of the top-left pixel, x right, y down"


def csv_text(result: TrackResult) -> str:
    head = ["frame", "t_s"]
    cols: list[np.ndarray] = []
    for tr in result.markers:
        head += [f"{tr.name}_px", f"{tr.name}_py", f"{tr.name}_x_m", f"{tr.name}_y_m", f"{tr.name}_ok"]
        xm, ym = result.world(tr)
        cols += [tr.px, tr.py, xm, ym, tr.ok]
    out = io.StringIO()
    out.write(",".join(head) + "\n")
    for i, frame in enumerate(result.frames):
        row = [str(int(frame)), _fmt(result.t_s[i], 6)]
        for k, col in enumerate(cols):
            kind = k % 5
            row.append(str(int(bool(col[i]))) if kind == 4 else _fmt(col[i], 4 if kind < 2 else 6))
        out.write(",".join(row) + "\n")
    return out.getvalue()


def sidecar(result: TrackResult, csv_path: Path) -> dict:
    clip = result.clip
    src: dict = {"kind": result.source}
    if result.video is not None:
        v = result.video
        src.update(video=str(v.path), width_px=v.width_px, height_px=v.height_px,
                   frame_count=v.frame_count, file_fps=v.file_fps)
    return {
        "format": "locust.track/1",
        "locust_version": __version__,
        "tracks": csv_path.name,
        "pixel_convention": PIXEL_CONVENTION,
        "source": src,
        "clip": {"start": clip.start, "end": clip.end, "step": clip.step, "fps": clip.fps,
                 "time": "t_s = (frame - start) / fps"},
        "calibration": result.calibration.as_dict(),
        "markers": [{"name": t.name, "spec": t.spec, "frames": len(t.ok), "found": t.found(),
                     "missing_frames": [int(f) for f in result.frames[~t.ok]]} for t in result.markers],
        "scores": {"frame": [int(f) for f in result.frames],
                   **{t.name: [_json_num(s) for s in t.score] for t in result.markers}},
    }


def write_tracks(result: TrackResult, csv_path: Path) -> tuple[Path, Path]:
    """Write ``csv_path`` and its sidecar ``<stem>.json``, each atomically."""
    json_path = csv_path.with_suffix(".json")
    atomic_write_text(csv_path, csv_text(result))
    atomic_write_json(json_path, sidecar(result, csv_path))
    return csv_path, json_path


def summary_lines(result: TrackResult) -> list[str]:
    lines = []
    n = len(result.frames)
    for t in result.markers:
        line = f"{t.name:10s} {t.found():5d}/{n} frames found"
        finite = t.score[np.isfinite(t.score) & t.ok]
        if finite.size:
            line += f", score median {np.median(finite):.3g}"
        missing = result.frames[~t.ok]
        if missing.size:
            shown = ", ".join(str(int(f)) for f in missing[:8]) + (" ..." if missing.size > 8 else "")
            line += f"; missing frames {shown}"
        lines.append(line)
    lines.append(result.calibration.summary())
    return lines


def _fmt(value: float, digits: int) -> str:
    return "nan" if not math.isfinite(value) else f"{value:.{digits}f}"


def _json_num(value: float):
    return float(value) if math.isfinite(value) else None
