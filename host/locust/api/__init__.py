"""The Python API: what a notebook calls, each a function over the toolkit's own machinery.

====================  ========================  =====================================================
function              module                    returns
====================  ========================  =====================================================
``robot``             :mod:`.robots`            :class:`locust.params.Robot`
``simulate``          :mod:`.simulation`        :class:`locust.sim.result.SimResult` (trace, video, plot)
``sweep_designs``     :mod:`.sweeps`            :class:`.sweeps.SweepResults` (to_dataframe, best)
``track_markers``     :mod:`.tracking`          :class:`.tracking.Tracks` (to_dataframe)
``read_tracks``       :mod:`.tracking`          :class:`.tracking.Tracks`
``calibrate_*``       :mod:`.calibration`       :class:`.calibration.Fit` (parameters, apply, plot)
``make_report``       :mod:`.reports`           :class:`locust.report.build.ReportResult`
``optimize``          :mod:`.optimizing`        :class:`locust.sweep.optimize.OptimizeSummary`
``make_cut_files``    :mod:`.fabrication`       dict (the manufacturing summary)
``hop``               :mod:`.hopping`           :class:`locust.io.run_record.RunRecord` (run.json)
====================  ========================  =====================================================

``bundled_recording(name)`` (:mod:`.calibration`, from :mod:`locust.bundled`) is the path of a
recording the toolkit ships, in a checkout or an installed wheel alike.

The command line calls the same functions (``locust sim``, ``sweep``, ``report``, ``fab``,
``calibrate beam|hinge|servo|ramp``, ``hop``). Every name is also at the package top: ``locust.simulate``.
"""

from __future__ import annotations

import importlib

# name -> the module of this package that defines it
EXPORTS = {
    "robot": "robots",
    "simulate": "simulation", "SimResult": "simulation",
    "sweep_designs": "sweeps", "SweepResults": "sweeps",
    "track_markers": "tracking", "read_tracks": "tracking", "Tracks": "tracking",
    "calibrate_beam": "calibration", "calibrate_hinge": "calibration", "calibrate_ramp": "calibration",
    "calibrate_servo": "calibration", "calibrate_hops": "calibration", "Fit": "calibration",
    "bundled_recording": "calibration",
    "make_report": "reports",
    "optimize": "optimizing", "make_cut_files": "fabrication",
    "hop": "hopping",
}

__all__ = list(EXPORTS)


def __getattr__(name: str):
    """Import a name's module on first use: ``import locust`` stays quick for the command line."""
    if name not in EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{EXPORTS[name]}"), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
