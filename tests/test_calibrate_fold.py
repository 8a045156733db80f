"""`locust calibrate fold` against known truth.

The statics checked by hand and against the virtual rig's own MuJoCo equilibrium; the fit on
SYNTHETIC photos of the virtual fold test (the bundled pair through the command and the API,
one freshly rendered seed, a clip-like folder of frames, and ten seeds whose 95 % intervals
must hold the hidden stiffness and rest angle in at least 8 of 10); and bad input, each a
CalibrationError saying what to do.
"""

from __future__ import annotations

import json
import math
import shutil

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

import locust
from locust.arucoboard import DEFAULT_BOARD, parse_board
from locust.bundled import bundled_recording
from locust.calibrate.coins import COINS
from locust.calibrate.foldfit import FreeLink, Load, fit_fold
from locust.calibrate.foldmoments import stiffness_and_rest, weight_moment_nm
from locust.calibrate.foldread import FOLD_STICKERS, FoldPhoto, read_state
from locust.calibrate.foldsynthetic import synthetic_fold_test
from locust.commands import cli
from locust.errors import CalibrationError
from locust.io.robot_toml import load_robot
from locust.params import GRAVITY_M_PER_S2, preset
from locust.sim.foldrig import FoldRig, settle
from locust.sim.fourbar import fold_angles_deg

UNLOADED, LOADED = "synthetic_fold_unloaded.jpg", "synthetic_fold_loaded.jpg"
TRUTH = json.loads(bundled_recording("synthetic_fold.truth.json").read_text())
BOARD = parse_board(DEFAULT_BOARD)
G = GRAVITY_M_PER_S2


def inside(est, truth: float) -> bool:
    return est.ci95_low <= truth <= est.ci95_high


# -- the statics ---------------------------------------------------------------------------
def test_a_known_deflection_gives_the_stiffness_by_hand():
    """A weightless link level, a 2.30 g coin 30 mm out turning it down by 10 deg:
    k = g m L cos(10 deg) / (10 deg in rad) = 3.8195e-3 N*m/rad."""
    k, rest = stiffness_and_rest((0.0, 0.0), (-10.0, -10.0), 0.0, 0.0023, 0.030)
    assert k == pytest.approx(G * 0.0023 * 0.030 * math.cos(math.radians(10.0)) / math.radians(10.0), rel=1e-12)
    assert k == pytest.approx(3.8195e-3, rel=1e-4)
    assert rest == 0.0


def test_the_links_own_weight_gives_the_rest_angle_by_hand():
    """A 1 g link 40 mm long, level clamp, drooping 5 deg unloaded and 25 deg with a 2 g coin
    30 mm out: the moments -g (S cos 5) and -g (S + m L) cos 25 with S = 1 g * 20 mm, their
    difference over the 20 deg turn is k, and the rest lies the unloaded moment / k above."""
    link_moment = 0.001 * 0.040 / 2
    m_a = -G * link_moment * math.cos(math.radians(5.0))
    m_b = -G * (link_moment + 0.002 * 0.030) * math.cos(math.radians(25.0))
    assert weight_moment_nm(-5.0, link_moment) == pytest.approx(m_a, rel=1e-12)
    assert weight_moment_nm(-25.0, link_moment, 0.002, 0.030) == pytest.approx(m_b, rel=1e-12)
    k, rest = stiffness_and_rest((-5.0, -5.0), (-25.0, -25.0), link_moment, 0.002, 0.030)
    assert k == pytest.approx((m_b - m_a) / math.radians(-20.0), rel=1e-12)
    assert k == pytest.approx(1.47771e-03, rel=1e-4)
    assert rest == pytest.approx(2.5784, abs=1e-4)


def test_a_coin_on_the_upper_face_adds_its_height_times_the_sine():
    """The coin's centre 1.3 mm above a link pointing 30 deg down to the right: its moment arm
    is L cos 30 + h sin 30 (it sits up the slope); pointing left, the upper face is the other side."""
    m = weight_moment_nm(-30.0, 0.0, 0.002, 0.020, 0.0013, side=1.0)
    assert m == pytest.approx(-G * 0.002 * (0.020 * math.cos(math.radians(30)) + 0.0013 * 0.5), rel=1e-12)
    m = weight_moment_nm(-150.0, 0.0, 0.002, 0.020, 0.0013, side=-1.0)
    assert m == pytest.approx(G * 0.002 * (0.020 * math.cos(math.radians(30)) + 0.0013 * 0.5), rel=1e-12)


