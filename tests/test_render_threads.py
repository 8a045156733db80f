"""An offscreen renderer used, closed or collected on another thread than the one that made it
does not crash the next render on either thread (it was a SIGSEGV in OSMesaMakeCurrent: a
context freed while still current on another thread). Two ways it happens: the garbage
collector runs wherever an allocation triggers it (a progress ticker, a test runner's own
thread), and a virtual robot's clip renders its first frames on the caller's thread and the
rest, then closes, on its plant thread."""

from __future__ import annotations

import subprocess
import sys

import pytest

COLLECTED = """
import gc, threading
from locust.params import preset
from locust.sim.clip import PoseRenderer
from locust.sim.camera import CameraView
from locust.sim.model import build

model = build(preset("small")).model
for _ in range(20):
    dropped = PoseRenderer(model, 64, 48, shadows=False)
    dropped.pose(model.qpos0)
    dropped.render(CameraView((0.0, 0.0, 0.05), 0.4))
    dropped.cycle = dropped          # only the cycle collector frees it
    del dropped
    t = threading.Thread(target=gc.collect)
    t.start()
    t.join()
    kept = PoseRenderer(model, 64, 48, shadows=False)
    kept.pose(model.qpos0)
    rgb, _ = kept.render(CameraView((0.0, 0.0, 0.05), 0.4))
    kept.close()
print(rgb.shape)
"""


SHARED = """
import threading
from locust.params import preset
from locust.sim.clip import PoseRenderer
from locust.sim.camera import CameraView
from locust.sim.model import build

model = build(preset("small")).model
view = CameraView((0.0, 0.0, 0.05), 0.4)
for _ in range(20):
    shared = PoseRenderer(model, 64, 48, shadows=False)   # its first frames here
    shared.pose(model.qpos0)
    shared.render(view)

    def elsewhere():
        shared.pose(model.qpos0)                          # the rest, and its end, on another thread
        shared.render(view)
        shared.close()

    t = threading.Thread(target=elsewhere)
    t.start()
    t.join()
    kept = PoseRenderer(model, 64, 48, shadows=False)
    kept.pose(model.qpos0)
    rgb, _ = kept.render(view)
    kept.close()
print(rgb.shape)
"""


@pytest.mark.parametrize("script", [COLLECTED, SHARED], ids=["collected elsewhere", "closed elsewhere"])
def test_a_renderer_freed_on_another_thread_leaves_the_next_render_whole(script):
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, (done.returncode, done.stderr[-2000:])
    assert done.stdout.strip() == "(48, 64, 3)"
