"""The printable board: the ArUco grid, and beside it what it is and how big it must be.

``locust track board board.png`` writes the sheet twice, drawn once with matplotlib: a PNG at
300 DPI (recorded in the file) and ``board.pdf`` beside it, whose page is the sheet's own
size (a PDF viewer's "actual size" prints it 1:1; its markers are the PNG's pixels, embedded
unresampled). The sheet is the board with its white margin (:meth:`BoardSpec.image`), and a
column on its right: a 100 mm scale bar in 10 mm steps, and the board's spec (its ID on the
command line), its marker and gap sizes and how to check the print. A printer that scales the
page (a "fit to page") scales the bar with it: a ruler laid along the bar tells, and so does
``locust track board --check PHOTO`` (:mod:`locust.track.boardcheck`).

The column keeps the default board on an A4 or US Letter sheet, landscape (276 x 210 mm).
"""

from __future__ import annotations

import io
import textwrap
from dataclasses import dataclass
from pathlib import Path

from ..arucoboard import BOARD_MARGIN_MM, BoardSpec
from ..errors import TrackError
from ..fileio import atomic_write_bytes
from ..plotting import CREATOR, pyplot
from .outputs import Say, quiet, refuse_overwrite, say_folder

SHEET_DPI = 300
BAR_MM = 100.0
BAR_STEP_MM = 10.0
BAR_WIDTH_MM = 3.0
FONT_PT = 6.0
LINE_MM = 3.0          # between the column's lines of text (6 pt is 2.1 mm)
CHAR_MM = 1.2          # a 6 pt character's mean advance, to wrap the lines
MM_PER_IN = 25.4


@dataclass(frozen=True)
class SheetLayout:
    """Where everything sits on the printed sheet [mm, x right, y up from the bottom-left].

    Attributes
    ----------
    width_mm, height_mm : float
        The sheet (the PDF's page).
    board_width_mm, board_height_mm : float
        The board with its white margin, at the sheet's bottom-left corner.
    bar_x_mm, bar_y_mm : float
        The scale bar's bottom-left corner; it runs up for :data:`BAR_MM`.
    text_x_mm : float
        The first line of text (each runs up the sheet, the next to its right).
    lines : tuple of str
        The text, one entry a line.
    """

    width_mm: float
    height_mm: float
    board_width_mm: float
    board_height_mm: float
    bar_x_mm: float
    bar_y_mm: float
    text_x_mm: float
    lines: tuple[str, ...]


def sheet_text(spec: BoardSpec) -> list[str]:
    """What the sheet says of itself, in sentences.

    Parameters
    ----------
    spec : BoardSpec
        The board.

    Returns
    -------
    list of str
        The spec, the sizes, how to print and how to check the print.
    """
    return [f"locust board {spec.text()}: markers {spec.marker_mm:g} mm, gaps {spec.gap_mm:g} mm, "
            f"board {spec.width_mm:g} x {spec.height_mm:g} mm",
            "print at 100 % (actual size, no fit to page): the bar must measure 100 mm",
            "check a print: photograph it with a bank or ID card (85.60 x 53.98 mm) beside it, "
            "then locust track board --check PHOTO"]


def layout(spec: BoardSpec) -> SheetLayout:
    """The sheet of ``spec``: the board at its bottom-left, the column on its right.

    Parameters
    ----------
    spec : BoardSpec
        The board.

    Returns
    -------
    SheetLayout
        Its sizes and where the bar and text go.
    """
    m = BOARD_MARGIN_MM
    bw, bh = spec.width_mm + 2 * m, spec.height_mm + 2 * m
    height = max(bh, BAR_MM + 2 * m)
    chars = max(int((height - 2 * m) / CHAR_MM), 20)
    lines = tuple(line for sentence in sheet_text(spec) for line in textwrap.wrap(sentence, chars))
    bar_x = bw + 1.0
    text_x = bar_x + BAR_WIDTH_MM + 3.5     # past the bar's numbers
    width = text_x + LINE_MM * len(lines) + 1.0
    return SheetLayout(width, height, bw, bh, bar_x, m, text_x, lines)


def _px(mm: float) -> int:
    return int(round(mm * SHEET_DPI / MM_PER_IN))


