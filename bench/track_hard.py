"""Tracking on a SYNTHETIC phone-like hard clip (locust.track.hardclip), against known truth.

The clip: a pink sticker hopping in a plane seen at a tilt, a pen cap of the same colour
lying in the scene, a shadow sweeping across, motion blur in flight, the sticker leaving
the top of the picture and coming back, and an ArUco grid board in the plane of motion.
The sticker is tracked by colour alone (no start point), the plane fitted from the board.

Prints one line per tracker (now, and the tracking package at ``--before REV``):

    found % (of frames with the whole sticker in the picture), wrong frames (> 8 px, of all
    frames found), found while out of the picture, RMS px (found frames), metric RMS mm

Acceptance: found >= 90 %, wrong <= 1 %, none found out of the picture, RMS <= 1.5 px,
metric RMS <= 2 mm.

    python bench/track_hard.py [--width 1920 --height 1080] [--frames 120] [--before 2ef6642 | none]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from locust.track.board import board_homography
from locust.track.calib import build
from locust.track.hardclip import make_hard_video
from locust.track.runner import track_video
from locust.track.spec import parse_markers
from locust.track.video import Clip, probe

WRONG_PX = 8.0


def figures(truth, px: np.ndarray, py: np.ndarray, ok: np.ndarray, plane=None) -> dict[str, float]:
    """The acceptance figures of one track against the hard clip's truth."""
    err = np.hypot(px - truth.px, py - truth.py)
    wrong = ok & ~(err <= WRONG_PX)          # found where the truth is nan counts as wrong too
    out = {"found_pct": 100.0 * ok[truth.whole].sum() / truth.whole.sum(),
           "wrong_pct": 100.0 * wrong.sum() / max(ok.sum(), 1),
           "found_out": int(ok[~truth.in_picture].sum()),
           "rms_px": float(np.sqrt(np.nanmean(err[ok & truth.in_picture] ** 2)))}
    if plane is not None:
        xm, ym = plane.to_world(px, py)
        e_mm = 1000 * np.hypot(xm - truth.x_m, ym - truth.y_m)
        out["metric_rms_mm"] = float(np.sqrt(np.nanmean(e_mm[ok & truth.in_picture] ** 2)))
    return out


def line(label: str, f: dict[str, float]) -> str:
    text = (f"{label:8s} found {f['found_pct']:5.1f} %, wrong (> {WRONG_PX:g} px) {f['wrong_pct']:5.2f} %, "
            f"found out of picture {f['found_out']}, RMS {f['rms_px']:.3f} px")
    if "metric_rms_mm" in f:
        text += f", metric RMS {f['metric_rms_mm']:.2f} mm"
    return text


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=1920)
    ap.add_argument("--height", type=int, default=1080)
    ap.add_argument("--frames", type=int, default=120)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--before", default="2ef6642",
                    help="git revision whose tracking package runs beside the current one ('none': skip)")
    args = ap.parse_args()
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from track_speed import load_before, marker_pixels

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "hard_synthetic.mp4"
        t = time.perf_counter()
        truth = make_hard_video(path, args.width, args.height, args.frames, seed=args.seed)
        print(f"synthetic hard clip: {args.width}x{args.height}, {args.frames} frames, sticker {truth.sticker_hex} "
              f"(whole in picture on {int(truth.whole.sum())}, out on {int((~truth.in_picture).sum())}), "
              f"board {truth.board.text()} ({time.perf_counter() - t:.1f} s to make)")
        info = probe(path)
        clip = Clip().resolved(info)
        plane = board_homography(info, clip, truth.board)
        print(f"  {plane.summary()}")
        spec = [f"sticker=color:{truth.sticker_hex}"]
        t = time.perf_counter()
        m = marker_pixels(track_video(info, clip, parse_markers(spec), build(info.height_px), require_found=False))
        now_s = time.perf_counter() - t
        if args.before != "none":
            (Path(tmp) / "before").mkdir()
            before = load_before(args.before, Path(tmp) / "before")
            if before is not None:
                b = marker_pixels(before.runner.track_video(
                    before.video.probe(path), before.video.Clip().resolved(info), before.spec.parse_markers(spec),
                    before.calib.build(info.height_px), require_found=False))
                print(line("before", figures(truth, *b["sticker"], plane)) + f"  ({args.before})")
        px, py, ok = m["sticker"]
        print(line("now", figures(truth, px, py, ok, plane)) + f"  ({len(ok) / now_s:.0f} frames/s)")


if __name__ == "__main__":
    main()
