"""`os` with uname() and a board's ilistdir(), for the virtual robot (MicroPython code).

A board's os.uname().machine names its chip ("Generic ESP32 module with ESP32", "... with
ESP32S3"); sys.platform is "esp32" on all of them. The unix port has no os.uname; this one
reports the chip the virtual robot models ($LOCUST_MACHINE).

A board's filesystem (littlefs, FAT) lists each entry as (name, type, inode, size); the unix
port's ilistdir gives (name, type, inode) only, so mpremote's `fs ls` showed every file as 0
bytes. This one adds the size from stat(), 0 for a directory as on a board.
"""
import uos as _os
from uos import *  # noqa: F403


class _Uname:
    sysname = "esp32"
    nodename = "esp32"
    release = "virtual"
    version = "locust virtual robot"

    def __init__(self, machine):
        self.machine = machine

    def __repr__(self):
        return "(sysname='%s', nodename='%s', release='%s', version='%s', machine='%s')" % (
            self.sysname, self.nodename, self.release, self.version, self.machine)


def uname():
    """The board's identity; ``machine`` names the modelled chip.

    Returns
    -------
    object
        ``sysname``, ``nodename``, ``release``, ``version`` and ``machine`` attributes.
    """
    return _Uname(_os.getenv("LOCUST_MACHINE") or "Generic ESP32 module with ESP32")


_DIR = 0x4000


def ilistdir(path="."):
    """The entries of ``path`` as a board lists them.

    Parameters
    ----------
    path : str, default "."
        The folder.

    Yields
    ------
    tuple
        (name, type, inode, size in bytes); the size is 0 for a folder.
    """
    for entry in _os.ilistdir(path):
        if len(entry) >= 4:
            yield entry
            continue
        name, kind, inode = entry[0], entry[1], entry[2]
        size = 0
        if kind != _DIR:
            full = name if path in ("", ".") else path.rstrip("/") + "/" + name
            try:
                size = _os.stat(full)[6]
            except OSError:
                pass
        yield (name, kind, inode, size)
