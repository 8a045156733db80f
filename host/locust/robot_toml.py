"""The text of a ``robot.toml``, written by a real TOML writer (tomlkit).

:mod:`locust.params` owns the file (its reader, ``load_robot``, and ``save_robot``, which reads
each write back before it replaces the old file); this module only turns values and their
provenance into TOML. Given the file being replaced, it changes that document in place, so
the comments and the layout a person gave it are kept; every string is escaped by tomlkit
(control characters, quotes, backslashes, newlines), and a string Python holds but UTF-8
cannot (a file name's undecodable byte, kept as a lone surrogate) is written as its ``\\udcXX``
escape text.
"""

from __future__ import annotations

import math
from typing import Any

import tomlkit
from tomlkit.items import InlineTable, Table

from .fileio import storable

HEADER = (
    "locust robot parameters. Each value: {value, source, uncertainty (1 sigma), date, note}.",
    "source: default | seed | photo:, cut_file:, datasheet:, data:, estimate:<what> | preset:<name>",
    "| override | fit:<recording>.",
)

PROVENANCE_KEYS = ("source", "uncertainty", "date", "note")


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
                  template: str | None = None) -> str:
    """The TOML text of a robot.

    Parameters
    ----------
    name : str
        The robot's name.
    sections : dict
        ``{section: {field: (value, provenance)}}``, the provenance a dict of ``source``,
        ``uncertainty`` (1 sigma, the value's unit), ``date`` and ``note`` (None: left out).
    template : str, optional
        The TOML text of the file being replaced (valid TOML): its comments, order and layout
        are kept, its values replaced. None: a new file with the usual header.

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
    for section, entries in sections.items():
        table = doc.get(section)
        if not isinstance(table, Table):
            if section in doc:
                del doc[section]
            table = tomlkit.table()
            doc[section] = table
        for key, (value, provenance) in entries.items():
            table[key] = _entry(value, provenance, table.get(key))
    return tomlkit.dumps(doc)
