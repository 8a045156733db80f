"""The host's side of the robot: serial ports, the protocol link, flashing, hops, and the virtual robot.

- ``ports``: list the serial ports, mark the likely ESP32, pick one for ``--port``;
  ``session``: resolve ``--port`` (a path, autodetection, or ``sim``, a virtual robot).
- ``link``: the protocol's host end (framed requests, replies, events, heartbeat);
  ``replies``: the board's replies and events checked like input files.
- ``flash``: copy the firmware to a board with mpremote, verify it, reset, shake hands.
- ``board``: the board's servo config read and changed (``locust config``);
  ``pose``: hold the servos at an angle (``locust pose``); ``hop``: run the hop schedule
  and keep ``run.json`` up to date; ``repl``: mpremote's REPL on the port.
- ``virtual``: the real firmware on the MicroPython unix port behind a pseudo-terminal,
  with the ``machine_shim`` modules as its hardware; ``plant``: what its servos drive
  (a recorder or the live MuJoCo model); ``announce``: which robot a running
  ``locust virtual`` simulates.
"""
