"""The board's servo config read back and changed over the protocol (``locust config``).

The firmware answers ``config`` with the config it runs on and ``hello`` with its chip and,
when config.json was unreadable or invalid, why it fell back to its defaults
(``config_problems``). A ``config`` request with ``write=1`` sets one key and saves the whole
config.json on the board (checked there against the limits and the chip's pins): a trim
changes without flashing anything, and a config the firmware could not read is replaced.
"""

from __future__ import annotations

from ..io import run_record as R
from .link import Link
from .replies import check_config


def read_board(link: Link, hello: dict | None = None) -> R.BoardConfig:
    """The config the firmware runs on (pins, trims, pulse ranges), its chip, and why it is
    not the saved config.json when it is not (the firmware's ``config_problems``).

    Parameters
    ----------
    link : Link
        An open link to the board.
    hello : dict, optional
        The board's ``hello`` reply when already had; asked for when None.

    Returns
    -------
    BoardConfig
        Both servos' config with the chip, machine and config problems.

    Raises
    ------
    DeviceError
        The board does not answer, refuses, or answers out of shape.
    """
    hello = hello or link.hello()
    cfg = check_config(link.call("config"), link.port, hello.get("chip"))
    return R.board_config({**cfg, "chip": hello.get("chip"), "machine": hello.get("machine"),
                           "config_problems": hello.get("config_problems") or []}, f"the board on {link.port}")


def write_values(link: Link, edits: list[tuple[str, float]], info=lambda msg: None) -> None:
    """Set each ``("left.trim_deg", 2.5)`` on the board and save its config.json.

    Parameters
    ----------
    link : Link
        An open link to the board.
    edits : list of (str, float)
        Dotted config keys and their new values, in the key's own unit (``trim_deg`` in degrees).
    info : callable, optional
        ``info(line)`` for each value set.

    Raises
    ------
    DeviceError
        The board refuses a value (out of its limits, or a pin the chip cannot use).
    """
    for key, value in edits:
        link.call("config", key=key, value=value, write=1)
        info(f"  set {key} = {value:g}")


def table(board: R.BoardConfig) -> str:
    """The board's config as a table for people.

    Parameters
    ----------
    board : BoardConfig
        From :func:`read_board`.

    Returns
    -------
    str
        One header row and one row per servo: pin, trim [deg], direction, pulse range [us],
        range [deg] and travel [deg].
    """
    rows = [("servo", "pin", "trim deg", "direction", "pulse us", "range deg", "travel deg")]
    for name, s in (("left", board.left), ("right", board.right)):
        rows.append((name, str(s.pin), f"{s.trim_deg:g}", f"{s.direction:+d}",
                     f"{s.pulse_min_us:g}-{s.pulse_max_us:g}", f"{s.range_deg:g}", f"{s.travel_deg:g}"))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows)
