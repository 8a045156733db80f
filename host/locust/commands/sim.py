"""``locust sim``: simulate the hop schedule on the MuJoCo model, audited."""

from __future__ import annotations

import sys
from contextlib import nullcontext
from pathlib import Path

import click

from ..fileio import json_text
from ..io.robot_toml import resolve_robot
from ..params import LEG_SETS
from ..tables import (
    ensemble_convergence_lines,
    explain_lines,
    nose_load_line,
    sensitivity_lines,
    sim_lines,
    spread_lines,
)
from .options import JobBar, robot_options


@click.command()
@robot_options
@click.option("--leg-set", "leg_set_name", type=click.Choice(list(LEG_SETS)), default=None,
              help="Put this leg set on the robot in place of the one it carries (its leg_set; "
                   "`locust params` shows it).")
@click.option("--cycles", type=click.IntRange(1, 1000), default=None,
              help="Hop cycles to run (default: schedule.cycles of the robot).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON (exit 0 even when invalid).")
@click.option("--video", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Render an MP4 (offscreen) and write the true marker pixels beside it (<video>.truth.csv).")
@click.option("--camera", type=click.Choice(["track", "fixed"]), default="track", show_default=True,
              help="For --video: follow the robot, or hold still (for measuring with `locust track`).")
@click.option("--still", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Render a side photo (PNG) of the robot settled at the 0 deg command, with the board and the "
                   "stickers `locust measure stance` reads, and their true pixels beside it (<still>.truth.csv).")
@click.option("--still-push", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="The same of the robot held up at the push command (the same camera).")
@click.option("--board", default=None, metavar="SPEC",
              help="For --still: the board beside the robot (default aruco:4X4_50:5x4:40:10).")
@click.option("--push-clip", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Render one push on the floor (MP4, fixed camera, the stickers `locust measure stroke` reads), "
                   "with the crank's true angle beside it (<clip>.crank.csv).")
@click.option("--push-clip-held", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="The same push with the robot held up by its plate.")
@click.option("--push-fps", type=click.IntRange(1, 1000), default=240, show_default=True,
              help="For --push-clip: frames per second.")
@click.option("--side", type=click.Choice(["left", "right"]), default="left", show_default=True,
              help="For --still and --push-clip: the side filmed (the right leg is at -y, the camera there).")
@click.option("--check-convergence", is_flag=True,
              help="Rerun with every step halved and report the relative change; with --samples, also the "
                   "draws again: each outcome's share against its 95 % binomial interval, the distance's and "
                   "highest nose's 10/50/90th percentiles against their bootstrap intervals, and the draws that "
                   "flip outcome (on the threshold).")
@click.option("--samples", type=click.IntRange(2, 4096), default=None, metavar="N",
              help="Also simulate N draws of the values that carry an uncertainty in the robot file "
                   "(one batched rollout) and report each outcome's share of them and its own distance "
                   "and highest nose, mean ± sd (--json: outcomes). When the draws split between "
                   "outcomes, also which values decide it (--sensitivity).")
@click.option("--sensitivity/--no-sensitivity", default=None,
              help="Move each uncertain value alone to -/+2 sd and report the outcome at each end: the "
                   "values that decide the regime (default: with --samples, when its draws split).")
@click.option("--explain", is_flag=True,
              help="Say why: for a run that goes over, when and on what (the support points, how far the centre "
                   "of mass is behind them and for how long, the servo torque); else how close it came. For "
                   "every uncertain and design value, how far the outcome's threshold is (in its unit and its "
                   "sd), and each uncertain value's -/+2 sd effect on nose rise and distance (some 300 runs: "
                   "--cycles 2 is quicker).")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of --samples.")
@click.option("--verbose", "-v", is_flag=True,
              help="Also the linkage's kinematics: its Grashof class and worst transmission angle.")
def sim(preset, config, sets, leg_set_name, cycles, as_json, video, camera, still, still_push, board, push_clip,
        push_clip_held, push_fps, side, check_convergence, samples, explain, seed, sensitivity, verbose):
    """Settle the robot on the floor, then run the bang-bang hop schedule.

    Every run is audited (non-finite state, loop closure, energy, MuJoCo warnings). A run
    that fails its audit is reported invalid with the reasons, and exits 1 unless --json.
    A valid run's outcome is one of: goes over (ends on its back), rears and returns (nose
    above 30 mm and back down, every hop), stays low. The standing robot's weight on its nose
    (a kitchen scale under the nose: `locust measure nose-load`) is printed with it.

    \b
    Examples:
      locust sim --preset seed --json
      locust sim --preset seed-notebook --json          # the notebook's Part 2 figures
      locust sim --preset large --set servo.stall_torque_nm=0.18 --video large.mp4
      locust sim --config calibration/robot.toml --samples 16   # with its spread
      locust sim --preset medium --samples 32 --json     # outcome shares
      locust sim --preset small --explain --cycles 2     # why it goes over, what would change it
      locust sim --config calibration/robot.toml --leg-set large   # another leg set on it
      locust sim --preset small --still rest.png --still-push push.png   # for locust measure stance
      locust sim --preset small --push-clip floor.mp4 --push-clip-held held.mp4   # for locust measure stroke
    """
    from ..sim.job import SimOptions, run_simulation

    robot = resolve_robot(preset, config, sets)
    options = SimOptions(cycles=cycles, leg_set=leg_set_name, samples=samples or 0, seed=seed, sensitivity=sensitivity,
                         keep_states=False, check_convergence=check_convergence, video=video, camera=camera,
                         still=still, still_push=still_push, board=board, push_clip=push_clip,
                         push_clip_held=push_clip_held, push_fps=push_fps, side={"left": "L", "right": "R"}[side],
                         invalid_linkage_result=as_json, explain=explain)
    with _bar(robot, options) as bar:
        result = run_simulation(robot, options, progress=bar.update if bar else None)
    if as_json:
        click.echo(json_text(result.to_json()), nl=False)
        return
    for line in sim_lines(result, verbose=verbose):
        click.echo(line)
    if result.valid:
        click.echo(nose_load_line(result.nose_load_kg, result.total_mass_kg))
    spread, sens = getattr(result, "spread", None), getattr(result, "sensitivity", None)
    for line in (spread_lines(spread) if spread is not None else []) + (sensitivity_lines(sens) if sens else []):
        click.echo(line)
    if result.ensemble_convergence is not None:
        for line in ensemble_convergence_lines(result.ensemble_convergence):
            click.echo(line)
    for line in explain_lines(result.explanation) if result.explanation is not None else []:
        click.echo(line)
    if not result.valid:
        sys.exit(1)


def _bar(robot, options):
    """The progress bar of every run of the draws, the sensitivity and the explanation (none
    without one of them)."""
    if not (options.samples or options.sensitivity or options.explain):
        return nullcontext()
    from ..sim.job import planned_runs

    return JobBar(*planned_runs(robot, options))
