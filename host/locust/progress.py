"""Progress bars on stderr, silent when stderr is not a terminal (logs, pipes, CI)."""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import Any

import click


class _Silent:
    """What ``progress`` gives off a terminal: the same use, no output."""

    def __init__(self, items: Iterable | None):
        self._items = items

    def __enter__(self) -> _Silent:
        return self

    def __exit__(self, *exc: Any) -> bool:
        return False

    def __iter__(self):
        return iter(self._items if self._items is not None else ())

    def update(self, n_steps: int = 1, current_item: Any = None) -> None:
        pass


def progress(items: Iterable | None = None, length: int | None = None, label: str = "", **options: Any):
    """``click.progressbar`` over ``items`` or ``length`` steps on stderr; silent off a terminal.

    Use as ``with progress(length=n, label="x") as bar: ... bar.update(1)`` or
    ``with progress(items, label="x") as bar: for item in bar: ...``.
    """
    if not sys.stderr.isatty():
        return _Silent(items)
    return click.progressbar(items, length=length, label=label, file=sys.stderr, **options)
