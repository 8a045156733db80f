"""``locust measure stance|nose-load|supply``: the robot as built, from photos (docs/measure.md),
a kitchen scale and a multimeter (docs/hardware.md).

One module a subcommand (:mod:`.stance`, :mod:`.nose_load`, :mod:`.supply`): each parses its
options, runs its job (:mod:`locust.measure`) and prints.
"""

from __future__ import annotations

import click

from .nose_load import nose_load
from .stance import stance
from .supply import supply


@click.group()
def measure():
    """Measure the robot as built: its stance from photos (docs/measure.md), its nose load on
    a kitchen scale and its supply with a multimeter (docs/hardware.md)."""


for _command in (stance, nose_load, supply):
    measure.add_command(_command)
