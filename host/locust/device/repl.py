"""``locust repl``: mpremote's interactive REPL on the robot's serial port.

The firmware's command loop owns the console until Ctrl-C stops it (while no hop runs): the
servos go to rest and the console is MicroPython's REPL. Ctrl-D at the ``>>>`` prompt is a
soft reset, which runs ``main.py`` and so the command loop again; leaving mpremote (Ctrl-]
or Ctrl-X) leaves the board as it is.
"""

from __future__ import annotations

import subprocess
import sys

from ..errors import DeviceError
from .holders import check_free


def mpremote_command(device: str, *args: str) -> list[str]:
    """``mpremote connect DEVICE ARGS...`` run by this Python (the pinned mpremote beside locust).

    Parameters
    ----------
    device : str
        The serial port.
    *args : str
        mpremote's further arguments, e.g. ``repl``.

    Returns
    -------
    list of str
        The command line, ready for :mod:`subprocess`.
    """
    return [sys.executable, "-m", "mpremote", "connect", device, *args]


def require_terminal() -> None:
    """Check that standard input is a terminal: mpremote's REPL puts it in raw mode.

    Raises
    ------
    DeviceError
        Standard input is not a terminal.
    """
    if not sys.stdin.isatty():
        raise DeviceError("`locust repl` needs a terminal (its standard input is not one)",
                          'run it in a terminal; to script the board, `mpremote connect PORT exec "CODE"` '
                          "gets past the idle command loop with its own Ctrl-C")


def run_repl(device: str) -> None:
    """Run mpremote's REPL on ``device`` in this terminal until the user leaves it.

    Parameters
    ----------
    device : str
        The serial port.

    Raises
    ------
    DeviceError
        Standard input is not a terminal, another program has the port open, or mpremote ends
        with a non-zero status.
    """
    require_terminal()
    check_free(device)   # (mpremote says only "failed to access" a port another program holds)
    code = subprocess.call(mpremote_command(device, "repl"))  # interrupted: mpremote is killed
    if code != 0:
        raise DeviceError(f"mpremote's REPL on {device} ended with status {code}",
                          "check the port (`locust ports`) and that no other program holds it "
                          "(`locust hop`, a serial monitor, another mpremote)")
