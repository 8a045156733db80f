"""What a report warns about: inputs that look wrong, and where its "measured" trials come from.

Every notice is a warning, printed to stderr (``warning: ...``), listed at the top of
``report.html`` and kept in ``report.json``; none stops the report:

- ``configuration-guessed``: a trial's leg set came from its folder's name
  (:func:`.configs.name_from_path`), not from ``--measured NAME=PATH``;
- ``virtual-robot``: its run record was made on the virtual robot (``locust hop --port sim``:
  the record's port is ``sim`` or a pseudo-terminal, ``/dev/pts/N``, or its firmware fields
  say so), so the trial measures the simulation, not the physical robot;
- ``mirrored``: the tracked marker travels the other way from the prediction (or, with no
  prediction, backwards): a hop filmed right-to-left, for ``--mirror``;
- ``units``: hops or jumps far beyond this robot's (hundreds of metres a hop: a track in mm
  read as metres), with the ``--units`` that would make them plausible.
"""

from __future__ import annotations

import math
import re
from dataclasses import asdict, dataclass

import numpy as np

from ..io.importing import units_hint
from ..io.run_record import RunRecord
from ..trials.measured import CONFIG_FROM_RECORD, CONFIG_GIVEN, Trial, span_hint
from .compare import Comparison

ROBOT = "robot"
VIRTUAL = "virtual robot"
SYNTHETIC = "synthetic"
_PTY = re.compile(r"^/dev/(pts/\d+|ttys\d+)$")             # Linux and macOS pseudo-terminals
_VIRTUAL_WORDS = re.compile(r"\b(virtual|sim|simulated|simulation)\b", re.IGNORECASE)
SIM_PORT = "sim"

MAX_HOP_M = 2.0          # a desk robot's hop; the seed hops about 0.25 m
MAX_JUMP_M = 1.0
TYPICAL_HOP_M = 0.25
TYPICAL_JUMP_M = 0.08
MIN_TRAVEL_M = 0.002     # travel below this has no direction worth a warning (camera noise: ~0.5 mm)
END_SAMPLES = 5          # the last samples of a track, averaged as where it ended


@dataclass(frozen=True)
class Notice:
    """One warning about a report's input.

    Attributes
    ----------
    kind : str
        ``configuration-guessed``, ``virtual-robot``, ``mirrored``, ``units`` or
        ``sweep-unfinished`` (of the report's ``--sweep``, no configuration or trial).
    config : str
        The configuration (leg set) it concerns.
    trial : str
        The trial's label.
    message : str
        The warning, with this trial's details.
    summary : str
        The same warning without this trial's details: notices sharing it are shown as one line.
    """

    kind: str            # configuration-guessed | virtual-robot | mirrored | units | sweep-unfinished
    config: str
    trial: str
    message: str
    # the same warning without this trial's details: notices sharing it are shown as one line
    summary: str = ""

    def to_json(self) -> dict:
        """The notice as ``report.json`` keeps it.

        Returns
        -------
        dict
            Each field by name.
        """
        return asdict(self)


def collapsed(found: list[Notice]) -> list[Notice]:
    """The notices as they are shown: those that say the same of several trials (one ``kind``
    and ``summary``) become one notice naming how many trials and which, in first-seen order.

    Parameters
    ----------
    found : list of Notice
        The notices, as :func:`notices` returns them.

    Returns
    -------
    list of Notice
        The notices to show.
    """
    groups: dict[tuple[str, str], list[Notice]] = {}
    for n in found:
        groups.setdefault((n.kind, n.summary or n.message), []).append(n)
    out = []
    for (kind, text), group in groups.items():
        if len(group) == 1 or not group[0].summary:
            out += group
            continue
        trials = ", ".join(n.trial for n in group)
        configs = ", ".join(dict.fromkeys(n.config for n in group))
        out.append(Notice(kind, configs, trials, f"{len(group)} trials ({trials}): {text}", text))
    return out


def recorded_on(record: RunRecord | None) -> tuple[str | None, str]:
    """Where a trial's run was recorded (robot, virtual robot, synthetic; None without a
    run record) and why that is known.

    Parameters
    ----------
    record : RunRecord or None
        The trial's run record.

    Returns
    -------
    where : str or None
        ``robot``, ``virtual robot`` or ``synthetic``; None without a record.
    why : str
        The evidence, as a phrase for the page.
    """
    if record is None:
        return None, "no run record"
    port = record.port.strip()
    if port == SIM_PORT:
        return VIRTUAL, f"its run record's port is {port!r}"
    if _PTY.match(port):
        return VIRTUAL, f"its run record's port {port} is a pseudo-terminal, as the virtual robot's (--port sim)"
    for what, text in (("firmware status", record.firmware_status), ("firmware version", record.firmware_version),
                       ("record's message", record.message)):
        if text and _VIRTUAL_WORDS.search(text):
            return VIRTUAL, f"its {what} says {text!r}"
    if SYNTHETIC in (port, record.firmware_version):
        return SYNTHETIC, "its run record is labelled synthetic"
    return ROBOT, f"port {port or '?'}"


