r"""``robot.toml``: the robot's parameters with their provenance, read and written here alone.

``load_robot`` reads and checks a file into a :class:`~locust.params.Robot`; ``save_robot``
writes one through a real TOML writer (tomlkit) and reads each write back before it replaces
the old file; ``update_robot`` changes a file under its lock; ``default_robot`` is the one
rule for the robot when none is named (this folder's ``calibration/robot.toml``, else the
robot as built); ``resolve_robot`` is the robot a command names (a preset or a file, with
``--set`` values on it). Given the file being replaced, it changes that document in place, so
the comments and the layout a person gave it are kept; every string is escaped by tomlkit
(control characters, quotes, backslashes, newlines), and a string Python holds but UTF-8
cannot (a file name's undecodable byte, kept as a lone surrogate) is written as its ``\udcXX``
escape text.
"""

from __future__ import annotations

import dataclasses
import math
import stat
import tomllib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import tomlkit
from tomlkit.items import InlineTable, Table

from ..errors import ParamsError
from ..fileio import atomic_write_text, locked, storable
from ..params.legsets import LEG_SETS
from ..params.limits import check_robot
from ..params.model import SECTIONS, Provenance, Robot, all_keys, parse_set_options, shown_value, split_key
from ..params.presets import DEFAULT_PRESET, PRESETS, preset

HEADER = (
    "locust robot parameters. leg_set: the filmed leg set the links carry (small, medium, large).",
    "Each value: {value, source, uncertainty (1 sigma), date, note}.",
    "source: default | seed | photo:, cut_file:, datasheet:, data:, estimate:<what> | preset:<name>",
    "| override | fit:<recording>.",
)

PROVENANCE_KEYS = ("source", "uncertainty", "date", "note")
TOP_KEYS = ("name", "base", "leg_set")   # the keys above the sections


def _item(value: Any) -> Any:
    if isinstance(value, str):
        return storable(value)
    if isinstance(value, float) and math.isnan(value):
        return math.nan   # (tomlkit writes nan, inf and -inf as TOML does)
    return value


def _entry(value: Any, provenance: dict[str, Any], old: Any) -> InlineTable:
    """The inline table ``{value, source, ...}``; ``old`` (the file's entry) keeps its own form."""
    entry = old if isinstance(old, InlineTable) else tomlkit.inline_table()
    entry["value"] = _item(value)
    for key in PROVENANCE_KEYS:
        v = provenance.get(key)
        if v is not None:
            entry[key] = _item(v)
        elif key in entry:
            del entry[key]
    for key in [k for k in entry if k != "value" and k not in PROVENANCE_KEYS]:
        del entry[key]   # what load_robot would not read is not kept
    return entry


def document_text(name: str, sections: dict[str, dict[str, tuple[Any, dict[str, Any]]]],
                  template: str | None = None, leg_set: str | None = None) -> str:
    """The TOML text of a robot.

    Parameters
    ----------
    name : str
        The robot's name.
    sections : dict
        ``{section: {field: (value, provenance)}}``, the provenance a dict of ``source``,
        ``uncertainty`` (1 sigma, the value's unit), ``date`` and ``note`` (None: left out). A
        value None (inherited) is absent from the file (TOML has no null): taken out of the
        template's section, and a section of nothing else is not made.
    template : str, optional
        The TOML text of the file being replaced (valid TOML): its comments, order and layout
        are kept, its values replaced. None: a new file with the usual header.
    leg_set : str, optional
        The leg set the robot carries (``Robot.leg_set``), written as ``leg_set`` after the name.

    Returns
    -------
    str
        TOML text that ``tomllib`` reads back to exactly these values.
    """
    if template is None:
        doc = tomlkit.document()
        for line in HEADER:
            doc.add(tomlkit.comment(line))
    else:
        doc = tomlkit.parse(template)
    doc["name"] = storable(name)
    if leg_set is not None:
        doc["leg_set"] = storable(leg_set)
    for section, entries in sections.items():
        table = doc.get(section)
        given = {key: entry for key, entry in entries.items() if entry[0] is not None}
        if not isinstance(table, Table):
            if section in doc:
                del doc[section]
            if not given:
                continue
            table = tomlkit.table()
            doc[section] = table
        for key in [k for k, (value, _) in entries.items() if value is None and k in table]:
            del table[key]
        for key, (value, provenance) in given.items():
            table[key] = _entry(value, provenance, table.get(key))
    return tomlkit.dumps(doc)



