"""`os` with uname(), for the virtual robot (MicroPython code).

A board's os.uname().machine names its chip ("Generic ESP32 module with ESP32", "... with
ESP32S3"); sys.platform is "esp32" on all of them. The unix port has no os.uname; this one
reports the chip the virtual robot models ($LOCUST_MACHINE).
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
