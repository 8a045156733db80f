"""Matplotlib without a display, and figures written atomically.

A figure path ends in an image suffix (:data:`FIGURE_SUFFIXES`, the format follows it), and
an existing file there is replaced only when it is a figure this toolkit wrote (each carries
``locust`` as its creator in the file's metadata) or with ``force``: a recording, a robot file
or a user's own picture given as a plot path is never turned into a figure.
"""

from __future__ import annotations

import io
import os
from pathlib import Path

from .errors import WriteError

FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
CREATOR = "locust"
# how each format carries its creator, and the bytes that show it
_METADATA = {"png": "Software", "svg": "Creator", "pdf": "Creator"}
_SIGNATURE = {"png": (b"\x89PNG", b"tEXtSoftware\x00" + CREATOR.encode()),
              "svg": (b"<", f"<dc:title>{CREATOR}</dc:title>".encode()),
              "pdf": (b"%PDF", f"/Creator ({CREATOR})".encode())}
_LARGEST_FIGURE_BYTES = 64 * 2**20


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure_bytes(fig, fmt: str = "png", dpi: int = 110) -> bytes:
    """The figure in ``fmt`` (png, svg, pdf), marked as this toolkit's; the figure is closed.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    fmt : str
    dpi : int
        Dots per inch.

    Returns
    -------
    bytes
    """
    from matplotlib.text import Text

    from .fileio import storable

    plt = pyplot()
    for text in fig.findobj(Text):   # a file name's undecodable byte (a lone surrogate) cannot be drawn
        text.set_text(storable(text.get_text()))
    buf = io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=dpi, bbox_inches="tight", metadata={_METADATA[fmt]: CREATOR})
    plt.close(fig)
    return buf.getvalue()


def png_bytes(fig, dpi: int = 110) -> bytes:
    """The figure as PNG bytes; the figure is closed.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    dpi : int

    Returns
    -------
    bytes
    """
    return figure_bytes(fig, "png", dpi)


def is_own_figure(path: str | Path) -> bool:
    """Whether ``path`` is a figure this toolkit wrote (its format's signature and creator).

    Parameters
    ----------
    path : path-like

    Returns
    -------
    bool
    """
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".")
    if fmt not in _SIGNATURE:
        return False
    try:
        if path.stat().st_size > _LARGEST_FIGURE_BYTES:
            return False
        data = path.read_bytes()
    except OSError:
        return False
    head, mark = _SIGNATURE[fmt]
    return data.lstrip()[:len(head)] == head and mark in data


def check_figure_path(path: str | Path, force: bool = False, option: str | None = "--plot") -> Path:
    """``path`` if a figure may be written there, else :class:`WriteError`: it must end in an
    image suffix, and an existing file is replaced only when it is one of this toolkit's
    figures (or ``force``).

    Parameters
    ----------
    path : path-like
    force : bool
    option : str or None
        The option that named ``path``, for messages.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
    """
    path = Path(path)
    what = f"{option} {path}" if option else str(path)
    if path.suffix.lower() not in FIGURE_SUFFIXES:
        raise WriteError(f"{what}: a figure's path must end in {', '.join(FIGURE_SUFFIXES)}",
                         f"give an image path, e.g. {path.with_suffix('.png').name}")
    if os.path.lexists(path) and not force and not is_own_figure(path):
        raise WriteError(f"{what}: the file exists and is not a figure this toolkit wrote; refusing to replace it",
                         "choose another path" + (", or add --force to replace it" if option else ""))
    return path


def save_png(fig, path: str | Path, dpi: int = 110, force: bool = False, option: str | None = None) -> Path:
    """Write the figure to ``path`` atomically, in the format its suffix names (png, svg, pdf);
    the figure is closed. Refused (:class:`WriteError`, the figure closed, nothing written) as
    :func:`check_figure_path` says.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : path-like
    dpi : int
    force : bool
        Replace a file that is not this toolkit's figure.
    option : str or None
        The option that named ``path``, for messages.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    locust.errors.WriteError
    """
    from .fileio import atomic_write_bytes

    try:
        path = check_figure_path(path, force, option)
    except WriteError:
        pyplot().close(fig)
        raise
    return atomic_write_bytes(path, figure_bytes(fig, path.suffix.lower().lstrip("."), dpi))
