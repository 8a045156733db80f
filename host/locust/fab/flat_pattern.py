"""The leg's flat pattern, drawn from the robot's four link lengths.

The four-bar is folded from one strip of laminate. The rule (the seed's ``zz.dxf``, an
18 x 3 cm strip, is this rule applied to links 4 | 4 | 2 | 6 cm):

- the links lie end to end along x in loop order: ground, crank, coupler, leg, followed
  by a glue tab (``glue_tab_mm``, 20 mm) that is glued under the start of the ground
  link to close the loop;
- a hinge sits at every boundary between two segments, so the hinge centres are the
  running sums of the link lengths: ground, ground+crank, ground+crank+coupler,
  ground+crank+coupler+leg (seed: 40, 80, 100, 160 mm);
- the strip is ``link_width_m`` wide (seed 30 mm); each hinge is a stadium slot
  ``slot_width_mm`` x ``slot_length_mm`` (seed 1 x 13 mm) centred on the strip's width.

So the Medium (+10 mm a link) and Large (+20 mm) leg sets have hinges at 50, 100, 130,
200 mm and 60, 120, 160, 240 mm, on 220 and 260 mm strips.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import accumulate
from pathlib import Path

from shapely.geometry import LineString, box

from ..errors import FabError
from .design import Design, HingeCut

LINK_ORDER = ("ground", "crank", "coupler", "leg")


@dataclass(frozen=True)
class FlatPattern:
    """The numbers that fix the strip, in millimetres.

    Attributes
    ----------
    links_mm : tuple of float
        Ground, crank, coupler and leg link lengths [mm].
    width_mm : float
        Strip width [mm].
    glue_tab_mm : float
        Length of the tab glued under the ground link [mm].
    slot_width_mm, slot_length_mm : float
        Each hinge slot's width (along the strip) and length (across it) [mm].
    name : str
        The robot's name, for the drawing's source.
    """

    links_mm: tuple[float, float, float, float]   # ground, crank, coupler, leg
    width_mm: float = 30.0
    glue_tab_mm: float = 20.0
    slot_width_mm: float = 1.0
    slot_length_mm: float = 13.0
    name: str = "leg"

    @property
    def hinges_x_mm(self) -> tuple[float, ...]:
        """The hinge centres along the strip, the running sums of the link lengths [mm]."""
        return tuple(round(x, 9) for x in accumulate(self.links_mm))

    @property
    def length_mm(self) -> float:
        """The strip's length, links and glue tab [mm]."""
        return sum(self.links_mm) + self.glue_tab_mm

    def check(self) -> None:
        """Refuse a strip that cannot be cut.

        Raises
        ------
        FabError
            A link no longer than a slot is wide, a slot that does not fit the strip, or a negative
            glue tab.
        """
        bad = [f"{n}={v:g} mm" for n, v in zip(LINK_ORDER, self.links_mm) if not v > self.slot_width_mm]
        if bad:
            raise FabError(f"flat pattern: link too short for a {self.slot_width_mm:g} mm hinge slot: {', '.join(bad)}",
                           "check the robot's geometry.*_m link lengths (metres)")
        if not 0 < self.slot_width_mm < self.slot_length_mm < self.width_mm:
            raise FabError(
                f"flat pattern: slot {self.slot_width_mm:g} x {self.slot_length_mm:g} mm does not fit "
                f"a {self.width_mm:g} mm wide strip",
                "the slot must be longer than wide and shorter than the strip width (geometry.link_width_m)")
        if self.glue_tab_mm < 0:
            raise FabError(f"flat pattern: negative glue tab {self.glue_tab_mm:g} mm", "give --glue-tab-mm >= 0")

    def slot_span_y_mm(self) -> tuple[float, float]:
        """Where the slots lie across the strip, centred on its width.

        Returns
        -------
        tuple of float
            (lowest, highest) y of every slot [mm].
        """
        c = self.width_mm / 2
        return c - self.slot_length_mm / 2, c + self.slot_length_mm / 2


def from_robot(robot, **overrides) -> FlatPattern:
    """The flat pattern of ``robot`` (a :class:`locust.params.Robot`), metres to mm.

    Parameters
    ----------
    robot : Robot
        Gives the link lengths and link width [m] and the name.
    **overrides
        Other :class:`FlatPattern` fields (``glue_tab_mm``, ``slot_width_mm``, ...).

    Returns
    -------
    FlatPattern
        The checked pattern.

    Raises
    ------
    FabError
        The pattern cannot be cut (:meth:`FlatPattern.check`).
    """
    links = tuple(round(v * 1000.0, 9) for v in robot.link_lengths_m())
    fp = FlatPattern(links_mm=links, width_mm=round(robot.geometry.link_width_m * 1000.0, 9),
                     name=robot.name, **overrides)
    fp.check()
    return fp


