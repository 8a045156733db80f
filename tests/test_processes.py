"""What a killed, terminated or starved command leaves behind: no temporary video after a
TERM, none after the rerun that follows a kill -9, and a video that fails on a full disk is an
error whose run record says so."""

from __future__ import annotations

import json
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import locust
from locust.fileio import remove_stale_temporaries, temp_beside

LOCUST = [sys.executable, "-c", "from locust.commands import main; main()"]


def _here(env: dict | None = None) -> dict:
    """``env`` (default: this one) with this checkout's locust first on the path: the commands
    below run in other folders, where a relative PYTHONPATH finds nothing."""
    env = dict(os.environ if env is None else env, MUJOCO_GL="osmesa", PYOPENGL_PLATFORM="osmesa")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(locust.__file__).resolve().parents[1]),
                                         *filter(None, env.get("PYTHONPATH", "").split(os.pathsep))])
    return env


def _dead_pid() -> int:
    child = subprocess.Popen(["true"])
    child.wait()
    return child.pid


def test_only_temporaries_of_the_same_target_whose_writer_is_gone_are_removed(tmp_path):
    dead, alive = _dead_pid(), os.getpid()
    target = tmp_path / "hop.mp4"
    fd, mine = temp_beside(target, suffix=".mp4")   # this process's own: kept
    os.close(fd)
    stale = [f".hop.mp4.{dead}.abcd_123.mp4", f".hop.mp4.{dead}.zz9zz9zz.tmp", f".hop.mp4.{dead}.q0q0q0q0"]
    kept = [f".hop.mp4.{alive}.abcd_123.mp4",          # a writer still running
            f".hop.mp4.{dead}.abc.mp4",                 # not mkstemp's 8 characters
            f"hop.mp4.{dead}.abcd_123.mp4",             # not hidden
            f".hop.mp4.{dead}.abcd_123.mp4.notes.txt",  # more after the suffix
            f".other.mp4.{dead}.abcd_123.mp4",          # another target's
            f".hop.mp4.x{dead}.abcd_123.mp4", ".hop.mp4.notes", "hop.truth.csv"]
    for name in stale + kept:
        (tmp_path / name).write_text("x")
    (tmp_path / f".hop.mp4.{dead}.dir00000").mkdir()  # not a regular file
    removed = remove_stale_temporaries(target)
    assert sorted(p.name for p in removed) == sorted(stale)
    left = {p.name for p in tmp_path.iterdir()}
    assert left == {*kept, Path(mine).name, f".hop.mp4.{dead}.dir00000"}


# the command signals itself while the video is being written (its third frame), as a kill
# from outside would: at a point that does not depend on the machine's speed
_SIGNALLED_AT_FRAME_3 = """
import os, signal, sys
from locust.sim import clip
SIGNAL = getattr(signal, sys.argv.pop(1))
add_frame = clip.ClipRecorder.add_frame
def add_frame_then_signal(self, *args):
    add_frame(self, *args)
    if self.frames == 3:
        os.kill(os.getpid(), SIGNAL)
clip.ClipRecorder.add_frame = add_frame_then_signal
from locust.commands import main
sys.argv[0] = "locust"
main()
"""


def _temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(".hop.mp4."))


def test_a_killed_video_leaves_a_temporary_the_next_run_removes_and_term_leaves_none(tmp_path):
    args = ["sim", "--cycles", "1", "--camera", "fixed", "--video", "hop.mp4"]
    env = _here()
    killed = subprocess.run([sys.executable, "-c", _SIGNALLED_AT_FRAME_3, "SIGKILL", *args], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=300)
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    left = _temporaries(tmp_path)
    assert len(left) == 1 and left[0].startswith(".hop.mp4.") and left[0].endswith(".mp4")   # kill -9: no cleanup
    termed = subprocess.run([sys.executable, "-c", _SIGNALLED_AT_FRAME_3, "SIGTERM", *args], cwd=tmp_path, env=env,
                            capture_output=True, text=True, timeout=300)
    assert termed.returncode == 128 + signal.SIGTERM, termed.stderr
    assert "Traceback" not in termed.stderr
    # the rerun removed the stale one before it began; TERM unwound and removed its own
    assert _temporaries(tmp_path) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == []


_ENCODE_TERMINATED_AT_FRAME_3 = """
import os, signal, sys
import numpy as np
from locust.fileio import unwind_on_termination
from locust.track.video import encode_video
unwind_on_termination()
def frames():
    for k in range(10):
        if k == 3:
            os.kill(os.getpid(), signal.SIGTERM)
        yield np.full((64, 64, 3), 20 * k, np.uint8)
encode_video(sys.argv[1], frames(), 30.0, (64, 64))
"""


def test_a_terminated_overlay_or_side_by_side_encode_leaves_nothing(tmp_path):
    """``track`` overlays and ``report --side-by-side`` write through encode_video."""
    r = subprocess.run([sys.executable, "-c", _ENCODE_TERMINATED_AT_FRAME_3, str(tmp_path / "hop.mp4")],
                       capture_output=True, text=True, timeout=120, env=_here())
    assert r.returncode == 128 + signal.SIGTERM, r.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_video_that_reads_back_short_is_refused(tmp_path):
    """A full disk makes OpenCV's writer drop frames without a word: the file is checked."""
    from locust.errors import WriteError
    from locust.track.video import check_encoded, encode_video

    path = encode_video(tmp_path / "ok.mp4", (np.full((64, 64, 3), 9 * k, np.uint8) for k in range(12)), 30.0,
                        (64, 64))
    check_encoded(path, 12, path)
    for frames in (11, 13):
        with pytest.raises(WriteError, match=f"12 of {frames} frames"):
            check_encoded(path, frames, path)
    cut = tmp_path / "cut.mp4"
    cut.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    with pytest.raises(WriteError, match="0 of 12 frames"):
        check_encoded(cut, 12, cut)


def test_a_filmed_hop_onto_a_full_disk_is_an_error_and_the_record_says_so(env, tmp_path):
    """A file-size limit (20 kB) stands in for a nearly full disk: run.json (under 2 kB) fits, the video
    (164 frames, about 190 kB) does not."""
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)

    proc = subprocess.run(LOCUST + ["hop", "--port", "sim", "--cycles", "1", "--video", "hop.mp4", "--out", "run"],
                          cwd=tmp_path, env=_here(env), preexec_fn=limit, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and "Exception in thread" not in proc.stderr
    assert "error: the virtual robot's simulation failed" in proc.stderr and "hint:" in proc.stderr
    assert "disk may be full" in proc.stderr
    rec = json.loads((tmp_path / "run" / "run.json").read_text())
    assert rec["status"] == "incomplete" and "the video could not be written" in rec["message"]
    assert len(rec["phases"]) == 2   # both phases of the cycle are kept
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]   # no video, no temporary file
