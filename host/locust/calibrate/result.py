"""What every calibration returns: :class:`Fit`, the robot values a recording determines with
their intervals, the experiment's own fit beside them, and the robot with them applied."""

from __future__ import annotations

import html
import math
from dataclasses import dataclass, field
from pathlib import Path

from ..params import Robot
from ..tables import estimate_line, sig, split_unit
from .fitstats import Estimate


@dataclass(frozen=True)
class Fit:
    """One calibration's outcome: the robot values a recording determines, with intervals.

    Attributes
    ----------
    experiment : str
        ``beam``, ``static-beam``, ``hinge``, ``servo``, ``ramp`` or ``hops``.
    source : str
        The recording(s) fitted, ``+``-joined; the values' provenance ``fit:<source>``.
    parameters : dict of str to locust.calibrate.fitstats.Estimate
        Robot parameter (dotted name, unit in its suffix) -> ``.value``, ``.std`` (one standard
        deviation) and ``.ci95`` (the 95% interval), in the parameter's unit; only the values
        the recordings determine (the experiment's own ``.estimates`` that are identifiable).
    result : object
        The experiment's own fit (every other quantity, ``.summary()``).
    note, subtitle : str
        The provenance note written with the values; the plot's subtitle (RMS per recording).
    warnings : list of str
        What looked wrong in the recording.
    input_note : str
        How the input was read (a unit or timing assumed), as the command line prints it.
    """

    experiment: str
    source: str
    parameters: dict[str, Estimate]
    result: object = field(repr=False)
    note: str = ""
    subtitle: str = ""
    warnings: list[str] = field(default_factory=list)
    input_note: str = ""

    def apply(self, robot: Robot) -> Robot:
        """``robot`` with the fitted values, each with its source ``fit:<recording>``, its
        uncertainty and the date, as ``locust calibrate --write`` records them.

        Parameters
        ----------
        robot : locust.params.Robot
            The robot the values are put into (left unchanged).

        Returns
        -------
        locust.params.Robot
            A copy with the fitted values.

        Raises
        ------
        locust.errors.CalibrationError
            A fitted value no desk hopper has (a recording read in the wrong unit).
        """
        from .write import check_plausible, with_fitted

        check_plausible(self.parameters)
        return with_fitted(robot, self.parameters, self.source, note=self.note)

    def summary(self) -> dict:
        """Everything the fit found, as ``locust calibrate --json`` prints it.

        Returns
        -------
        dict
            The experiment's figures by name (units in the names' suffixes).
        """
        return self.result.summary()

    def to_dataframe(self):
        """One row per fitted robot value.

        Returns
        -------
        pandas.DataFrame
            index ``key`` (dotted name); ``value``, ``std`` (1 sd), ``ci95_low``, ``ci95_high``,
            ``unit`` (from the key's name: ``N·m/rad`` for ``_nm_per_rad``).
        """
        import pandas as pd

        rows = [{"key": k, "value": e.value, "std": e.std, "ci95_low": e.ci95[0], "ci95_high": e.ci95[1],
                 "unit": split_unit(k)[1]} for k, e in self.parameters.items()]
        return pd.DataFrame(rows, columns=["key", "value", "std", "ci95_low", "ci95_high", "unit"]).set_index("key")

    def plot(self, run: int = 0):
        """Data and model above, residuals below (per recording); for a hop fit, run ``run``'s
        tracked markers against the fitted simulation.

        Parameters
        ----------
        run : int, default 0
            Which run of a hop fit to draw (ignored by the other fits).

        Returns
        -------
        matplotlib.figure.Figure
        """
        from .plots import fit_figure, run_figure

        if self.experiment == "hops":
            fit = self.result.runs[run]
            return run_figure(fit, f"RMS {1000 * fit.rms_m:.2f} mm")
        return fit_figure(self.result.curves, self.subtitle)

    def _rows(self) -> list[tuple[str, str, str, str, str]]:
        """(name, value to 4 figures, unit, ± 1 sd in %, 95 % interval) as the CLI prints them."""
        rows = []
        for key, e in self.parameters.items():
            name, unit = split_unit(key)
            rel = f"± {100 * e.std / abs(e.value):.1f} %" if e.value and math.isfinite(e.std) else "undetermined"
            rows.append((name, sig(e.value), unit, rel, f"{sig(e.ci95_low)} … {sig(e.ci95_high)}"))
        return rows

    def _source_name(self) -> str:
        """The recording's file name (its folder is the reader's own: not shown)."""
        return "+".join(Path(part).name for part in str(self.source).split("+"))

    def __repr__(self) -> str:
        lines = [f"Fit {self.experiment}: {self._source_name()}"]
        if self.subtitle:
            lines.append(f"  {self.subtitle}")
        lines += ["  " + estimate_line(k, e.value, e.std, e.ci95) for k, e in self.parameters.items()]
        figures = getattr(self.result, "figures", None)
        if figures is not None:         # a fit of no robot value: its own figures
            lines += ["  " + estimate_line(k, e.value, e.std, e.ci95) for k, e in figures().items()]
        if not self.parameters:
            lines.append("  no robot value determined")
        lines += [f"  warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        esc = html.escape
        head = "".join(f"<th>{c}</th>" for c in ("parameter", "value", "unit", "1 sd", "95 % interval"))
        body = "".join("<tr>" + "".join(f"<td>{esc(c)}</td>" for c in row) + "</tr>" for row in self._rows())
        warn = "".join(f"<p>warning: {esc(w)}</p>" for w in self.warnings)
        return (f"<b>Fit {esc(self.experiment)}</b>: {esc(self._source_name())}<br>{esc(self.subtitle)}"
                f"<table><tr>{head}</tr>{body}</table>{warn}")


def identified(result) -> dict[str, Estimate]:
    """The robot values an experiment's fit determines: its ``estimates`` (each under its robot
    key), less those its ``identifiable`` marks as not determined.

    Parameters
    ----------
    result : object
        An experiment's fit (:class:`~.beam.BeamFit`, :class:`~.hinge.HingeFit`,
        :class:`~.ramp.RampFit`, :class:`~.hop.HopFit`).

    Returns
    -------
    dict of str to Estimate
        Robot key -> its estimate, in the fit's order.
    """
    flags = getattr(result, "identifiable", {})
    return {key: est for key, est in result.estimates.items() if flags.get(key, True)}
