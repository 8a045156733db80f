"""Robots whose folds, stance, right crank and supply are hidden, measured as a student would
measure them (SYNTHETIC: MuJoCo renders of each hidden robot, re-encoded with noise), and
rebuilt from the measurements: each value recovered within its interval, and the rebuilt
robot's outcome the hidden one's.

Each hidden robot is the robot as built (``small``) with every fold's stiffness (3-35 times
the film hinge's) and rest offset (+-8 deg) drawn, its crank angle at rest and its ground
link's angle drawn, its right crank a tooth off either way, and a USB source that limits the
stalled servos' current (0.78-0.94 A: the robot as built draws 0.96 A stalled, its board's
included, and below 0.75 A browns out and does not push). It is measured: ``measure stance``
from two stills of its left (rest, push) and ``measure stance --side right`` from one of its
right (the tooth);
``calibrate fold`` from a fold test of each of its left leg's folds (a coin on the free link);
``measure stroke`` from clips of a push on the floor and held up; ``measure supply`` from a
multimeter's readings at the servo plug. The student's robot file (``small``) with those in
place is the rebuilt robot.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from locust.arucoboard import DEFAULT_BOARD, parse_board
from locust.calibrate.fold import assembled_deg, fold_test
from locust.calibrate.foldsynthetic import robot_fold_test
from locust.measure.meter import MeterSpec
from locust.measure.stance import fit_stance, model_servo_give, read_photo, with_stance
from locust.measure.stroke import measure_stroke
from locust.measure.supply import measure_supply, virtual_readings
from locust.measure.tooth import with_tooth
from locust.params import FOLDS, Provenance, preset, side_values
from locust.sim.pushclip import render_push_clips
from locust.sim.run import run
from locust.sim.still import render_stills
from test_measure_stance import as_photo
from test_measure_stroke import as_phone_clip, truth_of

SEEDS = range(10)
CYCLES = 3
VOLTS = MeterSpec(0.5, 2, 0.01)      # a multimeter's +-(0.5 % + 2 digits) on its 20 V range
CLIP_SIZE = (640, 480)


def hidden(seed: int):
    """The robot as built with its folds, stance, right crank and supply drawn from ``seed``."""
    rng = np.random.default_rng(4600 + seed)
    values = {"geometry.crank_start_deg": float(rng.uniform(-104.0, -96.0)),
              "geometry.ground_angle_deg": float(rng.uniform(-6.0, 6.0)),
              "right.crank_tooth": int(rng.choice([-1, 1])),
              "power.current_limit_a": float(rng.uniform(0.78, 0.94))}
    for fold in FOLDS:
        values[f"folds.{fold}_stiffness_nm_per_rad"] = float(math.exp(rng.uniform(math.log(5e-4), math.log(5e-3))))
        values[f"folds.{fold}_rest_offset_deg"] = float(rng.uniform(-8.0, 8.0))
    return preset("small").with_values(values, Provenance(source="estimate", note="hidden: the test's truth"))


def _inside(est, truth: float) -> bool:
    lo, hi = (est.ci95_low, est.ci95_high) if hasattr(est, "ci95_low") else est.ci95
    return lo <= truth <= hi


def _stance(truth, base, folder, seed, spec):
    """The student's robot file with the stance (left stills) and the right crank's tooth in place."""
    left = render_stills(truth, folder / "rest.png", folder / "push.png", board=spec)
    right, = render_stills(truth, folder / "rest_right.png", board=spec, side="R")
    photos = [read_photo(as_photo(i.path, i.path.with_suffix(".jpg"), seed=10 * seed + k), spec, {})
              for k, i in enumerate(left)]
    stance = fit_stance(base, photos, model_servo_give(base), seed=seed)
    measured = with_stance(base, stance, photos[0].path)
    photo = read_photo(as_photo(right.path, right.path.with_suffix(".jpg"), seed=10 * seed + 5), spec, {})
    side = fit_stance(measured, [photo], model_servo_give(measured, "R"), seed=seed, side="R")
    return with_tooth(measured, side.tooth, photo.path), side.tooth


def _folds(truth, measured, folder, seed):
    """Each left fold's test fitted: (fold, fit, true stiffness, true rest angle)."""
    out = []
    for i, fold in enumerate(FOLDS):
        test = robot_fold_test(truth, fold, "left", 100 * seed + i, folder)
        r = test.readings
        fit = fold_test(test.photos.unloaded, test.photos.loaded, fold, measured, coin_arm_m=r.arm_m, coin_name=r.coin,
                        side="left", link_length_m=r.link_length_m, seed=seed)
        own = side_values(truth, "L").folds[fold]
        out.append((fold, fit, own.stiffness_nm_per_rad, assembled_deg(truth, fold, "left") + own.rest_offset_deg))
    return out