@pytest.mark.parametrize("k, rest, clamped", [(1e-3, 10.0, 180.0), (4e-3, -15.0, 170.0), (6e-4, 60.0, 120.0)])
def test_the_statics_give_back_the_rigs_own_equilibrium(k, rest, clamped):
    """The rig settled by MuJoCo (its hinge's spring against its bodies' weight) read back by
    the closed form: the hidden stiffness and rest angle to the root-find's precision."""
    rig = FoldRig(stiffness_nm_per_rad=k, rest_deg=rest, clamped_deg=clamped, coin_arm_m=0.02)
    a, b = settle(rig, False), settle(rig, True)
    assert abs(b.fold_deg - a.fold_deg) > 5.0
    kk, rr = stiffness_and_rest((a.fold_deg, a.free_deg), (b.fold_deg, b.free_deg),
                                rig.free_mass_kg * rig.free_length_m / 2, rig.coin_mass_kg, rig.coin_arm_m,
                                (rig.thickness_m + rig.coin_thickness_m) / 2)
    assert kk == pytest.approx(k, rel=1e-7)
    assert rr == pytest.approx(rest, abs=1e-5)


# -- photos made of numbers, for the refusals ----------------------------------------------
PX_PER_M = 4000.0


def _px(p) -> tuple[float, float]:
    return (200.0 + PX_PER_M * p[0], 900.0 - PX_PER_M * p[1])


def photo(clamped_deg: float, free_deg: float, name: str = "p.png") -> FoldPhoto:
    """A photo as read: the board's corners on a grid, the stickers where the angles put them."""
    grid = np.array([(x, y) for x in np.linspace(0, 0.2, 5) for y in np.linspace(0, 0.15, 4)])
    axis = np.array([0.3, 0.1])
    tip = axis + 0.035 * np.array([math.cos(math.radians(free_deg)), math.sin(math.radians(free_deg))])
    base = axis + 0.025 * np.array([math.cos(math.radians(clamped_deg)), math.sin(math.radians(clamped_deg))])
    stickers = dict(zip(FOLD_STICKERS, (_px(axis), _px(tip), _px(base))))
    return FoldPhoto(name, np.array([_px(p) for p in grid]), grid, 0.1, stickers, dict.fromkeys(FOLD_STICKERS, 0.1),
                     2.0, 0.0)


LINK = FreeLink(0.0008, 1e-5, 0.040, 0.0005, "weighed")
LOAD = Load(0.0023, 5e-5, 0.030, 0.0013, 0.0002, "eur-1c")


def test_the_fold_as_the_model_counts_it_per_fold_and_side():
    """The same photos: the loop's angle is the clamped ground link's against the leg (the
    other way round), a right leg's is read mirrored; the stiffness is the same."""
    u, ld = [photo(180.0, 5.0)], [photo(180.0, -15.0)]
    knee = fit_fold(u, ld, LINK, LOAD, fold="knee", draws=50)
    loop = fit_fold(u, ld, LINK, LOAD, fold="loop", draws=50)
    right = fit_fold(u, ld, LINK, LOAD, fold="knee", side="right", draws=50)
    assert knee.unloaded_deg.value == pytest.approx(5.0, abs=1e-5)      # through the homography
    assert loop.rest_deg.value == pytest.approx(-knee.rest_deg.value, abs=1e-9)
    assert right.rest_deg.value == pytest.approx(-knee.rest_deg.value, abs=1e-9)
    assert loop.stiffness_nm_per_rad.value == right.stiffness_nm_per_rad.value == knee.stiffness_nm_per_rad.value
    assert set(right.estimates) == {"right.knee_stiffness_nm_per_rad"}          # no robot angle given
    with_robot = fit_fold(u, ld, LINK, LOAD, fold="knee", side="left", assembled_deg=63.1, draws=50)
    assert with_robot.estimates["left.knee_rest_offset_deg"].value == pytest.approx(knee.rest_deg.value - 63.1)


def test_a_coin_photo_without_deflection_is_refused():
    with pytest.raises(CalibrationError, match="no deflection") as err:
        fit_fold([photo(180.0, -5.0)], [photo(180.0, -5.2)], LINK, LOAD, draws=50)
    assert "heavier coin or a longer lever arm" in err.value.hint


def test_photos_in_the_wrong_order_are_refused():
    with pytest.raises(CalibrationError, match="against the coin's weight") as err:
        fit_fold([photo(180.0, -25.0)], [photo(180.0, -5.0)], LINK, LOAD, draws=50)
    assert "without the coin first" in err.value.hint


def test_a_coin_too_heavy_for_the_angles_is_refused():
    """The loaded link 8 deg from hanging straight down: its moment is the cosine of a nearly
    vertical angle; the hint says how far from the fold to tape the coin instead."""
    with pytest.raises(CalibrationError, match="too heavy") as err:
        fit_fold([photo(180.0, -10.0)], [photo(180.0, -82.0)], LINK, LOAD, draws=50)
    assert "8.0 deg from the vertical" in err.value.message
    # the arm scaled to turn the fold by some 20 deg instead of 72
    assert "nearer the fold: its lever arm is now 30.0 mm (about 8 mm would turn it" in err.value.hint


