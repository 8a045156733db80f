"""An independent hard clip for `locust track`: SYNTHETIC sticker, board and shadow composited
over REAL footage, then tracked through the CLI as a user would, and scored against its truth.

SYNTHETIC-OVER-REAL-FOOTAGE. The background is real video from Tracker's (Open Source Physics)
sample projects, read at run time from ``../shared/data/tracker`` (never copied into the project):
``CupsClips.zip`` (default: a lecturer, falling paper cups, a ruler and captions) or the video
inside ``BallToss.trz`` (a dark room, a white metre stick). Its frames are cropped to 16:9,
upscaled and played back and forth (cross-faded) for the length of the clip. Everything on top
of it is drawn here, written without looking at the project's own hard-clip generator:

- a round orange sticker (20 mm) on a robot's nose, lying in the plane of an ArUco grid board
  (``4X4_50``, 5 x 3 markers of 40 mm, 10 mm apart) that stands behind the hop. A pinhole camera
  (turned 30 deg from the board's normal, looking 12 deg down, rolled 3 deg) maps the board's plane
  into the picture, so the sticker's true position in the board's frame (mm, origin at the board's
  bottom-left corner, y up) is known on every frame;
- the nose rests, crouches, makes a small hop (130 mm high), rests, then a big hop (600 mm high)
  that leaves the top of the picture and comes back; ballistic flight (g = 9.81 m/s^2), a dip on
  each landing. Exposure 1/150 s: each frame averages 32 sub-frame renders across it (motion blur);
- a static pen cap of nearly the same orange (55 x 13 mm) lying in the plane near the path;
- a soft shadow (55 % darker at its core) sweeping across the scene, over the sticker at times;
- a slight flicker of the room's light, sensor noise, and the mp4v codec.

Truth per frame: the sticker's image centre is the area-weighted mean of its sub-frame centres
(the centroid of its blur streak); its plane position the same mean of its sub-frame positions on
the path (the two agree through the homography to a few hundredths of a mm, printed; the path at
the frame's mid-exposure time differs from it by up to ~3 mm on frames that straddle a take-off or
a landing). Visibility: ``full`` (every
sub-frame disk inside the picture), ``out`` (none of it inside) or ``partial``.

The tracker is run as ``locust track CLIP --marker nose=color:#RRGGBB@X,Y --board
aruco:4X4_50:5x3:40:10``, the colour picked from the written clip's first frame (median of the
sticker's core; ``--pick lit``: from the first frame where it is still and out of the shadow), the
start point the sticker's centre on the first frame, rounded. Printed: found % (of frames
with the sticker fully in the picture), wrong % (found frames more than 8 px from the truth, of all
found frames), frames found while the sticker was out of the picture, RMS px and metric RMS mm over
the found full frames that are not wrong (RMS over all found full frames printed beside it).
Acceptance: found >= 90 %, wrong <= 1 %, none found out of the picture, RMS <= 1.5 px,
metric RMS <= 2 mm.

    python bench/track_foreign.py                         # 1920x1080, 60 fps, 120 frames, CupsClips
    python bench/track_foreign.py --width 640 --height 360 --fps 30 --keep out/foreign
    python bench/track_foreign.py --background balltoss
"""

from __future__ import annotations

import argparse
import csv
import math
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SHARED_TRACKER = ROOT.parent / "shared" / "data" / "tracker"
SYNTHETIC_NOTE = "SYNTHETIC over REAL footage (Tracker's {bg} sample video as background)"