def draw_sheet(spec: BoardSpec):
    """The sheet as a matplotlib figure, its size the sheet's, its data units 1/300 inch.

    Parameters
    ----------
    spec : BoardSpec
        The board.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (close it when done).
    """
    from matplotlib.patches import Rectangle

    plt = pyplot()
    lay = layout(spec)
    k = SHEET_DPI / MM_PER_IN       # px per mm
    board = spec.image(k)
    w_px, h_px = _px(lay.width_mm), _px(lay.height_mm)
    fig = plt.figure(figsize=(w_px / SHEET_DPI, h_px / SHEET_DPI), dpi=SHEET_DPI)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(0, w_px)
    ax.set_ylim(0, h_px)
    ax.set_axis_off()
    # the markers pixel for pixel: the image's edges on whole pixels, nothing resampled
    ax.imshow(board, cmap="gray", vmin=0, vmax=255, interpolation="none", origin="upper",
              extent=(0, board.shape[1], 0, board.shape[0]))
    x0, y0 = lay.bar_x_mm * k, lay.bar_y_mm * k
    steps = int(BAR_MM / BAR_STEP_MM)
    for n in range(steps):
        ax.add_patch(Rectangle((x0, y0 + n * BAR_STEP_MM * k), BAR_WIDTH_MM * k, BAR_STEP_MM * k,
                               facecolor="black" if n % 2 == 0 else "white", edgecolor="none"))
    ax.add_patch(Rectangle((x0, y0), BAR_WIDTH_MM * k, BAR_MM * k, fill=False, edgecolor="black", linewidth=0.4))
    # each text turned to run up the sheet: its top faces left, so va="top" sets it right of x
    for mm, label, ha in ((0.0, "0", "left"), (BAR_MM / 2, f"{BAR_MM / 2:g}", "center"),
                          (BAR_MM, f"{BAR_MM:g} mm", "right")):
        ax.text(x0 + (BAR_WIDTH_MM + 0.5) * k, y0 + mm * k, label, rotation=90, fontsize=FONT_PT,
                ha=ha, va="top", rotation_mode="anchor")
    for n, line in enumerate(lay.lines):
        ax.text((lay.text_x_mm + n * LINE_MM) * k, BOARD_MARGIN_MM * k, line, rotation=90, fontsize=FONT_PT,
                ha="left", va="top", rotation_mode="anchor")
    return fig


def write_board_sheet(png: Path, spec: BoardSpec) -> tuple[Path, Path]:
    """Write the sheet as ``png`` (300 DPI, recorded) and as the PDF beside it (same name,
    ``.pdf``; its page the sheet's size), each atomically.

    Parameters
    ----------
    png : Path
        The PNG to write.
    spec : BoardSpec
        The board.

    Returns
    -------
    tuple of Path
        The PNG and the PDF written.
    """
    from PIL import Image
    from PIL.PngImagePlugin import PngInfo

    plt = pyplot()
    fig = draw_sheet(spec)
    try:
        drawn, pdf = io.BytesIO(), io.BytesIO()
        fig.savefig(drawn, format="png", dpi=SHEET_DPI)
        fig.savefig(pdf, format="pdf", dpi=SHEET_DPI, metadata={"Creator": CREATOR})
    finally:
        plt.close(fig)
    # grey levels, as the board's own image: what a printer and the detector take
    info = PngInfo()
    info.add_text("Software", CREATOR)
    buf = io.BytesIO()
    Image.open(drawn).convert("L").save(buf, format="PNG", dpi=(SHEET_DPI, SHEET_DPI), pnginfo=info)
    return atomic_write_bytes(png, buf.getvalue()), atomic_write_bytes(pdf_beside(png), pdf.getvalue())


def pdf_beside(png: Path) -> Path:
    """The PDF written beside the sheet's PNG: its name with ``.pdf``.

    Parameters
    ----------
    png : Path
        The PNG.

    Returns
    -------
    Path
    """
    return png.with_suffix(".pdf")


def make_board(png: Path | None, spec: BoardSpec, force: bool = False, say: Say = quiet) -> str:
    """``locust track board PNG``: write the sheet as ``png`` and the PDF beside it, never over
    an existing file without ``force``.

    Parameters
    ----------
    png : Path or None
        The PNG to write (a ``.pdf`` names the PDF: the PNG goes beside it); None is refused.
    spec : BoardSpec
        The board.
    force : bool
        Replace an existing PNG and PDF.
    say : callable
        Told the output folder.

    Returns
    -------
    str
        What to print: the files written, the sheet's size and how to print it.

    Raises
    ------
    locust.errors.TrackError
        No PNG, a name that is neither .png nor .pdf, or an existing output without ``force``.
    """
    if png is None:
        raise TrackError("give the PNG to write, or --check PHOTO", "e.g. locust track board board.png")
    if png.suffix.lower() not in (".png", ".pdf"):
        raise TrackError(f"{png}: the board is written as a .png, with a .pdf beside it",
                         f"e.g. locust track board {png.with_suffix('.png').name}")
    png = png.with_suffix(".png") if png.suffix.lower() == ".pdf" else png
    pdf = pdf_beside(png)
    say_folder(png, say)
    refuse_overwrite({"board": png, "pdf": pdf}, force)
    write_board_sheet(png, spec)
    lay = layout(spec)
    return (f"wrote {png} ({SHEET_DPI} DPI) and {pdf} ({lay.width_mm:.1f} x {lay.height_mm:.1f} mm "
            f"page): board {spec.text()}, {spec.width_mm:g} x {spec.height_mm:g} mm of markers; print at 100 % "
            f"(no fit to page), check the scale bar is 100 mm (or `locust track board --check PHOTO`), lay it "
            f"flat in the plane of motion")
