"""The demo's story and its truths: the virtual robot it hops, and that robot's bench.

- :mod:`.virtual_robot`: the hidden robot the virtual board simulates, a draw of the robot as
  built within its stated uncertainties (``HOP_FIT_SETS``: the leg sets whose filmed hops are
  fitted).
- :mod:`.bench`: that robot's parts on the bench (a hinge swing, a servo step and stall, ramp
  trials), written as SYNTHETIC recordings for ``locust calibrate``.

``locust demo`` (:mod:`locust.commands.demo`) runs the toolkit's commands on them; the tests
and benchmarks read the truths from here.
"""
