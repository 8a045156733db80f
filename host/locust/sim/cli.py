"""``locust sim``: simulate the hop schedule on the MuJoCo model, audited."""

from __future__ import annotations

import sys
from contextlib import nullcontext
from pathlib import Path

import click

from ..errors import GeometryError, SimError
from ..fileio import json_text
from ..params import resolve_robot
from ..params_cli import robot_options
from ..progress import progress
from ..tables import sim_lines, spread_line


@click.command()
@robot_options
@click.option("--cycles", type=click.IntRange(1, 1000), default=None,
              help="Hop cycles to run (default: schedule.cycles of the robot).")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON (exit 0 even when invalid).")
@click.option("--video", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Render an MP4 (offscreen) and write the true marker pixels beside it (<video>.truth.csv).")
@click.option("--camera", type=click.Choice(["track", "fixed"]), default="track", show_default=True,
              help="For --video: follow the robot, or hold still (for measuring with `locust track`).")
@click.option("--check-convergence", is_flag=True,
              help="Rerun at half the time step and report the relative change.")
@click.option("--samples", type=click.IntRange(2, 4096), default=None, metavar="N",
              help="Also simulate N draws of the values that carry an uncertainty in the robot file "
                   "(one batched rollout) and report the sd of distance and highest nose "
                   "(--json: distance_m_sd, max_nose_height_m_sd).")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of --samples.")
def sim(preset, config, sets, cycles, as_json, video, camera, check_convergence, samples, seed):
    """Settle the robot on the floor, then run the bang-bang hop schedule.

    Every run is audited (non-finite state, loop closure, energy, MuJoCo warnings). A run
    that fails its audit is reported invalid with the reasons, and exits 1 unless --json.

    \b
    Examples:
      locust sim --preset seed --json
      locust sim --preset seed-notebook --json          # the notebook's Part 2 figures
      locust sim --preset large --set servo.stall_torque_nm=0.18 --video large.mp4
      locust sim --config calibration/robot.toml --samples 16   # with its spread
    """
    from ..api.simulation import simulate
    from .run import check_convergence as converge
    from .run import invalid_result

    robot = resolve_robot(preset, config, sets)
    if video is not None:
        from .clip import check_video_path

        check_video_path(video)  # fail before simulating, not after
    try:
        with progress(length=samples, label=f"{samples} draws") if samples else nullcontext() as bar:
            result = simulate(robot, cycles=cycles, samples=samples or 0, seed=seed,
                              keep_states=video is not None,  # the video reuses the rollout
                              progress=bar.update if bar else None)
    except GeometryError as exc:
        if not as_json:
            raise
        result = invalid_result(robot, exc.message + (f" ({exc.hint})" if exc.hint else ""), cycles)
    if check_convergence and result.valid:
        result.convergence = converge(robot, result, cycles=cycles)
    if video is not None:
        if not result.valid:
            raise SimError("not rendering an invalid simulation", "fix the reasons listed above first")
        info = result.video(video, camera=camera)
        result.notes.append(f"video: {info.video_path} ({info.frames} frames); truth: {info.truth_path}")

    spread = getattr(result, "spread", None)
    if as_json:
        out = result.to_json()
        if spread is not None:
            out.update(distance_m_sd=spread.distance_m_sd, max_nose_height_m_sd=spread.max_nose_height_m_sd,
                       samples=spread.to_json())
        click.echo(json_text(out), nl=False)
        return
    for line in sim_lines(result):
        click.echo(line)
    if spread is not None:
        click.echo(spread_line(spread))
    if not result.valid:
        sys.exit(1)

