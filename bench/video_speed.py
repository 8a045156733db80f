"""``locust sim --video``: the frames at the model's own render quality against a video's, side by side.

    python bench/video_speed.py [--preset seed] [--cycles 1] [--repeat 3] [--width 1280 --height 720]

One rollout of the preset, its states kept, rendered to MP4 twice a round (``--repeat``
rounds, the two in turn; best of each): at the model's own quality (4 MSAA samples, a 2048 px
shadow map: the stills' and photos' quality, which are measured to a tenth of a pixel) and at
``locust.sim.clip.VIDEO_QUALITY`` (no multisampling, a 1024 px shadow map), what ``locust sim
--video`` renders. Where the time goes is printed for one frame of each: MuJoCo's render with
its read-back (OSMesa here: software OpenGL, the one back end a machine without a GPU has) and
OpenCV's MPEG-4 encoder; the rest of a frame is its truth (the markers' projection and how much
of each the camera sees). Each video is then tracked by ``locust track``'s default colour
markers, and the tracked pixels compared with the truth sidecar's (the markers' true pixel
centres), where the truth has a marker at least 90 % seen.

Last line: ``video speedup <N>x (<a> s against <b> s for <F> frames); tracked nose/foot
within <e1>/<e2> px RMS of the truth against <f1>/<f2> px``.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "osmesa")

import numpy as np
import pandas as pd

from locust.api.tracking import track_markers
from locust.params import preset
from locust.sim.camera import frame_views
from locust.sim.clip import VIDEO_QUALITY, PoseRenderer, render_video
from locust.sim.rollout import roll_out


def rms_px(video: Path) -> dict[str, float]:
    """Each marker's RMS distance from its true pixel [px], where the truth sees it at least 90 %."""
    truth = pd.read_csv(video.with_name(video.stem + ".truth.csv"), comment="#")
    tracks = track_markers(video, overlay="none").to_dataframe()
    out = {}
    for m in ("nose", "foot"):
        seen = truth[f"{m}_seen_frac"].to_numpy() >= 0.9
        d = np.hypot(tracks[f"{m}_px"].to_numpy() - truth[f"{m}_px"].to_numpy(),
                     tracks[f"{m}_py"].to_numpy() - truth[f"{m}_py"].to_numpy())[seen]
        out[m] = float(np.sqrt(np.nanmean(d ** 2)))
    return out


def one_frame(model, view, state_qpos, width: int, height: int, quality) -> tuple[float, float]:
    """One frame's render (MuJoCo's render and read-back, ``PoseRenderer.render``) and its
    encoding (OpenCV's MPEG-4 writer) [s], best of 5 each after 3 to warm up."""
    import cv2

    poser = PoseRenderer(model, width, height, True, quality)
    poser.pose(state_qpos)
    for _ in range(3):     # the first frames compile the software renderer's shaders
        poser.render(view)
    best_render = best_encode = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        writer = cv2.VideoWriter(str(Path(tmp) / "f.mp4"), cv2.VideoWriter_fourcc(*"mp4v"), 30.0, (width, height))
        for _ in range(5):
            t0 = time.perf_counter()
            rgb, _ = poser.render(view)
            t1 = time.perf_counter()
            writer.write(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
            t2 = time.perf_counter()
            best_render, best_encode = min(best_render, t1 - t0), min(best_encode, t2 - t1)
        writer.release()
    poser.close()
    return best_render, best_encode


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", default="seed")
    ap.add_argument("--cycles", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--width", type=int, default=1280)
    ap.add_argument("--height", type=int, default=720)
    args = ap.parse_args()
    robot = preset(args.preset)
    traj = roll_out(robot, cycles=args.cycles, keep_states=True)
    model = traj.built.model
    print(f"{args.preset}, {args.cycles} cycle(s), {args.width}x{args.height}; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    routes = {"model's own (4 MSAA, 2048 px shadows)": None,
              f"a video's ({VIDEO_QUALITY.msaa_samples} MSAA, {VIDEO_QUALITY.shadow_map_px} px shadows)": VIDEO_QUALITY}
    qpos = traj.states[len(traj.states) // 2, 1:1 + model.nq]
    sd, s = traj.sensordata, traj.built.sensors
    points = np.vstack([sd[:, s.nose_pos], sd[:, s.foot_pos], sd[:, s.chassis_pos], sd[:, s.com_pos]])
    _, view = frame_views(points, sd[:, s.chassis_pos][:, 0], robot.geometry.body_length_m, 0.0,
                          float(model.vis.global_.fovy), args.width / args.height)
    best = {name: float("inf") for name in routes}
    frames = 0
    with tempfile.TemporaryDirectory() as tmp:
        videos = {}
        for k in range(args.repeat):
            for i, (name, quality) in enumerate(routes.items()):
                path = Path(tmp) / f"v{i}_{k}.mp4"
                t0 = time.perf_counter()
                info = render_video(robot, path, trajectory=traj, width=args.width, height=args.height,
                                    quality=quality)
                best[name] = min(best[name], time.perf_counter() - t0)
                frames, videos[name] = info.frames, path
        print(f"{'route':44s} {'video_s':>8s} {'per frame ms':>12s} {'render ms':>9s} {'encode ms':>9s} "
              f"{'nose px':>8s} {'foot px':>8s}")
        errs = {}
        for name, quality in routes.items():
            render_s, encode_s = one_frame(model, view, qpos, args.width, args.height, quality)
            errs[name] = rms_px(videos[name])
            print(f"{name:44s} {best[name]:8.2f} {best[name] / frames * 1000:12.1f} {render_s * 1000:9.1f} "
                  f"{encode_s * 1000:8.1f} {errs[name]['nose']:8.3f} {errs[name]['foot']:8.3f}", flush=True)
    own, video = list(routes)
    print(f"video speedup {best[own] / best[video]:.2f}x ({best[video]:.2f} s against {best[own]:.2f} s for "
          f"{frames} frames); tracked nose/foot within {errs[video]['nose']:.3f}/{errs[video]['foot']:.3f} px RMS "
          f"of the truth against {errs[own]['nose']:.3f}/{errs[own]['foot']:.3f} px")


if __name__ == "__main__":
    sys.exit(main())
