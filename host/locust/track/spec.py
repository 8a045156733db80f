"""``--marker NAME=SPEC`` parsing, and the default marker set.

Specs::

    color:#RRGGBB[@X,Y]    a coloured sticker (tolerance: --color-tol), first looked for near (X, Y)
    template:X,Y@FRAME     Tracker's autotracker, template around (X, Y) on FRAME
    aruco:ID[@DICT]        an ArUco marker (default dictionary DICT_4X4_50)

Pixel positions typed here (and ``--origin``, ``--plane-points``, ``--scale``) are read in
Tracker's convention by default (``--pixels tracker``: origin at the top-left *corner* of the
image, so pixel i's centre is at i + 0.5; what a student copies from Tracker's table), or in
OpenCV's (``--pixels opencv``: origin at the centre of the top-left pixel), and turned into
OpenCV's, which every output pixel column uses, by :func:`locust.track.calib.typed_px`.

With no ``--marker`` the markers are the robot's own colours from
:data:`locust.markers.MARKER_COLOURS` (nose magenta, foot cyan), which the simulation
renders too.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..errors import TrackError
from ..markers import MARKER_COLOURS
from .aruco import DEFAULT_DICTIONARY, ArucoMarker
from .calib import PIXEL_CONVENTIONS, typed_px
from .color import ColorMarker, parse_hex
from .template import TemplateMarker

NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)"


@dataclass(frozen=True)
class ModelOptions:
    """Settings shared by all markers of one run; ``pixels``: the convention of typed positions."""

    color_tol: int = 80
    search_half_px: int = 40
    template_radius_px: int = 8
    accept: float = 0.5
    evolve: float = 0.2
    likeness: float = 0.5
    pixels: str = "tracker"

    def __post_init__(self) -> None:
        if not math.isfinite(self.accept):
            raise TrackError(f"--accept {self.accept}: not a finite number",
                             "give --accept as a plain number, see --help")
        if self.pixels not in PIXEL_CONVENTIONS:
            raise TrackError(f"pixel convention {self.pixels!r} is not known", "give tracker or opencv")


def default_specs() -> list[str]:
    """The default markers: ``nose`` and ``foot`` by their sticker colours.

    Returns
    -------
    list of str
        ``NAME=color:#RRGGBB`` specs.
    """
    return [f"{name}=color:{hex_colour}" for name, (hex_colour, _) in MARKER_COLOURS.items()]


def parse_marker(text: str, options: ModelOptions = ModelOptions()):
    """One ``NAME=SPEC`` string -> a marker model (see the module doc).

    Parameters
    ----------
    text : str
        ``NAME=SPEC``.
    options : ModelOptions
        The models' settings.

    Returns
    -------
    ColorMarker, TemplateMarker or ArucoMarker
        The marker model.

    Raises
    ------
    TrackError
        A bad name or spec.
    """
    name, sep, spec = text.partition("=")
    name, spec = name.strip(), spec.strip()
    if not sep or not NAME_RE.match(name):
        raise TrackError(f"--marker {text!r}: expected NAME=SPEC with a name of letters, digits and _",
                         "e.g. --marker nose=color:#ff00ff or --marker ball=template:131.3,207.9@2")
    kind, _, arg = spec.partition(":")
    kind = kind.lower()
    if kind in ("color", "colour"):
        colour, at, start = arg.partition("@")
        start_px = None
        if at:
            m = re.fullmatch(rf"\s*({NUM})\s*,\s*({NUM})\s*", start)
            if not m:
                raise TrackError(f"--marker {text!r}: colour spec must be color:#RRGGBB or color:#RRGGBB@X,Y",
                                 "give the sticker's pixel position on the first frame, e.g. color:#e8308c@412,630 "
                                 "(locust track preview VIDEO shows the positions)")
            start_px = typed_px(float(m.group(1)), float(m.group(2)), options.pixels)
        return ColorMarker(name, spec, parse_hex(colour), tolerance=options.color_tol,
                           search_half_px=options.search_half_px, start_px=start_px)
    if kind == "template":
        m = re.fullmatch(rf"\s*({NUM})\s*,\s*({NUM})\s*@\s*(\d+)\s*", arg)
        if not m:
            raise TrackError(f"--marker {text!r}: template spec must be template:X,Y@FRAME",
                             "give the pixel position of the feature on a frame, e.g. template:131.28,207.86@2")
        x, y = typed_px(float(m.group(1)), float(m.group(2)), options.pixels)
        return TemplateMarker(name, spec, x, y, int(m.group(3)),
                              radius_px=options.template_radius_px, search_half_px=options.search_half_px,
                              accept=options.accept, evolve=options.evolve,
                              min_likeness=options.likeness)
    if kind == "aruco":
        m = re.fullmatch(r"\s*(\d+)\s*(?:@\s*(DICT_\w+)\s*)?", arg)
        if not m:
            raise TrackError(f"--marker {text!r}: ArUco spec must be aruco:ID or aruco:ID@DICT_4X4_50",
                             "give the marker's id number, e.g. aruco:7")
        return ArucoMarker(name, spec, int(m.group(1)), m.group(2) or DEFAULT_DICTIONARY)
    raise TrackError(f"--marker {text!r}: unknown marker kind {kind!r}",
                     "use color:#RRGGBB[@X,Y], template:X,Y@FRAME or aruco:ID")


def parse_markers(texts: list[str] | tuple[str, ...], options: ModelOptions = ModelOptions()) -> list:
    """The marker models of ``--marker`` options (the default set when none is given).

    Parameters
    ----------
    texts : list of str
        ``NAME=SPEC`` strings.
    options : ModelOptions
        The models' settings.

    Returns
    -------
    list
        One marker model per spec.

    Raises
    ------
    TrackError
        A bad spec, or a name used twice.
    """
    models = [parse_marker(t, options) for t in (texts or default_specs())]
    names = [m.name for m in models]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise TrackError(f"marker name(s) used twice: {', '.join(dupes)}", "give each --marker its own name")
    return models
