"""The demo: its story, the commands it runs, and its truths (the virtual robot it hops, and
that robot's bench).

- :mod:`.options`: what a demo is asked for (``DemoOptions``: its folder and sizes, with the
  ranges ``locust demo`` takes).
- :mod:`.story`: the demo itself (``run_story``: its stages, what runs in each), called by
  ``locust demo`` and :func:`locust.run_demo` alike.
- :mod:`.runner`: each stage's commands as child processes, logged and timed, side by side
  where a stage allows it, all ended together when the demo is stopped.
- :mod:`.virtual_robot`: the hidden robot the virtual board simulates, a draw of the robot as
  built within its stated uncertainties (``HOP_FIT_SETS``: the leg sets whose filmed hops are
  fitted), and its truth files.
- :mod:`.bench`: that robot's parts on the bench (a hinge swing, a servo step and stall, ramp
  trials), written as SYNTHETIC recordings for ``locust calibrate``.

The tests and benchmarks read the truths from here.
"""
