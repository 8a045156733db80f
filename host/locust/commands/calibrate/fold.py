"""``locust calibrate fold``: a fold's stiffness and rest offset from two photos of a static test."""

from __future__ import annotations

from pathlib import Path

import click

from ...arucoboard import DEFAULT_BOARD
from ...calibrate import jobs
from ...calibrate.coins import COINS
from ...params import FOLDS
from ..options import POSITIVE
from .options import output_options, start_of_write
from .output import finish


def _robot(write_path: Path | None):
    """The robot whose fold it is: the --write file where it exists, the one a new --write file
    starts from, else the one every command runs on (named on the first line)."""
    from ...io.robot_toml import default_robot, load_robot, resolve_robot

    if write_path is not None and Path(write_path).exists():
        return load_robot(write_path)
    if write_path is not None:
        return start_of_write()
    click.echo(default_robot().line, err=True)
    return resolve_robot()


@click.command()
@click.argument("data", nargs=2, metavar="UNLOADED LOADED", type=click.Path(path_type=Path))
@click.option("--fold", "fold_name", type=click.Choice(FOLDS), required=True,
              help="The fold tested: servo and loop with the ground link clamped, knee with the crank, ankle with "
                   "the coupler.")
@click.option("--side", type=click.Choice(["both", "left", "right"]), default="both", show_default=True,
              help="Whose fold: both legs' (the folds section), or one leg's (a right fold photographed from the "
                   "robot's right is read mirrored).")
@click.option("--coin", type=click.Choice(list(COINS)), default=None,
              help="The coin by name: its published mass (a pocket coin's, ±2.5 %).")
@click.option("--coin-mass-kg", type=POSITIVE, default=None, help="Instead: the coin weighed [kg] (±0.01 g).")
@click.option("--coin-arm-m", type=POSITIVE, required=True,
              help="From the fold line to the coin's centre along the free link [m] (a ruler reading, ±0.5 mm).")
@click.option("--link-mass-kg", type=POSITIVE, default=None,
              help="The free link weighed [kg] [default: its size times the laminate's density, the robot's].")
@click.option("--link-length-m", type=POSITIVE, default=None,
              help="The free link from the fold line to its end [m] [default: the robot's link].")
@click.option("--board", default=DEFAULT_BOARD, show_default=True,
              help="The ArUco board standing in the stickers' plane (aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM).")
@output_options
def fold(data, fold_name, side, coin, coin_mass_kg, coin_arm_m, link_mass_kg, link_length_m, board, write_path,
         as_json, plot_path, no_plot, force):
    """Fit a fold's stiffness and rest angle from a static test: one photo unloaded, one with a coin.

    UNLOADED and LOADED are each a photo, a folder of photos or a clip of the fold, one link
    clamped and the other free, without and with the coin taped on the free link; in each the
    three fold stickers (axis on the fold line, tip on the free link, base on the clamped link)
    and the board standing upright in their plane. Prints the stiffness and the rest offset
    (the rest angle less the fold's angle in the assembled robot) with 95% intervals; with
    --write sets folds.<fold>_stiffness_nm_per_rad and folds.<fold>_rest_offset_deg (left. or
    right. with one --side), source fit:<photos>.

    \b
      locust calibrate fold unloaded.jpg loaded.jpg --fold knee --coin eur-1c --coin-arm-m 0.015
    """
    unloaded, loaded = data
    fit = jobs.fold(unloaded, loaded, fold_name, coin_arm_m=coin_arm_m, robot=_robot(write_path), coin=coin,
                    coin_mass_kg=coin_mass_kg, side=side, link_mass_kg=link_mass_kg, link_length_m=link_length_m,
                    board=board)
    finish(fit, Path(unloaded), write_path, as_json, plot_path, no_plot, force)
