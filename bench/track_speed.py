"""Tracking speed against pure decoding, measured side by side, plus accuracy on known truth.

Writes a synthetic 1280x720 hop video (locust.track.synth: known sub-pixel truth) twice:
MPEG-4 part 2 (OpenCV's encoder, about 1 Mbit/s: far less data than a camera writes, so it
decodes unusually fast) and motion-JPEG at quality 90 (about 7 Mbit/s, as webcams and
many action cameras record). For each it times, alternately and several times each:

- decode: every frame decoded to BGR by OpenCV, nothing else;
- track:  the same decoding plus the two default colour markers (nose, foot);
- before: the same with the tracking package as it was at ``--before REV`` (read from
  git into a temporary package), so an optimisation is judged in the same run, on the
  same machine load, against the code it replaced.

The last lines are ``track/decode ratio R ...`` (tracking frame rate over decoding frame
rate, MPEG-4 then motion-JPEG; 1.0 = tracking costs nothing beyond decoding; goal >= 0.75)
and the same for ``before``.

    python bench/track_speed.py [--frames 240] [--repeats 3] [--before 053160a | --before none]
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import subprocess
import sys
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


def decode_and_track(info, clip, package=None):
    """Decode + track the two default markers with the current package, or with ``package``
    (an older copy: its own probe, clip, markers and frame loop)."""
    if package is not None:
        info = package.video.probe(info.path)
        clip = package.video.Clip().resolved(info)
        run, markers, calibration = package.runner.track_video, package.spec.parse_markers([]), \
            package.calib.build(info.height_px)
    else:
        run, markers, calibration = track_video, parse_markers([]), build(info.height_px)
    t = time.perf_counter()
    result = run(info, clip, markers, calibration)
    return time.perf_counter() - t, result


class _Package:
    def __init__(self, name: str):
        self.video = importlib.import_module(f"{name}.video")
        self.runner = importlib.import_module(f"{name}.runner")
        self.spec = importlib.import_module(f"{name}.spec")
        self.calib = importlib.import_module(f"{name}.calib")


def marker_pixels(result) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Per marker its pixels and found flags, from this checkout's result (its tracks file's
    columns) or an older copy's (a list of tracked markers)."""
    if hasattr(result, "tracks"):
        t = result.tracks
        return {m: (t.px[m], t.py[m], t.ok[m]) for m in t.markers}
    return {tr.name: (tr.px, tr.py, tr.ok) for tr in result.markers}


def load_before(rev: str, folder: Path):
    """``host/locust/track`` as it was at git revision ``rev``, imported as ``locust.track_before``."""
    root = Path(__file__).resolve().parents[1]
    try:
        names = subprocess.run(["git", "-C", str(root), "ls-tree", "--name-only", rev, "host/locust/track/"],
                               capture_output=True, text=True, check=True).stdout.split()
        for name in names:
            if name.endswith(".py"):
                text = subprocess.run(["git", "-C", str(root), "show", f"{rev}:{name}"],
                                      capture_output=True, text=True, check=True).stdout
                (folder / Path(name).name).write_text(text)
    except (OSError, subprocess.CalledProcessError) as exc:
        print(f"no 'before' run: cannot read host/locust/track at {rev} from git ({exc})")
        return None
    spec = importlib.util.spec_from_file_location("locust.track_before", folder / "__init__.py",
                                                  submodule_search_locations=[str(folder)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["locust.track_before"] = module
    spec.loader.exec_module(module)
    return _Package("locust.track_before")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=240)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--before", default="053160a",
                    help="git revision whose tracking package is timed beside the current one ('none': skip)")
    args = ap.parse_args()
    ratios = []
    with tempfile.TemporaryDirectory() as tmp:
        before = None
        if args.before != "none":
            (Path(tmp) / "before").mkdir()
            before = load_before(args.before, Path(tmp) / "before")
        for fourcc, ext in (("mp4v", "mp4"), ("MJPG", "avi")):
            path = Path(tmp) / f"bench_hop_synthetic.{ext}"
            t = time.perf_counter()
            truth = make_hop_video(path, width=1280, height=720, n_frames=args.frames, fps=60.0, radius_px=8.0,
                                   occluded=(args.frames // 2, args.frames // 2 + 4), seed=11, fourcc=fourcc)
            mbit_s = path.stat().st_size * 8 / (args.frames / 60.0) / 1e6
            print(f"synthetic video {fourcc}: 1280x720, {args.frames} frames at 60 fps, {mbit_s:.1f} Mbit/s "
                  f"({time.perf_counter() - t:.1f} s to make)")
            ratios.append((fourcc, mbit_s, *measure(path, truth, args.repeats, before)))
    what = ", ".join(f"{c} {m:.0f} Mbit/s" for c, m, *_ in ratios)
    if before is not None:
        print(f"before ({args.before}) track/decode ratio " + " ".join(f"{r[3]:.3f}" for r in ratios) + f" ({what})")
    print("track/decode ratio " + " ".join(f"{r[2]:.3f}" for r in ratios) + f" ({what}; goal >= 0.75)")


def measure(path: Path, truth, repeats: int, before=None) -> tuple[float, float]:
    """Best-of-``repeats`` decode time over track time, now and (if given) before."""
    info = probe(path)
    clip = Clip().resolved(info)
    times: dict[str, list[float]] = {"decode": [], "track": [], "before": []}
    results = {}
    for _ in range(repeats):
        times["decode"].append(decode_only(info, clip))
        dt, results["track"] = decode_and_track(info, clip)
        times["track"].append(dt)
        if before is not None:
            dt, results["before"] = decode_and_track(info, clip, before)
            times["before"].append(dt)
    n = len(clip.frames())
    best = {k: min(v) for k, v in times.items() if v}
    for k, label in (("decode", "decode"), ("track", "decode + track 2"), ("before", "before: decode + track 2")):
        if k in best:
            print(f"  {label:26s} {best[k]:7.3f} s  {n / best[k]:7.1f} frames/s  (best of {repeats})")
    for kind, result in results.items():
        for name, (px, py, ok) in marker_pixels(result).items():
            vis = truth.visible[name]
            err = np.hypot(px - truth.px[name], py - truth.py[name])[vis]
            hidden_ok = bool((~ok[~vis]).all())
            print(f"  {kind:6s} {name:5s} RMS error {np.sqrt(np.nanmean(err ** 2)):.3f} px, "
                  f"max {np.nanmax(err):.3f} px, found {int(ok[vis].sum())}/{int(vis.sum())} visible, "
                  f"{int((~vis).sum())} occluded frames nan: {hidden_ok}")
    return best["decode"] / best["track"], best["decode"] / best["before"] if "before" in best else float("nan")


if __name__ == "__main__":
    main()
