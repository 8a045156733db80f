"""How ``locust calibrate`` ends: the fit's plot and robot.toml made (:mod:`locust.calibrate.outputs`),
then the results printed, as JSON or as a table a person reads; and Ctrl-C during a fit."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Iterator
from pathlib import Path

import click

from ...calibrate.outputs import save
from ...calibrate.result import Fit
from ...calibrate.write import implausible
from ...errors import CalibrationError
from ...fileio import json_text, make_folder
from ...progress import format_duration
from ...tables import estimate_line, value_line
from .options import plot_folder, start_of_write

HINGE_MODEL_ERROR_M = 0.0002   # hinge residual beyond ~3x a video's tracking noise: model error (docs/calibrate.md)
NOT_ROWS = ("experiment", "source", "notes", "warnings", "written", "plot", "angles_deg", "validation",
            "validation_plot", "gyro_gain_units_per_rad_per_s")


def default_plot_path(recording: Path | None, experiment: str) -> Path:
    """``<recording>-<experiment>-fit.png`` (``<experiment>-fit.png`` for several recordings) in
    the command's output folder (:func:`.options.out_folder`), never beside the recording (a data
    folder, maybe someone else's): each experiment's own name, so a beam fit and a hinge fit of
    one recording keep both plots."""
    folder = make_folder(plot_folder())
    return folder / (f"{Path(recording).stem}-{experiment}-fit.png" if recording is not None
                     else f"{experiment}-fit.png")


def finish(fit: Fit, recording: Path | None, write_path: Path | None, as_json: bool, plot_path: Path | None,
           no_plot: bool, force: bool, extra: dict | None = None) -> None:
    """Draw the plot (``recording`` names it by default; None for several), write robot.toml
    and print; a write refused for an implausible value is shown, then raised."""
    if not no_plot:
        plot_path = plot_path or default_plot_path(recording, fit.experiment)
    for warning in [*fit.warnings, *implausible(fit.parameters)]:
        click.echo(f"warning: {warning}", err=True)
    saved = save(fit, plot_path=None if no_plot else plot_path, write_path=write_path, robot=start_of_write(),
                 force=force, extra=extra)
    show(saved.summary, as_json)
    if saved.refused is not None:     # shown, then refused
        raise saved.refused


def show(out: dict, as_json: bool) -> None:
    """Print a calibration's results: JSON, or one row a value."""
    if as_json:
        click.echo(json_text(out), nl=False)
    else:
        print_text(out)


def print_text(out: dict) -> None:
    """The results as a person reads them: each value a row, then notes, plots and what was written."""
    click.echo(f"# {out['experiment']}: {out['source']}")
    click.echo(f"{'':28s} {'value':>10s}  {'unit':10s} ± 1 sd    (95 % interval)")
    _rows(out)
    for note in out.get("notes", []):
        click.echo(f"note: {note}")
    if "plot" in out:
        click.echo(f"plot: {out['plot']}")
    _validation(out)
    written(out)


def _rows(out: dict) -> None:
    """One row a value, an estimate with its interval (a hinge's flagged where the residual is model error)."""
    narrow = ""
    if out["experiment"] == "hinge" and (out.get("rms_residual_m") or 0) > HINGE_MODEL_ERROR_M:
        narrow = (f"   TOO NARROW: the residual ({1000 * out['rms_residual_m']:.2f} mm RMS) is model error, "
                  "not tracking noise (docs/calibrate.md, Hinge)")
    for key, val in out.items():
        if key in NOT_ROWS:
            continue
        if isinstance(val, dict) and "value" in val:
            hinge = key.startswith("compliance.hinge_") and val.get("identifiable", True)
            print_value(key, val, narrow if hinge else "")
        elif val is not None:
            click.echo(value_line(key, val))
    for k, gain in enumerate(out.get("gyro_gain_units_per_rad_per_s") or []):
        if gain is not None:
            print_value(f"gyro_gain_units_per_rad_per_s[{k}]", gain)


def _validation(out: dict) -> None:
    """A servo's --validate recordings: their RMS and each step's peak speed, measured and predicted."""
    for v in out.get("validation", []):
        click.echo(f"# validation: {v['source']}: RMS {v['rms']:.3g} {v['rms_unit']} (not fitted to it)")
        click.echo(f"{'step_deg':>10s} {'peak measured':>15s} {'peak predicted':>15s} {'error':>8s}  [rad/s]")
        for st in v["steps"]:
            click.echo(f"{st['step_deg']:10.4g} {st['peak_speed_measured_rad_per_s']:15.3f} "
                       f"{st['peak_speed_predicted_rad_per_s']:15.3f} {100 * st['error']:+7.1f}%")
    if "validation_plot" in out:
        click.echo(f"plot: {out['validation_plot']}")


def written(out: dict) -> None:
    """What ``--write`` wrote, or that nothing was identifiable."""
    if "written" in out:
        keys = out["written"]["keys"]
        click.echo(f"wrote {', '.join(keys)} to {out['written']['path']}" if keys
                   else f"nothing written to {out['written']['path']}: no value was identifiable")


def print_value(key: str, val: dict, note: str = "") -> None:
    """One estimate's row (``(given)`` for a value held, ``NOT IDENTIFIABLE`` for one not determined)."""
    flag = "" if val.get("identifiable", True) else "   NOT IDENTIFIABLE"
    if val.get("given"):
        click.echo(value_line(key, val["value"]) + "  (given)")
    else:
        click.echo(estimate_line(key, val["value"], val["std"], val.get("ci95"), flag + note))


@contextlib.contextmanager
def interruptible(what: str, hint: str = "run it again") -> Iterator[None]:
    """Ctrl-C during a fit: one clear error (exit 2) saying nothing was written, not click's
    bare ``Aborted!``."""
    started = time.monotonic()
    try:
        yield
    except KeyboardInterrupt:
        raise CalibrationError(f"interrupted: {what} stopped after {format_duration(time.monotonic() - started)}; "
                               "nothing was fitted or written", hint) from None
