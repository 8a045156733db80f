"""Update a robot.toml with fitted values, each with its source, uncertainty and date.

Only the keys given are touched; every other value, with its provenance, is kept as it
was. A file that does not exist yet starts from the seed preset. The file is replaced
atomically (a reader never sees half of it; a failed write leaves the old one).
"""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

from ..params import Provenance, load_robot, preset, save_robot
from .fitstats import Estimate

DEFAULT_ROBOT_TOML = Path("calibration") / "robot.toml"


def write_fitted(path: str | Path, values: dict[str, Estimate], recording: str | Path, *,
                 note: str = "", date: str | None = None) -> Path:
    """Set each dotted key in ``values`` to its fitted value, with ``fit:<recording>``."""
    path = Path(path)
    robot = load_robot(path) if path.exists() else preset("seed").renamed("calibrated")
    date = date or _dt.date.today().isoformat()
    for key, est in values.items():
        ci = f"95% CI [{est.ci95_low:.6g}, {est.ci95_high:.6g}]"
        prov = Provenance(source=f"fit:{Path(recording).name}", uncertainty=float(est.std), date=date,
                          note=f"{ci}; {note}" if note else ci)
        robot = robot.with_values({key: est.value}, prov)
    return save_robot(robot, path)
