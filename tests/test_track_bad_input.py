"""Bad input to `locust track`, class by class, many generated cases each: a frame rate no
camera films at, a Tracker project whose frame interval is 0, an import whose times repeat or
go back, and footage with no sticker of the marker's colour. Each is one clear `error:` and
`hint:`, exit 2, and no file changed (tests/probing.py)."""

from __future__ import annotations

import math
import re

import cv2
import numpy as np
import pytest

from locust.io.trk import MAX_CLIP_FRAMES
from locust.track.calib import build
from locust.track.runner import TrackResult
from locust.track.synth import make_hop_video, paint_dot
from locust.track.trk import project_xml
from locust.track.video import Clip, VideoInfo, encode_video, probe
from probing import assert_refused_and_unchanged, invoke

RNG = np.random.default_rng(28)


@pytest.fixture(autouse=True)
def _outputs_in_tmp(tmp_path, monkeypatch):
    """Tracks written without --out land in the current folder: each test's own."""
    monkeypatch.chdir(tmp_path)


@pytest.fixture(scope="module")
def hop(tmp_path_factory):
    """A SYNTHETIC 320x180 hop clip with the default nose and foot colours, 20 frames."""
    folder = tmp_path_factory.mktemp("hop")
    make_hop_video(folder / "hop.mp4", width=320, height=180, n_frames=20, seed=1)
    return folder


# -- --fps: a camera films 1 to 10000 frames/s -------------------------------------------
BAD_FPS = ["1e308", "0", "-30", "0.5", "0.999", "10000.5", "1e5", "nan", "inf", "-inf",
           *(f"{v:.6g}" for v in 10 ** RNG.uniform(4.01, 300, 6)), *(f"{v:.6g}" for v in RNG.uniform(-1e3, 0.99, 6))]


@pytest.mark.parametrize("fps", BAD_FPS)
def test_fps_outside_what_cameras_film_is_refused(hop, fps):
    assert_refused_and_unchanged(hop, ["track", hop / "hop.mp4", "--fps", fps, "--overlay", "none"],
                                 "--fps", "1 to 10000 frames/s")


def test_fps_edges_are_accepted(hop):
    info = probe(hop / "hop.mp4")
    for fps in (1.0, 240.0, 10000.0):
        clip = Clip(fps=fps).resolved(info)
        assert clip.time_s(clip.end) == pytest.approx(19 / fps, rel=1e-12)


# -- a Tracker project's frame interval (delta_t, ms) ------------------------------------
def _project_text(tmp_path, delta_t: str) -> str:
    n = 10
    frames = np.arange(n)
    result = TrackResult.from_pixels(frames, frames / 30.0, {"nose": 100 + 2.0 * frames}, {"nose": 200 - 1.0 * frames},
                                     {"nose": np.ones(n, bool)}, {"nose": "color:#ff00ff"}, {"nose": np.ones(n)},
                                     build(360, 0.001, None, 0.0, "stick 0.001 m/px"), Clip(0, n - 1, 1, 30.0),
                                     video=VideoInfo(tmp_path / "hop.mp4", 640, 360, n, 30.0))
    text = project_xml(result, tmp_path / "p.trk", None)
    assert text.count('name="delta_t" type="double">') == 1     # the clip control's
    return re.sub(r'(name="delta_t" type="double">)[^<]*', rf"\g<1>{delta_t}", text)


@pytest.mark.parametrize("delta_t", ["0", "0.0", "-33.3", "0.01", "1e-300", "1500", "1e308", "NaN", "Infinity"])
@pytest.mark.parametrize("command", ["from-trk", "import"])
def test_a_project_whose_frame_interval_is_no_camera_s_is_refused(tmp_path, delta_t, command):
    (tmp_path / "p.trk").write_text(_project_text(tmp_path, delta_t))
    assert_refused_and_unchanged(tmp_path, ["track", command, tmp_path / "p.trk", "--out", tmp_path / "o.csv"],
                                 "delta_t", "p.trk", "Clip Settings")


def test_a_project_with_a_camera_s_interval_gives_its_times(tmp_path):
    (tmp_path / "p.trk").write_text(_project_text(tmp_path, "4.1666667"))     # 240 frames/s
    res = invoke(["track", "from-trk", tmp_path / "p.trk", "--out", tmp_path / "o.csv"])
    assert res.exit_code == 0, res.output
    t = np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1, usecols=1, comments="#")
    assert np.allclose(t, np.arange(10) * 4.1666667e-3, rtol=0, atol=5e-7)   # the CSV writes t_s to the us


