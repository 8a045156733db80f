"""Design sweeps and optimisation over the simulation: design (axes, checks, one design's
evaluation), execute (local processes or Dask), store (results.csv and sweep.json), run
(the sweep), plot, optimize (Optuna), cli."""
