"""The configurations trials are filmed in (the report's and the hop fit's): named leg sets on one robot.

A configuration is the base robot (``--config robot.toml`` or ``--preset``) with the same
length added to all four links: ``small`` / ``medium`` / ``large`` are the notebook's
physical leg sets (:data:`locust.params.LEG_SETS`: +0 / +10 / +20 mm, each at its own
converged time step, as its preset), put in place of the leg set the base carries
(``Robot.leg_set``); any other name is the base as it is unless ``--added NAME=METRES``
gives its added length (at the base's step).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import TrialError
from ..params import LEG_SETS, Robot, leg_set, with_added_length

_TRIAL_SUFFIX = re.compile(r"(?:[-_.]|^)(?:(?:trial|run|take)[-_.]?)?\d+$", re.IGNORECASE)
_NAME_OK = re.compile(r"^[A-Za-z][A-Za-z0-9_+-]*$")


@dataclass(frozen=True)
class Configuration:
    """One configuration the trials were hopped in: a leg set, or the base robot with every
    link lengthened by ``added_m``.

    Attributes
    ----------
    name : str
        Its key, lower case (``small``).
    added_m : float
        The length added to every link of the base robot [m].
    robot : locust.params.Robot
        The robot in this configuration.
    """

    name: str          # lower case key: "small"
    added_m: float     # length added to every link of the base robot
    robot: Robot

    @property
    def label(self) -> str:
        """Display name: "Small"."""
        return self.name[:1].upper() + self.name[1:]


def configuration(robot: Robot, name: str, added_m: float | None = None) -> Configuration:
    """The configuration ``name`` on ``robot``: a known leg set, or ``robot`` plus ``added_m``.

    Parameters
    ----------
    robot : locust.params.Robot
        The robot the leg set is built on.
    name : str
        A leg set's name (``small``, ``medium``, ``large``) or the user's own.
    added_m : float, optional
        The length added to every link [m]; default the leg set's own (0 for an unknown name).

    Returns
    -------
    Configuration

    Raises
    ------
    locust.errors.TrialError
        ``name`` is not a plain name.
    """
    key = check_name(name)
    if key in LEG_SETS and (added_m is None or added_m == LEG_SETS[key].added_m):
        built = leg_set(robot, key, source=f"leg-set:{key}")   # in place of the leg set robot carries
        return Configuration(name=key, added_m=LEG_SETS[key].added_m, robot=built.renamed(key))
    added_m = added_m or 0.0
    note = f"report configuration {key}: {added_m * 1000:+g} mm on every link"
    built = with_added_length(robot, added_m, source=f"leg-set:{key}", note=note) if added_m else robot
    return Configuration(name=key, added_m=float(added_m), robot=built.renamed(key))


def check_name(name: str) -> str:
    """A configuration's name as a key: stripped, lower case, a plain name.

    Parameters
    ----------
    name : str

    Returns
    -------
    str

    Raises
    ------
    locust.errors.TrialError
        Not letters, digits, ``-``, ``_`` or ``+`` after a first letter.
    """
    key = name.strip().lower()
    if not _NAME_OK.match(key):
        raise TrialError(f"configuration name {name!r} is not a plain name",
                          "use letters, digits, - or _, e.g. small, medium, large, v2")
    return key


def name_from_path(path: Path) -> str:
    """A trial's configuration from where it lies: its folder's name less a trial number.

    ``hops/small/run.json`` -> small; ``hops/medium-2/`` -> medium; ``large_trial3/`` -> large.

    Parameters
    ----------
    path : pathlib.Path
        A run folder, its ``run.json`` or a track file.

    Returns
    -------
    str
        The configuration's key.

    Raises
    ------
    locust.errors.TrialError
        No plain name left once the trial number is taken off.
    """
    folder = path if path.is_dir() else path.parent
    for part in (folder.name, folder.parent.name):
        stem = _TRIAL_SUFFIX.sub("", part)
        if stem and _NAME_OK.match(stem) and stem.lower() not in ("trial", "run", "runs", "hops", "tracks"):
            return stem.lower()
    raise TrialError(f"{path}: cannot tell which configuration this trial is",
                      "name it on the command line: small=PATH (report: --measured small=PATH)")


def sort_key(name: str) -> tuple[int, str]:
    """Known leg sets in size order first, then the rest by name.

    Parameters
    ----------
    name : str
        A configuration's key.

    Returns
    -------
    tuple of (int, str)
    """
    order = list(LEG_SETS)
    return (order.index(name), "") if name in order else (len(order), name)


def parse_added(items: tuple[str, ...] | list[str]) -> dict[str, float]:
    """``["v2=0.015"]`` -> ``{"v2": 0.015}`` (metres added to every link).

    Parameters
    ----------
    items : sequence of str
        ``NAME=METRES`` (the command line's ``--added``).

    Returns
    -------
    dict of str to float
        Configuration -> length added to every link [m].

    Raises
    ------
    locust.errors.TrialError
        An item that is not ``NAME=METRES``, or a name that is not plain.
    """
    out: dict[str, float] = {}
    for item in items:
        name, sep, value = item.partition("=")
        try:
            out[check_name(name)] = float(value)
        except ValueError:
            sep = ""
        if not sep:
            raise TrialError(f"--added {item!r} is not NAME=METRES", "e.g. --added v2=0.015")
    return out
