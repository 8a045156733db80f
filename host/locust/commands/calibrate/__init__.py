"""``locust calibrate beam|hinge|servo|ramp|fold|hop``: recordings in, fitted values (and robot.toml) out.

One module a subcommand (:mod:`.beam`, :mod:`.hinge`, :mod:`.servo`, :mod:`.ramp`, :mod:`.fold`, :mod:`.hop`):
each parses its options, runs its job (:mod:`locust.calibrate.jobs`, what ``locust.calibrate_*``
runs too) and prints (:mod:`.output`); the options they share are in :mod:`.options`.
"""

from __future__ import annotations

import click

from .beam import beam
from .fold import fold
from .hinge import hinge
from .hop import hop
from .ramp import ramp
from .servo import servo


@click.group()
def calibrate() -> None:
    """Identify the robot's physics from the Part 2 experiments.

    \b
    beam   cardstock cantilever, dropped tip mass  -> hinge stiffness, damping
    hinge  a link swinging on a flexure hinge     -> hinge stiffness, damping (large angles)
    servo  servo steps: filmed angle, gyro on the horn -> no-load speed, armature, kp
    ramp   ramp tilted until the robot slides      -> static friction mu
    fold   a fold clamped, photos without and with a coin -> a fold's stiffness, rest angle
    hop    filmed hops of one or more leg sets     -> any parameters, jointly

    Each prints the fitted values with 95% confidence intervals, draws a fit plot, and with
    --write updates robot.toml (only the fitted values, each with source fit:<file>, its
    uncertainty and the date). How to film each experiment: calibration/protocols/.
    """


for _command in (beam, hinge, servo, ramp, fold, hop):
    calibrate.add_command(_command)