# -- a Tracker project's frames, clip and axes: every value a generator draws is refused ----
def _bad_project(text: str, rng) -> tuple[str, str]:
    """``text`` (a project of 10 frames) with one value no Tracker project holds: (text, a word
    of the error)."""
    kind = rng.choice(["frame", "clip", "axes", "empty"])
    if kind == "frame":
        bad = rng.choice(["[x]", f"[{rng.uniform(0, 9):.2f}]", f"[{2 ** 31}]", f"[{2 ** 63}]",
                          f"[-{rng.randrange(1, 99)}]", "[]", str(rng.randrange(10)), f"[{'9' * 400}]",
                          f"[{MAX_CLIP_FRAMES + rng.randrange(1, 10 ** 9)}]"])
        return text.replace(f'name="[{rng.randrange(10)}]"', f'name="{bad}"', 1), "frame"
    if kind == "clip":
        name = rng.choice(["stepcount", "startframe", "stepsize"])
        bad = {"stepcount": [2 ** 31, 2 ** 63, MAX_CLIP_FRAMES + 2, -5],
               "startframe": [-1, 2 ** 31, 2 ** 63, MAX_CLIP_FRAMES + 1],
               "stepsize": [0, -2, 2 ** 31]}[name]
        return re.sub(rf'(name="{name}" type="int">)[^<]*', rf"\g<1>{rng.choice(bad)}", text), "clip"
    if kind == "axes":
        name = rng.choice(["xorigin", "yorigin", "angle"])
        bad = rng.choice(["inf", "-Infinity", "NaN", "1e999"])
        return re.sub(rf'(name="{name}" type="double">)[^<]*', rf"\g<1>{bad}", text), name
    steps = re.sub(r'<property name="\[\d+\]" type="object">\s*<object class="[^"]*PointMass\$FrameData">'
                   r'.*?</object>\s*</property>\s*', "", text, flags=re.S)
    return re.sub(r'<property name="stepcount"[^<]*</property>\s*', "", steps), "no marked steps"


@pytest.mark.parametrize("seed", range(24))
@pytest.mark.parametrize("command", ["from-trk", "import"])
def test_a_project_whose_frames_clip_or_axes_are_no_tracker_s_is_refused(tmp_path, seed, command):
    import random

    text, word = _bad_project(_project_text(tmp_path, "33.333333"), random.Random(seed))
    assert text != _project_text(tmp_path, "33.333333")
    (tmp_path / "p.trk").write_text(text)
    assert_refused_and_unchanged(tmp_path, ["track", command, tmp_path / "p.trk", "--out", tmp_path / "o.csv"],
                                 "p.trk", word)


def test_a_tab_over_the_size_limit_is_refused_before_it_is_read(tmp_path):
    from locust.io.trz import MAX_TRK_BYTES

    with open(tmp_path / "p.trk", "wb") as f:
        f.truncate(MAX_TRK_BYTES + 1)   # sparse: no disk used
    assert_refused_and_unchanged(tmp_path, ["track", "from-trk", tmp_path / "p.trk"], "p.trk",
                                 f"{MAX_TRK_BYTES:,}")


# -- imports: times must increase row to row ------------------------------------------------
def _txy(t: np.ndarray) -> str:
    return "t,x,y\n" + "".join(f"{v:.6g},{0.01 * k:.6g},0.02\n" for k, v in enumerate(t))


def _tracker(t: np.ndarray) -> str:
    return "A\nt\tx\ty\n" + "".join(f"{v:.6g}\t{0.01 * k:.6g}\t0.02\n" for k, v in enumerate(t))


def _tracks_csv(t: np.ndarray) -> str:
    return "frame,t_s,nose_x_m,nose_y_m,nose_ok\n" + "".join(f"{k},{v:.6g},{0.01 * k:.6g},0.02,1\n"
                                                              for k, v in enumerate(t))


def _bad_times(seed: int) -> tuple[np.ndarray, list[int]]:
    """Times of 40 rows at 30 frames/s with some rows repeated or moved back; the 0-based rows
    whose time does not exceed the one before."""
    rng = np.random.default_rng(seed)
    t = np.arange(40) / 30.0
    for k in rng.choice(np.arange(1, 40), size=rng.integers(1, 6), replace=False):
        t[k] = t[k - 1] if rng.random() < 0.5 else t[k - 1] - rng.uniform(0.001, 0.5)
    bad = [k for k in range(1, 40) if not t[k] > t[k - 1]]
    return t, bad


