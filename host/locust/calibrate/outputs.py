"""What a calibration leaves behind: its fit plot and, when asked, the fitted values in a
robot.toml, with the figures ``locust calibrate --json`` prints (the plot's path and what was
written among them). The values are written only when every one is plausible
(:func:`.write.implausible`); otherwise the write is refused, after the fit is shown.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import CalibrationError
from ..fileio import make_folder
from ..params import Robot
from .plots import plot_fit, plot_run
from .result import Fit
from .write import UNIT_HINT, implausible, write_fitted


@dataclass(frozen=True)
class Saved:
    """A calibration's outputs.

    Attributes
    ----------
    summary : dict
        Everything the fit found and what was made of it, as ``--json`` prints it: the
        experiment's figures, ``warnings``, ``plot`` (the figure's path) and ``written`` (the
        robot.toml and its keys) where made.
    refused : locust.errors.CalibrationError or None
        The write refused: a fitted value no desk hopper has (a recording read in the wrong
        unit); nothing was written. The command shows the fit, then raises it.
    """

    summary: dict
    refused: CalibrationError | None = None


def save(fit: Fit, *, plot_path: Path | None = None, write_path: Path | None = None, robot: Robot | None = None,
         force: bool = False, extra: dict | None = None) -> Saved:
    """Draw ``fit``'s plot and write its values into a robot.toml.

    Parameters
    ----------
    fit : Fit
        A beam, hinge, servo or ramp calibration.
    plot_path : pathlib.Path, optional
        The fit plot (None: none drawn).
    write_path : pathlib.Path, optional
        The robot.toml the values go to (None: none written).
    robot : locust.params.Robot, optional
        The robot a new ``write_path`` starts from.
    force : bool, default False
        Replace a file at ``plot_path`` that is not one of this toolkit's figures.
    extra : dict, optional
        More figures for the summary (a validation's).

    Returns
    -------
    Saved
    """
    out = {**fit.summary(), **(extra or {})}
    if fit.input_note:
        out["input"] = fit.input_note
    odd = implausible(fit.parameters)
    out["warnings"] = list(fit.warnings) + odd
    if plot_path is not None:
        out["plot"] = str(plot_fit(fit.result.curves, plot_path, fit.subtitle, force))
    if write_path and odd:
        return Saved(out, CalibrationError("; ".join(odd) + "; not written", UNIT_HINT))
    if write_path:
        _write(fit, out, write_path, robot, Path(fit.source).name)
    return Saved(out)


def save_hops(fit: Fit, *, plot_folder: Path | None = None, write_path: Path | None = None,
              robot: Robot | None = None) -> dict:
    """Draw each run's plot of a hop fit (``<run>-hops-fit.png``) and write its values.

    Parameters
    ----------
    fit : Fit
        A hop fit (``locust.calibrate.jobs.hops``).
    plot_folder : pathlib.Path, optional
        Where the plots go, made if missing (None: none drawn).
    write_path : pathlib.Path, optional
        The robot.toml the identifiable values go to, source ``fit:hops``.
    robot : locust.params.Robot, optional
        The robot a new ``write_path`` starts from.

    Returns
    -------
    dict
        The fit's summary, with ``plots`` and ``written`` where made.

    Raises
    ------
    locust.errors.CalibrationError
        A fitted value no desk hopper has: nothing is written.
    """
    out = fit.summary()
    if plot_folder is not None:
        out["plots"] = []
        for run in fit.result.runs:
            if run.curves:
                plot = make_folder(plot_folder) / f"{Path(run.source).name}-hops-fit.png"
                out["plots"].append(str(plot_run(run, plot, f"RMS {1000 * run.rms_m:.2f} mm")))
    if write_path:
        _write(fit, out, write_path, robot, fit.source)
    return out


def _write(fit: Fit, out: dict, write_path: Path, robot: Robot | None, recording: str) -> None:
    """The fitted values into ``write_path`` (none to write: the file is left alone), said in ``out``."""
    if fit.parameters:
        write_fitted(write_path, fit.parameters, recording, note=fit.note, robot=robot)
    out["written"] = {"path": str(Path(write_path).resolve()), "keys": list(fit.parameters)}
