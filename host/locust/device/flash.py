"""Copy the firmware to a board with mpremote's Python API, verify it, reset, shake hands.

mpremote is pinned (1.29.0): its Python API changes between releases. The steps:

1. open the port (mpremote's ``SerialTransport``) and, if the locust firmware is running,
   ask it for the REPL with the ``repl`` command (mpremote's Ctrl-C would stop an idle
   firmware too; the request is answered, so a running firmware is known to have let go);
2. enter the raw REPL without a soft reset (on the unix port a soft reset ends the process);
3. write each file (optionally compiled with ``mpy-cross``) as ``NAME.part``, compare the
   board's SHA-256 of every one with ours, then rename them into place: a full or failing
   filesystem leaves the firmware on the board as it was;
4. write ``config.json`` if the board has none (or when asked; pulse range and travel from
   the robot parameters, :func:`servo_config`), soft-reset (Ctrl-D from
   the friendly REPL runs ``main.py``; the USB port stays up), and complete the handshake.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import serial

from ..errors import DeviceError
from ..firmware import config as fw_config
from ..firmware import protocol as P
from ..params import Servo
from .holders import check_free, in_use_error, port_holders
from .link import MIN_MICROPYTHON, OLD_MICROPYTHON_HINT, REPLY_LIMIT, Link

FIRMWARE_DIR = Path(P.__file__).resolve().parent
NOT_FLASHED = ("__init__.py",)
KEEP_SOURCE = ("main.py", "boot.py")  # the board runs these as source

NO_MICROPYTHON_HINT = (
    "this board does not run MicroPython yet. Install it once with esptool: erase the flash, "
    "then write the .bin for your chip at its offset (classic ESP32 and ESP32-S2: 0x1000; "
    "ESP32-S3 and C3: 0x0), e.g. `esptool --chip esp32 --port PORT write-flash -z 0x1000 "
    "ESP32_GENERIC-<version>.bin`; docs/hardware.md, \"Installing MicroPython\", has every "
    "chip's command and download page. Then run `locust flash` again"
)


def servo_config(servo: Servo, chip: str = "esp32") -> dict:
    """The board's ``config.json`` for ``servo``: its pulse range and travel, the firmware's pins
    for ``chip``, trims and directions. The firmware keeps its own copy of the default pulse
    range (it cannot import the host); the host always writes these from :class:`locust.params.Servo`.

    Parameters
    ----------
    servo : Servo
        The servo parameters (pulse range [us], range and travel [deg]).
    chip : str, default "esp32"
        The chip whose default pins are used (``esp32``, ``s2``, ``s3`` or ``c3``).

    Returns
    -------
    dict
        The config, both servos.
    """
    cfg = fw_config.default(chip)
    for name in fw_config.SERVOS:
        cfg[name].update(pulse_min_us=servo.pulse_min_us, pulse_max_us=servo.pulse_max_us,
                         range_deg=servo.range_deg, travel_deg=servo.travel_deg)
    return cfg


@dataclass(frozen=True)
class FlashedFile:
    """One file copied to the board and checked there.

    Attributes
    ----------
    name : str
        Its name on the board.
    size_bytes : int
        Its size.
    sha256 : str
        Its SHA-256 in hex, the same on the board as sent.
    """

    name: str
    size_bytes: int
    sha256: str


@dataclass
class FlashResult:
    """What ``locust flash`` did.

    Attributes
    ----------
    port : str
        The serial port flashed.
    compiled : bool
        The files were compiled to .mpy.
    firmware_version : str
        The version the board reports after the reset.
    board : str
        The board's machine string (or its platform when it names none).
    config_written : bool
        ``config.json`` was written.
    files : list of FlashedFile
        The files copied.
    elapsed_s : float
        Time from connecting to the handshake [s].
    config_problems : list of str
        Why the board runs on its default config, if it does.
    """

    port: str
    compiled: bool
    firmware_version: str
    board: str
    config_written: bool
    files: list[FlashedFile] = field(default_factory=list)
    elapsed_s: float = 0.0
    config_problems: list[str] = field(default_factory=list)   # why the board runs on its defaults


def firmware_files() -> list[Path]:
    """The firmware's source files flashed to a board.

    Returns
    -------
    list of Path
        Every ``.py`` of ``locust/firmware`` but ``__init__.py``, sorted.
    """
    return sorted(p for p in FIRMWARE_DIR.glob("*.py") if p.name not in NOT_FLASHED)


def mpy_version(header: bytes) -> int:
    """The .mpy format version of a header (bytecode-only files carry no sub-version or arch).

    The board reports its own in the low byte of ``sys.implementation._mpy``.

    Parameters
    ----------
    header : bytes
        The first bytes of a .mpy file.

    Returns
    -------
    int
        The format version.

    Raises
    ------
    DeviceError
        Not a .mpy header.
    """
    if len(header) < 3 or header[:1] != b"M":
        raise DeviceError("mpy-cross wrote an invalid .mpy file", "check the mpy-cross installation")
    return header[1]


def build(compile_mpy: bool, workdir: Path) -> list[tuple[str, bytes]]:
    """The files to flash, compiled with ``mpy-cross`` when asked (``main.py`` and ``boot.py`` stay source).

    Parameters
    ----------
    compile_mpy : bool
        Compile to .mpy.
    workdir : Path
        A folder for the compiled files.

    Returns
    -------
    list of (str, bytes)
        (name on the board, contents) for every firmware file.

    Raises
    ------
    DeviceError
        ``mpy-cross`` fails on a file.
    """
    out = []
    for src in firmware_files():
        if not compile_mpy or src.name in KEEP_SOURCE:
            out.append((src.name, src.read_bytes()))
            continue
        dest = workdir / (src.stem + ".mpy")
        proc = subprocess.run([sys.executable, "-m", "mpy_cross", "-o", str(dest), str(src)],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            raise DeviceError(f"mpy-cross failed on {src.name}: {proc.stderr.strip()}",
                              "flash without --compile, or fix the file")
        out.append((dest.name, dest.read_bytes()))
    return out


LOST_HINT = ("check the USB cable and the port (`locust ports`), re-plug the board and run `locust flash` again "
             "(the files are renamed into place only once every one has verified, so a cable pulled while "
             "they were copied leaves the board's firmware as it was)")


class GuardedPort:
    """mpremote's serial port, whose reads and writes raise :class:`DeviceError` when the port
    fails (a pulled cable): pyserial raises an ``OSError`` there, which mpremote's own
    ``except OSError`` takes for a missing file on the board (``fs_exists``) and which the
    command line would take for a disk error. Everything else passes through to the port.

    Parameters
    ----------
    port : serial.Serial
        The port mpremote opened.
    name : str
        Its path, for the message.
    """

    GUARDED = ("read", "write", "inWaiting", "read_all", "flush", "reset_input_buffer")

    def __init__(self, port, name: str):
        self.__dict__.update(_port=port, _name=name, step="connecting")

    def __getattr__(self, attr: str):
        value = getattr(self._port, attr)
        if attr in self.GUARDED:
            return lambda *args, **kwargs: self._guarded(value, *args, **kwargs)
        return value

    def __setattr__(self, attr: str, value) -> None:
        if attr == "step":
            self.__dict__["step"] = value
        else:
            setattr(self._port, attr, value)

    @property
    def in_waiting(self) -> int:
        """Bytes waiting to be read (pyserial's ``in_waiting``, guarded)."""
        return self._guarded(lambda: self._port.in_waiting)

    def _guarded(self, call, *args, **kwargs):
        try:
            return call(*args, **kwargs)
        except (serial.SerialException, OSError, TypeError) as exc:   # (TypeError: pyserial closed it under us)
            raise DeviceError(f"lost the serial port {self._name} while flashing ({self.step}): {exc}",
                              LOST_HINT) from None


def _transport(port: str):
    from mpremote.transport import TransportError
    from mpremote.transport_serial import SerialTransport

    try:
        transport = SerialTransport(port, baudrate=115200)   # (exclusive: mpremote's flock, as the Link's)
    except TransportError as exc:
        holders = port_holders(port)
        if holders:
            raise in_use_error(port, holders) from None
        raise DeviceError(f"cannot open {port}: {exc}", "check the cable and `locust ports`") from None
    try:
        check_free(port)   # a program that takes no lock (a serial monitor) would take the board's replies
    except DeviceError:
        transport.close()
        raise
    transport.serial = GuardedPort(transport.serial, port)
    return transport


def _close(transport) -> None:
    """Close mpremote's transport; on a port that is gone, its line changes fail: close the port anyway."""
    try:
        transport.close()
    except (OSError, DeviceError):
        try:
            transport.serial.close()
        except (OSError, DeviceError):
            pass


def _release_console(transport, tries: int = 3) -> bool:
    """Ask a running locust firmware for the REPL; False if nothing answered (plain REPL, or none).

    A firmware in the middle of a hop answers ``busy`` (and ignores Ctrl-C): it is told to stop
    first, so that a running hop is not mistaken for a board without MicroPython."""
    reader = P.LineReader(limit=REPLY_LIMIT)
    for attempt in range(tries):
        transport.serial.write(P.encode({"id": 900 + attempt, "cmd": "repl"}))
        deadline = time.monotonic() + 0.6
        while time.monotonic() < deadline:
            waiting = transport.serial.in_waiting
            data = transport.serial.read(waiting) if waiting else b""
            if not data:
                time.sleep(0.01)
            for line in reader.feed(data):
                try:
                    msg = P.decode(line, REPLY_LIMIT) if line else None
                except P.ProtocolError:
                    continue
                if msg and msg.get("id") == 900 + attempt and msg.get("ok"):
                    time.sleep(0.1)  # let main.py end and the REPL print its prompt
                    return True
                if msg and msg.get("id") == 900 + attempt and msg.get("error") == P.E_BUSY:
                    transport.serial.write(P.encode({"id": 899, "cmd": "stop"}))
                    time.sleep(0.2)  # the hop ends at its next check; then ask again
                    deadline = 0.0
    return False


def board_chip(transport) -> tuple[str, str | None]:
    """The board's machine string and chip, asked at the raw REPL. ``sys.platform`` is "esp32" on
    every chip: only the machine string tells.

    Parameters
    ----------
    transport : SerialTransport
        mpremote's transport, in the raw REPL.

    Returns
    -------
    tuple
        (``os.uname().machine``, chip); chip None if locust has no pin rules for it.
    """
    transport.exec("import os\ntry:\n _m = os.uname().machine\nexcept Exception:\n _m = ''")
    machine = transport.eval("_m")
    return machine, fw_config.chip_of(machine)


def planned_config(board: dict | None, written: dict | None, edits: list[tuple[str, float]],
                   chip: str) -> dict:
    """The config the board will run after flashing with ``edits``, checked against ``chip``'s pin
    rules before anything is written.

    Parameters
    ----------
    board : dict or None
        The board's own config.json (used when valid and nothing is written).
    written : dict or None
        The config about to be written, if any.
    edits : list of (str, float)
        ``("left.pin", 4)``-style edits applied on top.
    chip : str
        The board's chip.

    Returns
    -------
    dict
        The resulting config.

    Raises
    ------
    DeviceError
        An edit is refused for the chip, naming the bad value and the usable pins.
    """
    cfg = written or (board if board is not None and not fw_config.problems(board, chip) else None) \
        or servo_config(Servo(), chip)
    for key, value in edits:
        try:
            cfg = fw_config.with_value(cfg, key, value, chip)
        except ValueError as exc:
            raise DeviceError(f"--servo {key}={value:g} refused for the {fw_config.chip_name(chip)}: {exc}",
                              _refusal_hint(key, cfg, chip)) from None
    return cfg


def _refusal_hint(key: str, cfg: dict, chip: str) -> str:
    """What to do about a refused ``--servo`` value: the usable pins for a pin; for the travel
    or trim, the two together against half the pulse range (each value is checked in the
    order given, on the values before it)."""
    if key.endswith(".pin"):
        pins = ", ".join(str(p) for p in fw_config.usable_pins(chip))
        return (f"the {fw_config.chip_name(chip)}'s pins that can drive a servo: {pins}; "
                "nothing was written to the board")
    name = key.partition(".")[0]
    servo = cfg.get(name, {}) if isinstance(cfg, dict) else {}
    if key.endswith((".travel_deg", ".trim_deg")) and {"trim_deg", "travel_deg", "range_deg"} <= set(servo):
        return (f"{name} has trim {servo['trim_deg']:g} deg and travel {servo['travel_deg']:g} deg; travel plus |trim| "
                f"may be at most {servo['range_deg'] / 2:g} deg, and each --servo value is checked in the order given "
                f"(e.g. --servo {name}.trim_deg=0 before a larger travel); nothing was written to the board")
    return "see docs/hardware.md for each value's limits; nothing was written to the board"


def flash(port: str, compile_mpy: bool = False, config: dict | None = None,
          progress: Callable[[str], None] = lambda s: None, repl_timeout_s: float = 10.0,
          edits: list[tuple[str, float]] = (), servo: Servo | None = None) -> FlashResult:
    """Flash the firmware, verify it, reset the board and complete the handshake.

    ``config`` (a whole config.json, or with ``servo`` one made from those servo parameters
    and the chip's pins) and ``edits`` are checked against the board's chip before any file is
    written (the edits themselves are applied afterwards through the firmware, which checks
    them again).

    Parameters
    ----------
    port : str
        The serial port.
    compile_mpy : bool, default False
        Compile the files with ``mpy-cross`` (its .mpy version must be the board's).
    config : dict, optional
        A whole config.json to write.
    progress : callable, optional
        ``progress(step)`` for each step (connecting, copying NAME, ...).
    repl_timeout_s : float, default 10.0
        How long to wait for the raw REPL [s].
    edits : list of (str, float), optional
        ``("left.pin", 4)``-style config edits checked here.
    servo : Servo, optional
        Servo parameters to make the config from, when ``config`` is None.

    Returns
    -------
    FlashResult
        The files written and the version the board reports.

    Raises
    ------
    DeviceError
        A bad config or edit, no MicroPython (or one older than 1.26, or a chip locust does not
        know), a file that cannot be written or does not verify, or a board that reports another
        version after the reset.
    """
    from mpremote.transport import TransportError

    if config is not None and fw_config.problems(config):
        raise DeviceError("bad servo config: " + "; ".join(fw_config.problems(config)),
                          "see docs/device.md for the keys and their limits")
    t_start = time.monotonic()
    transport = _transport(port)
    in_raw_repl = False

    def step(what: str) -> None:    # (named in the error if the port goes away during it)
        transport.serial.step = what
        progress(what)

    try:
        step("connecting")
        _release_console(transport)
        # mpremote reads a pty with blocking reads: bound them while a silent port is possible
        transport.serial.timeout = 1.0
        try:
            transport.enter_raw_repl(soft_reset=False, timeout_overall=repl_timeout_s)
        except TransportError:
            raise DeviceError(f"no MicroPython REPL answered on {port}", NO_MICROPYTHON_HINT) from None
        in_raw_repl = True
        transport.serial.timeout = None
        board_mpy, platform, machine, chip = _board_identity(transport, port)
        config = _checked_config(transport, chip, config, servo, edits)
        files = _firmware_files(compile_mpy, board_mpy)
        result = FlashResult(port=port, compiled=compile_mpy, firmware_version="", board=machine or platform,
                             config_written=False)
        _write_files(transport, files, step, result)
        if config is not None or not transport.fs_exists(fw_config.FILE):
            step(f"writing {fw_config.FILE}")
            write_board_file(transport, fw_config.FILE, json.dumps(config or servo_config(Servo(), chip)).encode())
            result.config_written = True
        step("resetting")
        transport.exit_raw_repl()
        in_raw_repl = False
        transport.serial.write(b"\x04")  # soft reset from the friendly REPL: runs main.py
    except TransportError as exc:
        raise DeviceError(f"mpremote failed on {port}: {exc}", "reset the board and run `locust flash` again") from None
    finally:
        if in_raw_repl:  # refused before writing: give the board its firmware back
            try:
                transport.exit_raw_repl()
                transport.serial.write(b"\x04")
            except (TransportError, OSError, DeviceError):
                pass
        _close(transport)
    progress("handshake")
    with Link(port) as link:
        hello = link.hello(wait_s=8.0)
    if hello.get("version") != P.VERSION:
        raise DeviceError(f"the board reports firmware {hello.get('version')} after flashing {P.VERSION}",
                          "reset the board (a stale .py/.mpy may shadow the new files) and flash again")
    result.firmware_version = hello["version"]
    result.config_problems = list(hello.get("config_problems") or [])
    result.elapsed_s = time.monotonic() - t_start
    return result


def _board_identity(transport, port: str) -> tuple[int, str, str | None, str]:
    """(.mpy version, sys.platform, machine, chip) of the board in the raw REPL; refuses
    anything but MicroPython, new enough, on a chip whose pins locust knows."""
    transport.exec("import sys")
    impl, board_mpy, platform, version = transport.eval(
        "(sys.implementation.name, getattr(sys.implementation, '_mpy', 0), sys.platform, "
        "sys.implementation.version[:2])")
    if impl != "micropython":
        raise DeviceError(f"{port} runs {impl}, not MicroPython", NO_MICROPYTHON_HINT)
    if tuple(version) < MIN_MICROPYTHON:
        raise DeviceError(f"{port} runs MicroPython {version[0]}.{version[1]}; locust needs "
                          f"{MIN_MICROPYTHON[0]}.{MIN_MICROPYTHON[1]} or newer", OLD_MICROPYTHON_HINT)
    machine, chip = board_chip(transport)
    if chip is None:
        raise DeviceError(f"{port} is a {machine or 'board that does not name its chip'}: locust knows the "
                          "pins of the ESP32, ESP32-S2, ESP32-S3 and ESP32-C3 only",
                          "use one of those chips (docs/hardware.md)")
    return board_mpy, platform, machine, chip


def _checked_config(transport, chip: str, config: dict | None, servo: Servo | None,
                    edits: list[tuple[str, float]]) -> dict | None:
    """The config to write (``servo``'s when no whole one is given), checked against the chip,
    and the ``edits`` checked on it or on the board's own config: raises before anything is written."""
    if servo is not None and config is None:
        config = servo_config(servo, chip)
    if config is not None and fw_config.problems(config, chip):
        raise DeviceError(f"bad servo config for the {fw_config.chip_name(chip)}: "
                          + "; ".join(fw_config.problems(config, chip)),
                          f"usable pins: {', '.join(str(p) for p in fw_config.usable_pins(chip))}")
    board_cfg = None
    if edits and config is None and transport.fs_exists(fw_config.FILE):
        try:
            board_cfg = json.loads(transport.fs_readfile(fw_config.FILE))
        except ValueError:
            board_cfg = None
    planned_config(board_cfg, config, list(edits), chip)  # raises before anything is written
    return config


def _firmware_files(compile_mpy: bool, board_mpy: int) -> list[tuple[str, bytes]]:
    """The files to copy (name, bytes); compiled ones only in the .mpy version the board reads."""
    with tempfile.TemporaryDirectory(prefix="locust-flash-") as tmp:
        files = build(compile_mpy, Path(tmp))
    if compile_mpy:
        ours = mpy_version(next(data for name, data in files if name.endswith(".mpy")))
        theirs = board_mpy & 0xFF
        if ours != theirs:
            raise DeviceError(f"the board reads .mpy v{theirs}, mpy-cross writes v{ours}",
                              "flash without --compile, or install the mpy-cross matching the board's MicroPython")
    return files


PART = ".part"   # a file being copied to the board is written under NAME.part, renamed when whole
BOARD_FULL_HINT = ("the board's filesystem is full or failing: remove files you put on it (mpremote fs ls / rm), "
                   "then flash again; its firmware files are as they were")


def _write_files(transport, files: list[tuple[str, bytes]], progress: Callable[[str], None],
                 result: FlashResult) -> None:
    """Copy every file under a temporary name and check it by SHA-256 on the board, then rename
    them all into place (removing each one's stale .py/.mpy twin): a full or failing filesystem
    leaves the firmware on the board as it was, never a torn file."""
    try:
        for name, data in files:
            progress(f"copying {name}")
            _write_part(transport, name, data)
        for name, data in files:
            progress(f"verifying {name}")
            digest = hashlib.sha256(data).hexdigest()
            if transport.fs_hashfile(name + PART, "sha256").hex() != digest:
                raise DeviceError(f"{name} on the board does not match the copy sent (SHA-256); the firmware on it "
                                  "is as it was", "flash again; if it persists, " + BOARD_FULL_HINT)
            result.files.append(FlashedFile(name, len(data), digest))
    except BaseException:
        _remove_parts(transport, [name for name, _ in files])
        raise
    for name, _ in files:
        _rename(transport, name + PART, name)
        stem, ext = name.rsplit(".", 1)
        other = stem + (".py" if ext == "mpy" else ".mpy")
        if other not in KEEP_SOURCE and transport.fs_exists(other):
            transport.fs_rmfile(other)  # a stale .py would be imported before the new .mpy


def write_board_file(transport, name: str, data: bytes) -> None:
    """Replace ``name`` on the board whole, or leave it as it was (written as NAME.part, renamed).

    Parameters
    ----------
    transport : SerialTransport
        mpremote's transport, in the raw REPL.
    name : str
        The file's name on the board.
    data : bytes
        Its contents.

    Raises
    ------
    DeviceError
        The board cannot write the file (full or failing filesystem).
    """
    try:
        _write_part(transport, name, data)
    except BaseException:
        _remove_parts(transport, [name])
        raise
    _rename(transport, name + PART, name)


def _write_part(transport, name: str, data: bytes) -> None:
    try:
        transport.fs_writefile(name + PART, data)
    except OSError as exc:   # mpremote turns the board's OSError into one: (errno, the file's name)
        what = os.strerror(exc.errno) if exc.errno else str(exc)
        raise DeviceError(f"cannot write {name} on the board ({what})", BOARD_FULL_HINT) from None


def _rename(transport, old: str, new: str) -> None:
    transport.exec(f"import os\nos.rename({old!r}, {new!r})")


def _remove_parts(transport, names: list[str]) -> None:
    from mpremote.transport import TransportError

    for name in names:
        try:
            if transport.fs_exists(name + PART):
                transport.fs_rmfile(name + PART)
        except (TransportError, OSError, DeviceError):   # (the port lost too: the first error is reported)
            pass
