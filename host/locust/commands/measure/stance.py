"""``locust measure stance``: the stance from side photos (docs/measure.md)."""

from __future__ import annotations

from pathlib import Path

import click

from ...errors import MeasureError
from ...fileio import json_text
from ...io.trk import PIXEL_CONVENTIONS
from ...tables import for_person, label
from ..options import robot_options, say_written_from


@click.command()
@click.argument("rest", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.argument("push", type=click.Path(exists=True, dir_okay=False, path_type=Path), required=False)
@robot_options
@click.option("--board", default=None, metavar="SPEC",
              help="The board standing in the leg's plane, as `locust track board` prints it "
                   "(default aruco:4X4_50:5x4:40:10).")
@click.option("--point", "points", multiple=True, metavar="NAME=X,Y",
              help="A sticker's pixel in REST, instead of finding it by colour (nose, tail, axis, crank, knee, "
                   "foot). Repeatable.")
@click.option("--push-point", "push_points", multiple=True, metavar="NAME=X,Y",
              help="The same for PUSH. Repeatable.")
@click.option("--pixels", type=click.Choice(list(PIXEL_CONVENTIONS)), default="tracker", show_default=True,
              help="Convention of the given pixels: Tracker's (a pixel's centre at i + 0.5) or OpenCV's (at i).")
@click.option("--write", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the whole robot with the measured values in place (refuses to overwrite).")
@click.option("--force", is_flag=True, help="With --write: overwrite an existing file.")
@click.option("--json", "as_json", is_flag=True, help="Print the result as JSON.")
@click.option("--draws", type=click.IntRange(20, 5000), default=200, show_default=True,
              help="Bootstrap draws for the intervals.")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed of the bootstrap.")
@click.option("--side", type=click.Choice(["left", "right"]), default=None,
              help="The side photographed (the right leg is at -y: a photo from the robot's right); its crank's "
                   "spline tooth is found, and --write writes it (left.crank_tooth or right.crank_tooth) alone.")
def stance(rest, push, preset, config, sets, board, points, push_points, pixels, write, force, as_json, draws,
           seed, side):
    """Fit the robot's stance to a side photo at rest (and one held at the push command).

    REST shows the robot standing at the 0 deg command, PUSH (optional) the robot held up at
    the push command (`locust pose -30 -30 --port P`), both from the robot's left with the
    board standing in the plane of the left leg and the six stickers in place (docs/measure.md).
    The link lengths and the plate are the robot's (--preset, --config, --set). With --side,
    the photos show that side (the board in that leg's plane), and the crank's tooth on its
    spline is the nearest whole tooth off geometry.crank_start_deg.

    \b
    Examples:
      locust measure stance rest.jpg push.jpg --preset small --write measured.toml
      locust measure stance rest.jpg --preset large --point knee=412.5,633
      locust measure stance rest_r.jpg --side right --config measured.toml --write measured_r.toml
    """
    from ...arucoboard import DEFAULT_BOARD, parse_board
    from ...fileio import check_distinct
    from ...io.robot_toml import resolve_robot, save_robot
    from ...measure.stance import fit_stance, given_points, model_servo_give, read_photo, with_stance
    from ...measure.tooth import with_tooth

    robot = resolve_robot(preset, config, sets)
    say_written_from(preset, config, write)
    spec = parse_board(board or DEFAULT_BOARD)
    if write is not None:
        if write.exists() and not force:
            raise MeasureError(f"{write} exists", "choose another path, or add --force to overwrite it")
        check_distinct({"--write": write}, inputs=[p for p in (rest, push) if p is not None])
    if push_points and push is None:
        raise MeasureError("--push-point without a PUSH photo", "give the PUSH photo after REST")
    photos = [read_photo(rest, spec, given_points(points, pixels, "--point"))]
    if push is not None:
        photos.append(read_photo(push, spec, given_points(push_points, pixels, "--push-point")))
    code = None if side is None else {"left": "L", "right": "R"}[side]
    result = fit_stance(robot, photos, model_servo_give(robot, code or "L"), draws=draws, seed=seed, side=code)

    if write is not None:
        save_robot(with_stance(robot, result, rest) if code is None else with_tooth(robot, result.tooth, rest), write)
    if as_json:
        out = result.to_json()
        out["wrote"] = None if write is None else str(write)
        click.echo(json_text(out), nl=False)
        return
    for line in _lines(result, photos):
        click.echo(line)
    if write is not None:
        click.echo(f"wrote {write}")


def _lines(result, photos) -> list[str]:
    from ...measure.stance import STANCE_KEYS

    lines = []
    for ph in photos:
        given = [n for n, s in ph.sources.items() if s == "given"]
        worst = max(result.residual_mm[ph.path.name].items(), key=lambda kv: kv[1])
        lines.append(f"{ph.path.name}: board {len(ph.corners_px)} corners ({ph.corner_sd_px:.2f} px); stickers by "
                     f"colour{', ' + ', '.join(given) + ' given' if given else ''}; farthest from the fit: "
                     f"{worst[0]} {worst[1]:.2f} mm")
    def row(name: str, est, key: str) -> str:
        """A value as a person reads it (a length in mm), its unit beside it and its interval."""
        _, k, unit = for_person(key)
        lo, hi = est.ci95
        return f"{name:28s} {est.value * k:10.2f} {unit:3s}  [{lo * k:9.2f}, {hi * k:9.2f}]"

    lines.append(f"{'value':28s} {'measured':>14s}  {'95 % interval':>22s}")
    for key, est in zip(STANCE_KEYS, result.values().values()):
        if result.side is None or key != "geometry.crank_start_deg":   # a side's crank: its own row, below
            lines.append(row(label(key), est, key))
    lines.append(row("plate pitch at rest", result.rest_pitch_deg, "rest_pitch_deg"))
    if result.push_turn_deg is not None:
        est = result.push_turn_deg
        same = (est.value < 0) == (result.push_command_deg < 0)
        lines.append(row("crank turn at the push", est, "push_turn_deg")
                     + f"  for the {result.push_command_deg:g} deg command"
                     + ("" if same else ": the other way than the model turns it"))
    lines.append(f"the crank stood at {result.rest_crank_seen_deg:.2f} deg in {photos[0].path.name}; the model's servo "
                 f"gives {result.servo_give_deg:.2f} deg under the robot's weight, taken off")
    if result.tooth is not None:
        lines.extend(_tooth_lines(result, row))
    lines.append(f"intervals: parametric bootstrap, {result.draws} draws (stickers {result.sticker_sd_px:.2f} px, "
                 f"board corners {result.corner_sd_px:.2f} px)")
    return lines


def _tooth_lines(result, row) -> list[str]:
    """The side's crank and its tooth, its probability and margin."""
    t = result.tooth
    word = {"L": "left", "R": "right"}[t.side]
    ref = f"{t.reference_deg:.2f} deg" + (f" ± {t.reference_sd_deg:.2f}" if t.reference_sd_deg else "")
    return [row(f"{word} crank at 0 deg", result.side_crank_deg, "crank_deg"),
            f"{t.key} = {t.tooth} (was {t.file_tooth}): {t.offset_teeth:+.3f} ± {t.sd_teeth:.3f} teeth of "
            f"{t.tooth_deg:.2f} deg off geometry.crank_start_deg ({ref}); probability {t.probability:.3f}, "
            f"{t.margin_sd:.1f} sd inside the tooth's half-tooth band"]


