"""Measuring the robot as built (``locust measure``, whose commands are in
:mod:`locust.commands.measure`).

- :mod:`.stance`: the stance from side photos with a board and stickers (``measure stance``):
  crank start and ground angle [deg] and the servo axis's place along the plate [m].
- :mod:`.nose_load`: the servo axis's place along the plate [m] (and the plate's mass [kg])
  from the nose's weight on a kitchen scale (``measure nose-load``).
"""
