"""Marker colours shared by the simulation's renders and the video tracker.

The simulation draws emissive dots of these colours on the nose and the foot, so that
``locust track video.mp4`` with no ``--marker`` finds them in the virtual robot's videos;
stick paper dots of the same colours on the real robot for the same result.
"""

from __future__ import annotations

# name -> (#RRGGBB, where it sits)
MARKER_COLOURS: dict[str, tuple[str, str]] = {
    "nose": ("#ff00ff", "chassis side facing the camera, just behind and above the front edge"),
    "foot": ("#00ffff", "on the left leg's outer face, 25 mm up from the foot (the leg facing the camera)"),
}


# Stickers for a still photo of the robot from its left side (``locust sim --still``,
# ``locust measure stance``): six hues 60 degrees apart, so each is told from the others by
# colour alone; the video markers' two colours are kept for the nose and the foot.
# name -> (#RRGGBB, where it sits); the distances are sim/stickers.py's
STICKER_COLOURS: dict[str, tuple[str, str]] = {
    "nose": ("#ff00ff", "on the plate's side, 10 mm in from its nose end"),
    "tail": ("#ffff00", "on the plate's side, 10 mm in from its leg end"),
    "axis": ("#ff0000", "on the crank, over the servo horn's axis"),
    "crank": ("#00ff00", "on the crank, 8 mm in from the crank-coupler joint (its tip)"),
    "knee": ("#0000ff", "on the leg, 8 mm up from the coupler-leg joint (the joint itself touches the floor)"),
    "foot": ("#00ffff", "on the leg, 25 mm up from the coupler-leg joint (the videos' foot dot)"),
}


# Stickers for a fold's static test (``locust calibrate fold``, :mod:`locust.sim.foldrig`): three
# hues far from one another and from a coin's copper or brass, read from a side photo of the fold.
# name -> (#RRGGBB, where it sits)
FOLD_STICKER_COLOURS: dict[str, tuple[str, str]] = {
    "axis": ("#ff00ff", "on the clamped link's face, its centre on the fold line"),
    "tip": ("#00ff00", "on the free link's face near its tip, its centre on the link's centre line"),
    "base": ("#0000ff", "on the clamped link's face, its centre on the link's centre line, 2 to 3 cm from the fold"),
}


def hex_to_rgb01(hex_colour: str) -> tuple[float, float, float]:
    """A ``#RRGGBB`` colour as red, green and blue, each 0..1.

    Parameters
    ----------
    hex_colour : str
        ``#RRGGBB`` (the ``#`` optional).

    Returns
    -------
    tuple of float
    """
    h = hex_colour.lstrip("#")
    return tuple(int(h[i:i + 2], 16) / 255.0 for i in (0, 2, 4))  # type: ignore[return-value]
