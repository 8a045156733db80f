"""``locust repl``: MicroPython's REPL on the robot."""

from __future__ import annotations

import click

from ._device import PORT_HELP, info


@click.command()
@click.option("--port", default=None, help=PORT_HELP)
def repl(port):
    """Open MicroPython's REPL on the robot (mpremote connect PORT repl); leave with Ctrl-] or Ctrl-X.

    \b
    In the REPL session:
      Ctrl-C      stops the locust command loop (servos to rest) and gives the >>> prompt;
                  ignored while a hop runs
      Ctrl-D      at the >>> prompt: soft reset, main.py starts the command loop again
      Ctrl-] or Ctrl-X   leave mpremote (the board stays as it is)

    Until Ctrl-C the command loop owns the console: nothing is echoed, and a line you type is
    answered with a bad_frame reply. For scripts, `mpremote connect PORT exec "..."` gets in
    the same way (its own Ctrl-C); `locust hop`/`pose` need the command loop again (Ctrl-D
    here, `locust flash`, or a reset).

    With --port sim a virtual robot runs (its /dev/pts/N is printed) for as long as the REPL
    session; to use the same virtual robot with other commands too, start `locust virtual`
    and pass its /dev/pts/N as --port.
    """
    from ..device.interrupts import signals_interrupt
    from ..device.repl import require_terminal, run_repl
    from ..device.session import open_port

    require_terminal()  # before a virtual robot is started for nothing
    # a closed terminal (SIGHUP) or a kill (SIGTERM) must still stop a --port sim virtual robot
    with signals_interrupt(), open_port(port, plant="record", info=info, firmware=False) as device:
        info(f"mpremote REPL on {device}: Ctrl-C for the >>> prompt, Ctrl-D there restarts the firmware, "
             "Ctrl-] or Ctrl-X leaves")
        run_repl(device)