@pytest.mark.parametrize("layout, first_line", [(_txy, 2), (_tracker, 3), (_tracks_csv, 2)],
                         ids=["txy", "tracker", "tracks"])
@pytest.mark.parametrize("seed", range(8))
def test_times_that_repeat_or_go_back_are_refused_by_line(tmp_path, layout, first_line, seed):
    t, bad = _bad_times(seed)
    assert bad
    src = tmp_path / "times.txt"
    src.write_text(layout(t))
    lines = ", ".join(str(first_line + k) for k in bad[:6])
    assert_refused_and_unchanged(tmp_path, ["track", "import", src, "--out", tmp_path / "o.csv"],
                                 f"time does not increase on {len(bad)} of 40 rows", f"line {lines}")


def test_increasing_times_with_blank_rows_are_imported(tmp_path):
    src = tmp_path / "ok.csv"
    src.write_text("t,x,y\n0,0.1,0.2\n,,\n0.0667,0.1,0.2\n0.1,0.1,0.2\n")
    res = invoke(["track", "import", src, "--out", tmp_path / "o.csv"])
    assert res.exit_code == 0, res.output


def test_the_real_export_with_rounded_times_is_refused(shared_data, tmp_path):
    """A real Tracker t,x,y export written with 3 significant digits: from t = 10 s on, 161
    times repeat (../shared/data/README.md)."""
    src = shared_data / "tracker" / "snake_robot_30fps_quantised_t.csv"
    res = invoke(["track", "import", src, "--out", tmp_path / "o.csv"])
    assert res.exit_code == 2 and "161 repeat the time before, 0 go back" in res.stderr, res.output
    assert "more digits" in res.stderr and not (tmp_path / "o.csv").exists()


# -- footage without stickers: no colour marker may be taken on a dim patch or a speck -----
def _no_sticker_frames(seed: int, n: int = 24, w: int = 320, h: int = 180):
    """SYNTHETIC footage of a desk with no sticker: a grey speckled floor, wires and objects
    of the default markers' hues (magenta, cyan) but dim or pale (chroma under 0.3 of the
    stickers': paler and darker both, as a red wire or a green box under room light), and
    saturated specks of two pixels, drifting as a hand-held camera does."""
    rng = np.random.default_rng(seed)
    floor = rng.normal(120, 12, (h, w, 3)).clip(0, 255).astype(np.uint8)
    objects = []
    for _ in range(rng.integers(3, 7)):
        hue = rng.choice([150, 90]) + rng.integers(-6, 7)
        sat, val = rng.uniform(80, 200), rng.uniform(60, 95)        # chroma <= 200 * 95 / 255 = 75 < 0.3 * 255
        bgr = cv2.cvtColor(np.uint8([[[hue, sat, val]]]), cv2.COLOR_HSV2BGR)[0, 0].tolist()
        kind = rng.choice(["wire", "box", "disc"])
        objects.append((kind, bgr, rng.uniform(20, w - 20, 2), rng.uniform(0, math.pi), rng.uniform(5, 14)))
    specks = [(rng.integers(5, w - 5), rng.integers(5, h - 5), rng.choice([(255, 0, 255), (255, 255, 0)]))
              for _ in range(rng.integers(2, 6))]
    for i in range(n):
        img = floor.copy()
        drift = np.array([2.0 * math.sin(i / 4), 1.5 * math.cos(i / 5)])
        for kind, bgr, (x, y), angle, size in objects:
            c = np.array([x, y]) + drift
            if kind == "wire":
                d = 60 * np.array([math.cos(angle), math.sin(angle)])
                cv2.line(img, tuple(int(v) for v in c - d), tuple(int(v) for v in c + d), bgr, 3, cv2.LINE_AA)
            elif kind == "box":
                cv2.rectangle(img, tuple(int(v) for v in c - size), tuple(int(v) for v in c + size), bgr, -1)
            else:
                cv2.circle(img, tuple(int(v) for v in c), int(size), bgr, -1, cv2.LINE_AA)
        for x, y, bgr in specks:
            img[y:y + 2, x:x + 2] = bgr
        yield img


@pytest.mark.parametrize("seed", range(10))
def test_footage_without_stickers_is_refused(tmp_path, seed):
    encode_video(tmp_path / "desk.avi", _no_sticker_frames(seed), 30.0, (320, 180), "MJPG")
    assert_refused_and_unchanged(tmp_path, ["track", tmp_path / "desk.avi", "--overlay", "none"],
                                 "never found", "nose (color:#ff00ff)", "foot (color:#00ffff)", "3 px across")


