"""Laminate cut files for the foldable robot (``locust fab``).

Pipeline, one module a step:

- :mod:`.dxf_read`: any outline drawing (LINE, ARC, LWPOLYLINE with bulges, POLYLINE,
  CIRCLE, ELLIPSE, SPLINE) to contours in millimetres, open pieces chained into loops.
- :mod:`.design`: contours to a :class:`~.design.Design` (body, hinge cut-outs, holes,
  slits) through a layer-name mapping.
- :mod:`.flat_pattern`: the same :class:`~.design.Design` drawn from the robot's four
  link lengths (the leg's flat pattern).
- :mod:`.laminate`: the layer stack, alignment holes, support web, kerf compensation.
- :mod:`.export`, :mod:`.preview`, :mod:`.summary`: DXF files, PNG previews, the
  manufacturing summary.
- :mod:`.cadcheck`: open the written files in LibreCAD (headless) as a second opinion.
"""
