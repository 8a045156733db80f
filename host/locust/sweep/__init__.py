"""Design sweeps and optimisation over the simulation: design (axes, checks, one design's
evaluation), execute (local processes or Dask), run (the sweep, into the folder
:mod:`locust.io.sweep_store` owns: results.csv and sweep.json), plot, optimize (Optuna), cli."""
