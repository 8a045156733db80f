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


def hex_to_rgb01(hex_colour: str) -> tuple[float, float, float]:
    h = hex_colour.lstrip("#")
    return tuple(int(h[i:i + 2], 16) / 255.0 for i in (0, 2, 4))  # type: ignore[return-value]