# --- the scene, in the board's plane: mm, origin at the board's bottom-left corner, y up ----------
G_MM_S2 = 9810.0                     # gravity
STICKER_DIAMETER_MM = 20.0
STICKER_BGR = (20.0, 105.0, 245.0)   # a saturated orange as lit in the room (sRGB, 0-255)
CAP_BGR = (26.0, 100.0, 232.0)       # the pen cap: nearly the same orange plastic
CAP_CENTRE_MM = (150.0, -48.0)
CAP_LENGTH_MM, CAP_WIDTH_MM, CAP_ANGLE_DEG = 55.0, 13.0, 12.0
BOARD = "aruco:4X4_50:5x3:40:10"
BOARD_COLS, BOARD_ROWS, BOARD_MARKER_MM, BOARD_GAP_MM, BOARD_MARGIN_MM = 5, 3, 40.0, 10.0, 10.0
BOARD_W_MM = BOARD_COLS * BOARD_MARKER_MM + (BOARD_COLS - 1) * BOARD_GAP_MM    # 240
BOARD_H_MM = BOARD_ROWS * BOARD_MARKER_MM + (BOARD_ROWS - 1) * BOARD_GAP_MM    # 140
EXPOSURE_S = 1.0 / 150.0             # shutter time of an indoor phone video
SUBFRAMES = 32
SECONDS = 2.0

REST_MM = (-200.0, -30.0)            # nose at rest before the first hop
HOPS = (  # (take-off s, take-off x mm, landing x mm, apex height mm)
    (0.25, -200.0, 20.0, 130.0),
    (0.8333, 20.0, 320.0, 600.0),
)
CROUCH_S, CROUCH_MM = 0.10, 8.0      # dip before each take-off
LANDING_DIP_S, LANDING_DIP_MM = 0.15, 10.0

# camera: pinhole looking at the point TARGET_MM of the board's plane
CAM_TARGET_MM = (60.0, 105.0)
CAM_DISTANCE_MM = 800.0
CAM_FOCAL_PER_WIDTH = 1.0            # f = width px: about 53 deg across
CAM_YAW_DEG, CAM_PITCH_DEG, CAM_ROLL_DEG = 30.0, 12.0, 3.0

SHADOW_DEPTH = 0.55
NOISE_SIGMA = 2.5