# -- TOML ---------------------------------------------------------------------------
def _uncertainty(path: Path, key: str, raw: Any) -> float | None:
    """One standard deviation, a finite number >= 0 in the value's unit, or absent."""
    if raw is None:
        return None
    if isinstance(raw, bool) or not isinstance(raw, (int, float)) or not math.isfinite(raw) or raw < 0:
        raise ParamsError(f"{path}: {key} has uncertainty = {raw!r}, not a number >= 0",
                          "write one standard deviation in the value's own unit, "
                          "e.g. uncertainty = 0.01, or leave it out")
    return float(raw)


# A robot.toml is a few kB (every value with its source and note: under 20 kB).
MAX_ROBOT_FILE_BYTES = 1_000_000


def _check_robot_file(path: Path) -> None:
    """:class:`ParamsError` unless ``path`` is a regular file of at most
    :data:`MAX_ROBOT_FILE_BYTES`: a pipe or a device is refused before it is opened (reading
    one blocks or never ends)."""
    info = path.stat()
    if not stat.S_ISREG(info.st_mode):
        raise ParamsError(f"{path}: not a regular file (a pipe, device or folder)",
                          "give the path of a robot.toml file")
    if info.st_size > MAX_ROBOT_FILE_BYTES:
        raise ParamsError(f"{path}: {info.st_size:,} bytes, over the {MAX_ROBOT_FILE_BYTES:,} a robot.toml can be",
                          "give a robot.toml (a few kB, as `locust params --write` makes)")


def load_robot(path: str | Path) -> Robot:
    """Read a robot.toml. Missing values fall back to those of the preset its ``base`` names,
    by default the robot as built (:data:`locust.params.DEFAULT_PRESET`); its ``leg_set``, to
    that preset's.

    Parameters
    ----------
    path : path-like

    Returns
    -------
    locust.params.Robot
        Each value with its provenance from the file.

    Raises
    ------
    locust.errors.ParamsError
        No such file, not UTF-8 or not TOML, an unknown section or key, a value of the wrong type
        or out of its limits.
    """
    path = Path(path)
    doc = _document(path)
    robot = _top(path, doc)
    for key, entry in _entries(path, doc):
        value, prov = _value(path, key, entry)
        try:
            robot = robot.with_values({key: value}, prov)
        except ParamsError as exc:
            raise ParamsError(f"{path}: {exc.message}", exc.hint) from None
    return robot


def _document(path: Path) -> dict[str, Any]:
    """The TOML document ``path`` holds; each way it cannot be read is a ParamsError."""
    try:
        _check_robot_file(path)
        return tomllib.loads(path.read_bytes().decode("utf-8"))
    except RecursionError:
        raise ParamsError(f"{path}: not a robot.toml: its tables or lists are nested too deep to read",
                          "a robot.toml has sections of key = value (or {value = ..., source = ...}) and no "
                          "deeper nesting; regenerate it with `locust params --write`") from None
    except FileNotFoundError:
        raise ParamsError(f"{path}: no such file", "give the path of a robot.toml, or use --preset") from None
    except UnicodeDecodeError as exc:
        raise ParamsError(f"{path}: not a robot.toml: byte {exc.start} is not UTF-8 text",
                          "give a robot.toml (UTF-8 text, as `locust params --write` makes), not another "
                          "kind of file") from None
    except OSError as exc:
        raise ParamsError(f"{path}: cannot read it ({exc.strerror})",
                          "give the path of a readable robot.toml file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParamsError(f"{path}: not valid TOML ({exc})",
                          "fix the file, or regenerate it with `locust params --write`") from None


def _top(path: Path, doc: dict[str, Any]) -> Robot:
    """The robot the keys above the sections make: the ``base`` preset, named, on its ``leg_set``."""
    base, name = doc.get("base", DEFAULT_PRESET), doc.get("name", path.stem)
    if not isinstance(base, str) or base not in PRESETS:
        raise ParamsError(f"{path}: base = {shown_value(base)} is not a preset", f"choose one of {', '.join(PRESETS)}")
    if not isinstance(name, str):
        raise ParamsError(f"{path}: name = {shown_value(name)} is not a string", 'write it in quotes: name = "mine"')
    robot = preset(base).renamed(name)
    legs = doc.get("leg_set", robot.leg_set)
    if not isinstance(legs, str) or legs not in LEG_SETS:
        raise ParamsError(f"{path}: leg_set = {shown_value(legs)} is not a leg set",
                          f"the leg set the robot's links carry: one of {', '.join(LEG_SETS)}")
    return dataclasses.replace(robot, leg_set=legs)


