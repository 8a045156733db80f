"""An MP4's own clock, read and rewritten from its boxes (ISO/IEC 14496-12), in plain Python:
the truth the tracker's frame times are tested against, independent of OpenCV and FFmpeg.

A frame's presentation time is its decode time (the running sum of the ``stts`` box's sample
durations) plus its composition offset (``ctts``, where B-frames are), in the track's time
scale (``mdhd``), sorted into presentation order. :func:`retime` gives an MP4 that OpenCV
wrote at a constant rate the sample durations of a variable-rate one, as a phone's file
states them: the frames stay, their times change (``stts``, and the durations in ``mdhd``,
``tkhd``, ``mvhd`` and the edit list that follow from it)."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

CONTAINERS = {b"moov", b"trak", b"mdia", b"minf", b"stbl", b"edts"}


def parse(buf: bytes) -> list[list]:
    """The boxes of ``buf``: ``[type, body]``, a container's body its own list of boxes."""
    out, off = [], 0
    while off < len(buf):
        size, kind = struct.unpack(">I4s", buf[off:off + 8])
        assert size >= 8, "64-bit or open-ended boxes are not needed here"
        body = buf[off + 8:off + size]
        out.append([kind, parse(body) if kind in CONTAINERS else body])
        off += size
    return out


def build(boxes: list[list]) -> bytes:
    out = []
    for kind, body in boxes:
        raw = build(body) if isinstance(body, list) else body
        out.append(struct.pack(">I4s", 8 + len(raw), kind) + raw)
    return b"".join(out)


def find(boxes: list[list], kind: bytes):
    for box in boxes:
        if box[0] == kind:
            yield box
        if isinstance(box[1], list):
            yield from find(box[1], kind)


def _video_trak(boxes: list[list]) -> list:
    for trak in find(boxes, b"trak"):
        (hdlr,) = find(trak[1], b"hdlr")
        if hdlr[1][8:12] == b"vide":
            return trak
    raise AssertionError("no video track")


def presentation_times_s(path: Path) -> np.ndarray:
    """Every frame's presentation time [s], in presentation order, from the video track's boxes."""
    trak = _video_trak(parse(Path(path).read_bytes()))
    (mdhd,) = find(trak[1], b"mdhd")
    scale = struct.unpack(">I", mdhd[1][12:16] if mdhd[1][0] == 0 else mdhd[1][20:24])[0]
    (stts,) = find(trak[1], b"stts")
    deltas = []
    for k in range(struct.unpack(">I", stts[1][4:8])[0]):
        count, delta = struct.unpack(">II", stts[1][8 + 8 * k:16 + 8 * k])
        deltas += [delta] * count
    decode = np.concatenate([[0], np.cumsum(deltas)[:-1]]).astype(float)
    for ctts in find(trak[1], b"ctts"):
        body, offsets = ctts[1], []
        for k in range(struct.unpack(">I", body[4:8])[0]):
            count, off = struct.unpack(">I" + ("i" if body[0] else "I"), body[8 + 8 * k:16 + 8 * k])
            offsets += [off] * count
        decode = decode + np.array(offsets, float)
    return np.sort(decode) / scale


def retime(path: Path, runs: list[tuple[int, float]]) -> None:
    """Give the MP4 at ``path`` (one video track, as OpenCV writes it) the frame intervals
    ``runs``: ``(frames, interval_s)`` in order, e.g. ``[(120, 1/60), (120, 1/20)]``."""
    path = Path(path)
    boxes = parse(path.read_bytes())
    trak = _video_trak(boxes)
    (mdhd,) = find(trak[1], b"mdhd")
    body = bytearray(mdhd[1])
    assert body[0] == 0, "version-0 mdhd, as OpenCV's muxer writes"
    scale = struct.unpack(">I", body[12:16])[0]
    deltas = [(n, round(dt * scale)) for n, dt in runs]
    assert all(abs(d / scale - dt) < 1e-9 for (_, d), (_, dt) in zip(deltas, runs)), "not whole ticks"
    (stts,) = find(trak[1], b"stts")
    old = struct.unpack(">II", stts[1][8:16])
    assert sum(n for n, _ in runs) == old[0], "the frames stay: only their times change"
    stts[1] = struct.pack(">II", 0, len(deltas)) + b"".join(struct.pack(">II", n, d) for n, d in deltas)
    media = sum(n * d for n, d in deltas)
    body[16:20] = struct.pack(">I", media)
    mdhd[1] = bytes(body)
    (mvhd,) = find(boxes, b"mvhd")
    body = bytearray(mvhd[1])
    movie = round(media * struct.unpack(">I", body[12:16])[0] / scale)
    body[16:20] = struct.pack(">I", movie)
    mvhd[1] = bytes(body)
    (tkhd,) = find(trak[1], b"tkhd")
    body = bytearray(tkhd[1])
    body[20:24] = struct.pack(">I", movie)
    tkhd[1] = bytes(body)
    for elst in find(trak[1], b"elst"):
        body = bytearray(elst[1])
        assert struct.unpack(">I", body[4:8])[0] == 1, "one edit, as OpenCV's muxer writes"
        body[8:12] = struct.pack(">I", movie)
        elst[1] = bytes(body)
    path.write_bytes(build(boxes))
