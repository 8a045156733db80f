"""``locust measure stance|nose-load|stroke|supply``: the robot as built, from photos
(docs/measure.md), a kitchen scale, clips of a push and a multimeter (docs/hardware.md).

One module a subcommand (:mod:`.stance`, :mod:`.nose_load`, :mod:`.stroke`, :mod:`.supply`): each parses its
options, runs its job (:mod:`locust.measure`) and prints.
"""

from __future__ import annotations

import click

from .nose_load import nose_load
from .stance import stance
from .stroke import stroke
from .supply import supply


@click.group()
def measure():
    """Measure the robot as built: its stance from photos (docs/measure.md), its nose load on
    a kitchen scale, its servo's stroke from clips of a push and its supply with a multimeter
    (docs/hardware.md)."""


for _command in (stance, nose_load, stroke, supply):
    measure.add_command(_command)
