"""Update a robot.toml with fitted values, each with its source, uncertainty and date.

Only the keys given are touched; every other value, with its provenance, is kept as it
was. A file that does not exist yet starts from the robot the command resolved (the one
rule of ``locust.io.robot_toml.default_robot``), never from a preset picked here. The file is replaced
atomically (a reader never sees half of it; a failed write leaves the old one).
"""

from __future__ import annotations

import datetime as _dt
import math
from pathlib import Path

from ..errors import CalibrationError
from ..io.robot_toml import ROBOT_FILE, update_robot
from ..params import FOLDS, Provenance, Robot, problems
from .fitstats import Estimate

DEFAULT_ROBOT_TOML = ROBOT_FILE   # a bare --write

# what a desk hopper's fitted values can be (the seed's within a few decades): a fit outside
# came from a recording read in the wrong unit, and is not written
PLAUSIBLE = {
    "compliance.hinge_stiffness_nm_per_rad": (1e-5, 10.0),      # seed 0.056
    "compliance.hinge_damping_nms_per_rad": (1e-8, 1.0),        # seed 5.6e-4
    "servo.kp_nm_per_rad": (1e-3, 100.0),                       # SG90 0.26
    "servo.stall_torque_nm": (1e-3, 10.0),                      # SG90 0.15
    "servo.noload_speed_rad_per_s": (0.5, 200.0),               # SG90 10.2
    "servo.armature_kgm2": (1e-9, 0.1),                         # SG90 3.1e-4
    "servo.kv_nms_per_rad": (0.0, 10.0),
    "contact.foot_friction": (0.05, 5.0),                       # seed 1.7
    "contact.nose_friction": (0.05, 5.0),
    # a fold's film hinge (the as-built 1.5e-4) and its rest offset (within half a turn)
    **{f"{section}.{fold}_{name}": bounds for section in ("folds", "left", "right") for fold in FOLDS
       for name, bounds in (("stiffness_nm_per_rad", (1e-6, 10.0)), ("rest_offset_deg", (-180.0, 180.0)))},
}
UNIT_HINT = ("check the recording's units: times in seconds (not ms), angles in degrees (not radians), "
             "tracks in metres (or --units cm|mm); the fit is shown but not written")


def implausible(values: dict[str, Estimate]) -> list[str]:
    """Fitted values no desk hopper has (a unit slipped), one message each.

    Parameters
    ----------
    values : dict of str to locust.calibrate.fitstats.Estimate
        Dotted name -> fitted value, in the unit its name says.

    Returns
    -------
    list of str
        Empty when every value is plausible.
    """
    out = []
    for key, est in values.items():
        low, high = PLAUSIBLE.get(key, (-math.inf, math.inf))
        if not (math.isfinite(est.value) and low <= est.value <= high):
            out.append(f"fitted {key} = {est.value:.4g} is outside the plausible {low:g} .. {high:g}")
    return out


def check_plausible(values: dict[str, Estimate]) -> None:
    """Refuse (:class:`CalibrationError`) to write implausible fitted values.

    Parameters
    ----------
    values : dict of str to locust.calibrate.fitstats.Estimate
        Dotted name -> fitted value, in the unit its name says.

    Raises
    ------
    locust.errors.CalibrationError
        A value no desk hopper has.
    """
    found = implausible(values)
    if found:
        raise CalibrationError("; ".join(found) + "; not written", UNIT_HINT)


def write_fitted(path: str | Path, values: dict[str, Estimate], recording: str | Path, *,
                 robot: Robot | None = None, note: str = "", date: str | None = None) -> Path:
    """Set each dotted key in ``values`` to its fitted value, with ``fit:<recording>``; refused
    (nothing written) when a value is implausible or the robot could then not be simulated.

    The file is read, changed and written back under a lock (``robot_toml.update_robot``): two
    calibrations writing one file at once both land; its comments and layout are kept.

    Parameters
    ----------
    path : path-like
        The ``robot.toml``.
    robot : locust.params.Robot, optional
        The robot a file that does not exist yet starts from: the one the command resolved
        (``locust.io.robot_toml.default_robot``). None: ``path`` must exist.
    values : dict of str to locust.calibrate.fitstats.Estimate
        Dotted name -> fitted value, in the unit its name says.
    recording : str or path-like
        The recording fitted: the values' source ``fit:<recording>``.
    note : str
        Added to each value's note.
    date : str, optional
        The fit's date (default today).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    locust.errors.CalibrationError
        An implausible value, or a robot that could then not be simulated.
    """
    check_plausible(values)
    path = Path(path)

    def change(robot: Robot) -> Robot:
        robot = with_fitted(robot, values, recording, note=note, date=date)
        found = problems(robot)
        if found:   # a calibration file is what sim and hop run: it must be one they can
            raise CalibrationError(f"{path}: with the fitted values the robot cannot be simulated: "
                                   + "; ".join(found) + "; not written",
                                   "fix the value(s) in the robot file first "
                                   "(`locust params --config FILE` lists them)")
        return robot

    return update_robot(path, change, start=None if robot is None else (lambda: robot))


def with_fitted(robot: Robot, values: dict[str, Estimate], recording: str | Path, *, note: str = "",
                date: str | None = None) -> Robot:
    """``robot`` with each dotted key in ``values`` set to its fitted value, its source
    ``fit:<recording>``, its uncertainty (1 sigma), the date and the 95% interval in its note.

    Parameters
    ----------
    robot : locust.params.Robot
    values : dict of str to locust.calibrate.fitstats.Estimate
        Dotted name -> fitted value, in the unit its name says.
    recording : str or path-like
        The recording fitted.
    note : str
        Added to each value's note.
    date : str, optional
        The fit's date (default today).

    Returns
    -------
    locust.params.Robot
        A copy with the values.
    """
    date = date or _dt.date.today().isoformat()
    for key, est in values.items():
        ci = f"95% CI [{est.ci95_low:.6g}, {est.ci95_high:.6g}]"
        prov = Provenance(source=f"fit:{Path(recording).name}", uncertainty=float(est.std), date=date,
                          note=f"{ci}; {note}" if note else ci)
        robot = robot.with_values({key: est.value}, prov)
    return robot