# -- the bundled SYNTHETIC photos ------------------------------------------------------------
def test_the_bundled_photos_say_they_are_synthetic():
    from PIL import Image

    for name in (UNLOADED, LOADED):
        with Image.open(bundled_recording(name)) as image:
            assert image.info["comment"].startswith(b"SYNTHETIC")
    assert TRUTH["what"].startswith("SYNTHETIC")


@pytest.fixture(scope="module")
def bundled_fit():
    return locust.calibrate_fold(bundled_recording(UNLOADED), bundled_recording(LOADED), "knee", coin="eur-1c",
                                 coin_arm_m=TRUTH["rig"]["coin_arm_m"], robot=preset("small"))


def test_the_bundled_photos_give_the_hidden_stiffness_and_rest(bundled_fit):
    """The small robot's knee (its crank clamped, its coupler free, a 1 euro cent 12 mm out), the
    coupler's mass estimated from its size: each interval holds its truth, and is no wider than
    the sticker placement, the coin and the link's density make it."""
    fit = bundled_fit.result
    k, rest, offset = fit.stiffness_nm_per_rad, fit.rest_deg, fit.rest_offset_deg
    assert inside(k, TRUTH["stiffness_nm_per_rad"]) and inside(rest, TRUTH["rest_deg"])
    assert k.std / k.value < 0.08 and rest.std < 4.0
    assembled = fold_angles_deg(preset("small"), "L")["knee"]
    assert fit.assembled_deg == assembled
    assert inside(offset, TRUTH["rest_deg"] - assembled)
    assert offset.value == pytest.approx(rest.value - assembled, abs=1e-9)
    assert set(bundled_fit.parameters) == {"folds.knee_stiffness_nm_per_rad", "folds.knee_rest_offset_deg"}
    # the deflection the coin made, against the rig's settled angles (the photos' own precision)
    turn = TRUTH["poses"]["loaded"]["fold_deg"] - TRUTH["poses"]["unloaded"]["fold_deg"]
    assert inside(fit.deflection_deg, turn) and abs(fit.deflection_deg.value - turn) < 0.5


