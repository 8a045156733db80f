"""``locust hop``: the bang-bang schedule on the robot, into a run record."""

from __future__ import annotations

from pathlib import Path

import click

from ..errors import DeviceError
from ..fileio import json_text
from ..io import run_record as R
from ._device import PORT_HELP, ROBOT_SCHEDULE, info, plant_options
from .options import DEFAULTED, FiniteFloat, robot_options


@click.command()
@click.option("--port", default=None, help=PORT_HELP)
@click.option("--cycles", type=click.IntRange(*R.hop_range("cycles")), default=None,
              help=f"Hop cycles [robot schedule: {ROBOT_SCHEDULE.cycles}].")
@click.option("--push-deg", type=FiniteFloat(low=R.hop_range("push_deg")[0], high=R.hop_range("push_deg")[1]),
              default=None,
              help=f"Horn angle of the push, deg [robot schedule: {ROBOT_SCHEDULE.push_deg:g}].")
@click.option("--push-ms", type=click.IntRange(*R.hop_range("push_ms")), default=None,
              help=f"Push time, ms [robot schedule: {ROBOT_SCHEDULE.push_s * 1000:g}].")
@click.option("--wait-ms", type=click.IntRange(*R.hop_range("wait_ms")), default=None,
              help=f"Wait (rest) time, ms [robot schedule: {ROBOT_SCHEDULE.wait_s * 1000:g}].")
@click.option("--heartbeat-ms", type=click.IntRange(*R.hop_range("heartbeat_ms")),
              default=R.hop_default("heartbeat_ms"), show_default=True,
              help="The robot returns to rest if the host is silent this long.")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Directory for run.json (must not hold one), named on the first line. Default: "
                   "data/runs/<timestamp>/. A hop the board never answered leaves no folder.")
@click.option("--json", "as_json", is_flag=True, help="Print the run record as JSON.")
@click.option("--leg-set", "leg_set_name", default=None, metavar="NAME",
              help="The legs on the robot (small, medium, large, or a name of your own), recorded in "
                   "run.json for `locust report`. Default: the --preset when it is a leg set. "
                   "A known leg set is built on the --config robot for the virtual robot.")
@plant_options
@robot_options(say=False)   # the robot line comes once a virtual robot on --port is known
def hop(port, cycles, push_deg, push_ms, wait_ms, heartbeat_ms, out, as_json, leg_set_name, plant, video, video_fps,
        preset, config, sets):
    """Run the bang-bang hop schedule (push, wait; N cycles) and save the run record.

    Phases are timed on the robot (ticks_us); run.json gets the commanded and measured start
    of every phase and the jitter, which robot and leg set were hopped (--preset/--config,
    --leg-set), and the board's config (chip, pins, trims) read back before the hop. Ctrl-C or
    a lost cable: the robot goes to rest, the record keeps what arrived (status incomplete)
    and the command exits non-zero; so does a hop the board ran on its default config because
    its config.json was unreadable (status default_config).
    """
    from ..device.hop_job import HopOptions, run_hop_job

    options = HopOptions(port=port, cycles=cycles, push_deg=push_deg, push_ms=push_ms, wait_ms=wait_ms,
                         heartbeat_ms=heartbeat_ms, out=out, leg_set=leg_set_name, plant=plant, video=video,
                         video_fps=video_fps, preset=preset, config=config, sets=tuple(sets),
                         robot_line=click.get_current_context().meta.get(DEFAULTED))
    done = run_hop_job(options, say=info)
    if as_json:
        doc = done.record.to_dict()
        if done.simulated.get("plant") == "mujoco":
            doc["simulated"] = done.simulated      # what the virtual robot's simulation did, SI units
        click.echo(json_text(doc), nl=False)
    _summary(done.record, done.folder / R.RECORD_NAME)


def _summary(rec: R.RunRecord, path: Path) -> None:
    """The hop's last lines: phases, timing and the record's path; an exit status that is not 0
    for a hop that did not complete, or ran on the board's default config."""
    j, stall_s = R.jitter(rec.phases), R.host_stall_max_s(rec.phases)
    info(f"{rec.status}: {len(rec.phases)}/{rec.schedule.phases} phases"
         + (f", start error max {j.max_abs_ms:.3f} ms (mean {j.mean_ms:.3f}, sd {j.std_ms:.3f})" if j else "")
         + (f", host stall max {stall_s * 1000:.2f} ms" if stall_s is not None else "")
         + f"; record {path}")
    note = R.timing_note(rec.phases)
    if note:
        info(f"{note}; that lateness is the host's, not the firmware's: hop again with less running beside it")
    if rec.status == R.DEFAULT_CONFIG:
        raise DeviceError(f"every phase ran, but {rec.message}",
                          f"{R.CONFIG_FIX_HINT}; then hop again (this record, {path}, says {R.DEFAULT_CONFIG})")
    if rec.status != R.COMPLETE:
        raise DeviceError(f"the hop did not complete: {rec.message}", f"the partial record is in {path}")
