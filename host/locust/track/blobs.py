"""Blobs of a colour mask: their labels, boxes and shapes, as the colour locator judges them.

What :mod:`.color` asks of a mask, each done with as few OpenCV passes as it takes: the
blobs of a window in the order they are tried (nearest the prediction first), a blob's area
and equivalent ellipse, whether a window or the picture's edge cuts it, and a picture
sampled on a coarse grid.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import NamedTuple

import cv2
import numpy as np

EDGE_MARGIN_PX = 3   # a blob this near a window's edge is cut by it (the coverage ring needs room too)


class BlobShape(NamedTuple):   # a tuple: one is made per blob looked at, every frame
    """A blob's area and equivalent ellipse.

    Attributes
    ----------
    area_px : float
        Area [px²].
    major_px, minor_px : float
        Full lengths of the equivalent ellipse's axes (4 sigma): a disc's diameter [px].
    angle_rad : float
        Direction of the major axis, image x right, y down [rad].
    """

    area_px: float
    major_px: float     # full lengths of the equivalent ellipse (4 sigma): a disc's diameter
    minor_px: float
    angle_rad: float = 0.0   # direction of the major axis (image x right, y down)


def labelled_blobs(core: np.ndarray, offset: tuple[int, int], centre: tuple[float, float] | None
                   ) -> tuple[int, Iterable[tuple[list[int], np.ndarray, int]]]:
    """The blobs of a mask, in the order they are tried: nearest ``centre`` first (largest
    first without one).

    Only the box of the set pixels is labelled (the same components, at an offset): an empty
    mask (a hidden marker) is not labelled at all, and a window or the whole picture holding
    one sticker costs the sticker's box.

    Parameters
    ----------
    core : ndarray
        The mask (0/255) over a window of the picture.
    offset : tuple of int
        The window's top-left corner in the picture [px].
    centre : tuple of float or None
        The predicted position in the picture [px].

    Returns
    -------
    n : int
        OpenCV's label count (the background counted): 2 for one blob, below 2 for none.
    blobs : iterable of (stat, mask, label)
        Per blob its box and area in the window (x, y, w, h, area) [px], the mask it is
        ``label`` of: with one blob the core itself (0/255), else the window's labels.
    """
    rect = cv2.boundingRect(core)
    lx, ly, lw, lh = rect
    if lw == 0:   # a hidden marker: nothing to label
        return 0, ()
    part = core[ly:ly + lh, lx:lx + lw]
    n, labels = cv2.connectedComponents(part, connectivity=8)
    if n <= 1:
        return n, ()
    if n == 2:   # one blob (the usual case): the core is its mask; its statistics cost less than OpenCV's
        return n, [([*rect, cv2.countNonZero(part)], core, 255)]
    stats, cents = component_stats(part, labels, n)
    stats[:, 0] += lx
    stats[:, 1] += ly
    cents += (lx, ly)
    labels = cv2.copyMakeBorder(labels, ly, core.shape[0] - ly - lh, lx, core.shape[1] - lx - lw,
                                cv2.BORDER_CONSTANT, value=0)
    order = np.arange(1, n)
    if centre is None:   # largest first
        order = order[np.argsort(-stats[order, cv2.CC_STAT_AREA], kind="stable")]
    else:                # nearest the prediction first
        x0, y0 = offset
        order = order[np.argsort(np.hypot(cents[order, 0] + x0 - centre[0], cents[order, 1] + y0 - centre[1]),
                                 kind="stable")]
    return n, ((stats[i].tolist(), labels, i) for i in order.tolist())


def component_stats(core: np.ndarray, labels: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``cv2.connectedComponentsWithStats``'s stats and centroids from the labels, computed
    over the set pixels only (OpenCV's pass over a whole sparse 720p image costs ~8 ms).

    Parameters
    ----------
    core : ndarray
        The mask labelled.
    labels : ndarray
        Its labels (``cv2.connectedComponents``).
    n : int
        The label count.

    Returns
    -------
    stats : ndarray
        Per label x, y, w, h, area [px].
    centroids : ndarray
        Per label x, y [px].
    """
    pts = cv2.findNonZero(core).reshape(-1, 2)
    xs, ys = pts[:, 0], pts[:, 1]
    lab = labels[ys, xs]
    area = np.bincount(lab, minlength=n)
    x0, y0 = np.full(n, labels.shape[1]), np.full(n, labels.shape[0])
    x1, y1 = np.full(n, -1), np.full(n, -1)
    np.minimum.at(x0, lab, xs)
    np.minimum.at(y0, lab, ys)
    np.maximum.at(x1, lab, xs)
    np.maximum.at(y1, lab, ys)
    stats = np.stack([x0, y0, x1 - x0 + 1, y1 - y0 + 1, area], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cents = np.stack([np.bincount(lab, xs, n) / area, np.bincount(lab, ys, n) / area], axis=1)
    return stats, cents


def blob_shape(blob: np.ndarray, area: int) -> BlobShape:
    """Area and equivalent ellipse of a blob given as a mask (nonzero in the blob).

    Parameters
    ----------
    blob : ndarray
        The blob's mask, 0/1 or 0/255.
    area : int
        Its area [px²].

    Returns
    -------
    BlobShape
    """
    m = cv2.moments(blob)   # 0/1 or 0/255: the same shape
    a, b, c = m["mu20"] / m["m00"], m["mu11"] / m["m00"], m["mu02"] / m["m00"]
    root = math.sqrt(max((a - c) ** 2 / 4 + b * b, 0.0))
    # + 1/12 per axis: a pixel is a square, not a point
    lam1, lam2 = (a + c) / 2 + root + 1 / 12, (a + c) / 2 - root + 1 / 12
    return BlobShape(float(area), 4 * math.sqrt(lam1), 4 * math.sqrt(max(lam2, 0.0)), 0.5 * math.atan2(2 * b, a - c))


def along(angle_rad: float, velocity: tuple[float, float], diameter_px: float) -> bool:
    """True if a streak at ``angle_rad`` lies within 30 degrees of a motion of ``velocity``
    px/frame, fast enough to smear a marker of ``diameter_px`` visibly.

    Parameters
    ----------
    angle_rad : float
        The streak's direction [rad].
    velocity : tuple of float
        The motion [px/frame].
    diameter_px : float
        The marker's diameter [px].

    Returns
    -------
    bool
    """
    vx, vy = velocity
    speed = math.hypot(vx, vy)
    if speed < 0.3 * diameter_px:
        return False
    return abs(vx * math.cos(angle_rad) + vy * math.sin(angle_rad)) / speed >= math.cos(math.radians(30))


def on_image_border(stat: list[int], box, image_shape) -> bool:
    """True if a blob (``stat``: x, y, w, h in the window ``box``) touches the picture's edge.

    Parameters
    ----------
    stat : list of int
        The blob's box in the window [px].
    box : tuple of int
        The window (x0, y0, x1, y1) in the picture [px].
    image_shape : tuple of int
        The picture's shape.

    Returns
    -------
    bool
    """
    x, y, w, h = stat[:4]
    x0, y0 = box[0] + x, box[1] + y
    return x0 <= 0 or y0 <= 0 or x0 + w >= image_shape[1] or y0 + h >= image_shape[0]


def touches_edge(stat: list[int], roi_shape, box, image_shape) -> bool:
    """True if a blob reaches a window edge that is not also the image edge.

    Parameters
    ----------
    stat : list of int
        The blob's box in the window [px].
    roi_shape : tuple of int
        The window's shape.
    box : tuple of int
        The window (x0, y0, x1, y1) in the picture [px].
    image_shape : tuple of int
        The picture's shape.

    Returns
    -------
    bool
    """
    x, y, w, h = stat[:4]
    x0, y0, x1, y1 = box
    margin = EDGE_MARGIN_PX
    return ((x < margin and x0 > 0) or (y < margin and y0 > 0)
            or (x + w > roi_shape[1] - margin and x1 < image_shape[1])
            or (y + h > roi_shape[0] - margin and y1 < image_shape[0]))


def every(image: np.ndarray, step: int) -> np.ndarray:
    """``image[::step, ::step]`` as a contiguous picture. OpenCV's nearest-pixel resize to
    1/step takes exactly those pixels where the sizes divide by ``step``, ten times faster
    than NumPy's copy of a strided view (a 1280x720 frame at step 2: 0.26 ms against 2.9 ms);
    a last row or column past a whole number of steps is copied on its own.

    Parameters
    ----------
    image : ndarray
        An image.
    step : int
        Sampling step [px].

    Returns
    -------
    ndarray
        The sampled image, contiguous.
    """
    h, w = image.shape[:2]
    hq, wq = h // step, w // step
    if step == 1 or hq == 0 or wq == 0:
        return np.ascontiguousarray(image[::step, ::step])
    main = cv2.resize(image[:hq * step, :wq * step], (wq, hq), interpolation=cv2.INTER_NEAREST)
    main = main.reshape((hq, wq) + image.shape[2:])   # OpenCV drops a single channel's axis
    if h == hq * step and w == wq * step:
        return main
    out = np.empty((-(-h // step), -(-w // step)) + image.shape[2:], image.dtype)
    out[:hq, :wq] = main
    if h > hq * step:
        out[hq] = image[hq * step, ::step]
    if w > wq * step:
        out[:, wq] = image[::step, wq * step]
    return out


def contours(mask: np.ndarray) -> list:
    """Outer contours of the blobs of ``mask``.

    Parameters
    ----------
    mask : ndarray
        0/255.

    Returns
    -------
    list of ndarray
    """
    return cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)[0]


def filled(contour: np.ndarray, box: tuple[int, int, int, int]) -> np.ndarray:
    """0/1 mask of the blob ``contour`` outlines, over its bounding ``box`` (x, y, w, h).

    Parameters
    ----------
    contour : ndarray
        An outer contour (:func:`contours`).
    box : tuple of int
        Its bounding box [px].

    Returns
    -------
    ndarray
    """
    x, y, w, h = box
    mask = np.zeros((h, w), np.uint8)
    cv2.drawContours(mask, [contour], -1, 1, cv2.FILLED, offset=(-x, -y))
    return mask


def median_of(values) -> float:
    """``statistics.median`` of a few floats, without its type checks.

    Parameters
    ----------
    values : iterable of float

    Returns
    -------
    float
    """
    s = sorted(values)
    k = len(s) // 2
    return s[k] if len(s) % 2 else (s[k - 1] + s[k]) / 2
