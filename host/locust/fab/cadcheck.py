"""A second opinion from a real CAD program: LibreCAD draws the DXF into a PDF.

LibreCAD 2.2 (Debian ``librecad``) has one headless command, ``librecad dxf2pdf``. It
needs ``QT_QPA_PLATFORM=offscreen``; its ``-o`` option is broken (``-t DIR`` works); it
exits 0 even when it drew nothing, and it can hang on garbage, so it always runs under a
time limit and its PDF is read back to count what was really drawn.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
import zlib
from dataclasses import dataclass
from pathlib import Path

from ..errors import FabError

PAINT_OPS = {"S", "s", "f", "F", "f*", "B", "B*", "b", "b*"}


@dataclass(frozen=True)
class PdfDrawing:
    """What the PDF's page content really strokes or fills (content-stream units).

    Attributes
    ----------
    painted_paths : int
        Paths stroked or filled.
    segments : int
        Line and curve segments in the painted paths.
    bbox : tuple of float or None
        (x0, y0, x1, y1) of the painted points [PDF units], None when nothing was painted.
    """

    painted_paths: int
    segments: int                  # line and curve segments in painted paths
    bbox: tuple[float, float, float, float] | None

    @property
    def aspect(self) -> float:
        """Width over height of :attr:`bbox` (infinite when it has no height)."""
        x0, y0, x1, y1 = self.bbox
        return (x1 - x0) / (y1 - y0) if y1 > y0 else float("inf")


def _streams(pdf: bytes):
    for m in re.finditer(rb"stream\r?\n(.*?)\r?\n?endstream", pdf, re.S):
        raw = m.group(1)
        try:
            yield zlib.decompress(raw)
        except zlib.error:
            yield raw


def pdf_drawing(pdf: bytes) -> PdfDrawing:
    """Count painted path segments in every content stream (clip paths, ended by ``n``,
    are not drawing).

    Parameters
    ----------
    pdf : bytes
        A PDF file's bytes (compressed streams are inflated).

    Returns
    -------
    PdfDrawing
        The painted paths, their segments and bounding box.
    """
    painted = segments = 0
    xs: list[float] = []
    ys: list[float] = []
    for stream in _streams(pdf):
        nums: list[float] = []
        path_pts: list[tuple[float, float]] = []
        path_segs = 0
        for tok in stream.decode("latin-1").split():
            try:
                nums.append(float(tok))
                continue
            except ValueError:
                pass
            if tok in ("m", "l") and len(nums) >= 2:
                path_pts.append((nums[-2], nums[-1]))
                path_segs += tok == "l"
            elif tok == "c" and len(nums) >= 6:
                path_pts.append((nums[-2], nums[-1]))
                path_segs += 1
            elif tok == "re" and len(nums) >= 4:
                x, y, w, h = nums[-4:]
                path_pts += [(x, y), (x + w, y + h)]
                path_segs += 4
            elif tok in PAINT_OPS:
                if path_segs:
                    painted += 1
                    segments += path_segs
                    xs += [p[0] for p in path_pts]
                    ys += [p[1] for p in path_pts]
                path_pts, path_segs = [], 0
            elif tok == "n":
                path_pts, path_segs = [], 0
            nums = []
    bbox = (min(xs), min(ys), max(xs), max(ys)) if xs else None
    return PdfDrawing(painted, segments, bbox)


def librecad_available() -> bool:
    """Whether ``librecad`` is on ``PATH``.

    Returns
    -------
    bool
        True when it is.
    """
    return shutil.which("librecad") is not None


def dxf_to_pdf(dxf: str | os.PathLike, *, timeout_s: float = 60.0) -> bytes:
    """The PDF LibreCAD draws from ``dxf`` (``librecad dxf2pdf``, headless, under a time limit).

    Parameters
    ----------
    dxf : str or PathLike
        The DXF file.
    timeout_s : float, default 60.0
        Longest LibreCAD may run [s].

    Returns
    -------
    bytes
        The PDF.

    Raises
    ------
    FabError
        LibreCAD is not installed, does not finish in time, or writes no PDF.
    """
    exe = shutil.which("librecad")
    if exe is None:
        raise FabError("LibreCAD is not installed", "apt-get install -y librecad (Debian/Ubuntu)")
    dxf = Path(dxf).resolve()
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    with tempfile.TemporaryDirectory(prefix="locust-librecad-") as tmp:
        env.setdefault("XDG_RUNTIME_DIR", tmp)
        try:
            subprocess.run([exe, "dxf2pdf", "-t", tmp, str(dxf)], env=env, cwd=tmp, timeout=timeout_s,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
        except subprocess.TimeoutExpired:
            raise FabError(f"LibreCAD did not finish {dxf.name} within {timeout_s:g} s",
                           "the file may be damaged; open it in a CAD program") from None
        pdf = Path(tmp) / (dxf.stem + ".pdf")
        if not pdf.is_file() or pdf.stat().st_size == 0:
            raise FabError(f"LibreCAD wrote no PDF for {dxf.name}", "open the file in a CAD program to see why")
        return pdf.read_bytes()


def check_dxf(dxf: str | os.PathLike, *, timeout_s: float = 60.0) -> PdfDrawing:
    """Have LibreCAD draw ``dxf`` and count what it drew.

    Parameters
    ----------
    dxf : str or PathLike
        The DXF file.
    timeout_s : float, default 60.0
        Longest LibreCAD may run [s].

    Returns
    -------
    PdfDrawing
        What the PDF paints.

    Raises
    ------
    FabError
        LibreCAD fails, hangs, writes no PDF, or draws nothing.
    """
    drawing = pdf_drawing(dxf_to_pdf(dxf, timeout_s=timeout_s))
    if drawing.painted_paths == 0:
        raise FabError(f"LibreCAD drew nothing from {Path(dxf).name}", "open the file in a CAD program to see why")
    return drawing
