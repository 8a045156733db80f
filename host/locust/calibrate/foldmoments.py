"""The fold test's statics: a fold's stiffness and rest angle from two settled angles.

The free link of a fold, its other link clamped, settles where the hinge's spring balances the
weight hanging from it. In the photo's plane (x right, y up, angles counter-clockwise from x;
the fold's angle ``theta`` 0 with the links in line) a mass ``m`` at ``r`` along the free link,
``h`` off its centre line toward its left (seen from the fold), pulls with the moment
``-g m (r cos phi - h sin phi)`` about the fold, ``phi`` the free link's direction. With the
link's own first moment ``S = m_link * l / 2`` (a uniform strip of length ``l`` from the fold)
and the coin's mass ``m_c`` at the lever arm ``L``, ``h`` above the link on its upper face:

    unloaded:  k (theta_a - theta_0) = M_a = -g S cos phi_a
    loaded:    k (theta_b - theta_0) = M_b = -g (S cos phi_b + m_c (L cos phi_b - s h sin phi_b))

(``s`` = +1 where the link points right, the upper face on its left; -1 where it points left).
Their difference is the stiffness and the unloaded balance the rest angle:

    k = (M_b - M_a) / (theta_b - theta_a),   theta_0 = theta_a - M_a / k

the lever arms being the cosines of the angles each photo shows, large deflections included.
The functions take and return numbers (degrees, metres, kilograms, N·m).
"""

from __future__ import annotations

import math

import numpy as np

from ..params import GRAVITY_M_PER_S2


def wrap_deg(deg):
    """An angle (or array of them) in [-180, 180) [deg].

    Parameters
    ----------
    deg : float or numpy.ndarray

    Returns
    -------
    float or numpy.ndarray
    """
    return (np.asarray(deg) + 180.0) % 360.0 - 180.0 if isinstance(deg, np.ndarray) else (deg + 180.0) % 360.0 - 180.0


def link_angles_deg(axis_m, tip_m, base_m) -> tuple[float, float]:
    """The clamped and the free link's directions from the fold [deg, CCW from x], from the
    axis, tip and base stickers on the photo's plane.

    Parameters
    ----------
    axis_m, tip_m, base_m : (float, float)
        The stickers [m, x right, y up].

    Returns
    -------
    clamped_deg, free_deg : float
    """
    c = math.degrees(math.atan2(base_m[1] - axis_m[1], base_m[0] - axis_m[0]))
    f = math.degrees(math.atan2(tip_m[1] - axis_m[1], tip_m[0] - axis_m[0]))
    return c, f


def fold_deg(clamped_deg: float, free_deg: float) -> float:
    """The fold's angle: the free link's direction less the clamped link's, less 180 [deg]; 0 in line.

    Parameters
    ----------
    clamped_deg, free_deg : float
        The links' directions from the fold [deg].

    Returns
    -------
    float
        In [-180, 180).
    """
    return wrap_deg(free_deg - clamped_deg - 180.0)


def upper_side(free_deg: float) -> float:
    """Which side of the free link faces up as it points along ``free_deg``: +1 its left (seen
    from the fold: the link pointing right), -1 its right.

    Parameters
    ----------
    free_deg : float

    Returns
    -------
    float
    """
    return 1.0 if math.cos(math.radians(free_deg)) >= 0 else -1.0


def weight_moment_nm(free_deg: float, link_moment_kgm: float, coin_kg: float = 0.0, arm_m: float = 0.0,
                     above_m: float = 0.0, side: float = 1.0) -> float:
    """The weight's moment about the fold [N·m, CCW], the free link along ``free_deg``.

    Parameters
    ----------
    free_deg : float
        The free link's direction [deg].
    link_moment_kgm : float
        The link's first moment about the fold, ``m_link * l / 2`` [kg·m].
    coin_kg, arm_m, above_m : float
        The coin's mass [kg], its centre's distance along the link [m] and off its centre line [m].
    side : float
        +1: the coin on the link's left (seen from the fold), -1: its right.

    Returns
    -------
    float
    """
    phi = math.radians(free_deg)
    x = link_moment_kgm * math.cos(phi) + coin_kg * (arm_m * math.cos(phi) - side * above_m * math.sin(phi))
    return -GRAVITY_M_PER_S2 * x


def stiffness_and_rest(unloaded: tuple[float, float], loaded: tuple[float, float], link_moment_kgm: float,
                       coin_kg: float, arm_m: float, above_m: float = 0.0, side: float | None = None) \
        -> tuple[float, float]:
    """The hinge's stiffness and the fold's rest angle from the two settled poses.

    Parameters
    ----------
    unloaded, loaded : (float, float)
        Each pose's fold angle and free link direction [deg].
    link_moment_kgm : float
        The free link's first moment about the fold [kg·m].
    coin_kg, arm_m, above_m : float
        The coin [kg], its lever arm [m], its centre above the link's centre line [m].
    side : float, optional
        The coin's side (:func:`upper_side`); default: the upper face as the unloaded link lies.

    Returns
    -------
    stiffness_nm_per_rad, rest_deg : float
        ``k`` [N·m/rad] (not positive where the fold turned against the coin) and ``theta_0`` [deg].
    """
    (fa, pa), (fb, pb) = unloaded, loaded
    side = upper_side(pa) if side is None else side
    ma = weight_moment_nm(pa, link_moment_kgm)
    mb = weight_moment_nm(pb, link_moment_kgm, coin_kg, arm_m, above_m, side)
    turn = math.radians(wrap_deg(fb - fa))
    k = (mb - ma) / turn if turn else math.inf
    return k, fa - math.degrees(ma / k)


__all__ = ["fold_deg", "link_angles_deg", "stiffness_and_rest", "upper_side", "weight_moment_nm", "wrap_deg"]
