"""Measuring the robot as built (``locust measure``, whose commands are in
:mod:`locust.commands.measure`).

- :mod:`.stance`: the stance from side photos with a board and stickers (``measure stance``):
  crank start and ground angle [deg] and the servo axis's place along the plate [m]; with
  ``--side``, that side's crank and its spline tooth (:mod:`.tooth`).
- :mod:`.nose_load`: the servo axis's place along the plate [m] (and the plate's mass [kg])
  from the nose's weight on a kitchen scale (``measure nose-load``).
- :mod:`.stroke`: the stroke the servo delivers and its speed, from side clips of a push on
  the floor and held up, beside the model's (``measure stroke``): the crank's angle over a
  clip from four stickers (:mod:`.crankclip`), the push's swing read from it (:mod:`.swing`),
  the CSV and plot written (:mod:`.strokeout`); :mod:`.strokejob` is the job behind the
  command and :func:`locust.measure_stroke`.
- :mod:`.supply`: the supply's voltage and the source's resistance or current limit [ohm, A]
  from a multimeter at the servo plug, at rest and stalled (``measure supply``); :mod:`.meter`
  is a meter's accuracy, ±(P % + N digits), and the readings such a meter gives.
"""