def _rebuilt(measured, folds, supply_robot):
    """The student's robot with the folds' and the supply's values in place (each offset taken
    against the measured robot's own assembly)."""
    values = {"power.current_limit_a": supply_robot.power.current_limit_a}
    for fold, fit, _, _ in folds:
        values[f"folds.{fold}_stiffness_nm_per_rad"] = fit.stiffness_nm_per_rad.value
        values[f"folds.{fold}_rest_offset_deg"] = fit.rest_deg.value - assembled_deg(measured, fold, "left")
    return measured.with_values(values, Provenance(source="fit:hidden robot's tests"))


@pytest.mark.slow
def test_hidden_robots_measured_and_rebuilt(tmp_path):
    spec = parse_board(DEFAULT_BOARD)
    base = preset("small")
    counts: dict[str, int] = {}
    rows = []

    def count(name: str, ok: bool) -> None:
        counts[name] = counts.get(name, 0) + int(ok)

    for seed in SEEDS:
        truth = hidden(seed)
        folder = tmp_path / f"robot{seed}"
        folder.mkdir()
        measured, tooth = _stance(truth, base, folder, seed, spec)
        count("right.crank_tooth", tooth.tooth == truth.right.crank_tooth)
        folds = _folds(truth, measured, folder, seed)
        for fold, fit, k, rest in folds:
            count(f"{fold} stiffness", _inside(fit.stiffness_nm_per_rad, k))
            count(f"{fold} rest", _inside(fit.rest_deg, rest))
        made = render_push_clips(truth, folder / "floor.mp4", folder / "held.mp4", width=CLIP_SIZE[0],
                                 height=CLIP_SIZE[1])
        phone = [as_phone_clip(c.clip.video_path, folder / f"{c.kind}_phone.mp4", seed=seed) for c in made]
        strokes = measure_stroke(measured, phone, seed=seed)
        for c, r in zip(made, strokes.readings):
            count(f"stroke ({c.kind})", _inside(r.estimates["stroke_deg"], truth_of(c)["stroke_deg"]))
        supply = measure_supply(measured, virtual_readings(truth, VOLTS, seed=seed), VOLTS, solve="limit")
        count("power.current_limit_a", _inside(supply.value, truth.power.current_limit_a))
        rebuilt = _rebuilt(measured, folds, supply.robot)
        want, got = run(truth, cycles=CYCLES), run(rebuilt, cycles=CYCLES)
        count("outcome", want.valid and got.valid and want.outcome == got.outcome)
        rows.append((seed, want.outcome, got.outcome, want.hops[0].nose_apex_m, got.hops[0].nose_apex_m,
                     truth.power.current_limit_a, supply.value.value))
    print(f"\n{'seed':>4s} {'hidden':18s} {'rebuilt':18s} {'nose mm':>8s} {'rebuilt':>8s} {'limit A':>8s} "
          f"{'measured':>8s}")
    for seed, a, b, na, nb, la, lb in rows:
        print(f"{seed:4d} {a:18s} {b:18s} {na * 1000:8.1f} {nb * 1000:8.1f} {la:8.3f} {lb:8.3f}")
    for name, n in counts.items():
        print(f"{name:24s} {n:2d} of {len(SEEDS)}")
    for name, n in counts.items():
        assert n >= (9 if name == "outcome" else 8), name