@pytest.mark.parametrize("name", ["fourbar_robot_walk_oblique_1.mp4", "fourbar_robot_walk_oblique_2.mp4"])
def test_real_footage_without_stickers_is_refused(shared_data, tmp_path, name):
    """Real phone footage of a black robot with no stickers: the default colours once latched
    onto a red wire and a green object (17 % and 28 % of the frames of clip 1) and exited 0."""
    res = invoke(["track", shared_data / "video" / name, "--out", tmp_path / "o.csv", "--overlay", "none"])
    assert res.exit_code == 2 and "never found" in res.stderr, res.output
    assert "nose (color:#ff00ff), foot (color:#00ffff)" in res.stderr
    assert list(tmp_path.iterdir()) == []


# -- an upside-down video: heights inverted ------------------------------------------------
def _rest_hop_rest(seed: int, upside_down: bool, w: int = 320, h: int = 180, fps: float = 60.0,
                   over: bool = False):
    """SYNTHETIC: a magenta sticker resting on the floor, one ballistic hop, resting again
    (the heights a filmed hop has), drawn right way up or turned over (the phone upside down).
    ``over``: the robot goes over and rests on its back, the sticker at 0.6-0.8 of its rise."""
    rng = np.random.default_rng(seed)
    rest_before, rest_after = rng.integers(8, 20), rng.integers(8, 20)
    rise_px = rng.uniform(30, 120)
    flight = int(round(2 * math.sqrt(2 * rise_px * 0.002 / 9.81) * fps)) + 2    # 2 mm a pixel
    u = np.linspace(0, 1, flight)
    end_px = rng.uniform(0.6, 0.8) * rise_px if over else 0.0
    if over:     # it lies on its back longer than it stood: most still frames are high
        rest_after += 30
    arc = np.where(u < 0.5, 4 * rise_px * u * (1 - u), end_px + (rise_px - end_px) * 4 * u * (1 - u))
    y = np.r_[np.zeros(rest_before), arc, np.full(rest_after, end_px)]
    x = rng.uniform(40, 80) + np.r_[np.zeros(rest_before), u * rng.uniform(60, 160), np.full(rest_after, 0.0)]
    x[rest_before + flight:] = x[rest_before + flight - 1]
    floor_py = h - rng.uniform(20, 40)
    noise = np.random.default_rng(seed + 1000)
    for px, height in zip(x, y):
        img = np.full((h, w, 3), 90.0, np.float32)
        cv2.line(img, (0, int(floor_py) + 8), (w, int(floor_py) + 8), (40, 40, 40), 2)
        paint_dot(img, px, floor_py - height, 6.0, (255, 0, 255))
        frame = np.clip(np.rint(img + noise.normal(0, 1.5, img.shape)), 0, 255).astype(np.uint8)
        yield cv2.flip(frame, -1) if upside_down else frame


def _hop_clip(folder, seed, upside_down, over=False):
    path = folder / f"hop{seed}{'_over' if over else ''}{'_flipped' if upside_down else ''}.avi"
    encode_video(path, _rest_hop_rest(seed, upside_down, over=over), 60.0, (320, 180), "MJPG")
    return path


@pytest.mark.parametrize("seed", range(6))
def test_an_upside_down_hop_is_flagged_and_an_upright_one_is_not(tmp_path, seed):
    args = ["--marker", "nose=color:#ff00ff", "--scale", "0,0,500,0=1.0", "--overlay", "none"]
    upright = invoke(["track", _hop_clip(tmp_path, seed, False), *args])
    assert upright.exit_code == 0 and "upside down" not in upright.stderr, upright.output
    flipped = invoke(["track", _hop_clip(tmp_path, seed, True), *args])
    assert flipped.exit_code == 0, flipped.output
    share = re.search(r"nose stands still at the top of its heights \(\d+ still frames at y = \S+ m, (\d+)% ",
                      flipped.stderr)
    assert share and int(share.group(1)) >= 90, flipped.stderr    # at rest on the floor: 0 % upright
    assert "--angle 180" in flipped.stderr
    turned = invoke(["track", tmp_path / f"hop{seed}_flipped.avi", *args, "--angle", "180", "--out",
                     tmp_path / "turned.csv"])
    assert turned.exit_code == 0 and "upside down" not in turned.stderr, turned.output


