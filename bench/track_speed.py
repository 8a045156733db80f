"""Tracking speed against pure decoding, measured side by side, plus accuracy on known truth.

Writes a synthetic 1280x720 hop video (locust.track.synth: known sub-pixel truth) twice:
MPEG-4 part 2 (OpenCV's encoder, about 1 Mbit/s: far less data than a camera writes, so it
decodes unusually fast) and motion-JPEG at quality 90 (about 7 Mbit/s, as webcams and
many action cameras record). For each it times, alternately and several times each:

- decode: every frame decoded to BGR by OpenCV, nothing else;
- track:  the same decoding plus the two default colour markers (nose, foot).

The last line is ``track/decode ratio R ...``: tracking frame rate over decoding frame
rate for the MPEG-4 video, then for the motion-JPEG one (1.0 = tracking costs nothing
beyond decoding; goal >= 0.75).

    python bench/track_speed.py [--frames 240] [--repeats 3]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from locust.track.calib import build
from locust.track.runner import track_video
from locust.track.spec import parse_markers
from locust.track.synth import make_hop_video
from locust.track.video import Clip, probe, read_frames


def decode_only(info, clip) -> float:
    t = time.perf_counter()
    for _ in read_frames(info, clip):
        pass
    return time.perf_counter() - t


def decode_and_track(info, clip):
    t = time.perf_counter()
    result = track_video(info, clip, parse_markers([]), build(info.height_px))
    return time.perf_counter() - t, result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=240)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    ratios = []
    with tempfile.TemporaryDirectory() as tmp:
        for fourcc, ext in (("mp4v", "mp4"), ("MJPG", "avi")):
            path = Path(tmp) / f"bench_hop_synthetic.{ext}"
            t = time.perf_counter()
            truth = make_hop_video(path, width=1280, height=720, n_frames=args.frames, fps=60.0, radius_px=8.0,
                                   occluded=(args.frames // 2, args.frames // 2 + 4), seed=11, fourcc=fourcc)
            mbit_s = path.stat().st_size * 8 / (args.frames / 60.0) / 1e6
            print(f"synthetic video {fourcc}: 1280x720, {args.frames} frames at 60 fps, {mbit_s:.1f} Mbit/s "
                  f"({time.perf_counter() - t:.1f} s to make)")
            ratios.append((fourcc, mbit_s, measure(path, truth, args.repeats)))
    print("track/decode ratio " + " ".join(f"{r:.3f}" for _, _, r in ratios) + " ("
          + ", ".join(f"{c} {m:.0f} Mbit/s" for c, m, _ in ratios) + "; goal >= 0.75)")


def measure(path: Path, truth, repeats: int) -> float:
    info = probe(path)
    clip = Clip().resolved(info)
    decode_s, track_s, result = [], [], None
    for _ in range(repeats):
        decode_s.append(decode_only(info, clip))
        dt, result = decode_and_track(info, clip)
        track_s.append(dt)
    d, k = min(decode_s), min(track_s)
    n = len(clip.frames())
    print(f"  decode            {d:7.3f} s  {n / d:7.1f} frames/s  (best of {repeats})")
    print(f"  decode + track 2  {k:7.3f} s  {n / k:7.1f} frames/s  (best of {repeats})")
    for tr in result.markers:
        vis = truth.visible[tr.name]
        err = np.hypot(tr.px - truth.px[tr.name], tr.py - truth.py[tr.name])[vis]
        hidden_ok = bool((~tr.ok[~vis]).all())
        print(f"  {tr.name:5s} RMS error {np.sqrt(np.nanmean(err ** 2)):.3f} px, max {np.nanmax(err):.3f} px, "
              f"found {int(tr.ok[vis].sum())}/{int(vis.sum())} visible, "
              f"{int((~vis).sum())} occluded frames nan: {hidden_ok}")
    return d / k

if __name__ == "__main__":
    main()
