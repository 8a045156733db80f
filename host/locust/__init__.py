"""locust: firmware-plus-host toolkit for a foldable four-bar hopping robot.

The Python API (:mod:`locust.api`), for notebooks and scripts::

    import locust
    r = locust.simulate(locust.robot("small", **{"servo.kp_nm_per_rad": 0.4}), cycles=3)
    r.trace()                          # pandas.DataFrame, one row per physics step
    r.video("hop.mp4", overwrite=True)
    locust.sweep_designs(locust.robot("seed"), vary={"scale": (0.0, 0.05, 30)}, cycles=3).to_dataframe()

Functions (each with a numpydoc docstring: ``help(locust.simulate)``), named once in
:data:`locust.api.EXPORTS`:

- ``robot(preset_or_path, **values)``: a :class:`Robot` (presets seed, small, medium, large).
- ``simulate(robot, cycles)``: a ``SimResult`` (``.trace()``, ``.video()``, ``.plot()``).
- ``sweep_designs(robot, vary, cycles)``: a ``SweepResults`` (``.to_dataframe()``, ``.plot()``, ``.best``).
- ``track_markers(video, markers)``, ``read_tracks(path)``: ``Tracks`` (``.to_dataframe()``, ``.tidy()``:
  one row per marker per frame with velocity and acceleration, ``.plot()``, ``.write()``).
- ``calibrate_beam/hinge/servo/ramp/fold/hops(...)``: a ``Fit`` (``.parameters``, ``.to_dataframe()``,
  ``.plot()``, ``.apply(robot)``).
- ``bundled_recording(name)``: the path of a SYNTHETIC recording the toolkit ships (``synthetic_beam.csv``, ...).
- ``make_report(robot, measured)``: the HTML comparison of simulation and filmed hops.
- ``optimize(robot, vary, trials, out=...)``: Optuna's search for the farthest valid hop.
- ``make_cut_files(robot_or_dxf, out=...)``: the laminate's cut files and their summary.
- ``run_demo(out, cycles, trials, designs)``: ``locust demo``, the toolkit end to end on the virtual robot.
- ``hop(port, cycles, ...)``: the hop schedule on the robot or the virtual robot (``port="sim"``), its ``RunRecord``.
- ``measure_stroke(robot, floor, held)``: the servo's stroke and speed from clips of a push, beside the model's.

Errors are :class:`locust.errors.LocustError` (``.message``, ``.hint``).
"""

import importlib as _importlib

from .api import EXPORTS as _EXPORTS
from .version import __version__

# the API's names (locust.api.EXPORTS, the one list), and the version
__all__ = [*_EXPORTS, "__version__"]


def __getattr__(name: str):
    """The API's names, imported on first use (``import locust`` stays quick for the command line)."""
    if name in _EXPORTS:
        return getattr(_importlib.import_module("locust.api"), name)
    raise AttributeError(f"module 'locust' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
