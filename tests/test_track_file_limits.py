"""Track files have a stated size (locust.io.delimited.MAX_BYTES, MAX_LINES), refused before
they are read, as README says every file read has.

A 5,000,000-row tracks CSV (431 MB) ran `locust track import` into a MemoryError after 40 s at
2.6 GB; the reader splits about 1.3 kB of Python objects a row (673 MB for 500,000 rows,
measured). Every delimited file (tracks CSV, Tracker's text export, a t,x,y CSV, a gyro log)
is now at most 64 MB and 200,000 lines (14 minutes at 240 frames/s), refused before it is read
or split; the writers of tracks refuse what the reader would, and `locust track` a clip of more
frames, before it tracks. The files here are SYNTHETIC rows of increasing time."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from locust.errors import TrackError
from locust.io import delimited
from locust.io.tracks_csv import TracksCsv, read_tracks_csv, write_tracks_csv
from locust.track.video import Clip, VideoInfo
from probing import assert_clear_error, invoke, tree

HEADER = "frame,t_s,nose_px,nose_py,nose_x_m,nose_y_m,nose_ok\n"


def tracks_rows(path: Path, rows: int) -> Path:
    """A tracks CSV of ``rows`` frames at 240 frames/s, one marker, as `locust track` writes it."""
    frames = np.arange(rows)
    body = "".join(f"{f},{f / 240:.6f},{100 + f % 50}.1234,{80 + f % 30}.5678,0.012345,0.045678,1\n" for f in frames)
    path.write_text(HEADER + body)
    return path


def test_a_track_file_over_the_byte_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    big = tracks_rows(tmp_path / "big.tracks.csv", 1_250_000)      # 1.25 million frames
    size_mb = big.stat().st_size / 2**20
    assert size_mb > delimited.MAX_BYTES / 2**20
    before = tree(tmp_path)
    t0 = time.monotonic()
    res = invoke(["track", "import", big, "--out", "copy.csv"])
    seconds = time.monotonic() - t0
    assert_clear_error(res, f"big.tracks.csv is {size_mb:.0f} MB, over the 64 MB", "not read",
                       "cut the file to the experiment")
    assert seconds < 5, seconds       # refused from its size (read and split, it took 25 s and 1.2 GB)
    assert tree(tmp_path) == before


@pytest.mark.parametrize("layout", ["tracks", "tracker", "txy"])
def test_a_track_file_of_more_lines_than_the_limit_is_refused_and_one_at_it_read(tmp_path, layout):
    def write(path: Path, lines: int) -> Path:
        n = lines - {"tracks": 1, "tracker": 2, "txy": 1}[layout]
        t = np.arange(n) / 240
        if layout == "tracks":
            body = HEADER.replace(",nose_x_m,nose_y_m,nose_ok", "") + "".join(
                f"{k},{s:.6f},1,2\n" for k, s in enumerate(t))
        elif layout == "tracker":
            body = "mass A\nt\tx\ty\n" + "".join(f"{s:.6f}\t1\t2\n" for s in t)
        else:
            body = "t,x,y\n" + "".join(f"{s:.6f},1,2\n" for s in t)
        path.write_text(body)
        assert path.read_text().count("\n") == lines
        return path

    over = write(tmp_path / "over.csv", delimited.MAX_LINES + 1)
    res = invoke(["track", "import", over, "--out", tmp_path / "o.csv"])
    assert_clear_error(res, f"{delimited.MAX_LINES + 1:,} lines, over the {delimited.MAX_LINES:,}", "not read")
    assert not (tmp_path / "o.csv").exists()
    at = write(tmp_path / "at.csv", delimited.MAX_LINES)
    res = invoke(["track", "import", at, "--out", tmp_path / "o.csv"])
    assert res.exit_code == 0, res.output
    rows = delimited.MAX_LINES - (2 if layout == "tracker" else 1)
    back = read_tracks_csv(tmp_path / "o.csv")
    assert back.n_rows == rows and back.t_s[-1] == pytest.approx((rows - 1) / 240, abs=1e-6)


def test_tracks_a_reader_would_refuse_are_not_written(tmp_path):
    n = delimited.MAX_LINES          # with the header, one line over
    ones = np.ones(n)
    tracks = TracksCsv(np.arange(n), np.arange(n) / 240.0, px={"nose": ones}, py={"nose": ones}, x_m={"nose": ones},
                       y_m={"nose": ones}, ok={"nose": ones.astype(bool)})
    with pytest.raises(TrackError, match=f"would be {n + 1:,} lines, over the {delimited.MAX_LINES:,}"):
        write_tracks_csv(tmp_path / "t.csv", tracks)
    assert list(tmp_path.iterdir()) == []


def test_a_clip_of_more_frames_than_a_track_file_holds_is_refused_before_tracking():
    info = VideoInfo(Path("long.mp4"), 320, 240, 300_000, 240.0)      # 21 minutes at 240 frames/s
    with pytest.raises(TrackError, match="300,000 frames, more than a track file holds") as err:
        Clip().resolved(info)
    assert "--start" in err.value.hint and "--step" in err.value.hint
    assert len(Clip(step=2).resolved(info).frames()) == 150_000
    assert len(Clip(start=100_000).resolved(info).frames()) == 200_000