@pytest.mark.parametrize("seed", range(4))
def test_a_robot_that_went_over_is_judged_from_where_it_stood_on_the_floor(tmp_path, seed):
    """The nose rests high on the robot's back after the hop (at the top of its still
    heights): upright, no warning; the same video turned over still gets one."""
    args = ["--marker", "nose=color:#ff00ff", "--scale", "0,0,500,0=1.0", "--overlay", "none"]
    upright = invoke(["track", _hop_clip(tmp_path, seed, False, over=True), *args])
    assert upright.exit_code == 0 and "upside down" not in upright.stderr, upright.output
    flipped = invoke(["track", _hop_clip(tmp_path, seed, True, over=True), *args])
    assert flipped.exit_code == 0, flipped.output
    share = re.search(r"nose stands still at the top of its heights \(\d+ still frames at y = \S+ m, (\d+)% ",
                      flipped.stderr)
    assert share and int(share.group(1)) >= 90, flipped.stderr


# -- the one-command form's options that are subcommands now ---------------------------------
@pytest.mark.parametrize("args, new", [
    (["--import", "x.txt"], "locust track import FILE"),
    (["--from-trk", "x.trz"], "locust track from-trk PROJECT"),
    (["--make-board", "b.png"], "locust track board BOARD.png"),
    (["hop.mp4", "--preview", "0"], "locust track preview VIDEO --frame N"),
    (["hop.mp4", "--preview=0"], "locust track preview VIDEO --frame N"),
])
def test_the_old_options_name_their_subcommand(hop, args, new):
    assert_refused_and_unchanged(hop, ["track", *args], "a subcommand of its own", new)


def test_track_video_is_the_default_subcommand(hop, tmp_path):
    short = invoke(["track", hop / "hop.mp4", "--overlay", "none", "--out", tmp_path / "a.csv"])
    full = invoke(["track", "video", hop / "hop.mp4", "--overlay", "none", "--out", tmp_path / "b.csv"])
    assert short.exit_code == 0 and full.exit_code == 0, short.output + full.output
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()


def _dim_sticker_frames(chroma_share: float, radius_px: float, n: int = 16, w: int = 160, h: int = 120):
    """SYNTHETIC: one magenta sticker of ``chroma_share`` of #ff00ff's chroma (saturation and
    brightness both sqrt of it), drifting 1.5 px a frame on a grey floor; its true centres."""
    level = 255 * math.sqrt(chroma_share)
    bgr = cv2.cvtColor(np.uint8([[[150, round(level), round(level)]]]), cv2.COLOR_HSV2BGR)[0, 0].tolist()
    centres = [(50.3 + 1.5 * i, 60.7 - 0.5 * i) for i in range(n)]
    frames = []
    for cx, cy in centres:
        img = np.full((h, w, 3), 40.0, np.float32)
        paint_dot(img, cx, cy, radius_px, bgr)
        frames.append(np.rint(img).astype(np.uint8))
    return frames, np.array(centres)


@pytest.mark.parametrize("radius_px", [2.0, 3.0, 6.0])
@pytest.mark.parametrize("chroma_share", [0.35, 0.5, 1.0])
def test_a_sticker_in_shadow_or_small_is_still_taken(tmp_path, chroma_share, radius_px):
    """The first-sighting bounds (0.3 of the colour's chroma, 3 px across) keep real stickers:
    dim to 0.35 of the chroma, 4 px across, every frame found within 0.25 px of the truth."""
    frames, truth = _dim_sticker_frames(chroma_share, radius_px)
    encode_video(tmp_path / "dim.avi", frames, 30.0, (160, 120), "FFV1")
    res = invoke(["track", tmp_path / "dim.avi", "--marker", "nose=color:#ff00ff", "--overlay", "none"])
    assert res.exit_code == 0, res.output
    got = np.loadtxt(tmp_path / "dim.tracks.csv", delimiter=",", skiprows=1, usecols=(2, 3), comments="#")
    assert np.hypot(*(got - truth).T).max() <= 0.25


@pytest.mark.parametrize("chroma_share, radius_px", [(0.2, 6.0), (0.25, 6.0), (1.0, 1.0)])
def test_a_dim_patch_or_a_speck_is_never_taken(tmp_path, chroma_share, radius_px):
    frames, _ = _dim_sticker_frames(chroma_share, radius_px)
    encode_video(tmp_path / "dim.avi", frames, 30.0, (160, 120), "FFV1")
    assert_refused_and_unchanged(tmp_path, ["track", tmp_path / "dim.avi", "--marker", "nose=color:#ff00ff"],
                                 "never found", "nose (color:#ff00ff)")


