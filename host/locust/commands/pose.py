"""``locust pose``: the servos to an angle, held."""

from __future__ import annotations

import click

from ..errors import DeviceError
from ._device import PORT_HELP, info


@click.command(context_settings={"ignore_unknown_options": True})  # `pose -20 10`: -20 is an angle
@click.argument("left_deg", type=float, required=False)
@click.argument("right_deg", type=float, required=False)
@click.option("--rest", is_flag=True, help="Both horns to rest (0 deg, the servos' centre).")
@click.option("--port", default=None, help=PORT_HELP)
def pose(left_deg, right_deg, rest, port):
    """Move both servo horns to LEFT_DEG RIGHT_DEG and hold them there: for assembly and trim.

    \b
    Centring, before the horns go on:
      locust pose --rest            both servos to their centre (horn 0 deg) and hold
    then push each horn onto its spline as close to its rest position as the splines allow.
    Trimming the rest of the error:
      locust pose 0 0               look at the legs at rest
      locust config --set left.trim_deg=2.5   (shaft deg; reversed on the mirrored right leg)
    Checking the travel and the direction of each leg:
      locust pose -20 10            left horn -20 deg, right horn +10 deg

    Angles are horn degrees from rest in the firmware's units: push is negative and both legs
    use the same sign (the right servo is mirrored by its config's direction). The protocol
    allows -90..90; the robot refuses anything beyond its servo travel (travel_deg, +-45 deg
    by default). Negative angles can be typed directly or after `--` (`locust pose -- -20 -20`).

    The pose holds after the command ends, until the robot is told otherwise: another pose, or
    a hop, a servo config change or Ctrl-C into the REPL, which leave it at rest, or a reset,
    which stops the pulses (the servos go limp) until the firmware starts and sets them to rest.
    With --port sim the virtual robot lives only as long as the command: use `locust virtual`
    and its /dev/pts/N to watch a pose there.
    """
    from ..device.link import Link
    from ..device.ports import SIM
    from ..device.pose import check_angles
    from ..device.pose import pose as do_pose
    from ..device.session import open_port

    given = [a for a in (left_deg, right_deg) if a is not None]
    if rest and given:
        raise DeviceError("give either LEFT_DEG RIGHT_DEG or --rest, not both", "e.g. `locust pose -20 10`")
    if not rest and len(given) != 2:
        raise DeviceError("a pose needs both angles, LEFT_DEG and RIGHT_DEG (or --rest)",
                          "e.g. `locust pose -20 10`, `locust pose --rest`; see `locust pose --help`")
    if not rest:
        left_deg, right_deg = check_angles(left_deg, right_deg)  # before any port is opened
    with open_port(port, plant="record", info=info) as device:
        with Link(device) as link:
            left, right = do_pose(link, None if rest else left_deg, None if rest else right_deg)
    if port == SIM:   # its virtual robot has just stopped with the command: nothing holds the pose
        held = ("not held: this command's virtual robot stopped with it (to hold a pose, start `locust virtual` "
                "and pass its /dev/pts/N as --port)")
    else:
        held = "held until another command moves the servos or a reset"
    click.echo(f"{'rest' if rest else 'pose'}: left {left:g} deg, right {right:g} deg (horn, from rest) "
               f"on {port or device}; {held}")
