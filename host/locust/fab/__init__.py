"""Laminate cut files for the foldable robot: the steps behind ``locust fab`` and
:func:`locust.make_cut_files`.

Pipeline, one module a step:

- :mod:`.dxf_read`: any outline drawing (LINE, ARC, LWPOLYLINE with bulges, POLYLINE,
  CIRCLE, ELLIPSE, SPLINE, also inside block references) to contours in millimetres,
  open pieces chained into loops.
- :mod:`.dxf_limits`: what a drawing may hold, counted before it is expanded or flattened
  (block copies, spline points, arc chords, finite numbers).
- :mod:`.design`: contours to a :class:`~.design.Design` (body, hinge cut-outs, holes,
  slits) through a mapping of layer names to roles.
- :mod:`.flat_pattern`: the same :class:`~.design.Design` drawn from the robot's four
  link lengths (the leg's flat pattern).
- :mod:`.laminate`: the layer stack, alignment holes, support web and release cut, kerf
  compensation.
- :mod:`.export`, :mod:`.preview`, :mod:`.summary`: DXF files, PNG previews, the
  manufacturing summary.
- :mod:`.cadcheck`: open the written files in LibreCAD (headless) as a second opinion.
"""
