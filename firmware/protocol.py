# The serial protocol between the host and the robot: framing, message names, limits.
#
# This one file is the single source of truth: it runs on the ESP32 (MicroPython) and the
# host imports it verbatim as ``locust.firmware.protocol``. Keep it MicroPython-safe: no
# f-strings with '=' or nested quotes, no type annotations, no dataclasses, no CPython-only
# modules. See docs/protocol.md for the description a person reads.
#
# A frame is one line of ASCII:
#
#     $<json body>*<crc32 of the body, 8 lowercase hex digits>\n
#
# e.g. ``$ {"id":1,"cmd":"hello"}*…`` without the space. Requests carry an integer ``id``
# and a ``cmd``; replies echo the ``id`` with ``ok`` true or false; events carry ``ev``.

try:
    from binascii import crc32 as _crc32
except ImportError:  # a MicroPython build without binascii.crc32
    _crc32 = None

import json

NAME = "locust"
VERSION = "0.1.0"         # firmware release; the host checks it after flashing
PROTOCOL = 1              # bump on any incompatible change to this file

START = 0x24              # '$'
SEP = 0x2A                # '*'
MAX_FRAME = 256           # longest request line accepted, without the newline
CRC_HEX = 8

# error codes in replies ({"ok": false, "error": CODE, "detail": "..."})
E_FRAME = "bad_frame"             # no '$' start or no '*crc' tail
E_CHECKSUM = "bad_checksum"       # the crc does not match the body
E_TOO_LONG = "too_long"           # longer than MAX_FRAME: discarded up to the newline
E_JSON = "bad_json"               # body is not a JSON object
E_REQUEST = "bad_request"         # missing/invalid id or cmd, unknown or mistyped argument
E_UNKNOWN = "unknown_command"
E_RANGE = "out_of_range"          # an argument outside its limits (or the servo travel)
E_BUSY = "busy"                   # not allowed while a hop runs
E_INTERNAL = "internal"           # a bug in the firmware; the command loop survives it

# events ({"ev": NAME, ...}) sent by the firmware without being asked
EV_BOOT = "boot"                  # the command loop started
EV_PHASE = "phase"                # a hop phase started (live progress)
EV_DONE = "done"                  # a hop ended: complete, stopped or heartbeat_lost

HOP_COMPLETE = "complete"
HOP_STOPPED = "stopped"
HOP_HEARTBEAT = "heartbeat_lost"

MAX_ID = 0x7FFFFFFF
REPORT_PAGE = 8                   # phases per `report` reply

# cmd -> {argument: (kind, lowest, highest, default)}; default None means required.
# kind is "int", "num" (int or float) or "str" (lowest/highest bound its length).
COMMANDS = {
    "hello": {},
    "ping": {},
    "stop": {},
    "rest": {},
    "repl": {},
    "hop": {
        "cycles": ("int", 1, 1000, 6),
        "push_deg": ("num", -90, 90, -30.0),
        "push_ms": ("int", 20, 10000, 300),
        "wait_ms": ("int", 20, 60000, 1000),
        # 750 ms: a host on a busy machine may be late by a scheduler hiccup, beating each
        # heartbeat_ms / 8; a silent host still has the servos at rest within a second
        "heartbeat_ms": ("int", 100, 10000, 750),
    },
    "pose": {
        "left_deg": ("num", -90, 90, None),
        "right_deg": ("num", -90, 90, None),
    },
    "report": {"start": ("int", 0, 2000, 0)},
    "config": {
        "key": ("str", 0, 40, ""),          # "" reads the whole config; "left.trim_deg" one key
        "value": ("num", -100000, 100000, 0),
        "write": ("int", 0, 1, 0),          # 1: set key to value and save config.json
    },
}
# commands a running hop still answers (the rest get E_BUSY)
DURING_HOP = ("hello", "ping", "stop")


class ProtocolError(Exception):
    def __init__(self, code, detail, req_id=None):
        super().__init__(detail)
        self.code = code
        self.detail = detail
        self.req_id = req_id


def crc_hex(body):
    """CRC-32 (IEEE, as zlib) of ``body`` bytes, as 8 lowercase hex digits."""
    if _crc32 is not None:
        value = _crc32(body) & 0xFFFFFFFF
    else:
        value = _crc32_pure(body)
    return f"{value:08x}"


def _crc32_pure(data):
    crc = 0xFFFFFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ (0xEDB88320 if crc & 1 else 0)
    return crc ^ 0xFFFFFFFF


def encode(obj):
    """A message (dict) -> one frame, bytes ending in a newline."""
    body = json.dumps(obj, separators=(",", ":")).encode()
    return b"$" + body + b"*" + crc_hex(body).encode() + b"\n"