def _entries(path: Path, doc: dict[str, Any]) -> Iterator[tuple[str, Any]]:
    """Each value's dotted key and its entry as written, in the file's order, the sections and
    keys checked as they come."""
    for section, table in doc.items():
        if section in TOP_KEYS:
            continue
        if section not in SECTIONS:
            raise ParamsError(f"{path}: unknown section [{section}]", f"sections are {', '.join(SECTIONS)}")
        if not isinstance(table, dict):
            raise ParamsError(f"{path}: {section} = {shown_value(table)}, "
                              f"where a section [{section}] of values belongs",
                              f"write its values under a line [{section}]")
        for name, entry in table.items():
            key = f"{section}.{name}"
            try:
                split_key(key)
            except ParamsError as exc:
                raise ParamsError(f"{path}: {exc.message}", exc.hint) from None
            yield key, entry


def _value(path: Path, key: str, entry: Any) -> tuple[Any, Provenance]:
    """An entry's value and provenance: ``{value = ..., source = "..."}``, or a bare value
    (its source the file)."""
    if isinstance(entry, dict):
        if "value" not in entry:
            raise ParamsError(f"{path}: {key} has no 'value'", "write it as {value = ..., source = \"...\"}")
        for field in ("source", "date", "note"):
            if isinstance(entry.get(field), (dict, list)):
                raise ParamsError(f"{path}: {key} has {field} = {shown_value(entry[field])}, not a string",
                                  f'write it in quotes: {field} = "..."')
        prov = Provenance(
            source=str(entry.get("source", "default")),
            uncertainty=_uncertainty(path, key, entry.get("uncertainty")),
            date=None if entry.get("date") is None else str(entry["date"]),
            note=None if entry.get("note") is None else str(entry["note"]),
        )
        value = entry["value"]
    else:
        prov, value = Provenance(source=f"file:{path.name}"), entry
    if isinstance(value, (dict, list)):
        raise ParamsError(f"{path}: {key} = {shown_value(value)}, where a number belongs",
                          f"write one value: {key.split('.')[1]} = 0.05, or "
                          '{value = 0.05, source = "..."}')
    return value, prov


def to_toml(robot: Robot, template: str | None = None) -> str:
    """``robot`` as robot.toml text (:func:`document_text`); ``template``: the
    text of the file it replaces, whose comments and layout are kept.

    Parameters
    ----------
    robot : locust.params.Robot
    template : str, optional

    Returns
    -------
    str
    """
    sections = {
        section: {f.name: (robot.own(f"{section}.{f.name}"),
                           dataclasses.asdict(robot.source_of(f"{section}.{f.name}")))
                  for f in fields(SECTIONS[section])}
        for section in SECTIONS
    }
    return document_text(robot.name, sections, template, leg_set=robot.leg_set)


def _same(a: Any, b: Any) -> bool:
    """``a`` (read back) is ``b`` as the file stores it."""
    if isinstance(b, str):
        b = storable(b)
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))


def _read_back(robot: Robot, path: Path, tmp: Path) -> None:
    """Refuse (:class:`ParamsError`) a written robot.toml that does not read back to ``robot``."""
    try:
        back = load_robot(tmp)
    except ParamsError as exc:
        raise ParamsError(f"{path}: the robot file written does not read back ({exc.message}); "
                          "the old file is kept", "report this as a bug in locust, with the command run") from None
    differ = [key for key in all_keys()
              if not _same(back.own(key), robot.own(key))
              or dataclasses.astuple(back.source_of(key)) != dataclasses.astuple(_stored(robot.source_of(key)))]
    if back.name != storable(robot.name):
        differ.insert(0, "name")
    if back.leg_set != robot.leg_set:
        differ.insert(0, "leg_set")
    if differ:
        raise ParamsError(f"{path}: the robot file written reads back different ({', '.join(differ[:5])}); "
                          "the old file is kept", "report this as a bug in locust, with the command run")


def _stored(prov: Provenance) -> Provenance:
    """``prov`` as the file holds it (text UTF-8 can store)."""
    return Provenance(*(storable(v) if isinstance(v, str) else v for v in dataclasses.astuple(prov)))


def file_text(path: Path) -> str | None:
    """The robot.toml at ``path`` as text, to keep its layout; None when there is none or it is
    not TOML (then it is not replaced anyway: load_robot refused it first).

    Parameters
    ----------
    path : pathlib.Path

    Returns
    -------
    str or None
    """
    try:
        text = path.read_bytes().decode("utf-8")
        tomllib.loads(text)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return None
    return text


