"""The file formats, each owned by one module (typed object, writer and reader side by side).

This layer imports no other part of locust but ``errors``, ``fileio``, the firmware's protocol
table and (for ``robot.toml``) ``params``, so the simulation, tracking, calibration, the report
and the sweeps all read and write files through it without importing one another.

- :mod:`.delimited`    the tokenizer under every table of samples (tracks, exports, calibration CSVs)
- :mod:`.tracks_csv`   ``<video>.tracks.csv``, the tracks everyone reads
- :mod:`.tracker_text` Tracker's text export (*File > Export > Data*)
- :mod:`.trk`          Tracker projects (``.trk``, ``.trz``) and their calibration
- :mod:`.trz`          reading a ``.trz`` zip without trusting it: every member checked first
- :mod:`.importing`    any track file in any unit, renamed, mirrored: the one conversion that
                       ``track import``, ``calibrate`` and ``report`` read tracks through
- :mod:`.camera_json`  ``<video>.camera.json``, the pinhole camera of a simulated video
- :mod:`.run_record`   ``run.json``, a hop's run record
- :mod:`.sweep_store`  a sweep's folder: ``sweep.json`` and ``results.csv``
- :mod:`.study_store`  an optimisation's folder: ``trials.csv`` and ``pareto.csv``
- :mod:`.robot_toml`   ``robot.toml``, the robot's parameters with their provenance, and the robot
                       a command names (a preset or a file, with ``--set`` values)
"""
