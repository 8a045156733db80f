"""``locust track preview VIDEO --frame FRAME``: choose colours and start points without a GUI.

The frame is written as a PNG with a labelled pixel grid, the most saturated blobs circled
and numbered (their colour and position listed, ready for ``--marker
NAME=color:#RRGGBB@X,Y``), and what each current marker spec finds on that frame marked
with a cross and its name.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..errors import TrackError
from ..fileio import atomic_write_bytes
from ..io import trk as trk_io
from ..io.importing import is_project
from .calib import PIXEL_CONVENTIONS
from .outputs import Say, media, named, quiet, refuse_inputs, refuse_overwrite, stem, tracks_path
from .spec import ModelOptions, parse_markers
from .video import probe, read_frame

MIN_SATURATION = 110   # OpenCV 8-bit saturation: a sticker, not a tinted wall
MIN_VALUE = 50


@dataclass(frozen=True)
class Blob:
    """A blob of saturated colour in a preview frame.

    Attributes
    ----------
    px, py : float
        Its centroid [px].
    area_px : int
        Area [px].
    hex : str
        Median colour, ``#RRGGBB``.
    """

    px: float
    py: float
    area_px: int
    hex: str          # median colour, #RRGGBB

    def line(self, k: int) -> str:
        """The blob as a numbered line of the preview's listing.

        Parameters
        ----------
        k : int
            Its number.

        Returns
        -------
        str
            Number, colour, position [px] and area [px].
        """
        return f"  {k:2d}  {self.hex}  at {self.px:.0f},{self.py:.0f}  ({self.area_px} px)"


def saturated_blobs(image_bgr: np.ndarray, count: int = 10, min_area_px: int = 6) -> list[Blob]:
    """The ``count`` largest blobs of strongly saturated colour, largest first.

    Parameters
    ----------
    image_bgr : ndarray
        The frame, BGR.
    count : int
        How many blobs at most.
    min_area_px : int
        Smallest blob [px].

    Returns
    -------
    list of Blob
        The blobs.
    """
    hsv = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2HSV)
    mask = cv2.inRange(hsv, (0, MIN_SATURATION, MIN_VALUE), (179, 255, 255))
    n, labels, stats, cents = cv2.connectedComponentsWithStats(mask, connectivity=8)
    order = [k for k in np.argsort(-stats[:, cv2.CC_STAT_AREA]) if k != 0 and stats[k, 4] >= min_area_px][:count]
    blobs = []
    for k in order:
        x, y, w, h = stats[k, :4]
        pix = image_bgr[y:y + h, x:x + w][labels[y:y + h, x:x + w] == k]
        b, g, r = (int(v) for v in np.median(pix, axis=0))
        blobs.append(Blob(float(cents[k, 0]), float(cents[k, 1]), int(stats[k, 4]), f"#{r:02x}{g:02x}{b:02x}"))
    return blobs


def _label(image: np.ndarray, text: str, at: tuple[int, int], colour=(255, 255, 255), scale: float = 0.4) -> None:
    """Text with a dark outline: readable on any background."""
    cv2.putText(image, text, at, cv2.FONT_HERSHEY_SIMPLEX, scale, (0, 0, 0), 3, cv2.LINE_AA)
    cv2.putText(image, text, at, cv2.FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv2.LINE_AA)


def draw_grid(image: np.ndarray, step_px: int) -> None:
    """Grid lines every ``step_px`` (inverted pixels: visible on any background), labelled.

    Parameters
    ----------
    image : ndarray
        The frame, BGR; drawn on in place.
    step_px : int
        Grid spacing [px].
    """
    h, w = image.shape[:2]
    image[:, ::step_px] = 255 - image[:, ::step_px]
    image[::step_px, :] = 255 - image[::step_px, :]
    for x in range(step_px, w, step_px):
        _label(image, str(x), (x + 2, 12))
    for y in range(step_px, h, step_px):
        _label(image, str(y), (2, y - 3))


def preview(info, frame: int, models: list, path: Path) -> tuple[list[Blob], dict[str, tuple[float, float] | None]]:
    """Write the annotated ``frame`` of the video to ``path``; return the blobs and what each
    marker model finds there (None: nothing).

    Parameters
    ----------
    info : VideoInfo
        The probed video.
    frame : int
        The frame to show.
    models : list
        Marker models to try on it.
    path : Path
        The PNG to write.

    Returns
    -------
    blobs : list of Blob
        The saturated blobs.
    found : dict of str to (tuple of float or None)
        Per marker, where it was found [px].

    Raises
    ------
    TrackError
        A frame outside the video.
    """
    if not 0 <= frame < info.frame_count:
        raise TrackError(f"--frame {frame}: the video has frames 0..{info.frame_count - 1}", "pick a frame in it")
    image = read_frame(info, frame)   # an image sequence too: one frame needs no frame rate
    blobs = saturated_blobs(image)
    found = {}
    for m in models:
        if getattr(m, "key_frame", frame) != frame:
            found[m.name] = None   # a template is cut on its own key frame
            continue
        det = m.locate(frame, image)
        found[m.name] = det.point()
    out = image.copy()
    draw_grid(out, 50 if max(image.shape[:2]) <= 1000 else 100)
    for k, b in enumerate(blobs, 1):
        r = int(max(8, np.sqrt(b.area_px / np.pi) + 6))
        cv2.circle(out, (int(round(b.px)), int(round(b.py))), r, (0, 0, 0), 3, cv2.LINE_AA)
        cv2.circle(out, (int(round(b.px)), int(round(b.py))), r, (255, 255, 255), 1, cv2.LINE_AA)
        _label(out, str(k), (int(b.px) + r, int(b.py) - r), scale=0.5)
    for name, p in found.items():
        if p is not None:
            x, y = int(round(p[0])), int(round(p[1]))
            cv2.drawMarker(out, (x, y), (0, 255, 0), cv2.MARKER_CROSS, 20, 2)
            _label(out, name, (x + 8, y + 16), (0, 255, 0), 0.5)
    ok, png = cv2.imencode(".png", out)
    atomic_write_bytes(path, png.tobytes())
    return blobs, found


def preview_video(video: Path, frame: int, markers: tuple[str, ...] = (), model: ModelOptions | None = None,
                  out: Path | None = None, force: bool = False, say: Say = quiet) -> list[str]:
    """``locust track preview``: write the annotated ``frame`` of ``video`` (a video, an image
    sequence or a Tracker project that opens one) to ``<out>.preview.png`` in the output folder.

    Parameters
    ----------
    video : Path
        What to preview.
    frame : int
        The frame to show.
    markers : tuple of str
        ``NAME=SPEC`` of the markers to try on it; empty: the robot's nose and foot colours.
    model : ModelOptions, optional
        Their settings, and the convention their positions are typed (and printed) in.
    out : Path, optional
        ``--out``.
    force : bool
        Replace an existing preview.
    say : callable
        Told the output folder.

    Returns
    -------
    list of str
        What to print: the blobs, where each marker was found, the file written.

    Raises
    ------
    TrackError
        A frame outside the video, or a preview that may not be written.
    """
    model = model or ModelOptions()
    models, pixels = parse_markers(list(markers), model), model.pixels
    video = named(video)
    project = trk_io.read_project(video) if is_project(video) else None
    with media(video, project) as path:
        png = tracks_path(out, video, say)
        png = png.with_name(stem(png) + ".preview.png")
        info = probe(path)
        refuse_inputs({"preview": png}, [video, path])
        refuse_overwrite({"preview": png}, force)
        blobs, found = preview(info, frame, models, png)
    lines = [f"frame {frame} of {info.path.name} ({info.width_px}x{info.height_px}): most saturated blobs"]
    lines += [b.line(k) for k, b in enumerate(blobs, 1)] or ["  none (no strongly coloured patch in this frame)"]
    if found:
        lines.append(f"markers ({pixels}'s pixels, as --marker takes them):")
    for name, p in found.items():
        if p:   # found in OpenCV's pixels: shown in the convention the specs are typed in
            p = (p[0] - PIXEL_CONVENTIONS[pixels], p[1] - PIXEL_CONVENTIONS[pixels])
        lines.append(f"  marker {name}: " + (f"found at {p[0]:.1f},{p[1]:.1f}" if p else "not found"))
    return [*lines, f"wrote {png}"]
