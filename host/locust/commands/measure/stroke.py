"""``locust measure stroke``: the stroke the servo delivers, from clips of a push (docs/hardware.md)."""

from __future__ import annotations

import math
from pathlib import Path

import click

from ...fileio import json_text
from ..options import robot_options

ROWS = (("rest", "rest_deg", "deg", 2), ("extreme", "extreme_deg", "deg", 2), ("stroke", "stroke_deg", "deg", 2),
        ("peak speed", "peak_speed_deg_per_s", "deg/s", 0), ("mean speed", "mean_speed_deg_per_s", "deg/s", 0))


@click.command()
@click.argument("clip", type=click.Path(exists=True, path_type=Path))
@click.argument("clip2", type=click.Path(exists=True, path_type=Path), required=False)
@robot_options
@click.option("--held-only", is_flag=True, help="CLIP shows the push held up (no floor clip).")
@click.option("--side", type=click.Choice(["left", "right"]), default=None,
              help="The side the clips must show (default: the side they show; the right leg is at -y).")
@click.option("--fps", type=click.FloatRange(1.0, 10000.0), default=None,
              help="The clips' true frame rate (a slow-motion clip's file often says 30).")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the crank's angle over time, clip and model, one row per frame.")
@click.option("--plot", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Draw the crank's swing against the model's (PNG, SVG or PDF).")
@click.option("--force", is_flag=True, help="Replace an existing --csv or --plot.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option("--draws", type=click.IntRange(20, 5000), default=200, show_default=True,
              help="Bootstrap draws for the intervals.")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of the bootstrap.")
def stroke(clip, clip2, preset, config, sets, held_only, side, fps, csv_path, plot, force, as_json, draws, seed):
    """The crank's swing in a push, from a side clip on the floor (CLIP) and one held up (CLIP2).

    Each clip films the robot square from its side, from a second before the push to half a
    second after it (`locust hop`, or `locust pose -30 -30` with the robot held up by its
    plate), with the stickers of `locust measure stance` on that side; 120 frames/s or more
    for the speeds. Printed: the crank's rest and extreme angle from its ground link, the
    stroke between them and the swing's peak and mean speed, each with its 95 % interval,
    beside the model's robot making the same push (--preset, --config, --set).

    \b
    Examples:
      locust measure stroke floor.mp4 held.mp4 --preset medium --plot stroke.png
      locust measure stroke held.mp4 --held-only --fps 240 --csv angle.csv --json
    """
    from ...io.robot_toml import resolve_robot
    from ...measure.crankclip import SIDES
    from ...measure.strokejob import StrokeOptions, stroke_job
    from ...track.pipeline import progress_bars

    robot = resolve_robot(preset, config, sets)
    options = StrokeOptions(held_only=held_only, side=None if side is None else SIDES[side], fps=fps, csv=csv_path,
                            plot=plot, force=force, draws=draws, seed=seed)
    job = stroke_job(robot, [clip] + ([clip2] if clip2 is not None else []), options, bars=progress_bars)
    if as_json:
        out = job.result.to_json()
        out["written"] = [str(p) for p in job.written]
        click.echo(json_text(out), nl=False)
        return
    for line in lines(job.result):
        click.echo(line)
    for path in job.written:
        click.echo(f"wrote {path}")


def _cell(value: float | None, digits: int, width: int = 9, sign: str = "") -> str:
    if value is None or not math.isfinite(value):
        return f"{'-':>{width}s}"
    return f"{value + 0.0:{sign}{width}.{digits}f}"


def lines(result) -> list[str]:
    """What ``locust measure stroke`` prints: each clip's reading, its figures beside the model's.

    Parameters
    ----------
    result : locust.measure.stroke.StrokeResult

    Returns
    -------
    list of str
    """
    from ...measure.stroke import KIND_WORDS

    out = [f"robot {result.robot_name}: push {result.push_deg:g} deg"]
    for r in result.readings:
        s = r.series
        out.append(f"{s.path.name}: the robot's {'left' if s.side == 'L' else 'right'} side, {s.frames} frames at "
                   f"{s.fps:g} frames/s; stickers to {s.sticker_sd_px:.2f} px, the crank to "
                   f"{float(_median(s.sd_deg)):.2f} deg a frame; {r.swing.rest_frames} frames at rest")
        if r.swing.direction != r.model.direction:
            out.append("  the crank turns the other way than the model's push (check the servo's direction)")
    for r in result.readings:
        out.append(f"{'push ' + KIND_WORDS[r.kind]:26s} {'measured':>9s}       {'95 % interval':^22s}   {'model':>9s} "
                   f"{'difference':>10s}")
        diff = r.differences()
        model = r.model.figures()
        for name, key, unit, digits in ROWS:
            est = r.estimates[key]
            if est is None:
                out.append(f"  {name:24s} {'-':>9s} {unit:5s}   (too few frames in the swing: film at 120 frames/s "
                           "or more)")
                continue
            lo, hi = est.ci95
            out.append(f"  {name:24s} {_cell(est.value, digits)} {unit:5s} [{_cell(lo, digits)}, {_cell(hi, digits)}]"
                       f"   {_cell(model[key], digits)} {_cell(diff[key], digits, 10, '+')}")
    out.extend(_load_line(result))
    out.append(f"intervals: parametric bootstrap of the stickers' scatter, {result.draws} draws, with the extreme's "
               "sampling between frames; the model's run once on the robot file's values")
    return out


def _median(values) -> float:
    import numpy as np

    return float(np.nanmedian(values))


def _load_line(result) -> list[str]:
    """The floor's stroke less the held one's: what the load takes, measured and modelled."""
    floor, held = result.reading("floor"), result.reading("held")
    if floor is None or held is None:
        return []
    a, b = floor.estimates["stroke_deg"], held.estimates["stroke_deg"]
    d, sd = a.value - b.value, math.hypot(a.std, b.std)
    model = floor.model.stroke_deg - held.model.stroke_deg
    return [f"the floor's stroke less the held one's: {d:+.2f} ± {sd:.2f} deg (model {model:+.2f} deg)"]
