"""`locust track video` never writes onto a frame of an image sequence, nor a file the next
run would read as one of its frames, --force or not, and never writes
beside a device (`--out /dev/null`). The frames are synthetic: a magenta patch on black."""

from __future__ import annotations

import hashlib
from pathlib import Path

import cv2
import numpy as np
import pytest
from click.testing import CliRunner

from locust.commands import cli
from locust.track.video import probe, read_as_frame


def frames(folder: Path, n: int = 4) -> list[Path]:
    folder.mkdir()
    for i in range(n):
        img = np.zeros((60, 80, 3), np.uint8)
        img[20:30, 10 + 5 * i:20 + 5 * i] = (140, 48, 232)
        cv2.imwrite(str(folder / f"f{i:03d}.png"), img)
    return sorted(folder.iterdir())


def digests(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.md5(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


def track(*args):
    return CliRunner().invoke(cli, ["track", "video", *map(str, args)])


@pytest.mark.parametrize("out", ["f002", "f001.csv", "f007", "f1000"])
def test_numbered_run_out_on_its_frames_is_refused(tmp_path, out):
    seq = tmp_path / "seq"
    frames(seq)
    before = digests(seq)
    res = track(seq / "f000.png", "--fps", 10, "--out", seq / out, "--force")
    assert res.exit_code == 2, res.output
    assert "error:" in res.output and "a frame of the image sequence" in res.output and "hint:" in res.output
    assert digests(seq) == before   # no frame changed, nothing added


def test_folder_sequence_out_into_its_folder_is_refused(tmp_path):
    seq = tmp_path / "seq2"
    frames(seq)
    before = digests(seq)
    res = track(seq, "--fps", 10, "--out", f"{seq}/")
    assert res.exit_code == 2 and "seq2.tracks.png" in res.output, res.output
    assert digests(seq) == before
    assert len(probe(seq).images) == 4   # the next run still sees 4 frames


def test_out_beside_the_run_under_another_name_is_written(tmp_path):
    seq = tmp_path / "seq"
    frames(seq)
    res = track(seq / "f000.png", "--fps", 10, "--marker", "spot=color:#e8308c", "--out", seq / "tracked")
    assert res.exit_code == 0, res.output
    assert (seq / "tracked.csv").is_file() and (seq / "tracked.png").is_file()
    assert len(probe(seq / "f000.png").images) == 4   # tracked.png is no frame of f###.png


def test_read_as_frame_rules(tmp_path):
    seq = tmp_path / "seq"
    frames(seq)
    numbered, folder = probe(seq / "f000.png"), probe(seq)
    assert read_as_frame(numbered, seq / "f003.png") and read_as_frame(numbered, seq / "f050.png")
    assert not read_as_frame(numbered, seq / "f050.jpg") and not read_as_frame(numbered, seq / "g001.png")
    assert not read_as_frame(numbered, tmp_path / "f004.png")   # another folder
    assert read_as_frame(folder, seq / "anything.JPG") and not read_as_frame(folder, seq / "tracks.csv")


def test_out_on_a_device_is_refused(tmp_path):
    seq = tmp_path / "seq"
    frames(seq)
    res = track(seq / "f000.png", "--fps", 10, "--out", "/dev/null", "--force")
    assert res.exit_code == 2 and "is a device or pipe" in res.output, res.output
    assert not Path("/dev/null.csv").exists()