def decode(line, limit=MAX_FRAME):
    """One frame without its newline -> the message dict; raises ProtocolError.

    ``limit`` bounds a request (the board's buffer); the host reads replies and events, which
    may be longer (a hello with config problems), with a limit of its own."""
    if len(line) > limit:
        raise ProtocolError(E_TOO_LONG, "frame longer than %d bytes" % MAX_FRAME)
    if not line or line[0] != START:
        raise ProtocolError(E_FRAME, "frame does not start with '$'")
    star = len(line) - CRC_HEX - 1
    if star < 1 or line[star] != SEP:
        raise ProtocolError(E_FRAME, "frame does not end with '*' and 8 hex digits")
    body = line[1:star]
    try:
        given = line[star + 1:].decode()
    except Exception:
        raise ProtocolError(E_FRAME, "checksum is not ASCII") from None
    if given.lower() != crc_hex(body):
        raise ProtocolError(E_CHECKSUM, "crc32 mismatch")
    try:
        obj = json.loads(body.decode())
    except Exception:
        raise ProtocolError(E_JSON, "body is not valid JSON") from None
    if type(obj) is not dict:
        raise ProtocolError(E_JSON, "body is not a JSON object")
    return obj


def _finite(x):
    return x == x and -1e300 < x < 1e300


def check_request(obj):
    """A decoded request -> (id, cmd, args with defaults filled in); raises ProtocolError."""
    req_id = obj.get("id")
    if type(req_id) is not int or req_id < 0 or req_id > MAX_ID:
        raise ProtocolError(E_REQUEST, "id must be an integer 0..%d" % MAX_ID)
    cmd = obj.get("cmd")
    if type(cmd) is not str:
        raise ProtocolError(E_REQUEST, "cmd must be a string", req_id)
    spec = COMMANDS.get(cmd)
    if spec is None:
        raise ProtocolError(E_UNKNOWN, "unknown command " + _short(cmd), req_id)
    args = {}
    for key in obj:
        if key != "id" and key != "cmd" and key not in spec:
            raise ProtocolError(E_REQUEST, "unknown argument %s for %s" % (_short(key), cmd), req_id)
    for key in spec:
        kind, lo, hi, default = spec[key]
        if key not in obj:
            if default is None:
                raise ProtocolError(E_REQUEST, "%s needs %s" % (cmd, key), req_id)
            args[key] = default
            continue
        value = obj[key]
        if kind == "str":
            if type(value) is not str:
                raise ProtocolError(E_REQUEST, key + " must be a string", req_id)
            if not lo <= len(value) <= hi:
                raise ProtocolError(E_RANGE, "%s length outside %d..%d" % (key, lo, hi), req_id)
        else:
            ok = type(value) is int or (kind == "num" and type(value) is float)
            if not ok:
                wanted = "an integer" if kind == "int" else "a number"
                raise ProtocolError(E_REQUEST, "%s must be %s" % (key, wanted), req_id)
            if not _finite(value) or not lo <= value <= hi:
                raise ProtocolError(E_RANGE, "%s=%s outside %s..%s" % (key, _short(str(value)), lo, hi), req_id)
        args[key] = value
    return req_id, cmd, args


def _short(text, n=24):
    text = str(text)
    return repr(text[:n] + ("..." if len(text) > n else ""))


def reply(req_id, **fields):
    fields["id"] = req_id
    fields["ok"] = True
    return fields


def error(req_id, code, detail):
    return {"id": req_id, "ok": False, "error": code, "detail": detail}


def event(ev_name, **fields):
    fields["ev"] = ev_name
    return fields


class LineReader:
    """Splits a byte stream into lines (``\\n`` or ``\\r`` end a line; empty lines are dropped).

    ``feed(data)`` returns a list of items: ``bytes`` for a complete line, or ``None``
    for a line that grew past MAX_FRAME (it is discarded up to its end, and reported once).
    Memory stays bounded whatever arrives.
    """

    def __init__(self, limit=MAX_FRAME):
        self.limit = limit
        self.buf = bytearray()
        self.overflow = False

    def feed(self, data):
        out = []
        for b in data:
            if b == 0x0A or b == 0x0D:
                if self.overflow:
                    out.append(None)
                elif self.buf:
                    out.append(bytes(self.buf))
                self.buf = bytearray()
                self.overflow = False
            elif self.overflow:
                continue
            elif len(self.buf) >= self.limit:
                self.overflow = True
                self.buf = bytearray()
            else:
                self.buf.append(b)
        return out
