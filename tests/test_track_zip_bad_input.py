"""Hostile Tracker projects: a ``.trz`` whose members would land outside the folder they are
unpacked into (an absolute path, ``..``, a symbolic link), a zip bomb, too many members, an
encrypted member or one packed by an unknown method; a ``.trk`` with a billion laughs or an
external entity. Every command that opens one refuses it (``error:``/``hint:``, exit 2), reads
nothing from it, and no file anywhere changes (tests/probing.py).

The payloads are built here, around a synthetic project (a rendered hop video and its .trk):
the hostile member or entity is the only thing added; the real BallToss.trz
(../shared/data/tracker) still opens.
"""

from __future__ import annotations

import bz2
import hashlib
import os
import stat
import struct
import subprocess
import sys
import time
import zipfile
import zlib
from pathlib import Path

import numpy as np
import pytest

from locust.io import trz
from locust.track.calib import build
from locust.track.runner import TrackResult
from locust.track.synth import make_hop_video
from locust.track.trk import project_xml
from locust.track.video import Clip, VideoInfo
from probing import assert_clear_error, invoke, tree

LOCUST = [sys.executable, "-m", "locust.commands"]
VIDEO = "videos/hop.mp4"


@pytest.fixture(scope="module")
def members(tmp_path_factory) -> dict[str, bytes]:
    """A SYNTHETIC Tracker project's members: a 10-frame 160x90 hop video and the .trk opening
    it (one point mass, 1 mm/px), as Tracker saves a .trz."""
    folder = tmp_path_factory.mktemp("project")
    make_hop_video(folder / "hop.mp4", width=160, height=90, n_frames=10, seed=3)
    n = 10
    frames = np.arange(n)
    result = TrackResult.from_pixels(frames, frames / 30.0, {"nose": 80 + 2.0 * frames}, {"nose": 60 - 1.0 * frames},
                                     {"nose": np.ones(n, bool)}, {"nose": "color:#ff00ff"}, {"nose": np.ones(n)},
                                     build(90, 0.001, None, 0.0, "stick 0.001 m/px"), Clip(0, n - 1, 1, 30.0),
                                     video=VideoInfo(folder / "hop.mp4", 160, 90, n, 30.0))
    return {"p.trk": project_xml(result, folder / "p.trk", VIDEO).encode(),
            VIDEO: (folder / "hop.mp4").read_bytes()}


def hostile_trz(members: dict[str, bytes], folder: Path, kind: str, victim: Path) -> Path:
    """The project zipped with one member that would write ``victim`` (outside ``folder``)
    where its name points: an absolute path (the .trk opening a video beside the victim, so a
    reader that unpacks the video's folder reaches it), a ``..`` path (likewise), a symbolic
    link to the victim in the video's place, or a character device."""
    path = folder / f"{kind}.trz"
    trk, video = members["p.trk"], members[VIDEO]
    extra = []
    if kind == "absolute":
        trk = trk.replace(VIDEO.encode(), str(victim.parent / "hop.mp4").encode())
        extra = [(zipfile.ZipInfo(str(victim)), b"OVERWRITTEN BY ZIP")]
    elif kind == "dotdot":
        rel = os.path.relpath(victim.parent, folder)
        trk = trk.replace(VIDEO.encode(), f"{rel}/hop.mp4".encode())
        extra = [(zipfile.ZipInfo(f"{rel}/{victim.name}"), b"OVERWRITTEN BY ZIP")]
    elif kind == "symlink":
        link = zipfile.ZipInfo("videos/victim.txt")
        link.external_attr = (stat.S_IFLNK | 0o777) << 16
        extra = [(link, str(victim).encode())]
    elif kind == "device":
        dev = zipfile.ZipInfo("videos/tty")
        dev.external_attr = (stat.S_IFCHR | 0o666) << 16
        extra = [(dev, b"")]
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("p.trk", trk)
        z.writestr(VIDEO, video)
        for info, data in extra:
            z.writestr(info, data)
    return path


