"""Measuring the robot as built (``locust measure``).

``nose_load.py``: the servo axis's place along the plate (and the plate's mass) from the
nose's weight on a kitchen scale (``measure nose-load``); ``cli.py``: the command group.
"""
