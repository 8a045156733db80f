"""The batched evaluation of a design's draws (locust.sim.samples): in batches with progress,
the draws and their figures are the ones a single batch gives."""

from __future__ import annotations

import numpy as np

from locust.params import preset
from locust.sim import samples
from locust.sim.rollout import available_cores


def test_draws_in_batches_with_progress_are_the_same_draws():
    robot = preset("small")
    n = samples.BATCH_PER_CORE * available_cores() + 3          # one full batch and a part
    whole = samples.sample(robot, n, cycles=1, seed=5)
    calls: list[int] = []
    batched = samples.sample(robot, n, cycles=1, seed=5, progress=calls.append)
    assert sum(calls) == n and len(calls) >= 2
    for key in ("distance_m", "max_nose_height_m"):   # bit for bit, failed draws (nan) alike
        assert np.array_equal(getattr(batched, key), getattr(whole, key), equal_nan=True), key
    assert whole.n_valid >= n - 2   # the as-built small's draws mostly stand (the check is not vacuous)
