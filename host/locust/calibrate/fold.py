"""A fold's stiffness and rest angle from a static test: ``locust calibrate fold``'s job.

The test (docs/calibrate.md, *Fold*): one link of the fold clamped (:data:`.foldfit.FOLD_LINKS`:
the ground link for the servo and the loop folds, the link before the fold for the knee and
the ankle), the other free; a side photo of the fold settled under the free link's own weight,
and one with a coin taped on the free link at a lever arm read off a ruler (or a folder of
photos, or a clip, of each). Three stickers (:data:`locust.markers.FOLD_STICKER_COLOURS`: on
the fold line, on the free link's tip, on the clamped link) and the ArUco board standing
upright in their plane beside it.

:func:`fold_test` reads the photos (:mod:`.foldread`), makes the coin (:mod:`.coins`: named,
or weighed) and the free link (weighed, or its size from the robot times the laminate's
density, with their uncertainties) and the fold's angle in the robot as assembled
(:func:`locust.sim.fourbar.fold_angles_deg`), and fits (:func:`.foldfit.fit_fold`): the
hinge's stiffness and the rest offset the robot file holds, ``folds.<fold>_*`` for both legs
or ``left.``/``right.<fold>_*`` for one.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..arucoboard import DEFAULT_BOARD, BoardSpec, parse_board
from ..errors import CalibrationError, TrackError
from ..params import Robot
from .coins import WEIGHED_SD_KG, WEIGHED_THICKNESS_M, WEIGHED_THICKNESS_SD_M, coin
from .foldfit import DRAWS, FOLD_LINKS, LENGTH_SD_M, FoldFit, FreeLink, Load, fit_fold
from .foldread import read_state

ESTIMATED_MASS_REL_SD = 0.2      # a link's mass from its size, where the robot file gives no uncertainty
SIDE_OF = {"left": ("L",), "right": ("R",), "both": ("L", "R")}
COIN_ABOVE_SD_M = 0.0002         # the coin's centre above the link's: half of each one's thickness


def free_link(robot: Robot, fold: str, mass_kg: float | None = None, length_m: float | None = None) -> FreeLink:
    """The fold's free link: weighed (``mass_kg``, to a 0.01 g scale), else its size times the
    laminate's density, the robot's, each with the uncertainty its robot file records.

    Parameters
    ----------
    robot : Robot
        The robot whose fold it is.
    fold : str
        The fold (:data:`locust.params.FOLDS`).
    mass_kg : float, optional
        The free link weighed [kg].
    length_m : float, optional
        The free link from the fold line to its end [m] (default: the robot's link).

    Returns
    -------
    FreeLink
    """
    name = FOLD_LINKS[fold][1]
    length = robot.get(f"geometry.{name}_m") if length_m is None else length_m
    if mass_kg is not None:
        return FreeLink(mass_kg, WEIGHED_SD_KG, length, LENGTH_SD_M, f"weighed, {mass_kg * 1000:.2f} g")
    keys = ("geometry.link_density_kg_per_m3", "geometry.link_width_m", "geometry.link_thickness_m")
    values = [robot.get(k) for k in keys]
    rel = [(robot.source_of(k).uncertainty or 0.0) / v for k, v in zip(keys, values)]
    rel_sd = math.sqrt(sum(r * r for r in rel)) or ESTIMATED_MASS_REL_SD
    mass = math.prod(values) * length
    return FreeLink(mass, rel_sd * mass, length, LENGTH_SD_M,
                    f"{mass * 1000:.2f} g ± {rel_sd * 100:.0f} %, estimated: its {length * 1000:g} mm of "
                    f"{robot.geometry.link_width_m * 1000:g} mm strip at {values[0]:g} kg/m^3 (weigh it: "
                    "--link-mass-kg)")


def coin_load(arm_m: float, link_thickness_m: float, name: str | None = None,
              mass_kg: float | None = None) -> Load:
    """The coin as taped on: a named coin's published mass (:mod:`.coins`) or a weighed one's,
    its lever arm, its centre above the free link's centre line.

    Parameters
    ----------
    arm_m : float
        From the fold line to the coin's centre, along the free link [m] (a ruler reading).
    link_thickness_m : float
        The laminate's thickness [m].
    name : str, optional
        A coin of :data:`locust.calibrate.coins.COINS`.
    mass_kg : float, optional
        The coin weighed [kg].

    Returns
    -------
    Load

    Raises
    ------
    locust.errors.CalibrationError
        Neither or both of ``name`` and ``mass_kg``, an unknown coin, or a lever arm that is not positive.
    """
    if (name is None) == (mass_kg is None):
        raise CalibrationError("give the coin: --coin NAME (its published mass) or --coin-mass-kg M (weighed)",
                               "e.g. --coin eur-1c, or --coin-mass-kg 0.00230 for a coin weighed on a 0.01 g scale")
    if not arm_m > 0:
        raise CalibrationError(f"--coin-arm-m {arm_m:g}: the coin's lever arm must be positive",
                               "measure from the fold line to the coin's centre along the free link, in metres")
    if name is not None:
        c = coin(name)
        return Load(c.mass_kg, c.mass_sd_kg, arm_m, (link_thickness_m + c.thickness_m) / 2, COIN_ABOVE_SD_M,
                    f"{c.name}, {c.mass_kg * 1000:.3g} g ({c.source.split(':', 1)[1]})")
    return Load(mass_kg, WEIGHED_SD_KG, arm_m, (link_thickness_m + WEIGHED_THICKNESS_M) / 2,
                math.hypot(COIN_ABOVE_SD_M, WEIGHED_THICKNESS_SD_M / 2), f"weighed, {mass_kg * 1000:.2f} g")


def assembled_deg(robot: Robot, fold: str, side: str) -> float:
    """The fold's angle in the robot as assembled at rest; for ``both``, the two legs' own (they must agree).

    Parameters
    ----------
    robot : Robot
    fold : str
    side : {"both", "left", "right"}

    Returns
    -------
    float

    Raises
    ------
    locust.errors.CalibrationError
        The two legs assemble the fold at different angles (``both``).
    """
    from ..sim.fourbar import fold_angles_deg

    angles = {s: fold_angles_deg(robot, s)[fold] for s in SIDE_OF[side]}
    if max(angles.values()) - min(angles.values()) > 1e-6:
        raise CalibrationError(
            f"the robot's legs assemble the {fold} fold at different angles (left {angles['L']:.2f} deg, right "
            f"{angles['R']:.2f} deg: a crank a tooth off), so one rest offset does not hold for both",
            "name the leg the fold is of: --side left or --side right")
    return next(iter(angles.values()))


def fold_test(unloaded: str | Path, loaded: str | Path, fold: str, robot: Robot, *, coin_arm_m: float,
              coin_name: str | None = None, coin_mass_kg: float | None = None, side: str = "both",
              link_mass_kg: float | None = None, link_length_m: float | None = None,
              board: str | BoardSpec = DEFAULT_BOARD, draws: int = DRAWS, seed: int = 0) -> FoldFit:
    """The fold test: its photos read, its bench readings taken, fitted.

    Parameters
    ----------
    unloaded, loaded : path-like
        The fold without and with the coin: a photo, a folder of photos, or a clip, each.
    fold : {"servo", "knee", "ankle", "loop"}
    robot : Robot
        The robot whose fold it is (its link's size and density, its assembled angle).
    coin_arm_m : float
        The coin's lever arm [m].
    coin_name, coin_mass_kg
        The coin: named (:data:`locust.calibrate.coins.COINS`) or weighed [kg].
    side : {"both", "left", "right"}
        Which leg's fold (``right``: photographed from the robot's right, read mirrored).
    link_mass_kg, link_length_m : float, optional
        The free link weighed [kg] and measured from the fold [m].
    board : str or BoardSpec
        The printed board in the photos.
    draws : int
        Monte Carlo draws for the intervals.
    seed : int

    Returns
    -------
    FoldFit

    Raises
    ------
    locust.errors.CalibrationError
        A bad reading, a photo without its board or a sticker, or a test that cannot give the fold's values.
    """
    if fold not in FOLD_LINKS:
        raise CalibrationError(f"fold {fold!r}: not one of {', '.join(FOLD_LINKS)}",
                               "choose --fold " + "|".join(FOLD_LINKS))
    if side not in SIDE_OF:
        raise CalibrationError(f"side {side!r}: not one of {', '.join(SIDE_OF)}", "choose --side left|right|both")
    load = coin_load(coin_arm_m, robot.geometry.link_thickness_m, coin_name, coin_mass_kg)
    link = free_link(robot, fold, link_mass_kg, link_length_m)
    if coin_arm_m > link.length_m:
        raise CalibrationError(f"--coin-arm-m {coin_arm_m:g}: the coin's centre beyond the free link's end "
                               f"({link.length_m * 1000:g} mm from the fold)",
                               "tape the coin on the free link and measure from the fold line to its centre; give "
                               "--link-length-m if the free link is not the robot's")
    angle = assembled_deg(robot, fold, side)
    try:
        spec = parse_board(board) if isinstance(board, str) else board
    except TrackError as exc:
        raise CalibrationError(exc.message, exc.hint) from None
    source = f"{Path(unloaded).name}+{Path(loaded).name}"
    return fit_fold(read_state(unloaded, spec, seed), read_state(loaded, spec, seed + 1), link, load, fold=fold,
                    side=side, assembled_deg=angle, draws=draws, seed=seed, source=source)


__all__ = ["assembled_deg", "coin_load", "fold_test", "free_link"]
