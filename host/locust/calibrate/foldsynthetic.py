"""SYNTHETIC fold tests of known truth, drawn from a seed: the virtual rig of
:mod:`locust.sim.foldrig` photographed by :mod:`locust.sim.foldphotos`, and what a student
reads off the bench beside the photos (for the tests and the demo).

Each seed draws the hidden hinge (stiffness log-uniform over :data:`STIFFNESS_RANGE_NM_PER_RAD`,
rest angle uniform over ±:data:`REST_RANGE_DEG`), the clamp's angle, a coin of :data:`COINS`
(its true mass off its published one as :data:`PUBLISHED_MASS_REL_SD` says, or weighed), the
laminate's true density (about the robot's as its uncertainty says), where each sticker really
sits (:data:`locust.calibrate.fold.PLACEMENT_SD_M` off its line), the board's lean, and the
camera's pose and noise. The coin goes where a student would tape it: at a lever arm that turns
the fold by 10 to 35 deg, nearer the fold while the loaded link would hang within 25 deg of the
vertical. The readings carry the bench's errors: the ruler's on the lever arm and the link's
length, the scale's on a weighed coin or link, or the link's mass estimated from its size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import SimError
from ..params import GRAVITY_M_PER_S2, Robot, side_values
from ..sim.foldphotos import FoldPhotos, FoldShot, render_fold_test
from ..sim.foldrig import FoldRig, settle, with_placement
from .coins import COINS, PUBLISHED_MASS_REL_SD, WEIGHED_SD_KG
from .fold import assembled_deg, coin_load
from .foldfit import ARM_SD_M, FOLD_LINKS, LENGTH_SD_M, PLACEMENT_SD_M, TILT_SD_DEG, FreeLink, Load, photo_sign
from .foldmoments import wrap_deg

STIFFNESS_RANGE_NM_PER_RAD = (5e-4, 5e-3)
REST_RANGE_DEG = 20.0
DENSITY_KG_PER_M3 = (700.0, 150.0)        # the laminate's, as the robot as built has it (value, sd)
DEFLECTION_RANGE_DEG = (10.0, 35.0)
CLEAR_OF_VERTICAL_DEG = 25.0


@dataclass(frozen=True)
class FoldReadings:
    """What the student reads off the bench: the coin and its lever arm, the free link."""

    coin: str | None             # a named coin (its published mass), or None: weighed
    coin_mass_kg: float | None   # the weighed mass (None: named)
    arm_m: float
    link_mass_kg: float | None   # weighed (None: estimated from its size)
    link_length_m: float
    density_kg_per_m3: float     # the robot file's density, for the estimate
    density_sd_kg_per_m3: float


@dataclass(frozen=True)
class SyntheticFoldTest:
    """A drawn fold test: its photos (with their truth) and the bench readings."""

    photos: FoldPhotos
    readings: FoldReadings

    def link(self) -> FreeLink:
        """The free link as the readings give it (weighed, or estimated from its size)."""
        r, rig = self.readings, self.photos.rig
        if r.link_mass_kg is not None:
            return FreeLink(r.link_mass_kg, WEIGHED_SD_KG, r.link_length_m, LENGTH_SD_M, "weighed")
        size = r.link_length_m * rig.width_m * rig.thickness_m
        return FreeLink(r.density_kg_per_m3 * size, r.density_sd_kg_per_m3 * size, r.link_length_m, LENGTH_SD_M,
                        "estimated from its size")

    def load(self) -> Load:
        """The coin as the readings give it (:func:`locust.calibrate.fold.coin_load`)."""
        r = self.readings
        return coin_load(r.arm_m, self.photos.rig.thickness_m, r.coin, r.coin_mass_kg)


def _arm(rig: FoldRig, rng: np.random.Generator) -> FoldRig:
    """The coin taped where it turns the fold by some 10-35 deg and leaves the link clear of the vertical."""
    free = settle(rig, False)
    target = math.radians(rng.uniform(*DEFLECTION_RANGE_DEG))
    cos = max(abs(math.cos(math.radians(free.free_deg))), 0.2)
    arm = rig.stiffness_nm_per_rad * target / (rig.coin_mass_kg * GRAVITY_M_PER_S2 * cos)
    lo, hi = rig.coin_radius_m, rig.free_length_m - 0.002
    rig = replace(rig, coin_arm_m=float(min(max(arm, lo), hi)))
    while rig.coin_arm_m > lo:
        loaded = settle(rig, True, free.fold_deg)
        if abs(math.cos(math.radians(loaded.free_deg))) >= math.sin(math.radians(CLEAR_OF_VERTICAL_DEG)):
            break
        rig = replace(rig, coin_arm_m=max(rig.coin_arm_m * 0.8, lo))
    return rig


def draw_rig(seed: int) -> tuple[FoldRig, FoldShot, np.random.Generator]:
    """The seed's rig, shot and the generator the readings go on with.

    Parameters
    ----------
    seed : int

    Returns
    -------
    rig : locust.sim.foldrig.FoldRig
    shot : locust.sim.foldphotos.FoldShot
    rng : numpy.random.Generator
    """
    rng = np.random.default_rng(seed)
    lo, hi = STIFFNESS_RANGE_NM_PER_RAD
    name = list(COINS)[int(rng.integers(len(COINS)))]
    c = COINS[name]
    rig = FoldRig(stiffness_nm_per_rad=float(math.exp(rng.uniform(math.log(lo), math.log(hi)))),
                  rest_deg=float(rng.uniform(-REST_RANGE_DEG, REST_RANGE_DEG)),
                  clamped_deg=float(180.0 + rng.uniform(-10.0, 10.0)),
                  density_kg_per_m3=float(max(rng.normal(*DENSITY_KG_PER_M3), 200.0)),
                  coin_mass_kg=float(c.mass_kg * (1.0 + rng.normal(0.0, PUBLISHED_MASS_REL_SD))),
                  coin_radius_m=c.diameter_m / 2, coin_thickness_m=c.thickness_m)
    rig = with_placement(_arm(rig, rng), rng, PLACEMENT_SD_M)
    shot = FoldShot(yaw_deg=float(rng.uniform(-4, 4)), pitch_deg=float(rng.uniform(-4, 4)),
                    roll_deg=float(rng.uniform(-3, 3)), distance_scale=float(rng.uniform(0.9, 1.15)),
                    noise_levels=float(rng.uniform(1.0, 4.0)), board_tilt_deg=float(rng.normal(0.0, TILT_SD_DEG)))
    return rig, shot, rng


def synthetic_fold_test(seed: int, folder: str | Path, frames: int = 1) -> SyntheticFoldTest:
    """Draw a fold test from ``seed``, photograph it into ``folder`` and read the bench.

    Parameters
    ----------
    seed : int
    folder : path-like
        Where the SYNTHETIC photos and their truth go.
    frames : int
        Photos of each state (more than one: a folder of them).

    Returns
    -------
    SyntheticFoldTest
    """
    rig, shot, rng = draw_rig(seed)
    shot = replace(shot, frames=frames)
    weighed_coin, weighed_link = bool(rng.integers(2)), bool(rng.integers(2))
    name = next(n for n, c in COINS.items() if c.thickness_m == rig.coin_thickness_m
                and c.diameter_m == 2 * rig.coin_radius_m)
    readings = FoldReadings(
        coin=None if weighed_coin else name,
        coin_mass_kg=float(rig.coin_mass_kg + rng.normal(0.0, WEIGHED_SD_KG)) if weighed_coin else None,
        arm_m=float(rig.coin_arm_m + rng.normal(0.0, ARM_SD_M)),
        link_mass_kg=float(rig.free_mass_kg + rng.normal(0.0, WEIGHED_SD_KG)) if weighed_link else None,
        link_length_m=float(rig.free_length_m + rng.normal(0.0, LENGTH_SD_M)),
        density_kg_per_m3=DENSITY_KG_PER_M3[0], density_sd_kg_per_m3=DENSITY_KG_PER_M3[1])
    photos = render_fold_test(rig, folder, shot, seed=seed, stem=f"synthetic_fold_{seed}")
    return SyntheticFoldTest(photos, readings)


def _clear_of_vertical(rig: FoldRig) -> bool:
    """The loaded link balances clear of the vertical (the fit's range check, with a margin)."""
    try:
        loaded = settle(rig, True, settle(rig, False).fold_deg)
    except SimError:
        return False
    return abs(math.cos(math.radians(loaded.free_deg))) >= math.sin(math.radians(CLEAR_OF_VERTICAL_DEG))


def robot_fold_test(robot: Robot, fold: str, side: str, seed: int, folder: str | Path) -> SyntheticFoldTest:
    """A SYNTHETIC fold test of one of ``robot``'s own folds: the hinge the robot's (its
    stiffness, and its rest angle as assembled plus its rest offset, :func:`locust.params.side_values`),
    the links the robot's (its laminate's density as its file says), the rest as :func:`synthetic_fold_test`
    draws it; the clamp turned so that the free link stands out within 20 deg of level, as a
    student sets it (the coin's moment is largest there).

    Parameters
    ----------
    robot : Robot
        The robot whose fold is tested (its values the truth).
    fold : {"servo", "knee", "ankle", "loop"}
    side : {"left", "right"}
    seed : int
    folder : path-like
        Where the SYNTHETIC photos and their truth go.

    Returns
    -------
    SyntheticFoldTest
    """
    rng = np.random.default_rng(seed)
    values = side_values(robot, "L" if side == "left" else "R").folds[fold]
    rest = photo_sign(fold, side) * (assembled_deg(robot, fold, side) + values.rest_offset_deg)
    clamped, free = FOLD_LINKS[fold]
    level = float(rng.choice([0.0, 180.0]) + rng.uniform(-20.0, 20.0))
    # a coin from the student's pocket; one that folds the link past the vertical even taped
    # at the fold is swapped for the next lighter one (as the refusal's hint says)
    order = sorted(COINS, key=lambda n: -COINS[n].mass_kg)
    start = int(rng.integers(len(order)))
    for name in order[start:] + order[:start][::-1]:
        c = COINS[name]
        rig = FoldRig(stiffness_nm_per_rad=values.stiffness_nm_per_rad, rest_deg=rest,
                      clamped_deg=float(wrap_deg(level - 180.0 - rest)),
                      clamped_length_m=robot.get(f"geometry.{clamped}_m"),
                      free_length_m=robot.get(f"geometry.{free}_m"),
                      width_m=robot.geometry.link_width_m, thickness_m=robot.geometry.link_thickness_m,
                      density_kg_per_m3=robot.geometry.link_density_kg_per_m3,
                      coin_mass_kg=float(c.mass_kg * (1.0 + rng.normal(0.0, PUBLISHED_MASS_REL_SD))),
                      coin_radius_m=c.diameter_m / 2, coin_thickness_m=c.thickness_m)
        rig = _arm(rig, rng)
        if _clear_of_vertical(rig):
            break
    rig = with_placement(rig, rng, PLACEMENT_SD_M)
    shot = FoldShot(yaw_deg=float(rng.uniform(-4, 4)), pitch_deg=float(rng.uniform(-4, 4)),
                    roll_deg=float(rng.uniform(-3, 3)), distance_scale=float(rng.uniform(0.9, 1.15)),
                    noise_levels=float(rng.uniform(1.0, 4.0)), board_tilt_deg=float(rng.normal(0.0, TILT_SD_DEG)))
    readings = FoldReadings(coin=name, coin_mass_kg=None, arm_m=float(rig.coin_arm_m + rng.normal(0.0, ARM_SD_M)),
                            link_mass_kg=None, link_length_m=float(rig.free_length_m + rng.normal(0.0, LENGTH_SD_M)),
                            density_kg_per_m3=robot.geometry.link_density_kg_per_m3,
                            density_sd_kg_per_m3=robot.source_of("geometry.link_density_kg_per_m3").uncertainty or 0.0)
    photos = render_fold_test(rig, folder, shot, seed=seed, stem=f"synthetic_{fold}_fold_{seed}")
    return SyntheticFoldTest(photos, readings)


# the bundled example (calibration/recordings/synthetic_fold_*): the small robot's knee fold, its
# crank clamped pointing up and back so that the coupler stands out level, a 1 euro cent on the
# coupler 12 mm from the fold line; a film hinge stiffer than the as-built one, which a coin
# would fold flat (docs/calibrate.md, Fold)
BUNDLED_RIG = FoldRig(stiffness_nm_per_rad=1.0e-3, rest_deg=70.0, clamped_deg=110.0, clamped_length_m=0.04,
                      free_length_m=0.02, density_kg_per_m3=700.0, coin_mass_kg=COINS["eur-1c"].mass_kg,
                      coin_radius_m=COINS["eur-1c"].diameter_m / 2, coin_thickness_m=COINS["eur-1c"].thickness_m,
                      coin_arm_m=0.012, axis_offset_m=(0.0002, -0.0003), tip_across_m=0.0003, base_across_m=-0.0002,
                      tip_inset_m=0.004)
BUNDLED_SHOT = FoldShot(yaw_deg=2.0, pitch_deg=-1.5, roll_deg=1.0, noise_levels=2.0, jpeg_quality=90)


def bundled_fold_test(folder: str | Path) -> FoldPhotos:
    """Write the bundled example's photos (``synthetic_fold_unloaded.jpg``, ``synthetic_fold_loaded.jpg``)
    and their truth (``synthetic_fold.truth.json``) into ``folder`` (deterministic).

    Parameters
    ----------
    folder : path-like

    Returns
    -------
    locust.sim.foldphotos.FoldPhotos
    """
    return render_fold_test(BUNDLED_RIG, folder, BUNDLED_SHOT, seed=6007, stem="synthetic_fold")


__all__ = ["BUNDLED_RIG", "BUNDLED_SHOT", "FoldReadings", "SyntheticFoldTest", "bundled_fold_test", "draw_rig",
           "robot_fold_test",
           "synthetic_fold_test"]