def save_robot(robot: Robot, path: str | Path, *, template: str | None = None, exclusive: bool = False) -> Path:
    """Write ``robot`` to the robot.toml ``path``, atomically, and read it back first.

    Parameters
    ----------
    robot : Robot
        What to write: every value with its provenance.
    path : str or Path
        The file; one there already is replaced (but see ``exclusive``).
    template : str, optional
        TOML text whose comments and layout the new file keeps (the file being replaced, or the
        one the robot was read from).
    exclusive : bool
        Only create ``path``: :class:`~locust.errors.WriteError` if it exists, even when another
        process made it a moment ago.

    Returns
    -------
    Path
        The file written. It reads back (``load_robot``) to ``robot``'s values and provenance,
        or it is not written and the old file is kept (:class:`ParamsError`).
    """
    path = Path(path)
    text = to_toml(robot, template)
    return atomic_write_text(path, text, check=lambda tmp: _read_back(robot, path, tmp), exclusive=exclusive)


def update_robot(path: str | Path, change: Callable[[Robot], Robot], *, start: Callable[[], Robot] | None = None,
                 wait_s: float = 60.0) -> Path:
    """Read the robot.toml ``path``, change it and write it back, as one step for every process.

    Under an exclusive lock on ``path`` (:func:`locust.fileio.locked`), so two commands updating
    one file (``calibrate ... --write`` of two experiments) each see the other's values: no
    update is lost. The file's comments and layout are kept (:func:`save_robot`).

    Parameters
    ----------
    path : str or Path
        The robot.toml to update.
    change : callable
        ``Robot -> Robot``, the update; it may raise to leave the file as it is.
    start : callable, optional
        The robot when ``path`` does not exist yet: the one the command resolved
        (:func:`default_robot`, or the robot it was told), never a preset picked here. None:
        ``path`` must exist.
    wait_s : float
        How long to wait for another process's update, seconds.

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
    with locked(path, wait_s) as target:
        if target.exists():
            robot, template = load_robot(target), file_text(target)
        elif start is not None:
            robot, template = start(), None
        else:
            raise ParamsError(f"{path}: no such file", "give the path of an existing robot.toml to update")
        return save_robot(change(robot), path, template=template)


# what `locust calibrate --write` makes and every door looks for first: the robot as calibrated here
ROBOT_FILE = Path("calibration") / "robot.toml"


@dataclass(frozen=True)
class RobotChoice:
    """Which robot a command or the API runs on, and the line that says so.

    Attributes
    ----------
    preset : str or None
        The preset, when no robot file is used.
    robot_file : pathlib.Path or None
        The robot file, when one is used.
    line : str
        What the command prints first (on stderr): ``robot: ...``.
    """

    preset: str | None
    robot_file: Path | None
    line: str


def default_robot() -> RobotChoice:
    """The one resolution rule, for every door (the commands, the API, the notebook, the demo,
    ``calibrate --write`` of a new file): the robot file given (the caller's business), else
    this folder's ``calibration/robot.toml``, else the robot as built (:data:`DEFAULT_PRESET`).

    Returns
    -------
    RobotChoice
    """
    if ROBOT_FILE.is_file():
        return RobotChoice(None, ROBOT_FILE, f"robot: {ROBOT_FILE} (found here; --preset or --config to choose "
                                             "another)")
    return RobotChoice(DEFAULT_PRESET, None, f"robot: {DEFAULT_PRESET}, the robot as built (no {ROBOT_FILE} here; "
                                             "--preset or --config to choose another)")


def resolve_robot(preset_name: str | None = None, config: str | Path | None = None,
                  sets: tuple[str, ...] | list[str] = ()) -> Robot:
    """The robot a command runs on: ``--config`` file, else ``--preset``, else
    :func:`default_robot`; then ``--set``.

    Parameters
    ----------
    preset_name : str, optional
        A preset, used when no ``config`` is given.
    config : path-like, optional
        A robot.toml.
    sets : sequence of str
        ``KEY=VALUE`` overrides (``--set``), recorded with source ``override``.

    Returns
    -------
    locust.params.Robot

    Raises
    ------
    locust.errors.ParamsError
        An unknown preset, a file :func:`load_robot` refuses, a bad ``--set``, or a robot that
        cannot be simulated.
    """
    if config is None and preset_name is None:
        choice = default_robot()
        preset_name, config = choice.preset, choice.robot_file
    robot = load_robot(config) if config else preset(preset_name)
    overrides = parse_set_options(sets)
    return check_robot(robot.with_values(overrides, "override") if overrides else robot)
