"""``locust sim --still`` and ``locust measure stance`` against the simulation's own truth.

The stills are synthetic: MuJoCo renders of a robot whose stance is known. Each is re-encoded
as a JPEG with added pixel noise (:func:`as_photo`) before it is measured, so that only the
picture carries over, never the truth files beside it.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from locust.arucoboard import DEFAULT_BOARD
from locust.commands import cli
from locust.io.camera_json import read_camera_json
from locust.measure.stance import find_stickers, fit_points, given_points
from locust.params import preset
from locust.sim.stickers import STICKERS

# the robot of the fast tests: Medium, its stance inside the as-built uncertainties
TRUTH = {"geometry.crank_start_deg": -95.0, "geometry.ground_angle_deg": 5.0, "geometry.servo_axis_x_m": 0.018}
SETS = [f"{k}={v}" for k, v in TRUTH.items()]
NOISE_LEVELS = 2.0       # sd of the added pixel noise, in grey levels of 255
JPEG_QUALITY = 90


def as_photo(png: Path, jpg: Path, seed: int) -> Path:
    """A synthetic 'photo' of a rendered still: its pixels with Gaussian noise of
    NOISE_LEVELS, saved as a JPEG of JPEG_QUALITY."""
    image = cv2.imread(str(png)).astype(float)
    image += np.random.default_rng(seed).normal(0.0, NOISE_LEVELS, image.shape)
    cv2.imwrite(str(jpg), np.clip(np.rint(image), 0, 255).astype(np.uint8), [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    return jpg


def read_truth(path: Path) -> tuple[dict[str, float], dict[str, dict[str, float]]]:
    """A still's truth CSV: the values of its comment line and each sticker's row."""
    lines = path.read_text().splitlines()
    values = {}
    for part in lines[1].lstrip("# ").split(";"):
        key, _, rest = part.strip().partition(" = ")
        values[key] = float(rest.split()[0])
    header = lines[3].split(",")
    rows = {}
    for line in lines[4:]:
        cells = line.split(",")
        rows[cells[0]] = {h: float(c) for h, c in zip(header[1:], cells[1:])}
    return values, rows


def run_cli(*args: str):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


@pytest.fixture(scope="module")
def stills(tmp_path_factory):
    folder = tmp_path_factory.mktemp("stills")
    result = run_cli("sim", "--preset", "medium", *sum((["--set", s] for s in SETS), []), "--cycles", "1",
                     "--still", str(folder / "rest.png"), "--still-push", str(folder / "push.png"))
    assert result.exit_code == 0, result.output
    return {kind: {"png": folder / f"{kind}.png", "truth": read_truth(folder / f"{kind}.truth.csv"),
                   "camera": folder / f"{kind}.camera.json",
                   "jpg": as_photo(folder / f"{kind}.png", folder / f"{kind}.jpg", seed=k)}
            for k, kind in enumerate(("rest", "push"))}


def test_the_truth_pixels_are_where_the_stickers_are_drawn(stills):
    for kind, s in stills.items():
        _, rows = s["truth"]
        found, _ = find_stickers(cv2.imread(str(s["png"])), s["png"], {})
        for name in STICKERS:
            assert rows[name]["seen_frac"] == 1.0, (kind, name)
            assert math.dist(found[name], (rows[name]["px"], rows[name]["py"])) < 0.3, (kind, name)
        # the camera file projects each sticker's world position onto its true pixel
        cam = read_camera_json(s["camera"])
        world = np.array([[rows[n]["x_m"], rows[n]["y_m"], rows[n]["z_m"]] for n in STICKERS])
        pc = (world - cam.positions_m[0]) @ cam.rotation.T
        uv = (pc @ cam.K.T)[:, :2] / pc[:, 2:]
        assert np.allclose(uv, [[rows[n]["px"], rows[n]["py"]] for n in STICKERS], atol=1e-3)


def test_the_sticker_model_is_the_simulated_pose(stills):
    """The planar model the fit uses, at the true stance, puts the stickers where MuJoCo posed them."""
    robot = preset("medium").with_values(TRUTH)
    views, cranks = [], []
    for kind in ("rest", "push"):
        values, rows = stills[kind]["truth"]
        views.append([[-rows[n]["x_m"], rows[n]["z_m"]] for n in STICKERS])   # seen from +y: x runs left
        cranks.append(values["crank_deg"])
    p, mirrored, rss = fit_points(robot, np.vstack(views))
    assert not mirrored
    assert math.sqrt(rss / 24) < 2e-6                    # metres: the loop closes to a few um in MuJoCo
    assert p[0] == pytest.approx(5.0, abs=0.01)
    assert p[1] == pytest.approx(0.018, abs=1e-5)
    assert p[5] == pytest.approx(cranks[0], abs=0.01)
    assert p[9] == pytest.approx(cranks[1], abs=0.01)
    # photographed from the robot's right the view is mirrored: the same stance, found as such
    mirrored_view = np.vstack(views) * [-1.0, 1.0]
    q, mirrored, _ = fit_points(robot, mirrored_view)
    assert mirrored
    assert q[[0, 1, 5, 9]] == pytest.approx(p[[0, 1, 5, 9]], abs=1e-4)


def test_measure_stance_from_two_photos_writes_the_whole_robot(stills, tmp_path):
    out = tmp_path / "measured.toml"
    result = run_cli("measure", "stance", str(stills["rest"]["jpg"]), str(stills["push"]["jpg"]), "--preset", "medium",
                     "--write", str(out), "--json")
    assert result.exit_code == 0, result.output
    got = json.loads(result.stdout)
    for key, tol in (("crank_start_deg", 2.0), ("ground_angle_deg", 3.0), ("servo_axis_x_m", 0.002)):
        truth = TRUTH[f"geometry.{key}"]
        assert got[key]["value"] == pytest.approx(truth, abs=tol)
        lo, hi = got[key]["ci95"]
        assert lo <= truth <= hi, key
    turn = stills["push"]["truth"][0]["servo_deg"] - stills["rest"]["truth"][0]["servo_deg"]
    assert got["push_turn_deg"]["value"] == pytest.approx(turn, abs=0.5)
    assert got["rest_pitch_deg"]["value"] == pytest.approx(stills["rest"]["truth"][0]["plate_pitch_deg"], abs=0.5)

    params = run_cli("params", "--config", str(out), "--json")
    assert params.exit_code == 0, params.output
    doc = json.loads(params.stdout)
    text = json.dumps(doc)
    assert text.count('"measured:rest.jpg"') == 3
    sim = run_cli("sim", "--config", str(out), "--cycles", "1", "--json")
    assert sim.exit_code == 0, sim.output
    assert json.loads(sim.stdout)["valid"] is True
    # the written robot is the preset but for the measured values
    again = run_cli("measure", "stance", str(stills["rest"]["jpg"]), "--preset", "medium", "--write", str(out))
    assert again.exit_code == 2 and "exists" in again.output


def test_the_printed_stance_reads_as_a_person_reads_it(stills):
    """Each measured value as a label and its unit, the JSON's value and interval times the
    unit's factor, to the printed 0.01 (the servo axis in mm: it was printed as
    `geometry.servo_axis_x_m (mm)`, a key in metres beside a value in mm)."""
    photos = [str(stills["rest"]["jpg"]), str(stills["push"]["jpg"])]
    got = json.loads(run_cli("measure", "stance", *photos, "--preset", "medium", "--json").stdout)
    text = run_cli("measure", "stance", *photos, "--preset", "medium").stdout
    rows = {m.group(1): [float(v) for v in m.group(2, 4, 5)] + [m.group(3)] for m in re.finditer(
        r"^([a-z ]+?)\s+(-?[\d.]+) (mm|deg)\s+\[\s*(-?[\d.]+),\s*(-?[\d.]+)\]", text, re.M)}
    for label, key, factor, unit in (("servo axis x", "servo_axis_x_m", 1000.0, "mm"),
                                     ("crank start", "crank_start_deg", 1.0, "deg"),
                                     ("ground angle", "ground_angle_deg", 1.0, "deg"),
                                     ("plate pitch at rest", "rest_pitch_deg", 1.0, "deg"),
                                     ("crank turn at the push", "push_turn_deg", 1.0, "deg")):
        value, lo, hi, shown = rows[label]
        assert shown == unit, label
        want = [got[key]["value"] * factor, *(v * factor for v in got[key]["ci95"])]
        assert [value, lo, hi] == pytest.approx(want, abs=0.005), label
    assert "_m" not in text and "_deg" not in text and "(mm)" not in text


def test_one_photo_gives_the_stance_without_the_push(stills):
    result = run_cli("measure", "stance", str(stills["rest"]["jpg"]), "--preset", "medium", "--json")
    assert result.exit_code == 0, result.output
    got = json.loads(result.stdout)
    assert got["push_turn_deg"] is None
    for key, tol in (("crank_start_deg", 2.0), ("ground_angle_deg", 3.0), ("servo_axis_x_m", 0.002)):
        lo, hi = got[key]["ci95"]
        assert lo <= TRUTH[f"geometry.{key}"] <= hi and hi - lo < tol, key


def test_a_still_never_overwrites(stills):
    result = run_cli("sim", "--preset", "medium", "--still", str(stills["rest"]["png"]))
    assert result.exit_code == 2
    assert f"error: {stills['rest']['png']} exists already; not overwriting it" in result.output


def test_pixels_given_in_trackers_convention_are_half_a_pixel_from_opencvs():
    assert given_points(("knee=10,20",), "tracker", "--point") == {"knee": (9.5, 19.5)}
    assert given_points(("knee=10,20",), "opencv", "--point") == {"knee": (10.0, 20.0)}


def test_an_unknown_sticker_name_is_refused(stills):
    result = run_cli("measure", "stance", str(stills["rest"]["jpg"]), "--preset", "medium", "--point", "toe=1,2")
    assert result.exit_code == 2
    assert "error: --point 'toe=1,2'" in result.output and "knee" in result.output


def test_a_photo_without_the_board_is_refused(stills, tmp_path):
    image = cv2.imread(str(stills["rest"]["jpg"]))
    # paint the half of the picture the board stands in (it stands beside the robot, to its right)
    xs = [r["px"] for r in stills["rest"]["truth"][1].values()]
    image[:, int(max(xs)) + 40:] = 128
    bad = tmp_path / "noboard.jpg"
    cv2.imwrite(str(bad), image)
    result = run_cli("measure", "stance", str(bad), "--preset", "medium")
    assert result.exit_code == 2
    assert f"error: noboard.jpg: board {DEFAULT_BOARD} not found" in result.output
    assert "hint:" in result.output


def test_an_oblique_photo_is_refused(stills, tmp_path):
    image = cv2.imread(str(stills["rest"]["jpg"]))
    h, w = image.shape[:2]
    # the camera turned about the vertical: the picture's right edge 12 % taller than its left
    src = np.float32([[0, 0], [w, 0], [w, h], [0, h]])
    dst = np.float32([[0, 0.06 * h], [w, 0], [w, h], [0, 0.94 * h]])
    warped = cv2.warpPerspective(image, cv2.getPerspectiveTransform(src, dst), (w, h))
    cv2.imwrite(str(tmp_path / "oblique.jpg"), warped)
    result = run_cli("measure", "stance", str(tmp_path / "oblique.jpg"), "--preset", "medium")
    assert result.exit_code == 2
    assert "error: oblique.jpg is not square to the board: its right edge is" in result.output
    share = float(result.output.split("its right edge is ")[1].split(" %")[0])
    assert 4.0 < share < 12.0        # the board spans part of the picture's width
    assert "hint:" in result.output


def test_a_point_no_pose_reaches_is_named_with_its_distance(stills):
    _, rows = stills["rest"]["truth"]
    shift_px = 30.0
    knee = (rows["knee"]["px"] + shift_px, rows["knee"]["py"])
    result = run_cli("measure", "stance", str(stills["rest"]["jpg"]), "--preset", "medium", "--pixels", "opencv",
                     "--point", f"knee={knee[0]},{knee[1]}")
    assert result.exit_code == 2
    assert "error: rest.jpg: the knee sticker is " in result.output
    off_mm = float(result.output.split("the knee sticker is ")[1].split(" mm")[0])
    # the scale at the leg's plane, from the camera the still was rendered with
    cam = read_camera_json(stills["rest"]["camera"])
    mm_per_px = cam.m_per_px_at(rows["knee"]["y_m"]) * 1000.0
    assert off_mm == pytest.approx(shift_px * mm_per_px, rel=0.25)


# -- ten robots across the threshold (slow) ----------------------------------------------
# Two sets of ten, each drawn from the as-built uncertainties (crank -100 +- 10 deg, ground
# 0 +- 15 deg, plate 4 +- 1 g, and the servo axis 20 +- 5 mm from the plate's middle, or 28 +- 3 mm
# as the top view reads it at 3.0 px/mm; normal, clipped at 2 sd) on a random leg set, and kept
# in the order drawn: the first three of each regime (and a fourth that goes over). The
# rear-and-return band is a few degrees of crank wide, so the rest of its three are drawn the
# same way with the crank stepped by 2 deg across the band (-90 and -88 deg).
TEN = {  # leg set, crank_start_deg, ground_angle_deg, servo_axis_x_m, body_mass_kg, regime of the truth
    "axis 20 +- 5 mm": [   # seed 1; band seed 5
        ("medium", -91.78, 4.96, 0.01348, 0.00491, "stays_low"),
        ("medium", -95.54, -8.05, 0.02291, 0.00436, "goes_over"),
        ("small", -99.72, 8.2, 0.01632, 0.00384, "goes_over"),
        ("small", -104.82, 8.98, 0.0202, 0.00371, "goes_over"),
        ("large", -102.57, 0.12, 0.01862, 0.00529, "goes_over"),
        ("small", -103.78, 30.0, 0.02323, 0.00466, "stays_low"),
        ("large", -92.48, 3.8, 0.02448, 0.00365, "rears_and_returns"),
        ("medium", -87.81, 5.74, 0.01562, 0.00249, "stays_low"),
        ("large", -90.0, -3.73, 0.0221, 0.00514, "rears_and_returns"),
        ("large", -88.0, -8.29, 0.01608, 0.00475, "rears_and_returns"),
    ],
    "axis 28 +- 3 mm": [   # seed 11; band seed 5
        ("small", -86.4, 18.37, 0.02647, 0.0037, "stays_low"),
        ("small", -105.27, 8.55, 0.02783, 0.00475, "goes_over"),
        ("large", -84.33, -1.45, 0.03004, 0.00386, "rears_and_returns"),
        ("medium", -103.79, 6.95, 0.03047, 0.0038, "goes_over"),
        ("large", -106.71, -28.81, 0.02556, 0.00353, "goes_over"),
        ("medium", -114.92, 0.55, 0.03069, 0.00377, "goes_over"),
        ("large", -89.57, -3.1, 0.02556, 0.00435, "rears_and_returns"),
        ("large", -97.52, 16.48, 0.02415, 0.00334, "stays_low"),
        ("large", -86.14, 12.33, 0.02988, 0.0044, "stays_low"),
        ("large", -88.0, -3.73, 0.02926, 0.00514, "rears_and_returns"),
    ],
}
REAR_NOSE_M = 0.03       # the nose above this and back down, every hop: rears and returns
CAME_DOWN_M = 0.01       # the nose ending higher than this above its standing height: it went over


def regime(robot) -> str:
    """goes_over / rears_and_returns / stays_low, from one audited run of the hop schedule."""
    from locust.sim.audit import audit
    from locust.sim.hops import summarise
    from locust.sim.rollout import roll_out

    traj = roll_out(robot)
    assert audit(traj).valid
    summary = summarise(traj)
    apex = [h.nose_apex_m for h in summary.hops]
    if summary.end_nose_rise_m > CAME_DOWN_M:
        return "goes_over"
    if min(apex) > REAR_NOSE_M:
        return "rears_and_returns"
    return "stays_low" if max(apex) < REAR_NOSE_M else "mixed"


@pytest.mark.slow
@pytest.mark.parametrize("drawn", list(TEN))
def test_ten_robots_across_the_threshold_are_measured_and_rebuilt(drawn, tmp_path):
    from locust.arucoboard import parse_board
    from locust.measure.stance import STANCE_KEYS, fit_stance, model_servo_give, read_photo
    from locust.sim.still import render_stills

    spec = parse_board(DEFAULT_BOARD)
    rows, regimes = [], []
    for k, (leg, crank, ground, axis, mass, expected) in enumerate(TEN[drawn]):
        base = preset(leg).with_values({"geometry.body_mass_kg": mass})   # the plate weighed
        truth = base.with_values(dict(zip(STANCE_KEYS, (crank, ground, axis))))
        actual = regime(truth)
        assert actual == expected, (k, actual)
        regimes.append(actual)
        infos = render_stills(truth, tmp_path / f"rest{k}.png", tmp_path / f"push{k}.png", board=spec)
        photos = [read_photo(as_photo(i.path, i.path.with_suffix(".jpg"), seed=10 * k + j), spec, {})
                  for j, i in enumerate(infos)]
        got = fit_stance(base, photos, model_servo_give(base), seed=k)
        measured = {key: est.value for key, est in got.values().items()}
        rebuilt = base.with_values(measured)
        unweighed = preset(leg).with_values(measured)   # for the table only: the preset's 4 g plate
        rows.append((leg, (crank, ground, axis), got, actual, regime(rebuilt), regime(unweighed)))

    print(f"\n{drawn}\n{'leg':7s} {'crank deg: truth, measured, 95 %':>34s} {'ground deg':>34s} {'axis mm':>34s}  "
          f"{'truth':18s} {'rebuilt':18s} rebuilt with a 4 g plate")
    for leg, truth, got, actual, again, plain in rows:
        cells = []
        for t, est, k in zip(truth, got.values().values(), (1.0, 1.0, 1000.0)):
            cells.append(f"{t * k:7.2f} {est.value * k:8.3f} [{est.ci95[0] * k:7.2f},{est.ci95[1] * k:7.2f}]")
        print(f"{leg:7s} " + " ".join(f"{c:>34s}" for c in cells) + f"  {actual:18s} {again:18s} {plain}")
    for i, key in enumerate(STANCE_KEYS):
        errors = [abs(got.values()[key].value - truth[i]) for _, truth, got, *_ in rows]
        covered = sum(got.values()[key].ci95[0] <= truth[i] <= got.values()[key].ci95[1] for _, truth, got, *_ in rows)
        print(f"{key}: largest error {max(errors):.4g}, intervals cover {covered} of {len(rows)}")
    print(f"outcome kept: {sum(r[3] == r[4] for r in rows)} of {len(rows)}; "
          f"with the preset's plate: {sum(r[3] == r[5] for r in rows)} of {len(rows)}")

    assert all(regimes.count(r) >= 3 for r in ("goes_over", "rears_and_returns", "stays_low"))
    for i, tol in enumerate((2.0, 3.0, 0.002)):
        errors = [abs(got.values()[STANCE_KEYS[i]].value - truth[i]) for _, truth, got, *_ in rows]
        assert max(errors) <= tol, (STANCE_KEYS[i], errors)
        covered = sum(est.ci95[0] <= truth[i] <= est.ci95[1]
                      for _, truth, got, *_ in rows for est in [got.values()[STANCE_KEYS[i]]])
        assert covered >= 8, (STANCE_KEYS[i], covered)
    assert sum(r[3] == r[4] for r in rows) >= 9


@pytest.mark.parametrize("drawn", [TEN["axis 20 +- 5 mm"][2], TEN["axis 28 +- 3 mm"][2]],
                         ids=lambda d: f"{d[0]}-{d[5]}")
def test_a_drawn_robot_is_measured_and_rebuilt_in_its_regime(drawn, tmp_path):
    """Two of the ten (a Small that goes over, a Large that rears and returns) in the default run."""
    from locust.arucoboard import parse_board
    from locust.measure.stance import STANCE_KEYS, fit_stance, model_servo_give, read_photo
    from locust.sim.still import render_stills

    leg, crank, ground, axis, mass, expected = drawn
    spec = parse_board(DEFAULT_BOARD)
    base = preset(leg).with_values({"geometry.body_mass_kg": mass})
    truth = base.with_values(dict(zip(STANCE_KEYS, (crank, ground, axis))))
    infos = render_stills(truth, tmp_path / "rest.png", tmp_path / "push.png", board=spec)
    photos = [read_photo(as_photo(i.path, i.path.with_suffix(".jpg"), seed=j), spec, {}) for j, i in enumerate(infos)]
    got = fit_stance(base, photos, model_servo_give(base), draws=100)
    for (key, est), t, tol in zip(got.values().items(), (crank, ground, axis), (2.0, 3.0, 0.002)):
        assert est.value == pytest.approx(t, abs=tol), key
    assert regime(base.with_values({k: e.value for k, e in got.values().items()})) == expected