def test_a_virtual_robot_that_went_over_is_upright_and_its_flipped_video_is_not(tmp_path):
    """The simulation films Small going over onto its back (its nose rests high after the
    hop, the foot sticker dips as the leg pushes and is then hidden): upright, no warning; the
    same frames turned over (both axes, a phone held upside down), one."""
    import locust
    from locust.sim.live import LiveSim
    from locust.track.video import read_frames

    robot = locust.robot("small")
    s = robot.schedule
    path = tmp_path / "over.mp4"       # filmed as the virtual robot films a hop: standing first
    sim = LiveSim(robot, video_path=str(path), fps=30, width=320, height=240, cycles=1)
    sim.advance_to(0.1)
    sim.set_servo_angles_deg(s.push_deg, s.push_deg)
    sim.advance_to(0.1 + s.push_s)
    sim.set_servo_angles_deg(0.0, 0.0)
    sim.advance_to(0.1 + s.push_s + s.wait_s)
    assert sim.close()["valid"]
    upright = invoke(["track", path, "--overlay", "none"])
    assert upright.exit_code == 0 and "upside down" not in upright.stderr, upright.output
    info = probe(path)
    frames = [cv2.flip(f, -1) for _, f in read_frames(info, Clip().resolved(info))]
    encode_video(tmp_path / "flipped.avi", iter(frames), info.file_fps, (info.width_px, info.height_px), "MJPG")
    flipped = invoke(["track", tmp_path / "flipped.avi", "--scale", "0,0,100,0=0.05", "--overlay", "none"])
    assert flipped.exit_code == 0, flipped.output
    assert "nose stands still at the top of its heights" in flipped.stderr, flipped.stderr


# -- calibrations no camera or print can have: points on a line, a board of 10 um, a camera
#    file of nested brackets --------------------------------------------------------------
def _bad_calibration(folder, rng) -> tuple[list, list[str]]:
    import random as _random

    assert isinstance(rng, _random.Random)
    kind = rng.choice(["collinear", "repeated", "board", "camera"])
    video = folder / "hop.mp4"
    if kind in ("collinear", "repeated"):
        px = [(rng.uniform(0, 320), rng.uniform(0, 180)) for _ in range(4)]
        xy = [(rng.uniform(0, 1), rng.uniform(0, 1)) for _ in range(4)]
        line = rng.choice(["px", "xy"])
        if kind == "collinear":   # every point on one line, in pixels or on the plane
            a, d = (rng.uniform(0, 100), rng.uniform(0, 100)), (rng.uniform(-1, 1), rng.uniform(-1, 1))
            pts = [(a[0] + t * d[0], a[1] + t * d[1]) for t in (rng.uniform(-50, 50) for _ in range(4))]
        else:                     # one point given four times
            pts = [(rng.uniform(0, 100), rng.uniform(0, 100))] * 4
        px, xy = (pts, xy) if line == "px" else (px, pts)
        text = ";".join(f"{p[0]:.4f},{p[1]:.4f}={q[0]:.4f},{q[1]:.4f}" for p, q in zip(px, xy))
        return ["track", video, "--overlay", "none", "--out", folder / "o", "--plane-points", text], \
            ["--plane-points", "pixels" if line == "px" else "plane positions"]
    if kind == "board":
        marker = rng.choice([10 ** rng.uniform(-9, -0.01), 10 ** rng.uniform(2.71, 9)])
        cols = rng.randrange(2, 6)
        return ["track", "board", folder / "b.png", "--board", f"aruco:4X4_50:{cols}x4:{marker:.6g}:0"], ["--board"]
    depth = rng.randrange(2_000, 200_000)
    o, c = rng.choice([("[", "]"), ('{"a":', "}")])
    (folder / "hop.camera.json").write_text(o * depth + "1" + c * depth)
    return ["track", video, "--overlay", "none", "--out", folder / "o"], ["hop.camera.json", "nested too deep"]


@pytest.mark.parametrize("seed", range(16))
def test_a_calibration_no_camera_or_print_has_is_refused(hop, tmp_path, seed):
    import random

    (tmp_path / "hop.mp4").write_bytes((hop / "hop.mp4").read_bytes())
    args, words = _bad_calibration(tmp_path, random.Random(seed))
    assert_refused_and_unchanged(tmp_path, args, *words)