def _run(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def test_the_command_writes_both_legs_or_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in (UNLOADED, LOADED):
        shutil.copy(bundled_recording(name), tmp_path / name)
    toml = tmp_path / "robot.toml"
    common = [UNLOADED, LOADED, "--fold", "knee", "--coin", "eur-1c", "--coin-arm-m", "0.012", "--no-plot"]
    res = _run("calibrate", "fold", *common, "--json", "--write", toml)
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    k = out["folds.knee_stiffness_nm_per_rad"]
    robot = load_robot(toml)
    assert robot.get("folds.knee_stiffness_nm_per_rad") == pytest.approx(k["value"], rel=1e-9)
    prov = robot.source_of("folds.knee_stiffness_nm_per_rad")
    assert prov.source == f"fit:{UNLOADED}+{LOADED}" and prov.uncertainty == pytest.approx(k["std"], rel=1e-6)
    offset = robot.get("folds.knee_rest_offset_deg")
    assert offset == pytest.approx(out["folds.knee_rest_offset_deg"]["value"], rel=1e-9)
    assert robot.own("left.knee_stiffness_nm_per_rad") is None
    res = _run("calibrate", "fold", *common, "--side", "left", "--write", toml)
    assert res.exit_code == 0, res.output
    assert "wrote left.knee_stiffness_nm_per_rad, left.knee_rest_offset_deg" in res.output
    robot = load_robot(toml)
    assert robot.get("left.knee_stiffness_nm_per_rad") == pytest.approx(k["value"], rel=1e-9)
    assert robot.get("folds.knee_rest_offset_deg") == offset        # the folds section kept


def test_photos_missing_a_sticker_or_the_board_are_refused(tmp_path):
    image = cv2.imread(str(bundled_recording(LOADED)))
    x, y = TRUTH["points_px"]["loaded"]["tip"]
    cv2.circle(image, (round(x), round(y)), 9, (77, 77, 77), -1)
    cv2.imwrite(str(tmp_path / "no_tip.png"), image)
    with pytest.raises(CalibrationError, match="no_tip.png: the tip sticker") as err:
        read_state(tmp_path / "no_tip.png", BOARD)
    assert "stick a #00ff00 dot there" in err.value.hint
    cv2.imwrite(str(tmp_path / "blank.png"), np.full((480, 640, 3), 128, np.uint8))
    with pytest.raises(CalibrationError, match="blank.png: board .* not found"):
        read_state(tmp_path / "blank.png", BOARD)
    with pytest.raises(CalibrationError, match="no such photo"):
        read_state(tmp_path / "nothing.jpg", BOARD)


def test_a_clip_of_each_state_is_read_frame_by_frame(tmp_path):
    """A clip of the still fold (MPEG-4, 8 frames): each frame a photo of the state, its
    stickers where the photo's are to a pixel."""
    from locust.track.video import encode_video

    image = cv2.imread(str(bundled_recording(LOADED)))
    h, w = image.shape[:2]
    clip = encode_video(tmp_path / "loaded.mp4", (image for _ in range(8)), 30.0, (w, h))
    photos = read_state(clip, BOARD)
    assert [p.name for p in photos] == [f"loaded.mp4#{k}" for k in range(8)]
    still = read_state(bundled_recording(LOADED), BOARD)[0]
    for n in FOLD_STICKERS:
        assert np.hypot(*np.subtract(photos[-1].stickers_px[n], still.stickers_px[n])) < 1.0, n


def test_bad_readings_are_refused():
    u, ld = bundled_recording(UNLOADED), bundled_recording(LOADED)
    with pytest.raises(CalibrationError, match="give the coin"):
        locust.calibrate_fold(u, ld, "knee", coin_arm_m=0.012, robot=preset("small"))
    with pytest.raises(CalibrationError, match="give the coin"):
        locust.calibrate_fold(u, ld, "knee", coin="eur-1c", coin_mass_kg=0.0023, coin_arm_m=0.012,
                              robot=preset("small"))
    with pytest.raises(CalibrationError, match="beyond the free link's end"):
        locust.calibrate_fold(u, ld, "knee", coin="eur-1c", coin_arm_m=0.025, robot=preset("small"))
    with pytest.raises(CalibrationError, match="not one of eur-1c"):
        locust.calibrate_fold(u, ld, "knee", coin="eur-3c", coin_arm_m=0.012, robot=preset("small"))
    tooth = preset("small").with_values({"right.crank_tooth": 1})
    with pytest.raises(CalibrationError, match="different angles") as err:
        locust.calibrate_fold(u, ld, "knee", coin="eur-1c", coin_arm_m=0.012, robot=tooth)
    assert "--side left or --side right" in err.value.hint


# -- freshly rendered fold tests ---------------------------------------------------------------
def _fit_seed(seed: int, folder, frames: int = 1):
    test = synthetic_fold_test(seed, folder, frames=frames)
    fit = fit_fold(read_state(test.photos.unloaded, BOARD), read_state(test.photos.loaded, BOARD, 1), test.link(),
                   test.load(), source=f"seed {seed}")
    return test.photos.rig, fit


def test_one_rendered_seed_recovers_its_hidden_fold(tmp_path):
    rig, fit = _fit_seed(2, tmp_path)
    assert inside(fit.stiffness_nm_per_rad, rig.stiffness_nm_per_rad)
    assert inside(fit.rest_deg, rig.rest_deg)
    assert fit.stiffness_nm_per_rad.std / fit.stiffness_nm_per_rad.value < 0.1 and fit.rest_deg.std < 4.0


def test_several_photos_of_each_state_are_averaged(tmp_path):
    """Four photos a state, each its own noise: each state is their mean, the stickers' scatter
    over them is measured (at least the photos' own), and the interval still holds the truth."""
    rig, fit = _fit_seed(5, tmp_path, frames=4)
    assert fit.photos == (4, 4)
    assert fit.sticker_sd_px >= 0.1
    assert inside(fit.stiffness_nm_per_rad, rig.stiffness_nm_per_rad) and inside(fit.rest_deg, rig.rest_deg)


@pytest.mark.slow
def test_the_intervals_cover_the_hidden_fold_over_ten_seeds(tmp_path):
    """Ten seeds (stiffness 5e-4 to 5e-3 N*m/rad, rest -20 to 20 deg, a coin of each kind named
    or weighed, the link weighed or estimated, stickers placed by eye, camera pose and noise):
    each 95 % interval holds its truth in at least 8 of 10 (9.5 expected; 8 or more 99 % of the time)."""
    hits = {"k": 0, "rest": 0}
    for seed in range(10):
        rig, fit = _fit_seed(seed, tmp_path / str(seed))
        hits["k"] += inside(fit.stiffness_nm_per_rad, rig.stiffness_nm_per_rad)
        hits["rest"] += inside(fit.rest_deg, rig.rest_deg)
    assert hits["k"] >= 8 and hits["rest"] >= 8, hits


def test_coins_are_the_published_ones():
    assert {n: c.mass_kg * 1000 for n, c in COINS.items() if n in ("eur-1c", "usd-1c", "gbp-1p")} == \
        pytest.approx({"eur-1c": 2.30, "usd-1c": 2.500, "gbp-1p": 3.56}, rel=1e-12)
