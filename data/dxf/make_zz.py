"""Rebuild the seed's ``zz.dxf`` from the notebook's description of it (Part 4).

The original file is not available. The notebook prints what its reader found in it:
layers ``plate``, ``hinge_1`` .. ``hinge_4``; the body an 18 x 3 cm rectangle from
(0, 0) to (18, 3) cm drawn with LINEs; four stadium hinge slots 0.1 x 1.3 cm centred at
x = 4, 8, 10, 16 cm spanning y 0.85 .. 2.15 cm, each two LINEs and two ARCs (radius
0.05 cm). Units: centimetres ($INSUNITS 5). This script draws exactly that and nothing
else, so ``zz.dxf`` here is REBUILT, not the seed's own file.

    python data/dxf/make_zz.py            # writes data/dxf/zz.dxf
"""

from __future__ import annotations

import sys
from pathlib import Path

import ezdxf

LENGTH_CM, WIDTH_CM = 18.0, 3.0
SLOT_X_CM = (4.0, 8.0, 10.0, 16.0)
SLOT_Y_CM = (0.85, 2.15)
SLOT_W_CM = 0.1


def build() -> ezdxf.document.Drawing:
    """The seed's zz.dxf as its notebook describes it: the plate and its four hinge slots."""
    doc = ezdxf.new("R2010", units=5)            # centimetres, like the seed
    doc.header["$MEASUREMENT"] = 1
    doc.header["$PSVPSCALE"] = 1.0               # ezdxf's 0 makes LibreCAD print nothing
    msp = doc.modelspace()
    doc.layers.add("plate", color=7)
    corners = [(0, 0), (LENGTH_CM, 0), (LENGTH_CM, WIDTH_CM), (0, WIDTH_CM)]
    for a, b in zip(corners, corners[1:] + corners[:1]):
        msp.add_line(a, b, dxfattribs={"layer": "plate"})
    r = SLOT_W_CM / 2
    y0, y1 = SLOT_Y_CM[0] + r, SLOT_Y_CM[1] - r     # arc centres: straight part 0.9 .. 2.1
    for i, x in enumerate(SLOT_X_CM, start=1):
        attrs = {"layer": f"hinge_{i}"}
        doc.layers.add(f"hinge_{i}", color=1)
        msp.add_line((x - r, y0), (x - r, y1), dxfattribs=attrs)
        msp.add_line((x + r, y0), (x + r, y1), dxfattribs=attrs)
        msp.add_arc((x, y1), r, 0, 180, dxfattribs=attrs)
        msp.add_arc((x, y0), r, 180, 360, dxfattribs=attrs)
    return doc


def main(out: str | None = None) -> Path:
    """Write the drawing to ``out`` (default: zz.dxf beside this script), the same bytes every run."""
    path = Path(out) if out else Path(__file__).with_name("zz.dxf")
    ezdxf.options.write_fixed_meta_data_for_testing = True    # fixed dates and GUIDs:
    doc = build()                                              # the same bytes every run
    doc.saveas(path)
    print(f"wrote {path} (rebuilt from the notebook's description)")
    return path


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
