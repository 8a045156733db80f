"""The Python API: what a notebook calls, each a function over the toolkit's own machinery.

:data:`EXPORTS` is the one list of the public names: ``locust.__all__`` is built from it, the
tests read it, and this table is checked against it (``tests/test_api.py``), a row a name:

=====================  =========================  ====================================================
name                   module                     what it is
=====================  =========================  ====================================================
``robot``              :mod:`.robots`             a :class:`Robot` from a preset or a robot.toml
``simulate``           :mod:`.simulation`         one audited simulation: a ``SimResult``
``SimResult``          :mod:`.simulation`         :class:`locust.sim.result.SimResult` (trace, video, plot)
``sweep_designs``      :mod:`.sweeps`             a design sweep: ``SweepResults``
``SweepResults``       :mod:`.sweeps`             the sweep's rows (to_dataframe, plot, best)
``track_markers``      :mod:`.tracking`           a video's markers tracked: ``Tracks``
``read_tracks``        :mod:`.tracking`           a tracks file read: ``Tracks``
``Tracks``             :mod:`.tracking`           marker tracks (to_dataframe, tidy, plot, write)
``calibrate_beam``     :mod:`.calibration`        a beam's fit: ``Fit``
``calibrate_hinge``    :mod:`.calibration`        a hinge's fit: ``Fit``
``calibrate_ramp``     :mod:`.calibration`        a ramp's friction fit: ``Fit``
``calibrate_servo``    :mod:`.calibration`        a servo's fit: ``Fit``
``calibrate_fold``     :mod:`.calibration`        a fold's static test: ``Fit``
``calibrate_hops``     :mod:`.calibration`        a fit to filmed hops: ``Fit``
``Fit``                :mod:`.calibration`        fitted robot values (parameters, apply, plot)
``bundled_recording``  :mod:`locust.bundled`      the path of a recording the toolkit ships
``make_report``        :mod:`.reports`            :class:`locust.report.build.ReportResult`
``optimize``           :mod:`.optimizing`         :class:`locust.sweep.optimize.OptimizeSummary`
``make_cut_files``     :mod:`.fabrication`        dict (the manufacturing summary)
``run_demo``           :mod:`.demos`              the toolkit end to end on the virtual robot
``hop``                :mod:`.hopping`            the hop schedule on a robot: its run.json's ``RunRecord``
``measure_stroke``     :mod:`.measuring`          the servo's stroke from clips of a push, beside the model's
``Robot``              :mod:`locust.params`       the robot's parameters, each with its provenance
``LocustError``        :mod:`locust.errors`       every error the toolkit raises (message, hint)
=====================  =========================  ====================================================

The command line calls the same functions (``locust sim``, ``sweep``, ``report``, ``fab``,
``calibrate beam|hinge|servo|ramp|fold``, ``demo``, ``hop``). Every name is also at the package top:
``locust.simulate``.
"""

from __future__ import annotations

import importlib

# name -> the module that defines it: a module of this package, or a ``locust.`` path
# (one entry a line: the table above and ``locust.__all__`` follow this dict)
EXPORTS = {
    "robot": "robots",
    "simulate": "simulation",
    "SimResult": "simulation",
    "sweep_designs": "sweeps",
    "SweepResults": "sweeps",
    "track_markers": "tracking",
    "read_tracks": "tracking",
    "Tracks": "tracking",
    "calibrate_beam": "calibration",
    "calibrate_hinge": "calibration",
    "calibrate_ramp": "calibration",
    "calibrate_servo": "calibration",
    "calibrate_fold": "calibration",
    "calibrate_hops": "calibration",
    "Fit": "calibration",
    "bundled_recording": "locust.bundled",
    "make_report": "reports",
    "optimize": "optimizing",
    "make_cut_files": "fabrication",
    "run_demo": "demos",
    "hop": "hopping",
    "measure_stroke": "measuring",
    "Robot": "locust.params",
    "LocustError": "locust.errors",
}

__all__ = list(EXPORTS)


def module_of(name: str) -> str:
    """The absolute name of the module that defines the exported ``name``.

    Parameters
    ----------
    name : str
        A key of :data:`EXPORTS`.

    Returns
    -------
    str
        ``locust.api.<module>``, or the ``locust.`` path :data:`EXPORTS` gives.
    """
    module = EXPORTS[name]
    return module if module.startswith("locust.") else f"{__name__}.{module}"


def __getattr__(name: str):
    """Import a name's module on first use: ``import locust`` stays quick for the command line."""
    if name not in EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(module_of(name)), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
