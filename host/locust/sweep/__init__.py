"""Design sweeps and optimisation over the simulation: the steps behind ``locust sweep`` and
``locust optimize`` (:func:`locust.sweep_designs`, :func:`locust.optimize`).

- ``design``: one design: the axes and bounds it varies (``--vary``), the robot they make,
  its checks before simulating and its result row.
- ``execute``: where designs run: local processes, or a Dask cluster.
- ``run``: the sweep over a grid of designs, into the folder :mod:`locust.io.sweep_store`
  owns (results.csv and sweep.json), resumed when rerun; ``plot``: its landscape plots.
- ``optimize``: the Optuna study of the designs that hop farthest and highest without going
  over; ``objectives``: what a design is judged by; ``robust``: a design judged on its
  nominal run or over draws of its uncertain values; ``pareto``: the front, its ends and
  knee, ``pareto.png``; ``storage``: the study's journal or database, checked before Optuna
  touches it; ``journal``: a journal torn by a full disk, and its repair.
"""