# --- geometry --------------------------------------------------------------------------------------
def plane_to_image(width: int, height: int) -> np.ndarray:
    """3x3 homography from the board's plane (mm, y up) to pixels (OpenCV: centre of the top-left
    pixel at 0,0), through a pinhole camera turned away from the board's normal."""
    yaw, pitch, roll = np.radians([CAM_YAW_DEG, CAM_PITCH_DEG, CAM_ROLL_DEG])
    target = np.array([*CAM_TARGET_MM, 0.0])
    # world: x right, y up, z out of the board towards the camera (right-handed)
    centre = target + CAM_DISTANCE_MM * np.array([np.sin(yaw) * np.cos(pitch), np.sin(pitch),
                                                  np.cos(yaw) * np.cos(pitch)])
    fwd = (target - centre) / np.linalg.norm(target - centre)
    right = np.cross(fwd, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    down = np.cross(fwd, right)
    c, s = np.cos(roll), np.sin(roll)
    right, down = c * right + s * down, -s * right + c * down
    rot = np.stack([right, down, fwd])
    t = -rot @ centre
    f = CAM_FOCAL_PER_WIDTH * width
    k = np.array([[f, 0.0, (width - 1) / 2], [0.0, f, (height - 1) / 2], [0.0, 0.0, 1.0]])
    h = k @ np.column_stack([rot[:, 0], rot[:, 1], t])
    return h / h[2, 2]


def apply_h(h: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Map points (..., 2) through a homography."""
    p = np.asarray(xy, float)
    q = p @ h[:, :2].T + h[:, 2]
    return q[..., :2] / q[..., 2:3]


def local_scale(h: np.ndarray, xy_mm: np.ndarray) -> np.ndarray:
    """Pixels per mm (square root of the Jacobian's determinant) at plane points (..., 2)."""
    e = 0.5
    px = apply_h(h, xy_mm + [e, 0.0]) - apply_h(h, xy_mm - [e, 0.0])
    py = apply_h(h, xy_mm + [0.0, e]) - apply_h(h, xy_mm - [0.0, e])
    return np.sqrt(np.abs(px[..., 0] * py[..., 1] - px[..., 1] * py[..., 0])) / (2 * e)


def nose_mm(t_s: np.ndarray) -> np.ndarray:
    """The sticker's centre in the board's plane (mm) at times t_s: rest, crouch, ballistic hops,
    landing dips."""
    t = np.asarray(t_s, float)
    x = np.full(t.shape, REST_MM[0])
    y = np.full(t.shape, REST_MM[1])
    for t0, x0, x1, apex in HOPS:
        vy = math.sqrt(2 * G_MM_S2 * apex)
        flight = 2 * vy / G_MM_S2
        vx = (x1 - x0) / flight
        s = t - t0
        crouch = (s > -CROUCH_S) & (s < 0)
        y = np.where(crouch, REST_MM[1] - CROUCH_MM * np.sin(np.pi * (s + CROUCH_S) / CROUCH_S), y)
        air = (s >= 0) & (s <= flight)
        x = np.where(air, x0 + vx * s, x)
        y = np.where(air, REST_MM[1] + vy * s - 0.5 * G_MM_S2 * s**2, y)
        landed = s > flight
        x = np.where(landed, x1, x)
        dip = landed & (s - flight < LANDING_DIP_S)
        y = np.where(dip, REST_MM[1] - LANDING_DIP_MM * np.sin(np.pi * (s - flight) / LANDING_DIP_S), y)
    return np.stack([x, y], axis=-1)


def shadow_factor(x: np.ndarray, y: np.ndarray, t_s: float, width: int, height: int) -> np.ndarray:
    """Multiplier of the light (1: none, 1 - SHADOW_DEPTH at the core) of a soft elliptical shadow
    sweeping left to right and a little up across the picture (over the sticker at rest and as it
    takes off for the big hop)."""
    cx = width * (0.20 + 0.55 * t_s / SECONDS)
    cy = height * (0.60 - 0.15 * t_s / SECONDS)
    rho = np.hypot((x - cx) / (0.17 * width), (y - cy) / (0.30 * height))
    s = np.clip((1.0 - rho) / 0.45, 0.0, 1.0)
    return 1.0 - SHADOW_DEPTH * s * s * (3 - 2 * s)


# --- the real footage --------------------------------------------------------------------------------
def background_frames(kind: str, width: int, height: int) -> tuple[list[np.ndarray], float]:
    """The real footage's frames, cropped to 16:9 and scaled to width x height, and its frame rate."""
    if kind == "cups":
        with zipfile.ZipFile(SHARED_TRACKER / "CupsClips.zip") as z:
            names = sorted(n for n in z.namelist() if n.startswith("videos/") and n.endswith(".jpg"))
            raw = [cv2.imdecode(np.frombuffer(z.read(n), np.uint8), cv2.IMREAD_COLOR) for n in names]
        fps = 30.0
    else:
        with zipfile.ZipFile(SHARED_TRACKER / "BallToss.trz") as z, tempfile.TemporaryDirectory() as tmp:
            name = next(n for n in z.namelist() if n.endswith(".mp4"))
            path = Path(tmp) / "balltoss.mp4"
            path.write_bytes(z.read(name))
            cap = cv2.VideoCapture(str(path))
            fps = cap.get(cv2.CAP_PROP_FPS) or 15.0
            raw = []
            while True:
                ok, frame = cap.read()
                if not ok:
                    break
                raw.append(frame)
            cap.release()
    h0, w0 = raw[0].shape[:2]
    crop_h = round(w0 * 9 / 16)
    top = (h0 - crop_h) // 2
    return [cv2.resize(f[top:top + crop_h], (width, height), interpolation=cv2.INTER_CUBIC) for f in raw], fps


def background_at(frames: list[np.ndarray], fps: float, t_s: float) -> np.ndarray:
    """The footage at time t_s, played forward and back (cross-faded between its frames)."""
    n = len(frames)
    period = 2 * (n - 1)
    s = (t_s * fps) % period
    s = s if s <= n - 1 else period - s
    i = min(int(s), n - 2)
    a = s - i
    return (1 - a) * frames[i].astype(np.float32) + a * frames[i + 1].astype(np.float32)


# --- the things drawn on it ----------------------------------------------------------------------------
def board_layer(h: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """The printed board (with its white margin) warped into the picture: colour and coverage."""
    dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50)
    grid = cv2.aruco.GridBoard((BOARD_COLS, BOARD_ROWS), BOARD_MARKER_MM / 1000, BOARD_GAP_MM / 1000, dictionary)
    k_hi = 10   # px/mm of the print
    art = grid.generateImage((round(BOARD_W_MM * k_hi), round(BOARD_H_MM * k_hi)), marginSize=0)
    m = round(BOARD_MARGIN_MM * k_hi)
    art = cv2.copyMakeBorder(art, m, m, m, m, cv2.BORDER_CONSTANT, value=255)
    scale = float(local_scale(h, np.array([BOARD_W_MM / 2, BOARD_H_MM / 2])))
    k = max(1.0, 1.5 * scale)   # resample to about the picture's scale before warping
    art = cv2.resize(art, (round(art.shape[1] * k / k_hi), round(art.shape[0] * k / k_hi)),
                     interpolation=cv2.INTER_AREA)
    kx = art.shape[1] / (BOARD_W_MM + 2 * BOARD_MARGIN_MM)
    ky = art.shape[0] / (BOARD_H_MM + 2 * BOARD_MARGIN_MM)
    # print pixel (u, v) -> plane mm (x right, y up; origin at the board's bottom-left corner)
    a = np.array([[1 / kx, 0, 0.5 / kx - BOARD_MARGIN_MM],
                  [0, -1 / ky, BOARD_H_MM + BOARD_MARGIN_MM - 0.5 / ky],
                  [0, 0, 1]])
    warp = h @ a
    ink = cv2.warpPerspective(art.astype(np.float32), warp, (width, height), flags=cv2.INTER_LINEAR)
    cover = cv2.warpPerspective(np.ones(art.shape, np.float32), warp, (width, height), flags=cv2.INTER_LINEAR)
    paper = 28.0 + (ink / 255.0) * (222.0 - 28.0)               # black ink and white paper in room light
    colour = np.dstack([paper * 0.97, paper * 0.99, paper])     # a warm white
    return colour.astype(np.float32), cover


def cap_layer(h: np.ndarray, width: int, height: int) -> np.ndarray:
    """Coverage of the pen cap (a capsule lying in the board's plane), anti-aliased."""
    ang = np.radians(CAP_ANGLE_DEG)
    u, v = np.array([np.cos(ang), np.sin(ang)]), np.array([-np.sin(ang), np.cos(ang)])
    half, rad = CAP_LENGTH_MM / 2 - CAP_WIDTH_MM / 2, CAP_WIDTH_MM / 2
    phi = np.linspace(-np.pi / 2, np.pi / 2, 24)
    right = [half * u + rad * (np.cos(p) * u + np.sin(p) * v) for p in phi]
    left = [-half * u + rad * (-np.cos(p) * u - np.sin(p) * v) for p in phi]
    outline = np.array(CAP_CENTRE_MM) + np.array(right + left)
    ss = 8
    pts = np.round((apply_h(h, outline) + 0.5) * ss - 0.5).astype(np.int32)
    big = np.zeros((height * ss, width * ss), np.uint8)
    cv2.fillPoly(big, [pts], 255)
    return cv2.resize(big, (width, height), interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0


@dataclass(frozen=True)
class Truth:
    """Per frame: the sticker's image centre (px), plane position (mm), visibility, and more."""

    t_s: np.ndarray
    px: np.ndarray
    py: np.ndarray
    x_mm: np.ndarray
    y_mm: np.ndarray
    visibility: np.ndarray      # "full", "partial", "out"
    streak_px: np.ndarray       # length of the blur streak (centre travel during the exposure)
    shadow: np.ndarray          # light multiplier at the sticker's centre
    radius_px: np.ndarray
    cap_px: tuple[float, float]
    homography_err_mm: float    # max |H^-1(centre px) - centre mm|

    @property
    def full(self) -> np.ndarray:
        return self.visibility == "full"

    @property
    def out(self) -> np.ndarray:
        return self.visibility == "out"


def sticker_frame(h: np.ndarray, t_s: float, width: int, height: int):
    """Sub-frame plane positions (mm), centres and radii (px) of the sticker during the exposure
    around t_s, and its visibility."""
    tk = t_s + EXPOSURE_S * ((np.arange(SUBFRAMES) + 0.5) / SUBFRAMES - 0.5)
    mm = nose_mm(tk)
    c = apply_h(h, mm)
    r = local_scale(h, mm) * STICKER_DIAMETER_MM / 2
    inside = ((c[:, 0] - r >= -0.5) & (c[:, 0] + r <= width - 0.5)
              & (c[:, 1] - r >= -0.5) & (c[:, 1] + r <= height - 0.5))
    gone = ((c[:, 1] + r < -0.5) | (c[:, 1] - r > height - 0.5)
            | (c[:, 0] + r < -0.5) | (c[:, 0] - r > width - 0.5))
    vis = "full" if inside.all() else "out" if gone.all() else "partial"
    return mm, c, r, vis


def sticker_alpha(c: np.ndarray, r: np.ndarray, width: int, height: int):
    """Coverage of the blurred sticker: the mean of anti-aliased disks at the sub-frame centres,
    over a patch (x0, y0, alpha) of the picture, or None when none of it is in the picture."""
    x0 = max(0, int(np.floor((c[:, 0] - r).min())) - 2)
    x1 = min(width, int(np.ceil((c[:, 0] + r).max())) + 3)
    y0 = max(0, int(np.floor((c[:, 1] - r).min())) - 2)
    y1 = min(height, int(np.ceil((c[:, 1] + r).max())) + 3)
    if x1 <= x0 or y1 <= y0:
        return None
    yy, xx = np.mgrid[y0:y1, x0:x1].astype(np.float32)
    alpha = np.zeros(xx.shape, np.float32)
    for (cx, cy), rk in zip(c, r):
        alpha += np.clip(rk - np.hypot(xx - cx, yy - cy) + 0.5, 0.0, 1.0)
    return x0, y0, alpha / len(c)


def make_clip(path: Path, width: int, height: int, fps: float, background: str, seed: int = 7,
              progress: bool = True) -> Truth:
    """Write the clip (mp4v) and return its truth."""
    h = plane_to_image(width, height)
    h_inv = np.linalg.inv(h)
    frames, bg_fps = background_frames(background, width, height)
    board_rgb, board_cover = board_layer(h, width, height)
    cap = cap_layer(h, width, height)
    cap_yx = np.argwhere(cap > 0.5).mean(axis=0)
    rng = np.random.default_rng(seed)
    n = round(SECONDS * fps)
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), fps, (width, height))
    if not writer.isOpened():
        raise SystemExit(f"cannot write {path} with mp4v")
    rows = {k: [] for k in ("t", "px", "py", "x", "y", "vis", "streak", "shadow", "r")}
    for i in range(n):
        t = i / fps
        img = background_at(frames, bg_fps, t)
        img = img * (1 - board_cover[..., None]) + board_rgb * board_cover[..., None]
        img = img * (1 - cap[..., None]) + np.float32(CAP_BGR) * cap[..., None]
        mm, c, r, vis = sticker_frame(h, t, width, height)
        patch = sticker_alpha(c, r, width, height)
        if patch is not None:
            x0, y0, a = patch
            roi = img[y0:y0 + a.shape[0], x0:x0 + a.shape[1]]
            roi[:] = roi * (1 - a[..., None]) + np.float32(STICKER_BGR) * a[..., None]
        w = r**2
        centre = (c * w[:, None]).sum(axis=0) / w.sum()
        centre_mm = (mm * w[:, None]).sum(axis=0) / w.sum()
        light = shadow_factor(xx, yy, t, width, height) * (1 + 0.015 * np.sin(2 * np.pi * 7 * t))
        img = img * light[..., None] + rng.normal(0, NOISE_SIGMA, img.shape).astype(np.float32)
        writer.write(np.clip(np.round(img), 0, 255).astype(np.uint8))
        streak = float(np.hypot(*(c[-1] - c[0])))
        for k, v in zip(rows, (t, centre[0], centre[1], centre_mm[0], centre_mm[1], vis, streak,
                               float(shadow_factor(centre[0], centre[1], t, width, height)), float(r.mean()))):
            rows[k].append(v)
        if progress and sys.stderr.isatty():
            print(f"\rrendering {i + 1}/{n}", end="", file=sys.stderr)
    if progress and sys.stderr.isatty():
        print(file=sys.stderr)
    writer.release()
    px, py = np.array(rows["px"]), np.array(rows["py"])
    back = apply_h(h_inv, np.stack([px, py], axis=1))
    err = np.hypot(back[:, 0] - np.array(rows["x"]), back[:, 1] - np.array(rows["y"]))
    vis = np.array(rows["vis"])
    return Truth(t_s=np.array(rows["t"]), px=px, py=py, x_mm=np.array(rows["x"]), y_mm=np.array(rows["y"]),
                 visibility=vis, streak_px=np.array(rows["streak"]), shadow=np.array(rows["shadow"]),
                 radius_px=np.array(rows["r"]), cap_px=(float(cap_yx[1]), float(cap_yx[0])),
                 homography_err_mm=float(err[vis != "out"].max()))


def write_truth(path: Path, truth: Truth, note: str) -> None:
    """The truth table: one row per frame."""
    with path.open("w", newline="") as f:
        f.write(f"# {note}\n# px, py: OpenCV pixels; x_mm, y_mm: board plane, origin bottom-left corner, y up\n")
        w = csv.writer(f)
        w.writerow(["frame", "t_s", "px", "py", "x_mm", "y_mm", "visibility", "streak_px", "shadow", "radius_px"])
        for i in range(len(truth.t_s)):
            w.writerow([i, f"{truth.t_s[i]:.6f}", f"{truth.px[i]:.4f}", f"{truth.py[i]:.4f}",
                        f"{truth.x_mm[i]:.4f}", f"{truth.y_mm[i]:.4f}", truth.visibility[i],
                        f"{truth.streak_px[i]:.2f}", f"{truth.shadow[i]:.3f}", f"{truth.radius_px[i]:.2f}"])


def read_frames(clip: Path, indices) -> dict[int, np.ndarray]:
    """Some frames of the written clip, decoded."""
    want, got = set(int(i) for i in indices), {}
    cap = cv2.VideoCapture(str(clip))
    i = 0
    while want - got.keys():
        ok, frame = cap.read()
        if not ok:
            break
        if i in want:
            got[i] = frame
        i += 1
    cap.release()
    return got


def colour_at(frame: np.ndarray, x: float, y: float, radius_px: float) -> str:
    """Median colour (#RRGGBB) of a frame within radius_px of (x, y)."""
    yy, xx = np.mgrid[0:frame.shape[0], 0:frame.shape[1]]
    core = np.hypot(xx - x, yy - y) <= max(1.0, radius_px)
    b, g, r = np.median(frame[core], axis=0).round().astype(int)
    return f"#{r:02x}{g:02x}{b:02x}"


# --- as a user would: pick the colour, run the CLI -------------------------------------------------------
def picked_colour(clip: Path, truth: Truth, pick: str = "first") -> tuple[str, int, int]:
    """The sticker's colour (median of its core, as a colour picker would give) and its centre on
    the first frame, rounded: what goes into ``--marker``. ``pick="first"``: the colour on the first
    frame (what ``locust track preview`` shows); ``"lit"``: on the first frame where the sticker is still,
    whole and out of the shadow."""
    i = 0
    if pick == "lit":
        i = int(np.flatnonzero(truth.full & (truth.streak_px < 0.5) & (truth.shadow > 0.97))[0])
    frame = read_frames(clip, [i]).get(i)
    if frame is None:
        raise SystemExit(f"cannot read frame {i} of {clip}")
    return colour_at(frame, truth.px[i], truth.py[i], 0.5 * truth.radius_px[i]), round(truth.px[0]), round(truth.py[0])


def run_locust_track(clip: Path, colour: str, x: int, y: int, out: Path) -> tuple[str, Path]:
    """``locust track`` on the clip, as on the command line; its printed summary and the tracks CSV."""
    cmd = [sys.executable, "-m", "locust.commands", "track", str(clip), "--marker", f"nose=color:{colour}@{x},{y}",
           "--board", BOARD, "--out", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise SystemExit(f"locust track failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return "locust track " + " ".join(cmd[4:]) + "\n" + proc.stdout, out


# --- scoring -----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Figures:
    found_pct: float            # of frames with the sticker fully in the picture
    wrong_pct: float            # found frames > WRONG_PX from the truth, of all found frames
    out_found: int              # frames found while the sticker was out of the picture
    rms_px: float               # found full frames, not wrong
    rms_all_px: float           # found full frames, all
    metric_rms_mm: float        # found full frames, not wrong
    metric_rms_all_mm: float
    n_full: int
    n_found: int
    details: tuple[str, ...]    # one line per wrong / out-found / partial-found frame


WRONG_PX = 8.0


def score(truth: Truth, tracks_path: Path, clip: Path | None = None, marker: str = "nose") -> Figures:
    """Compare the tracks CSV with the truth (``clip``: to say what colour a wrong pick had)."""
    from locust.io.tracks_csv import read_tracks_csv

    tracks = read_tracks_csv(tracks_path)
    n = len(truth.t_s)
    frame = tracks.frame.astype(int)
    ok = np.zeros(n, bool)
    px, py, xm, ym = (np.full(n, np.nan) for _ in range(4))
    sel = (frame >= 0) & (frame < n)
    ok[frame[sel]] = tracks.ok[marker][sel].astype(bool)
    px[frame[sel]], py[frame[sel]] = tracks.px[marker][sel], tracks.py[marker][sel]
    xm[frame[sel]], ym[frame[sel]] = tracks.x_m[marker][sel] * 1000, tracks.y_m[marker][sel] * 1000
    err = np.hypot(px - truth.px, py - truth.py)
    err_mm = np.hypot(xm - truth.x_mm, ym - truth.y_mm)
    full, out = truth.full, truth.out
    wrong = ok & ~out & (err > WRONG_PX)
    good = ok & full & ~wrong
    frames = read_frames(clip, np.flatnonzero(ok & (wrong | out))) if clip else {}
    details = []
    for i in np.flatnonzero(ok & (wrong | out | (truth.visibility == "partial"))):
        near_cap = math.hypot(px[i] - truth.cap_px[0], py[i] - truth.cap_px[1])
        what = ("the pen cap" if near_cap < 3 * truth.radius_px[i] else
                "the sticker" if err[i] <= 3 * truth.radius_px[i] else "something else")
        if i in frames:
            what += f" (colour there {colour_at(frames[i], px[i], py[i], 0.3 * truth.radius_px[i])})"
        details.append(f"frame {i:3d} ({truth.visibility[i]:7s}): found at {px[i]:7.1f},{py[i]:7.1f}, "
                       f"truth {truth.px[i]:7.1f},{truth.py[i]:7.1f}, off {err[i]:6.1f} px -> {what}")
    missed = np.flatnonzero(full & ~ok)
    if missed.size:
        details.append("missed with the sticker whole in the picture: " + ", ".join(
            f"{i} (light {truth.shadow[i]:.2f}, streak {truth.streak_px[i]:.0f} px)" for i in missed))
    off = np.flatnonzero(good & (err > 1.5))
    if off.size:
        details.append("found but more than 1.5 px off: " + ", ".join(
            f"{i} ({err[i]:.1f} px, light {truth.shadow[i]:.2f})" for i in off))

    def rms(a: np.ndarray, s: np.ndarray) -> float:
        return float(np.sqrt(np.mean(a[s] ** 2))) if s.any() else float("nan")

    return Figures(found_pct=100.0 * ok[full].sum() / max(1, full.sum()),
                   wrong_pct=100.0 * wrong.sum() / max(1, ok.sum()), out_found=int((ok & out).sum()),
                   rms_px=rms(err, good), rms_all_px=rms(err, ok & full), metric_rms_mm=rms(err_mm, good),
                   metric_rms_all_mm=rms(err_mm, ok & full), n_full=int(full.sum()), n_found=int(ok.sum()),
                   details=tuple(details))


def last_line(f: Figures) -> str:
    return (f"foreign clip: found {f.found_pct:.1f}% wrong {f.wrong_pct:.1f}% out-found {f.out_found} "
            f"rms {f.rms_px:.2f} px metric {f.metric_rms_mm:.2f} mm")


def run(folder: Path, width: int, height: int, fps: float, background: str, seed: int = 7,
        progress: bool = True, pick: str = "first") -> tuple[Truth, Figures, str]:
    """Make the clip and its truth in ``folder``, track it, score it: truth, figures, CLI summary."""
    name = {"cups": "CupsClips", "balltoss": "BallToss"}[background]
    note = SYNTHETIC_NOTE.format(bg=name)
    clip = folder / f"foreign_{width}x{height}.mp4"
    truth = make_clip(clip, width, height, fps, background, seed, progress)
    write_truth(folder / f"foreign_{width}x{height}.truth.csv", truth, note)
    colour, x, y = picked_colour(clip, truth, pick)
    summary, tracks = run_locust_track(clip, colour, x, y, folder / f"foreign_{width}x{height}.tracks.csv")
    return truth, score(truth, tracks, clip), summary


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--width", type=int, default=1920)
    ap.add_argument("--height", type=int, default=1080)
    ap.add_argument("--fps", type=float, default=60.0, help="frame rate (the clip lasts 2 s)")
    ap.add_argument("--background", choices=("cups", "balltoss"), default="cups")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--pick", choices=("first", "lit"), default="first",
                    help="where the marker's colour is picked: the first frame (as locust track preview) or the first "
                         "frame where the sticker is still and out of the shadow")
    ap.add_argument("--keep", type=Path, help="write the clip, truth and tracks to this folder (default: a temp one)")
    args = ap.parse_args()
    if not SHARED_TRACKER.is_dir():
        raise SystemExit(f"real footage not found at {SHARED_TRACKER} (clone with ../shared beside the project)")
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        truth, fig, summary = run(folder, args.width, args.height, args.fps, args.background, args.seed,
                                  pick=args.pick)
    name = {"cups": "CupsClips", "balltoss": "BallToss"}[args.background]
    print(SYNTHETIC_NOTE.format(bg=name))
    print(f"{args.width}x{args.height}, {args.fps:g} fps, {len(truth.t_s)} frames: sticker fully in the picture on "
          f"{fig.n_full}, partly on {int((truth.visibility == 'partial').sum())}, out on {int(truth.out.sum())}; "
          f"blur streak up to {truth.streak_px.max():.0f} px (sticker {2 * truth.radius_px.mean():.0f} px); "
          f"in shadow (< 0.8 light) on {int((truth.shadow < 0.8).sum())} frames; "
          f"truth consistency {truth.homography_err_mm:.3f} mm")
    print(summary.rstrip())
    for line in fig.details:
        print("  " + line)
    print(f"found {fig.n_found} frames; RMS over all found full frames {fig.rms_all_px:.2f} px, "
          f"{fig.metric_rms_all_mm:.2f} mm")
    print(last_line(fig))


if __name__ == "__main__":
    main()
