"""Who else has a serial port open: two readers of one port split its bytes between them.

A serial port (a USB-serial bridge's ``/dev/ttyUSB0``, a virtual robot's ``/dev/pts/N``) may
be opened by any number of processes; each byte the board sends goes to whichever reads
first. A second program on the port (mpremote's REPL, ``screen``, a looping ``locust config``)
therefore takes pieces of the replies meant for the first, which then sees garbled frames,
silence ("no reply") or pyserial's "device reports readiness to read but returned no data".

locust's own commands open the port with pyserial's ``exclusive=True`` (an ``flock``, which
mpremote takes too), so a second one is refused at once; programs that take no lock
(``screen``, ``cat``, ``minicom``) are found here by their open file descriptors under
``/proc/*/fd``, where Linux lets this user read them. The process holding a pseudo-terminal's
master side (a virtual robot, which also keeps its client side open) is the board end, not a
second program.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from ..errors import DeviceError

PTMX = ("/dev/ptmx", "/dev/pts/ptmx")    # what a pseudo-terminal master's descriptor links to
COMMAND_CHARS = 120                      # a holder's command line is shown up to this long

IN_USE_HINT = ("one program at a time talks to the robot: close that one or let it finish, then run this again "
               "(mpremote's REPL and `locust repl`: Ctrl-] or Ctrl-X; screen: Ctrl-A k; another locust command: "
               "wait for it to end)")


@dataclass(frozen=True)
class Holder:
    """A process that has the port open.

    Attributes
    ----------
    pid : int
        Its process id.
    command : str
        Its command line (program names without their folders), shortened.
    """

    pid: int
    command: str

    def __str__(self) -> str:
        return f"pid {self.pid} ({self.command})"


def _command(pid: int) -> str:
    try:
        args = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
        words = [a.decode(errors="replace") for a in args if a]
        if not words:
            words = [Path(f"/proc/{pid}/comm").read_text().strip()]
    except OSError:
        return "?"
    words[0] = os.path.basename(words[0])
    if len(words) > 1 and words[0].startswith("python") and words[1].endswith(("/mpremote", "/locust")):
        words = [os.path.basename(words[1]), *words[2:]]   # a console script run by its interpreter
    text = " ".join(" ".join(words).split())    # (a `python -c` script's lines on one line)
    return text if len(text) <= COMMAND_CHARS else text[:COMMAND_CHARS - 3] + "..."


def _tty_index(pid: int, fd: str) -> int | None:
    """The pseudo-terminal number a master descriptor serves (``tty-index`` in its fdinfo)."""
    try:
        for line in Path(f"/proc/{pid}/fdinfo/{fd}").read_text().splitlines():
            if line.startswith("tty-index:"):
                return int(line.split(":", 1)[1])
    except (OSError, ValueError):
        pass
    return None


def port_holders(device: str) -> list[Holder]:
    """The other processes that have ``device`` open, as far as ``/proc`` shows them.

    Parameters
    ----------
    device : str
        The serial port, e.g. ``/dev/ttyUSB0`` or ``/dev/pts/3`` (a link to it is followed).

    Returns
    -------
    list of Holder
        Every process but this one with a descriptor on the port, sorted by pid; not the
        process holding a pseudo-terminal's master side (the board end), nor the processes
        this user may not look into. Empty where there is no ``/proc``.
    """
    target = os.path.realpath(device)
    pts = Path(target).parent == Path("/dev/pts") and Path(target).name.isdigit()
    index = int(Path(target).name) if pts else None
    me = os.getpid()
    found = []
    try:
        pids = sorted(int(p) for p in os.listdir("/proc") if p.isdigit())
    except OSError:
        return []
    for pid in pids:
        if pid == me:
            continue
        try:
            fds = os.listdir(f"/proc/{pid}/fd")
        except OSError:     # gone, or another user's
            continue
        opened = board_end = False
        for fd in fds:
            try:
                link = os.readlink(f"/proc/{pid}/fd/{fd}")
            except OSError:
                continue
            if link == target:
                opened = True
            elif index is not None and link in PTMX and _tty_index(pid, fd) == index:
                board_end = True
        if opened and not board_end:
            found.append(Holder(pid, _command(pid)))
    return found


def in_use_error(device: str, holders: list[Holder]) -> DeviceError:
    """The error for a port another program holds.

    Parameters
    ----------
    device : str
        The serial port.
    holders : list of Holder
        Who holds it (from :func:`port_holders`); empty when only its lock says so.

    Returns
    -------
    DeviceError
        "port in use by another program", naming them.
    """
    if holders:
        who = "; ".join(str(h) for h in holders)
        return DeviceError(f"port in use by another program: {device} is open in {who}", IN_USE_HINT)
    return DeviceError(f"port in use by another program: {device} is locked by a process this user cannot see",
                       "close the other program on the port (`sudo fuser -v " + device + "` names it), "
                       "then run this again")


def check_free(device: str) -> None:
    """Refuse a port another program has open (call it once this process has opened it).

    Parameters
    ----------
    device : str
        The serial port.

    Raises
    ------
    DeviceError
        Another process has it open.
    """
    holders = port_holders(device)
    if holders:
        raise in_use_error(device, holders)
