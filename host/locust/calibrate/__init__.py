"""``locust calibrate``: identify the robot's physics from the three Part 2 experiments.

- ``beam``: a cardstock cantilever with a dropped tip mass -> hinge stiffness and damping.
- ``servo``: a servo stepped while carrying a battery -> kp, kv and torque limit of the
  position-servo law the MuJoCo model uses.
- ``ramp``: a ramp tilted until the robot slides -> static friction, mu = tan(theta).

Each fit is a pure function (numbers in, a result dataclass out); reading recordings,
plotting and updating ``robot.toml`` happen at the edges (``recordings``, ``plots``,
``write``, ``cli``).
"""
