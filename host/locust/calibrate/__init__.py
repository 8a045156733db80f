"""Identifying the robot's physics from recordings (``locust calibrate``, ``locust.calibrate_*``).

The experiments, one fit each (numbers in, a result dataclass out, values with intervals;
each robot value under its dotted robot key, ``compliance.hinge_stiffness_nm_per_rad``, in
the result's ``estimates``; what is the rig's, not the robot's, under a name of its own):

- :mod:`.beam`: a cardstock cantilever with a dropped tip mass -> the tip's stiffness [N/m] and
  damping [N·s/m]; with the beam's length, their pseudo-rigid-body hinge equivalents (k L², b L²),
  which hold for the robot only if its hinge is of the same material and width.
- :mod:`.beam_static`: the same cantilever loaded by hand and left to settle -> its static
  deflection, stiffness m g / delta and bending stiffness E I = k L³ / 3 (no robot value: the
  model's links are rigid and its hinges are folds).
- :mod:`.hinge`: a link ringing down on a flexure hinge -> the hinge's stiffness, damping and
  neutral angle; :mod:`.hingeswing` is the swinging link and its equation of motion,
  :mod:`.hingestart` what the swing shows before the fit (pivot, window, start values).
- :mod:`.servo`: a servo stepped while carrying a load (filmed horn or rate gyro) -> no-load
  speed, armature, kp and kv of the position-servo law the MuJoCo model uses.
- :mod:`.ramp`: a ramp tilted until the robot slides -> static friction, mu = tan(theta).
- :mod:`.fold`: a fold with one link clamped, photographed without and with a coin on its free
  link -> the fold's stiffness and rest offset; :mod:`.foldread` reads each photo's board and
  stickers, :mod:`.foldmoments` is its statics, :mod:`.foldfit` the fit and its intervals,
  :mod:`.coins` the coins' published masses, :mod:`.foldsynthetic` SYNTHETIC fold tests of
  known truth (the virtual rig of :mod:`locust.sim.foldrig`).
- :mod:`.hop`: filmed hops -> what no bench experiment reaches (friction under impact, the
  folded hinges in the linkage, the servo on the robot's battery); :mod:`.hopruns` loads each
  run (a :class:`locust.trials.measured.Trial`), simulates it on its measured phase times and
  sets its markers against the simulation's, :mod:`.hopresidual` stacks every run's residual
  for the solver, and :mod:`.hopmodels` sets a candidate's values in one compiled MuJoCo model
  instead of compiling each.

Each experiment as one job, what ``locust calibrate`` and ``locust.calibrate_*`` both run:
:mod:`.jobs` (recordings read and fitted), returning a :class:`~.result.Fit` (:mod:`.result`:
the robot values the recordings determine), whose plot and robot.toml :mod:`.outputs` writes.

Shared by the fits: :mod:`.fitparams` (each fit's values with unit, bounds and scaling, and
the solver's vector of them), :mod:`.fitstats` (intervals from the Jacobian, cluster-robust
where residuals are correlated) and :mod:`.curves` (data and model for a plot). At the edges:
:mod:`.recordings` (CSV, ``locust track`` CSV, Tracker files as one table), :mod:`.gyro_log`
(a controller's gyro log), :mod:`.inputs` (each experiment's recordings as its fit's inputs),
:mod:`.plots` (the fit plots), :mod:`.write` (fitted values into ``robot.toml``) and
:mod:`.synthetic` (SYNTHETIC recordings from known parameters, for the demo and the tests).
"""