def commands(project: Path, out: Path) -> list[list]:
    """Every command that opens a Tracker project."""
    return [["track", "video", project, "--out", out / "v", "--force", "--overlay", "none"],
            ["track", "from-trk", project, "--out", out / "f.csv"],
            ["track", "import", project, "--out", out / "i.csv"],
            ["track", "preview", project, "--out", out / "p"],
            ["track", "video", out / "hop.mp4", "--calibration-from", project, "--out", out / "c", "--overlay", "none"],
            ["calibrate", "beam", project, "--mass-kg", "0.01", "--no-plot"],
            ["calibrate", "hinge", project, "--inertia-kgm2", "8.5e-7", "--gravity", "out-of-plane", "--no-plot"]]


def _md5(path: Path) -> str:
    return hashlib.md5(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("kind, words", [
    ("absolute", ["absolute path"]), ("dotdot", ["'..'"]), ("symlink", ["symbolic link"]),
    ("device", ["device"])])
def test_a_member_that_points_outside_is_refused_by_every_command(members, tmp_path, monkeypatch, kind, words):
    work, elsewhere = tmp_path / "work", tmp_path / "elsewhere"
    work.mkdir()
    elsewhere.mkdir()
    victim = elsewhere / "victim.txt"
    victim.write_text("mine\n")
    md5 = _md5(victim)
    project = hostile_trz(members, work, kind, victim)
    (work / "hop.mp4").write_bytes(members[VIDEO])
    monkeypatch.chdir(work)
    before, others = tree(work), tree(elsewhere)
    temporaries = set(Path(os.environ.get("TMPDIR", "/tmp")).glob("locust-trz-*"))
    for args in commands(project, work):
        res = invoke(args)
        assert _md5(victim) == md5 and tree(elsewhere) == others, args
        assert_clear_error(res, project.name, *words)
        assert tree(work) == before, args
    assert set(Path(os.environ.get("TMPDIR", "/tmp")).glob("locust-trz-*")) == temporaries


def test_the_project_without_the_hostile_member_opens(members, tmp_path):
    with zipfile.ZipFile(tmp_path / "ok.trz", "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    res = invoke(["track", "video", tmp_path / "ok.trz", "--out", tmp_path / "v", "--overlay", "none"])
    assert res.exit_code == 0, res.output
    assert "10/10 frames found" in res.output, res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.trz", "v.csv", "v.json"]


def test_the_real_project_still_opens(shared_data, tmp_path):
    res = invoke(["track", "from-trk", shared_data / "tracker" / "BallToss.trz", "--out", tmp_path / "b.csv"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "b.csv").read_text().count("\n") == 14   # header and the clip's 13 frames


# -- bombs, and members no reader can take -----------------------------------------------
@pytest.fixture(scope="module", params=["bzip2", "deflate"])
def bomb_member(request) -> tuple[int, bytes, int, int]:
    """A .trk member of XML whitespace, 1.25 times the member limit: (method, packed bytes,
    CRC, unpacked size). bzip2 packs it into under 1 kB; deflate (1000:1 at most) into 41 kB."""
    size = trz.MAX_TRK_BYTES * 5 // 4
    head, piece = b"<?xml version='1.0'?>", b" " * 2**20
    if request.param == "bzip2":
        method, packer = zipfile.ZIP_BZIP2, bz2.BZ2Compressor(9)
    else:
        method, packer = zipfile.ZIP_DEFLATED, zlib.compressobj(9, zlib.DEFLATED, -15)
    crc, packed = zlib.crc32(head), packer.compress(head)
    for _ in range(size // len(piece)):
        packed += packer.compress(piece)
        crc = zlib.crc32(piece, crc)
    return method, packed + packer.flush(), crc, len(head) + size // len(piece) * len(piece)


def bomb_trz(path: Path, member: tuple[int, bytes, int, int], declared: int | None = None) -> Path:
    """A .trz of one .trk ``member`` and a 9 kB thumbnail; ``declared``: the unpacked size both
    headers say (default the true one), so only counting what comes out stops it."""
    method, packed, crc, size = member
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("thumbnail.png", os.urandom(9000))
    raw = bytearray(path.read_bytes())
    cut = raw.find(b"PK\x01\x02")   # the central directory, rebuilt below with the bomb's entry
    name = b"bomb.trk"
    fields = (struct.pack("<HHHHIII", 0, method, 0, 0x21, crc, len(packed), declared or size))
    local = b"PK\x03\x04" + struct.pack("<H", 46) + fields + struct.pack("<HH", len(name), 0) + name
    with zipfile.ZipFile(path) as z:
        thumb = z.getinfo("thumbnail.png")
    thumb_central = raw[cut:raw.find(b"PK\x05\x06")]
    central = (b"PK\x01\x02" + struct.pack("<HH", 0x0314, 46) + fields
               + struct.pack("<HHHHHII", len(name), 0, 0, 0, 0, 0o100644 << 16, cut) + name)
    body = bytes(raw[:cut]) + local + packed
    directory = bytes(thumb_central) + central
    end = b"PK\x05\x06" + struct.pack("<HHHHIIH", 0, 0, 2, 2, len(directory), len(body), 0)
    path.write_bytes(body + directory + end)
    assert thumb.header_offset == 0
    return path


# Runs the command and prints its own peak memory: measured from a small parent, as a child
# forked from this (large) test process would count the pages it shared before its exec.
_MEASURE = ("import resource, subprocess, sys; rc = subprocess.run(sys.argv[1:]).returncode; "
            "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, file=sys.stderr); sys.exit(rc)")


def _run_measured(args: list, cwd: Path) -> tuple[subprocess.CompletedProcess, float, float]:
    """``args`` in a process of its own: (its result, seconds, its own peak resident memory in MB)."""
    t0 = time.monotonic()
    proc = subprocess.run([sys.executable, "-c", _MEASURE, *LOCUST, *[str(a) for a in args]], cwd=cwd,
                          capture_output=True, text=True, timeout=60)
    seconds = time.monotonic() - t0
    stderr, _, peak_kb = proc.stderr.rstrip("\n").rpartition("\n")
    return subprocess.CompletedProcess(args, proc.returncode, proc.stdout, stderr), seconds, int(peak_kb) / 1024


@pytest.mark.parametrize("lie", [False, True], ids=["declared", "lying-header"])
def test_a_zip_bomb_is_refused_quickly_in_little_memory(tmp_path, bomb_member, lie):
    method = bomb_member[0]
    bomb = bomb_trz(tmp_path / "bomb.trz", bomb_member, declared=1000 if lie else None)
    assert bomb.stat().st_size < (10_500 if method == zipfile.ZIP_BZIP2 else 60_000)
    assert zipfile.ZipFile(bomb).getinfo("bomb.trk").file_size == (1000 if lie else bomb_member[3])
    proc, seconds, peak_mb = _run_measured(["track", "from-trk", bomb, "--out", "o.csv"], tmp_path)
    assert proc.returncode == 2 and "error:" in proc.stderr and "hint:" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and "bomb.trk" in proc.stderr
    word = ("compression method 12" if method == zipfile.ZIP_BZIP2 else "Bad CRC-32" if lie else
            f"over the limit of {trz.MAX_TRK_BYTES:,}")
    assert word in proc.stderr, proc.stderr
    assert seconds < 10   # mostly the interpreter's start; the report gives the figure on a quiet machine
    assert peak_mb < 300, peak_mb
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bomb.trz"]


def _member_zip(path: Path, mutate) -> Path:
    with zipfile.ZipFile(path, "w") as z:
        info = zipfile.ZipInfo("p.trk")
        z.writestr(info, b"<?xml version='1.0'?><object class='x'/>", zipfile.ZIP_DEFLATED)
    raw = bytearray(path.read_bytes())
    mutate(raw)
    path.write_bytes(bytes(raw))
    return path


def _set_method(raw: bytearray, method: int) -> None:
    """The compression method of every header (local at 8, central at 10) set to ``method``."""
    for sig, offset in ((b"PK\x03\x04", 8), (b"PK\x01\x02", 10)):
        at = raw.find(sig)
        raw[at + offset:at + offset + 2] = method.to_bytes(2, "little")


def _set_encrypted(raw: bytearray) -> None:
    for sig, offset in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        at = raw.find(sig)
        raw[at + offset] |= 1


@pytest.mark.parametrize("mutate, words", [
    (lambda raw: _set_method(raw, 99), ["compression method 99"]),
    (lambda raw: _set_method(raw, 12345), ["compression method 12345"]),
    (_set_encrypted, ["encrypted"]),
], ids=["method-99", "method-12345", "encrypted"])
def test_a_member_no_reader_can_unpack_is_refused(tmp_path, mutate, words):
    project = _member_zip(tmp_path / "p.trz", mutate)
    for args in commands(project, tmp_path)[:3]:
        before = tree(tmp_path)
        assert_clear_error(invoke(args), "p.trk", *words)
        assert tree(tmp_path) == before


def test_too_many_members_are_refused_before_any_is_read(tmp_path):
    path = tmp_path / "many.trz"
    with zipfile.ZipFile(path, "w") as z:
        for i in range(trz.MAX_MEMBERS + 1):
            z.writestr(f"f{i}.png", b"")
    before = tree(tmp_path)
    assert_clear_error(invoke(["track", "from-trk", path]), f"{trz.MAX_MEMBERS + 1:,} members")
    assert tree(tmp_path) == before


# -- XML: expat's protections, pinned -----------------------------------------------------
LAUGHS = ("<?xml version='1.0'?>\n<!DOCTYPE object [\n<!ENTITY a0 'ha'>\n"
          + "".join(f"<!ENTITY a{i} '{('&a' + str(i - 1) + ';') * 10}'>\n" for i in range(1, 10))
          + "]>\n<object class='org.opensourcephysics.cabrillo.tracker.TrackerPanel'>"
            "<property name='name' type='string'>&a9;</property></object>\n")


def external(target: Path) -> str:
    return ("<?xml version='1.0'?>\n<!DOCTYPE object [<!ENTITY x SYSTEM 'file://" + str(target) + "'>]>\n"
            "<object class='org.opensourcephysics.cabrillo.tracker.TrackerPanel'>"
            "<property name='name' type='string'>&x;</property></object>\n")


@pytest.mark.parametrize("payload", ["laughs", "external"])
@pytest.mark.parametrize("container", ["trk", "trz", "trk-utf16"])
def test_xml_entities_are_refused_without_expanding(tmp_path, payload, container):
    secret = tmp_path / "secret.txt"
    secret.write_text("SECRET-CONTENTS\n")
    text = LAUGHS if payload == "laughs" else external(secret)
    if container.startswith("trk"):
        project = tmp_path / "p.trk"
        project.write_bytes(text.replace("version='1.0'", "version='1.0' encoding='UTF-16'").encode("utf-16")
                            if container == "trk-utf16" else text.encode())
    else:
        project = tmp_path / "p.trz"
        with zipfile.ZipFile(project, "w") as z:
            z.writestr("p.trk", text)
    proc, seconds, peak_mb = _run_measured(["track", "from-trk", project, "--out", "o.csv"], tmp_path)
    assert proc.returncode == 2 and "error:" in proc.stderr and "hint:" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and "SECRET" not in proc.stderr + proc.stdout
    assert "declares XML entities" in proc.stderr and "before any is expanded" in proc.stderr, proc.stderr
    assert seconds < 10 and peak_mb < 100, (seconds, peak_mb)   # flat: 58 MB, as refusing any file
    assert not (tmp_path / "o.csv").exists()
