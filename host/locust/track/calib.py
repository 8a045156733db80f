"""Pixels to metres: scale, origin and axes, as Tracker's calibration stick and axes
(:class:`~locust.io.trk.Calibration`, the type a Tracker project's calibration is read into).

World coordinates are metres, y up. ``angle_deg`` is the direction of the world x axis
measured counter-clockwise (as seen on screen) from the image x axis, as in Tracker's
``ImageCoordSystem``. The origin is a pixel position (OpenCV convention); by default the
centre of the bottom-left pixel, so a robot on the floor has y >= 0.
"""

from __future__ import annotations

import math
import re

from ..errors import TrackError
from ..io.trk import PIXEL_CONVENTIONS, Calibration

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def parse_scale(text: str) -> tuple[float, float, float, float, float]:
    """``X1,Y1,X2,Y2=LENGTH_M`` -> the stick's two ends (px) and its length (m).

    Parameters
    ----------
    text : str
        The ``--scale`` value.

    Returns
    -------
    tuple of float
        x1, y1, x2, y2 [px] and the length [m].

    Raises
    ------
    TrackError
        Not that form, a length that is not positive, or ends less than a pixel apart.
    """
    m = re.fullmatch(rf"\s*({NUM})\s*,\s*({NUM})\s*,\s*({NUM})\s*,\s*({NUM})\s*=\s*({NUM})\s*", text)
    if not m:
        raise TrackError(f"--scale {text!r}: expected X1,Y1,X2,Y2=LENGTH_M",
                         "give both ends of a stick of known length in pixels, e.g. --scale 272.2,446.1,273.2,47.4=1.0")
    x1, y1, x2, y2, length = map(float, m.groups())
    if not length > 0:
        raise TrackError(f"--scale {text!r}: the length must be positive (metres)")
    if math.hypot(x2 - x1, y2 - y1) < 1.0:
        raise TrackError(f"--scale {text!r}: the two ends are less than a pixel apart",
                         "use the two ends of the stick, as far apart as it shows")
    return x1, y1, x2, y2, length


PIXELS_HELP = ("Convention of the pixel positions typed in --marker, --origin, --scale and --plane-points: "
               "tracker (Tracker's table: origin at the image's top-left corner, a pixel's centre at i + 0.5) "
               "or opencv (origin at the top-left pixel's centre). Output pixel columns are OpenCV's.")


def typed_px(x: float, y: float, pixels: str) -> tuple[float, float]:
    """A pixel position typed in convention ``pixels`` (``tracker`` or ``opencv``), in OpenCV's.

    Parameters
    ----------
    x, y : float
        The position as typed [px].
    pixels : str
        ``tracker`` (pixel centres at i + 0.5) or ``opencv`` (at i).

    Returns
    -------
    tuple of float
        (x, y) in OpenCV's convention [px].

    Raises
    ------
    TrackError
        An unknown convention.
    """
    if pixels not in PIXEL_CONVENTIONS:
        raise TrackError(f"pixel convention {pixels!r} is not known", "give tracker or opencv")
    d = PIXEL_CONVENTIONS[pixels]
    return x + d, y + d



def parse_point(text: str, option: str) -> tuple[float, float]:
    """``X,Y`` in pixels, as an option gives it.

    Parameters
    ----------
    text : str
        The option's value.
    option : str
        The option's name, for the message.

    Returns
    -------
    tuple of float
        (x, y) [px].

    Raises
    ------
    TrackError
        Not two numbers separated by a comma.
    """
    m = re.fullmatch(rf"\s*({NUM})\s*,\s*({NUM})\s*", text)
    if not m:
        raise TrackError(f"{option} {text!r}: expected X,Y in pixels", f"e.g. {option} 131.3,207.9")
    return float(m.group(1)), float(m.group(2))


def parse_aruco_scale(text: str) -> tuple[int, float]:
    """``--scale-aruco ID=SIDE_M``: the marker whose printed side sets the scale.

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    marker_id : int
        The ArUco id.
    side_m : float
        Its printed side length [m].

    Raises
    ------
    TrackError
        Not ``ID=SIDE_M`` with a positive side.
    """
    m = re.fullmatch(rf"\s*(\d+)\s*=\s*({NUM})\s*", text)
    if not m or not float(m.group(2)) > 0:
        raise TrackError(f"--scale-aruco {text!r}: expected ID=SIDE_M (the printed side length in metres)",
                         "e.g. --scale-aruco 7=0.04 for a 4 cm marker")
    return int(m.group(1)), float(m.group(2))


def m_per_px_from_stick(x1: float, y1: float, x2: float, y2: float, length_m: float) -> float:
    """The scale given by a calibration stick of known length between two pixels.

    Parameters
    ----------
    x1, y1, x2, y2 : float
        The stick's ends [px].
    length_m : float
        Its length [m].

    Returns
    -------
    float
        Metres per pixel [m/px].
    """
    return length_m / math.hypot(x2 - x1, y2 - y1)


def build(height_px: int, m_per_px: float = math.nan, origin: tuple[float, float] | None = None,
          angle_deg: float = 0.0, source: str = "none") -> Calibration:
    """A calibration; the origin defaults to the bottom-left pixel's centre.

    Parameters
    ----------
    height_px : int
        The frame's height [px].
    m_per_px : float
        Scale [m/px]; nan for none (pixels only).
    origin : tuple of float, optional
        The world origin (x, y) [px].
    angle_deg : float
        The x axis's angle to the image's x axis, counter-clockwise [deg].
    source : str
        How the scale was set, as recorded.

    Returns
    -------
    Calibration
        The calibration.
    """
    ox, oy = origin if origin is not None else (0.0, float(height_px - 1))
    return Calibration(m_per_px, ox, oy, angle_deg, source)
