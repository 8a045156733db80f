"""An offscreen renderer dropped unclosed and collected on another thread (the garbage
collector runs wherever an allocation triggers it: a progress ticker, the virtual robot's
plant, a test runner's own thread) does not crash the next render: its OpenGL context is freed
only on the thread it was current on (it was a SIGSEGV in OSMesaMakeCurrent)."""

from __future__ import annotations

import subprocess
import sys

SCRIPT = """
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


def test_a_renderer_collected_on_another_thread_leaves_the_next_render_whole():
    done = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, (done.returncode, done.stderr[-2000:])
    assert done.stdout.strip() == "(48, 64, 3)"
