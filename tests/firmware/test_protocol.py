# Framing and request checks (runs under CPython and MicroPython).
import json

import protocol as P
from lcg import Lcg


def _frame(body):
    return b"$" + body + b"*" + P.crc_hex(body).encode()


def test_crc_check_value():
    # the CRC-32 check value of "123456789" (IEEE 802.3 / zlib) is 0xcbf43926
    assert P.crc_hex(b"123456789") == "cbf43926"
    assert P._crc32_pure(b"123456789") == 0xCBF43926


def test_pure_crc_matches_library():
    rng = Lcg(7)
    for n in (0, 1, 5, 64, 255):
        data = rng.bytes(n)
        assert f"{P._crc32_pure(data):08x}" == P.crc_hex(data)


def test_roundtrip():
    msg = {"id": 42, "cmd": "hop", "cycles": 6, "push_deg": -30.0}
    frame = P.encode(msg)
    assert frame.startswith(b"$") and frame.endswith(b"\n")
    assert P.decode(frame[:-1]) == msg


def _code(line):
    try:
        P.decode(line)
    except P.ProtocolError as e:
        return e.code
    return None


def test_decode_errors():
    good = P.encode({"id": 1, "cmd": "ping"})[:-1]
    assert _code(good) is None
    assert _code(good[1:]) == P.E_FRAME
    assert _code(good[:-1]) == P.E_FRAME
    flipped = bytearray(good)
    flipped[5] ^= 0x01
    assert _code(bytes(flipped)) == P.E_CHECKSUM
    assert _code(_frame(b"[1,2]")) == P.E_JSON
    assert _code(_frame(b"{nope")) == P.E_JSON
    assert _code(b"$" + b"x" * 300) == P.E_TOO_LONG


def _check(obj):
    try:
        return P.check_request(obj)
    except P.ProtocolError as e:
        return e.code


def test_request_checks():
    req_id, cmd, args = P.check_request({"id": 3, "cmd": "hop"})
    assert (req_id, cmd) == (3, "hop")
    assert args == {"cycles": 6, "push_deg": -30.0, "push_ms": 300, "wait_ms": 1000, "heartbeat_ms": 750}
    assert _check({"cmd": "ping"}) == P.E_REQUEST
    assert _check({"id": -1, "cmd": "ping"}) == P.E_REQUEST
    assert _check({"id": True, "cmd": "ping"}) == P.E_REQUEST
    assert _check({"id": 1, "cmd": 5}) == P.E_REQUEST
    assert _check({"id": 1, "cmd": "jump"}) == P.E_UNKNOWN
    assert _check({"id": 1, "cmd": "hop", "cycles": 0}) == P.E_RANGE
    assert _check({"id": 1, "cmd": "hop", "cycles": 2.5}) == P.E_REQUEST
    assert _check({"id": 1, "cmd": "hop", "push_deg": 1e400}) == P.E_RANGE
    assert _check({"id": 1, "cmd": "hop", "push_deg": "-30"}) == P.E_REQUEST
    assert _check({"id": 1, "cmd": "hop", "speed": 1}) == P.E_REQUEST
    assert _check({"id": 1, "cmd": "pose", "left_deg": 1}) == P.E_REQUEST
    assert _check({"id": 1, "cmd": "pose", "left_deg": 1, "right_deg": -2.5})[2] == {"left_deg": 1, "right_deg": -2.5}


def test_nan_is_rejected():
    nan = float("nan")
    assert _check({"id": 1, "cmd": "pose", "left_deg": nan, "right_deg": 0}) == P.E_RANGE


def test_error_reply_shape():
    msg = json.loads(P.encode(P.error(9, P.E_RANGE, "x"))[1:-10].decode())
    assert msg == {"id": 9, "ok": False, "error": "out_of_range", "detail": "x"}


def test_line_reader_splits_and_bounds():
    r = P.LineReader(limit=16)
    assert r.feed(b"abc") == []
    assert r.feed(b"def\r\n\nxy\n") == [b"abcdef", b"xy"]
    out = r.feed(b"z" * 1000 + b"\nok\n")
    assert out == [None, b"ok"]
    assert len(r.buf) == 0
    r.feed(b"q" * 5000)
    assert len(r.buf) <= 16
