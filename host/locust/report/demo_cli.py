"""``locust demo``: the toolkit end to end on built-in defaults.

For now: simulate the seed robot and its Small/Medium/Large leg sets, audited, render the
seed's hop to video, and write a summary. The pipeline grows into: virtual-robot hops ->
tracking -> calibration -> sweep -> report.
"""

from __future__ import annotations

import json
from pathlib import Path

import click

from ..fileio import atomic_write_json, atomic_write_text, unique_dir
from ..params import preset


@click.command()
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=Path("demo-out"),
              show_default=True, help="Folder for the results; a new run-N subfolder is made each time.")
@click.option("--cycles", type=click.IntRange(1, 50), default=6, show_default=True)
@click.option("--no-video", is_flag=True, help="Skip the offscreen render.")
def demo(out, cycles, no_video):
    """Simulate the seed robot and the three leg sets; render the seed's hop; summarise."""
    from ..sim.run import run

    folder = unique_dir(out, "run")
    rows = []
    names = ["seed", "small", "medium", "large"]
    with click.progressbar(names, label="simulating", file=click.get_text_stream("stderr")) as bar:
        for name in bar:
            r = run(preset(name), cycles=cycles)
            rows.append(r)
            atomic_write_json(folder / f"sim_{name}.json", r.to_json())
    lines = [f"{'preset':8s} {'valid':6s} {'distance_cm':>12s} {'max_nose_cm':>12s}  reasons"]
    for r in rows:
        dist = f"{r.distance_m * 100:12.2f}" if r.valid else f"{'-':>12s}"
        nose = f"{r.max_nose_height_m * 100:12.2f}" if r.valid else f"{'-':>12s}"
        lines.append(f"{r.robot:8s} {str(r.valid):6s} {dist} {nose}  {'; '.join(r.reasons)}")
    summary = "\n".join(lines) + "\n"
    atomic_write_text(folder / "summary.txt", summary)
    click.echo(summary)
    if not no_video:
        from ..sim.video import render_video

        info = render_video(preset("seed"), folder / "seed_hop.mp4", cycles=min(cycles, 2))
        click.echo(f"video: {info.video_path}")
    atomic_write_json(folder / "index.json", {"results": [f"sim_{n}.json" for n in names],
                                              "summary": "summary.txt"})
    click.echo(f"results in {folder}")
