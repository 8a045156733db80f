"""The host's side of the robot: serial ports, the protocol link, flashing, hops, and the virtual robot.

- :mod:`.ports`: list the serial ports, mark the likely ESP32, pick one for ``--port``;
  :mod:`.session`: resolve ``--port`` (a path, autodetection, or ``sim``, a virtual robot).
- :mod:`.link`: the protocol's host end (framed requests, replies, events, heartbeat);
  :mod:`.replies`: the board's replies and events checked like input files; :mod:`.holders`:
  who else has the port open (a second reader takes the board's bytes).
- :mod:`.flash`: copy the firmware to a board with mpremote, verify it, reset, shake hands.
- :mod:`.board`: the board's servo config read and changed (``locust config``);
  :mod:`.pose`: hold the servos at an angle (``locust pose``); :mod:`.hop`: run the hop schedule
  and keep ``run.json`` up to date; :mod:`.hop_job`: the hop as a job, from options to the
  record (``locust hop`` and ``locust.hop``); :mod:`.repl`: mpremote's REPL on the port;
  :mod:`.interrupts`: a TERM or HUP ends a command as Ctrl-C does.
- :mod:`.virtual`: the real firmware on the MicroPython unix port behind a pseudo-terminal,
  with the ``machine_shim`` modules as its hardware; :mod:`.console`: the bridge between its
  pseudo-terminals; :mod:`.pwm`: its PWM writes as horn angles; :mod:`.plant`: what its servos drive
  (a recorder or the live MuJoCo model); :mod:`.stalls`: how long the host held its
  interpreter off the CPU while a phase was due; :mod:`.announce`: which robot a running
  ``locust virtual`` simulates.
"""
