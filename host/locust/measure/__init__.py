"""Measuring the robot as built from photos (``locust measure``).

``stance.py``: the stance from side photos with a board and stickers (``measure stance``);
``cli.py``: the command group.
"""
