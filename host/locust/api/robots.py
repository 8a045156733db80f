"""``locust.robot``: a preset or a robot file, with values overridden by their dotted names."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import ParamsError
from ..io.robot_toml import default_robot, load_robot
from ..params import PRESETS, Robot, check_robot, preset


def robot(preset_or_path: str | Path | Robot | None = None, **overrides: Any) -> Robot:
    """The robot a simulation runs on: a preset or a robot TOML, with some values changed.

    Parameters
    ----------
    preset_or_path : str, path-like or Robot, optional
        A preset name (``small``, the robot as built; ``medium``, ``large``, its other leg
        sets; ``seed``, the notebook's design; ``seed-notebook``), the path of a robot TOML
        (``calibration/robot.toml``, ``locust params --write``), or a robot to change. None
        (the default): the robot every command runs on when told none, by the one rule of
        :func:`locust.io.robot_toml.default_robot` (this folder's ``calibration/robot.toml``,
        else ``small``, the robot as built).
    **overrides
        Values to change, by dotted name with the unit in it (``locust params`` lists them);
        since a dotted name is not a Python keyword, pass them as ``**{"servo.kp_nm_per_rad":
        0.3}``. Each is recorded with the source ``override``.

    Returns
    -------
    Robot
        The checked parameter set (``.get(key)``, ``.flat()``, ``.source_of(key)``).

    Raises
    ------
    locust.errors.ParamsError
        An unknown preset, a missing or bad file, an unknown key or a value out of its range,
        each with a hint.

    Examples
    --------
    >>> import locust
    >>> small = locust.robot("small")
    >>> small.geometry.leg_m
    0.06
    >>> stiff = locust.robot("small", **{"servo.kp_nm_per_rad": 0.4})
    >>> stiff.get("servo.kp_nm_per_rad"), stiff.source_of("servo.kp_nm_per_rad").source
    (0.4, 'override')
    """
    if preset_or_path is None:
        choice = default_robot()
        preset_or_path = choice.robot_file or choice.preset
    if isinstance(preset_or_path, Robot):
        base = preset_or_path
    elif isinstance(preset_or_path, str) and preset_or_path in PRESETS:
        base = preset(preset_or_path)
    elif Path(preset_or_path).suffix.lower() == ".toml" or Path(preset_or_path).exists():
        base = load_robot(preset_or_path)
    else:
        raise ParamsError(f"{preset_or_path!r} is neither a preset nor a robot file",
                          f"give a preset ({', '.join(PRESETS)}) or the path of a robot .toml")
    return check_robot(base.with_values(overrides, "override") if overrides else base)


__all__ = ["robot"]