def notices(comps: list[Comparison]) -> list[Notice]:
    """Every warning about the comparisons' inputs, configuration by configuration.

    Parameters
    ----------
    comps : list of Comparison
        The report's comparisons.

    Returns
    -------
    list of Notice
        Guessed leg sets and virtual-robot runs for every trial; mirrored tracks and implausible
        units for every trial with a track.
    """
    out: list[Notice] = []
    for c in comps:
        for t in c.all_trials:
            out += _trial_notices(t)
        predicted = c.predicted_marker_travel_m if c.prediction.valid else math.nan   # the same marker's
        for m in c.trials:
            out += _track_notices(c, m, predicted)
    return out


def _trial_notices(t: Trial) -> list[Notice]:
    out = []
    if t.config_from not in (CONFIG_GIVEN, CONFIG_FROM_RECORD):
        where = t.run_path.parent if t.run_path else t.track.path if t.track else t.label
        out.append(Notice("configuration-guessed", t.config, t.label,
                          f"{t.label}: leg set {t.config!r} was guessed from the {t.config_from} ({where}), not "
                          f"given: say which leg set was filmed with --measured {t.config}=PATH",
                          f"the leg set was guessed from the {t.config_from}, not given: say which leg set was "
                          "filmed with --measured NAME=PATH, or record it with `locust hop --leg-set NAME`"))
    where, why = recorded_on(t.record)
    if where == VIRTUAL:
        out.append(Notice("virtual-robot", t.config, t.label,
                          f"{t.label}: the 'measured' trial comes from the virtual robot ({why}): it measures the "
                          "simulated robot, not the physical one",
                          "the 'measured' trials come from the virtual robot: they measure the simulated robot, "
                          "not the physical one"))
    return out


def _track_notices(c: Comparison, m: Trial, predicted_m: float) -> list[Notice]:
    out = []
    track, label = m.track, m.label
    travel = float(np.median(m.trace.x_m[-END_SAMPLES:]))           # from where it stood to where it ended
    marker = f"tracked {track.marker}"
    if math.isfinite(predicted_m) and abs(predicted_m) >= MIN_TRAVEL_M and abs(travel) >= MIN_TRAVEL_M \
            and (travel > 0) != (predicted_m > 0):
        advice = ("the track was mirrored with --mirror: try without it" if track.mirrored else
                  "the camera likely saw the hop mirrored (filmed right-to-left): give --mirror")
        out.append(Notice("mirrored", c.config, label,
                          f"{label}: the {marker} travels {_length(travel)} overall where the model predicts "
                          f"{_length(predicted_m)}: {advice}",
                          f"the {marker} travels against the model's prediction: {advice}"))
    elif not math.isfinite(predicted_m) and travel <= -MIN_TRAVEL_M and not track.mirrored:
        out.append(Notice("mirrored", c.config, label,
                          f"{label}: the {marker} moves backwards overall ({_length(travel)}): if the hop was "
                          "filmed right-to-left (the camera saw it mirrored), give --mirror",
                          f"the {marker} moves backwards overall: if the hop was filmed right-to-left (the camera "
                          "saw it mirrored), give --mirror"))
    hops = [abs(h.distance_m) for h in m.hops if math.isfinite(h.distance_m)]
    jumps = [h.apex_m for h in m.hops if math.isfinite(h.apex_m)]
    # the typical sizes are a desk robot's, not the prediction's: a model can be off by more than a unit
    if hops and max(hops) > MAX_HOP_M:
        size = max(hops)
        out.append(Notice("units", c.config, label,
                          f"{label}: {size:.3g} m in one hop is not this robot's (at most {MAX_HOP_M:g} m): "
                          + units_hint(size, 1e-3, MAX_HOP_M, TYPICAL_HOP_M, track.units)))
    elif jumps and max(jumps) > MAX_JUMP_M:
        size = max(jumps)
        out.append(Notice("units", c.config, label,
                          f"{label}: a {size:.3g} m jump is not this robot's (at most {MAX_JUMP_M:g} m): "
                          + units_hint(size, 1e-3, MAX_JUMP_M, TYPICAL_JUMP_M, track.units)))
    elif hint := span_hint(track):
        out.append(Notice("units", c.config, label, f"{label}: {hint}"))
    return out


def _length(value_m: float) -> str:
    """``+9.0 mm``, ``-600 m``: a signed travel in mm (the hop figures' unit), or metres from 1 m."""
    return f"{value_m * 1000:+.1f} mm" if abs(value_m) < 1 else f"{value_m:+.4g} m"
