"""Design sweeps and optimisation over the simulation: the steps behind ``locust sweep`` and
``locust optimize`` (:func:`locust.sweep_designs`, :func:`locust.optimize`).

- :mod:`.design`: one design: the axes and bounds it varies (``--vary``), the robot they make,
  its checks before simulating and its result row.
- :mod:`.execute`: where designs run: local processes, or a Dask cluster.
- :mod:`.run`: the sweep over a grid of designs, into the folder :mod:`locust.io.sweep_store`
  owns (results.csv and sweep.json), resumed when rerun; :mod:`.plot`: its landscape plots.
- :mod:`.study`: the study job both ``locust optimize`` and :func:`locust.optimize` call
  (``optimize_study`` with its ``OptimizeOptions``).
- :mod:`.optimize`: the Optuna study of the designs that hop farthest and highest without going
  over; :mod:`.trial`: one trial of it, in a worker; :mod:`.objectives`: what a design is
  judged by; :mod:`.robust`: a design judged on its nominal run or over draws of its uncertain
  values; :mod:`.pareto`: the front, its ends and knee, ``pareto.png``; :mod:`.views`:
  Optuna's own history, importances and interactive front, ``study.html``; :mod:`.storage`:
  the study's journal or database, checked before Optuna touches it; :mod:`.journal`: a
  journal torn by a full disk, and its repair.
"""
