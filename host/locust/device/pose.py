"""Hold the servos at an angle (``locust pose``): centring before the horns go on, trimming.

The firmware's ``pose`` request sets both horns and returns at once; nothing else moves them
until the next command, a reset or a hop, so the pose holds after the host lets go. The
angles are checked here against the protocol's limits (``COMMANDS["pose"]`` in the
firmware's ``protocol.py``) before any port is opened; the servo travel (``travel_deg`` in
the board's ``config.json``) only the robot knows, and it refuses a pose beyond it.
"""

from __future__ import annotations

from ..errors import DeviceError
from ..firmware import config as fw_config
from ..firmware import protocol as P
from .link import Link
from .replies import pose_angles

DEFAULT_TRAVEL_DEG = fw_config.default()["left"]["travel_deg"]


def limits(name: str = "left_deg") -> tuple[float, float]:
    """The protocol's (lowest, highest) horn angle for ``pose``.

    Parameters
    ----------
    name : str, default "left_deg"
        The ``pose`` argument, ``left_deg`` or ``right_deg``.

    Returns
    -------
    tuple of float
        (lowest, highest) horn angle [deg].
    """
    _, lo, hi, _ = P.COMMANDS["pose"][name]
    return lo, hi


def check_angles(left_deg: float, right_deg: float) -> tuple[float, float]:
    """The angles as floats, checked by the protocol's own ``check_request``, so host and robot
    cannot disagree.

    Parameters
    ----------
    left_deg, right_deg : float
        Horn angles from rest [deg].

    Returns
    -------
    tuple of float
        (left_deg, right_deg) as floats [deg].

    Raises
    ------
    DeviceError
        The protocol refuses an angle (out of its limits, or not a number).
    """
    left_deg, right_deg = float(left_deg), float(right_deg)
    try:
        P.check_request({"id": 0, "cmd": "pose", "left_deg": left_deg, "right_deg": right_deg})
    except P.ProtocolError as exc:
        lo, hi = limits()
        bad = [f"{name} {value:g}" for name, value in (("left", left_deg), ("right", right_deg))
               if not lo <= value <= hi]  # NaN fails the comparison too
        raise DeviceError(f"bad pose: {', '.join(bad) or exc.detail} (horn angles must be {lo:g}..{hi:g} deg)",
                          "horn angles are degrees from rest (push negative, the same sign on both legs), and the "
                          f"robot also keeps them within its servo travel (travel_deg, +-{DEFAULT_TRAVEL_DEG:g} by "
                          "default); e.g. `locust pose -20 10`") from None
    return left_deg, right_deg


def _refused(cmd: str, reply: dict) -> DeviceError:
    code, detail = reply.get("error"), reply.get("detail")
    if code == P.E_RANGE:
        hint = ("the travel is travel_deg in the board's config.json (the same for both legs: the smaller "
                "one counts); change it with `locust flash --servo left.travel_deg=DEG --servo right.travel_deg=DEG`")
    elif code == P.E_BUSY:
        hint = "a hop is running: wait for it to end (the robot rests on its own when its host goes silent)"
    else:
        hint = "see docs/protocol.md"
    return DeviceError(f"the robot refused {cmd}: {code}: {detail}", hint)


def pose(link: Link, left_deg: float | None, right_deg: float | None) -> tuple[float, float]:
    """Send ``pose`` (or ``rest`` when both angles are None) after the handshake.

    Parameters
    ----------
    link : Link
        An open link to the board.
    left_deg, right_deg : float or None
        Horn angles from rest [deg]; both None sends the servos to rest.

    Returns
    -------
    tuple of float
        (left_deg, right_deg) the robot says it commanded [deg].

    Raises
    ------
    DeviceError
        An angle out of the protocol's limits, or the robot refuses the pose (beyond its servo
        travel, or a hop is running).
    """
    link.hello()
    if left_deg is None and right_deg is None:
        cmd, reply = "rest", link.request("rest")
    else:
        left_deg, right_deg = check_angles(left_deg, right_deg)
        cmd, reply = "pose", link.request("pose", left_deg=left_deg, right_deg=right_deg)
    if not reply.get("ok"):
        raise _refused(cmd, reply)
    return pose_angles(reply, link.port)
