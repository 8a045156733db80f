"""A sticker's centre from the share of each pixel it covers: anti-aliased edge pixels count
by the share they hold.

Coverage is estimated from luma, which codecs keep at full resolution (4:2:0 halves the
colour planes), where the surround is uniform; around a textured surround (a ruler's marks)
from chroma (the pixel's colour less its grey level) between the local background's and the
sticker's, so the texture weighs nothing (:func:`coverage_centroid`).
"""

from __future__ import annotations

import cv2
import numpy as np

RING_PX = 4   # the pixels around a blob its centroid reads: the blob grown by two, and a ring of two
_KERNEL_9 = np.ones((9, 9), np.uint8)    # two 5x5 dilations in one
_KERNEL_5 = np.ones((5, 5), np.uint8)
_KERNEL_3 = np.ones((3, 3), np.uint8)
UNIFORM_SHARE = 0.1      # a surround varying by less than this share of the sticker's luma contrast is uniform
CHROMA_CONTRAST = 40.0   # least sticker-to-background chroma difference (0-255 scale) to weigh by colour


def coverage_centroid(roi: np.ndarray, blob: np.ndarray) -> tuple[float, float]:
    """Centroid of per-pixel coverage over ``blob`` (a boolean mask) grown by two pixels.

    Coverage comes from luma (full resolution under 4:2:0, so the least noisy) when the
    surround is uniform: the luma of the two-pixel ring around the grown blob varies (standard
    deviation) by less than ``UNIFORM_SHARE`` of the sticker-to-surround luma contrast, so no
    surround pixel passes for more than a tenth of sticker. A textured surround (a ruler's
    marks, a checker floor's edges) would: then coverage comes from chroma
    (``_chroma_centroid``), where grey texture weighs nothing. A pale sticker (too little
    chroma contrast) stays with luma; a sticker as bright as its surround with the colour core.

    Parameters
    ----------
    roi : ndarray
        The picture around the blob, BGR: the blob and the ``RING_PX`` pixels around it (or
        the image edge).
    blob : ndarray of bool
        The blob's mask over ``roi``.

    Returns
    -------
    tuple of float
        (x, y) in ``roi`` [px].
    """
    blob_u8 = blob.view(np.uint8)
    grown = cv2.dilate(blob_u8, _KERNEL_5)
    luma = cv2.cvtColor(roi.astype(np.float32), cv2.COLOR_BGR2GRAY)   # BT.601: 0.114 B + 0.587 G + 0.299 R
    inner_u8 = cv2.erode(blob_u8, _KERNEL_3)
    inner = luma[inner_u8.view(bool)]
    level = float(_median(inner if inner.size else luma[blob]))
    ring_u8 = (cv2.dilate(blob_u8, _KERNEL_9) > grown).view(np.uint8)   # the two pixels around the grown blob
    ring = luma[ring_u8.view(bool)]
    if not ring.size:
        return _moments_centroid(blob_u8)
    background = float(_median(ring))
    contrast = abs(level - background)
    ring -= background
    if contrast < 20 or float(np.dot(ring, ring)) >= (UNIFORM_SHARE * contrast) ** 2 * ring.size:
        at = _chroma_centroid(roi, blob_u8, grown, ring_u8, inner_u8)
        if at is not None:
            return at
    if contrast < 20:   # sticker as bright as its surround: the colour core alone
        return _moments_centroid(blob_u8)
    cover = luma   # in place: luma is not needed any more
    cover -= background
    cover /= level - background
    np.maximum(cover, 0.0, out=cover)
    np.minimum(cover, 1.0, out=cover)
    cover *= grown
    return _moments_centroid(cover)


def _moments_centroid(weights: np.ndarray) -> tuple[float, float]:
    m = cv2.moments(weights)
    return m["m10"] / m["m00"], m["m01"] / m["m00"]


def _chroma_centroid(roi: np.ndarray, blob_u8: np.ndarray, grown: np.ndarray, ring_u8: np.ndarray,
                     inner_u8: np.ndarray) -> tuple[float, float] | None:
    """Centroid of per-pixel coverage estimated from colour, not brightness: each pixel's
    chroma (its colour less its grey level) is projected on the line from the local
    background's chroma to the sticker's. A textured grey surround (a ruler's marks, a
    picture frame's edge) then weighs nothing, however bright or dark, where luma coverage
    takes its dark or bright pixels for part of the sticker. ``None`` when the sticker's
    chroma differs too little from its surround's (a pale sticker): then luma decides.
    """
    pixels = roi.astype(np.float32)
    chroma = pixels - pixels.mean(axis=2, keepdims=True)
    core = inner_u8 if inner_u8.any() else blob_u8
    sticker = np.median(chroma[core.view(bool)], axis=0)
    background = np.median(chroma[ring_u8.view(bool)], axis=0)
    axis = sticker - background
    contrast = float(np.linalg.norm(axis))
    if contrast < CHROMA_CONTRAST:
        return None
    w = axis / contrast ** 2
    cover = cv2.transform(chroma, w.reshape(1, 3)) - float(background @ w)
    np.clip(cover, 0.0, 1.0, out=cover)
    cover *= grown
    return _moments_centroid(cover)


def _median(values: np.ndarray) -> np.floating:
    """``np.median`` of a 1-D float32 array, without its general-purpose overhead; ``values``
    is a scratch copy (a masked selection): it is partitioned in place."""
    n = values.size
    k = n // 2
    if n % 2:
        values.partition(k)
        return values[k]
    values.partition((k - 1, k))
    return (values[k - 1] + values[k]) / np.float32(2)