def assembly(robot) -> dict:
    """What the cut files do not hold of ``robot``'s design, and its building and hopping need:
    the crank's angle at rest (the servo horn goes onto its spline there: docs/hardware.md),
    where the servo axis sits on the plate, and the push the design was chosen with (a
    ``locust optimize`` design varies these beside its links).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    dict
        ``robot`` (its name), ``links_mm`` (ground, crank, coupler, leg [mm]), ``link_width_mm``,
        ``crank_start_deg``, ``servo_axis_x_mm`` (from the plate's centre), ``push_deg`` and
        ``push_s``.
    """
    g, s = robot.geometry, robot.schedule
    return {"robot": robot.name,
            "links_mm": {name: round(v * 1000.0, 6) for name, v in zip(LINK_ORDER, robot.link_lengths_m())},
            "link_width_mm": round(g.link_width_m * 1000.0, 6), "crank_start_deg": g.crank_start_deg,
            "servo_axis_x_mm": round(g.servo_axis_x_m * 1000.0, 6), "push_deg": s.push_deg, "push_s": s.push_s}


def stadium(x_mm: float, y0_mm: float, y1_mm: float, width_mm: float):
    """A vertical slot with round ends spanning y0..y1 (overall), ``width_mm`` wide.

    Parameters
    ----------
    x_mm : float
        The slot's centre line [mm].
    y0_mm, y1_mm : float
        Its overall ends [mm].
    width_mm : float
        Its width [mm].

    Returns
    -------
    Polygon
        The slot [mm].
    """
    r = width_mm / 2
    return LineString([(x_mm, y0_mm + r), (x_mm, y1_mm - r)]).buffer(r, cap_style="round", quad_segs=64)


def design(fp: FlatPattern) -> Design:
    """The pattern as a :class:`~.design.Design`: the strip as body, a stadium slot at each hinge.

    Parameters
    ----------
    fp : FlatPattern
        The pattern.

    Returns
    -------
    Design
        The design [mm], layers ``plate`` and ``hinge_1`` ... ``hinge_4``.

    Raises
    ------
    FabError
        The pattern cannot be cut.
    """
    fp.check()
    y0, y1 = fp.slot_span_y_mm()
    hinges = tuple(HingeCut(f"hinge_{i + 1}", "slot", stadium(x, y0, y1, fp.slot_width_mm))
                   for i, x in enumerate(fp.hinges_x_mm))
    return Design(body=box(0.0, 0.0, fp.length_mm, fp.width_mm), hinges=hinges,
                  source=f"flat pattern of {fp.name}", units="mm", units_from="robot parameters",
                  layer_roles={"plate": "body", **{h.layer: "hinge" for h in hinges}})


def drawing_bytes(fp: FlatPattern) -> bytes:
    """The flat pattern as the seed drew it: LINE outline on ``plate``, each slot as two
    LINEs and two ARCs on ``hinge_N``; millimetres ($INSUNITS 4).

    Parameters
    ----------
    fp : FlatPattern
        The pattern.

    Returns
    -------
    bytes
        The DXF file.

    Raises
    ------
    FabError
        The pattern cannot be cut.
    """
    import io

    import ezdxf

    fp.check()
    doc = ezdxf.new("R2010", units=4)
    doc.header["$PSVPSCALE"] = 1.0     # else LibreCAD prints everything onto one point
    msp = doc.modelspace()
    doc.layers.add("plate", color=7)
    L, W = fp.length_mm, fp.width_mm
    corners = [(0, 0), (L, 0), (L, W), (0, W)]
    for a, b in zip(corners, corners[1:] + corners[:1]):
        msp.add_line(a, b, dxfattribs={"layer": "plate"})
    y0, y1 = fp.slot_span_y_mm()
    r = fp.slot_width_mm / 2
    for i, x in enumerate(fp.hinges_x_mm):
        layer = f"hinge_{i + 1}"
        doc.layers.add(layer, color=1)
        attrs = {"layer": layer}
        msp.add_line((x - r, y0 + r), (x - r, y1 - r), dxfattribs=attrs)
        msp.add_line((x + r, y0 + r), (x + r, y1 - r), dxfattribs=attrs)
        msp.add_arc((x, y1 - r), r, 0, 180, dxfattribs=attrs)
        msp.add_arc((x, y0 + r), r, 180, 360, dxfattribs=attrs)
    stream = io.StringIO()
    doc.write(stream)
    return stream.getvalue().encode("utf-8")


def write_drawing(fp: FlatPattern, path: str | Path) -> Path:
    """Write :func:`drawing_bytes` to ``path`` atomically (:func:`locust.fileio.atomic_write_bytes`).

    Parameters
    ----------
    fp : FlatPattern
        The pattern.
    path : str or Path
        The DXF file to write.

    Returns
    -------
    Path
        The file written.
    """
    from ..fileio import atomic_write_bytes

    return atomic_write_bytes(path, drawing_bytes(fp))
