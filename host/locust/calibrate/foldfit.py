"""The fold test's fit: a fold's stiffness and rest angle from its photos unloaded and loaded,
with intervals (:func:`fit_fold`, the arithmetic of :mod:`.foldmoments` on the stickers
:mod:`.foldread` found).

Each state's link directions are the mean over its photos; the two settled poses give the
hinge's stiffness ``k`` and the fold's weightless rest angle ``theta_0``.

Intervals: Monte Carlo, :data:`DRAWS` draws of everything the result rests on, each taken
through the same arithmetic: every sticker centre by its measured scatter (:mod:`.foldread`;
with several photos of a state, at least the scatter of its centres over them), every board
corner by the board's reprojection scatter, each sticker's placement on its line by
:data:`PLACEMENT_SD_M` (the axis sticker both ways, the others across their links), the
board's lean from upright by :data:`TILT_SD_DEG`, the coin's mass (a weighed or a named coin's,
:mod:`.coins`), its lever arm by the ruler's :data:`ARM_SD_M`, its height above the link, and
the free link's mass and length. The value is the nominal arithmetic; the interval the draws'
2.5 and 97.5 percentiles moved by the value's distance from their median.

Angles are given as the model counts the fold (:func:`locust.sim.fourbar.fold_angles_deg`: the
turn from the link before it around the loop to the link after it): the photo looks at the
fold's outer face as the robot's left side shows it, the free link's turn from the clamped
one's line counter-clockwise (the loop's, its leg free on the clamped ground link, the other
way round); a right leg's fold, photographed from the robot's right, is read mirrored.
Refused, with what to do: a coin that hardly turns the fold, one the fold turns against, and
one too heavy for the angles (the loaded link near the vertical, or folded flat).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..errors import CalibrationError
from ..params import FOLDS
from .curves import Curves
from .fitstats import Estimate
from .foldmoments import fold_deg, link_angles_deg, stiffness_and_rest, upper_side, weight_moment_nm, wrap_deg
from .foldread import FOLD_STICKERS, FoldPhoto

# fold -> (the clamped link, the free link)
FOLD_LINKS = {"servo": ("ground", "crank"), "knee": ("crank", "coupler"), "ankle": ("coupler", "leg"),
              "loop": ("ground", "leg")}
# the fold's angle as the model counts it, per the photo's (free link against the clamped one,
# CCW on the outer face seen as the robot's left side shows it): the loop's is the ground
# link's against the leg, the clamped link's against the free one
PHOTO_SIGN = {"servo": 1.0, "knee": 1.0, "ankle": 1.0, "loop": -1.0}
SIDES = {"both": "folds", "left": "left", "right": "right"}    # --side -> the robot file's section
DRAWS = 400
ARM_SD_M = 0.0005               # a ruler read to half its millimetre
LENGTH_SD_M = 0.0005
PLACEMENT_SD_M = 0.0005         # a sticker's centre placed by eye on its line
TILT_SD_DEG = 0.5               # the board standing on a level table, upright by eye
MIN_DEFLECTION_DEG = 1.0
VERTICAL_MARGIN_DEG = 15.0      # the loaded link no nearer the vertical than this
FOLD_RANGE_DEG = 170.0          # beyond: the free link folded onto the clamped one
CLAMP_MOVED_DEG = 1.0           # the clamped link turning more between the photos is warned of
TARGET_DEFLECTION_DEG = 20.0    # what a suggested lever arm aims at


@dataclass(frozen=True)
class Load:
    """The coin as taped on: its mass, its lever arm from the fold line, its centre's height
    above the free link's centre line, each with its standard uncertainty, and what it is."""

    mass_kg: float
    mass_sd_kg: float
    arm_m: float
    above_m: float
    above_sd_m: float
    what: str
    arm_sd_m: float = ARM_SD_M


@dataclass(frozen=True)
class FreeLink:
    """The free link: its mass and its length from the fold, with their standard uncertainties
    and how they were had (weighed, estimated from its size)."""

    mass_kg: float
    mass_sd_kg: float
    length_m: float
    length_sd_m: float
    what: str

    @property
    def moment_kgm(self) -> float:
        """Its first moment about the fold, a uniform strip's ``m l / 2`` [kg·m]."""
        return self.mass_kg * self.length_m / 2


@dataclass(frozen=True)
class FoldFit:
    """A fold's static test, as the photos give it (angles as the model counts the fold).

    Attributes
    ----------
    fold, side : str
        Which fold, and ``both``, ``left`` or ``right``.
    source : str
        The photos, ``unloaded+loaded``.
    stiffness_nm_per_rad : Estimate
        The hinge's stiffness [N·m/rad].
    rest_deg : Estimate
        The fold's weightless rest angle [deg].
    rest_offset_deg : Estimate or None
        The rest angle less the fold's angle in the robot as assembled (None: no robot angle given).
    assembled_deg : float or None
        That angle [deg].
    unloaded_deg, loaded_deg, deflection_deg : Estimate
        The fold's angle in each photo and the coin's turn of it [deg].
    loaded_free_deg : float
        The loaded free link's direction from the horizontal (the photo's x) [deg].
    moments_nm : (float, float)
        The weight's moment about the fold in each photo [N·m, the model's sense].
    link : FreeLink
    load : Load
    sticker_sd_px, corner_sd_px : float
        The largest sticker scatter taken, and the board corners' [px].
    photos : (int, int)
        Photos of each state.
    draws : int
    notes, warnings : list of str
    curves : Curves
        The moments against the fold angle, the fitted spring line through them.
    """

    fold: str
    side: str
    source: str
    stiffness_nm_per_rad: Estimate
    rest_deg: Estimate
    rest_offset_deg: Estimate | None
    assembled_deg: float | None
    unloaded_deg: Estimate
    loaded_deg: Estimate
    deflection_deg: Estimate
    loaded_free_deg: float
    moments_nm: tuple[float, float]
    link: FreeLink
    load: Load
    sticker_sd_px: float
    corner_sd_px: float
    photos: tuple[int, int]
    draws: int
    curves: Curves = field(repr=False)
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    @property
    def estimates(self) -> dict[str, Estimate]:
        """The robot values: the fold's stiffness and (with a robot angle) its rest offset, by their keys."""
        prefix = f"{SIDES[self.side]}.{self.fold}"
        out = {f"{prefix}_stiffness_nm_per_rad": self.stiffness_nm_per_rad}
        if self.rest_offset_deg is not None:
            out[f"{prefix}_rest_offset_deg"] = self.rest_offset_deg
        return out

    def summary(self) -> dict:
        """Every figure of the test, as ``locust calibrate fold --json`` prints it.

        Returns
        -------
        dict
        """
        return {"experiment": "fold", "source": self.source, "fold": self.fold, "side": self.side,
                **{k: e.as_dict() for k, e in self.estimates.items()},
                "rest_deg": self.rest_deg.as_dict(), "unloaded_fold_deg": self.unloaded_deg.as_dict(),
                "loaded_fold_deg": self.loaded_deg.as_dict(), "deflection_deg": self.deflection_deg.as_dict(),
                "assembled_fold_deg": self.assembled_deg, "loaded_link_from_horizontal_deg": self.loaded_free_deg,
                "weight_moment_unloaded_nm": self.moments_nm[0], "weight_moment_loaded_nm": self.moments_nm[1],
                "coin_mass_kg": self.load.mass_kg, "coin_arm_m": self.load.arm_m,
                "link_mass_kg": self.link.mass_kg, "link_length_m": self.link.length_m,
                "sticker_sd_px": self.sticker_sd_px, "corner_sd_px": self.corner_sd_px,
                "photos": list(self.photos), "draws": self.draws, "notes": self.notes}


@dataclass(frozen=True)
class _Draw:
    """One draw of what the photos do not fix (zeros: the nominal reading)."""

    axis_m: np.ndarray
    tip_m: float
    base_m: float
    tilt_deg: float

    @staticmethod
    def nominal() -> _Draw:
        return _Draw(np.zeros(2), 0.0, 0.0, 0.0)


def _state_angles(points: list[np.ndarray], draw: _Draw) -> tuple[float, float]:
    """A state's clamped and free link directions [deg], the mean over its photos' plane points."""
    c_all, f_all = [], []
    for axis, tip, base in points:
        c, _ = link_angles_deg(axis, tip, base)
        cr = math.radians(c)
        along, across = draw.axis_m
        pivot = axis + along * np.array([math.cos(cr), math.sin(cr)]) + across * np.array([math.sin(cr), -math.cos(cr)])
        c, f = link_angles_deg(pivot, tip, base)
        c += math.degrees(draw.base_m / max(float(np.hypot(*(base - pivot))), 1e-6))
        f += math.degrees(draw.tip_m / max(float(np.hypot(*(tip - pivot))), 1e-6))
        c_all.append(c + draw.tilt_deg)
        f_all.append(f + draw.tilt_deg)
    c0, f0 = c_all[0], f_all[0]
    return (c0 + float(np.mean(wrap_deg(np.array(c_all) - c0))), f0 + float(np.mean(wrap_deg(np.array(f_all) - f0))))


def _sticker_sd(photos: list[FoldPhoto]) -> dict[str, float]:
    """Each sticker's scatter for a state [px]: its photos' own, at least its spread over them (3 or more)."""
    out = {n: max(p.sticker_sd_px[n] for p in photos) for n in FOLD_STICKERS}
    if len(photos) >= 3:
        pts = np.array([p.plane_points() for p in photos])          # (photos, 3, 2)
        scale = float(np.mean([p.m_per_px() for p in photos]))
        spread = np.sqrt(np.sum((pts - pts.mean(axis=0)) ** 2, axis=(0, 2)) / (2 * (len(photos) - 1))) / scale
        out = {n: max(out[n], float(s)) for n, s in zip(FOLD_STICKERS, spread)}
    return out


def _points(photos: list[FoldPhoto], sds: dict[str, float], rng: np.random.Generator | None) -> list[np.ndarray]:
    if rng is None:
        return [p.plane_points() for p in photos]
    sd = np.array([[sds[n]] for n in FOLD_STICKERS])
    return [p.plane_points(rng.normal(0.0, p.corner_sd_px, p.corners_px.shape), rng.normal(0.0, 1.0, (3, 2)) * sd)
            for p in photos]


def _solve(unloaded, loaded, link_moment: float, coin_kg: float, arm_m: float,
           above_m: float) -> tuple[float, float, float, float, float, float]:
    """(k, rest, unloaded fold, loaded fold, unloaded free dir, loaded free dir) of one reading."""
    (ca, fa), (cb, fb) = unloaded, loaded
    ta, tb = fold_deg(ca, fa), fold_deg(cb, fb)
    k, rest = stiffness_and_rest((ta, fa), (ta + wrap_deg(tb - ta), fb), link_moment, coin_kg, arm_m, above_m)
    return k, rest, ta, tb, fa, fb


def _estimate(value: float, draws: np.ndarray) -> Estimate:
    draws = draws[np.isfinite(draws)]
    lo, hi = np.percentile(draws, [2.5, 97.5])
    shift = value - float(np.median(draws))
    return Estimate(float(value), float(np.std(draws, ddof=1)), float(lo + shift), float(hi + shift))


def _check_turn(turn_deg: float, turn_sd_deg: float, load: Load, source: str) -> None:
    least = max(MIN_DEFLECTION_DEG, 3.0 * turn_sd_deg)
    if abs(turn_deg) < least:
        raise CalibrationError(
            f"{source}: the coin turned the fold by {turn_deg:.2f} deg (± {turn_sd_deg:.2f} deg), no deflection to "
            f"measure (at least {least:.2f} deg)",
            f"check that the second photo is the one with the coin on the free link; then a heavier coin or a longer "
            f"lever arm (now {load.arm_m * 1000:.1f} mm), so that the coin turns the fold by 10 to 30 deg")


def _check_sign(k: float, turn_deg: float, source: str) -> None:
    if not k > 0:
        raise CalibrationError(
            f"{source}: the fold turned by {turn_deg:.2f} deg against the coin's weight",
            "give the photo without the coin first and the one with it second; the coin on the free link, "
            "not on the clamped one")


def _check_range(loaded_free_deg: float, loaded_fold: float, turn_deg: float, load: Load, source: str) -> None:
    """The loaded link clear of the vertical and of the clamped link; else the coin is too heavy,
    and the lever arm that would turn the fold by some :data:`TARGET_DEFLECTION_DEG` is suggested."""
    off_vertical = min(abs(90.0 - abs(wrap_deg(loaded_free_deg))), 90.0)
    folded = abs(loaded_fold) > FOLD_RANGE_DEG
    if off_vertical >= VERTICAL_MARGIN_DEG and not folded:
        return
    arm = load.arm_m * TARGET_DEFLECTION_DEG / max(abs(turn_deg), 1e-9)
    what = (f"folds the free link to {loaded_fold:.1f} deg, onto the clamped link" if folded else
            f"pulls the free link to {off_vertical:.1f} deg from the vertical, where its moment is the cosine of a "
            "nearly vertical angle and hardly known")
    raise CalibrationError(
        f"{source}: the coin ({load.what}) is too heavy for the fold: it {what} (the loaded link must stay "
        f"{VERTICAL_MARGIN_DEG:g} deg or more from the vertical)",
        f"a lighter coin, or tape it nearer the fold: its lever arm is now {load.arm_m * 1000:.1f} mm (about "
        f"{arm * 1000:.0f} mm would turn it by some {TARGET_DEFLECTION_DEG:g} deg; a fold this soft may want a "
        "lighter weight, a paper clip weighed: --coin-mass-kg)")


def photo_sign(fold: str, side: str) -> float:
    """+1 or -1: the model's fold angle per the photo's, for ``fold`` of the leg on ``side``
    (a right leg's fold is photographed from the robot's right, mirrored)."""
    return PHOTO_SIGN[fold] * (-1.0 if side == "right" else 1.0)


def fit_fold(unloaded: Sequence[FoldPhoto], loaded: Sequence[FoldPhoto], link: FreeLink, load: Load, *,
             fold: str = "knee", side: str = "both", assembled_deg: float | None = None, draws: int = DRAWS,
             seed: int = 0, source: str = "fold") -> FoldFit:
    """The fold's stiffness and rest angle from its photos unloaded and loaded, with intervals.

    Parameters
    ----------
    unloaded, loaded : sequence of FoldPhoto
        Each state's photos (:func:`locust.calibrate.foldread.read_state`).
    link : FreeLink
        The free link's mass and length.
    load : Load
        The coin.
    fold : {"servo", "knee", "ankle", "loop"}
    side : {"both", "left", "right"}
        ``right``: the photos are of a right leg's fold from the robot's right (read mirrored).
    assembled_deg : float, optional
        The fold's angle in the robot as assembled at rest [deg]; the rest offset with it.
    draws : int
        Monte Carlo draws for the intervals.
    seed : int
    source : str
        The photos' names, for messages and provenance.

    Returns
    -------
    FoldFit

    Raises
    ------
    locust.errors.CalibrationError
        No deflection, a deflection against the coin, or a coin too heavy for the angles.
    """
    if fold not in FOLDS:
        raise CalibrationError(f"fold {fold!r}: not one of {', '.join(FOLDS)}", "choose --fold " + "|".join(FOLDS))
    if side not in SIDES:
        raise CalibrationError(f"side {side!r}: not one of {', '.join(SIDES)}", "choose --side left|right|both")
    unloaded, loaded = list(unloaded), list(loaded)
    sds = [_sticker_sd(unloaded), _sticker_sd(loaded)]
    nominal = _Draw.nominal()
    a, b = _state_angles(_points(unloaded, sds[0], None), nominal), _state_angles(_points(loaded, sds[1], None),
                                                                                 nominal)
    value = _solve(a, b, link.moment_kgm, load.mass_kg, load.arm_m, load.above_m)
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(draws):
        d = _Draw(rng.normal(0.0, PLACEMENT_SD_M, 2), rng.normal(0.0, PLACEMENT_SD_M),
                  rng.normal(0.0, PLACEMENT_SD_M), rng.normal(0.0, TILT_SD_DEG))
        mass = rng.normal(link.mass_kg, link.mass_sd_kg)
        length = rng.normal(link.length_m, link.length_sd_m)
        rows.append(_solve(_state_angles(_points(unloaded, sds[0], rng), d),
                           _state_angles(_points(loaded, sds[1], rng), d), mass * length / 2,
                           rng.normal(load.mass_kg, load.mass_sd_kg), rng.normal(load.arm_m, load.arm_sd_m),
                           rng.normal(load.above_m, load.above_sd_m)))
    rows = np.array(rows)
    k, rest, ta, tb, fa, fb = value
    turn = wrap_deg(tb - ta)
    turns = wrap_deg(rows[:, 3] - rows[:, 2])
    _check_turn(turn, float(np.std(turns, ddof=1)), load, source)
    _check_range(fb, tb, turn, load, source)
    _check_sign(k, turn, source)
    sign = photo_sign(fold, side)
    rest_est = _estimate(sign * rest, sign * rows[:, 1])
    offset = None
    if assembled_deg is not None:
        offset = _estimate(wrap_deg(sign * rest - assembled_deg), wrap_deg(sign * rows[:, 1] - assembled_deg))
    side_of_coin = upper_side(fa)
    moments = (weight_moment_nm(fa, link.moment_kgm),
               weight_moment_nm(fb, link.moment_kgm, load.mass_kg, load.arm_m, load.above_m, side_of_coin))
    warnings = []
    moved = wrap_deg(b[0] - a[0])
    if abs(moved) > CLAMP_MOVED_DEG:
        warnings.append(f"the clamped link turned by {moved:.1f} deg between the photos: the clamp slipped, or the "
                        "board moved (the fold's own angle is still read against the clamped link)")
    oblique = max(p.oblique for p in unloaded + loaded)
    if oblique > 0.05:
        warnings.append(f"the board is seen at a slant (its edges' scales differ by {oblique * 100:.1f} %): a "
                        "sticker off the board's plane reads off; photograph square to the board")
    fit = FoldFit(
        fold=fold, side=side, source=source, stiffness_nm_per_rad=_estimate(k, rows[:, 0]), rest_deg=rest_est,
        rest_offset_deg=offset, assembled_deg=assembled_deg,
        unloaded_deg=_estimate(sign * ta, sign * rows[:, 2]), loaded_deg=_estimate(sign * tb, sign * rows[:, 3]),
        deflection_deg=_estimate(sign * turn, sign * turns), loaded_free_deg=float(wrap_deg(fb)),
        moments_nm=(sign * moments[0], sign * moments[1]), link=link, load=load,
        sticker_sd_px=float(max(max(s.values()) for s in sds)),
        corner_sd_px=float(max(p.corner_sd_px for p in unloaded + loaded)), photos=(len(unloaded), len(loaded)),
        draws=draws, curves=_curves(sign, k, rest, [[_state_angles([p], nominal) for p in _points(photos, sd, None)]
                                                    for photos, sd in ((unloaded, sds[0]), (loaded, sds[1]))],
                                    link, load, fold), warnings=warnings,
        notes=[f"link: {link.what}", f"coin: {load.what}, lever arm {load.arm_m * 1000:.1f} mm"])
    return fit


def _curves(sign: float, k: float, rest: float, states, link: FreeLink, load: Load, fold: str) -> Curves:
    """Each photo's weight moment against its fold angle, and the spring's line
    ``k (theta - theta_0)`` that balances them (both in the model's sense of the fold): with
    several photos of a state, the residuals are their scatter about it."""
    side = upper_side(states[0][0][1])
    x, data = [], []
    for loaded, angles in enumerate(states):
        for c, f in angles:
            x.append(sign * fold_deg(c, f))
            coin = (load.mass_kg, load.arm_m, load.above_m, side) if loaded else (0.0, 0.0, 0.0, side)
            data.append(sign * weight_moment_nm(f, link.moment_kgm, *coin))
    x = np.array(x)
    fine = np.linspace(min(*x, sign * rest) - 2.0, max(*x, sign * rest) + 2.0, 50)

    def line(deg):
        return k * np.radians(deg - sign * rest)

    return Curves(x=x, data=np.array(data), model=line(x), x_label=f"{fold} fold angle [deg]",
                  y_label="the weight's moment about the fold [N·m]",
                  title=f"{fold} fold: each photo unloaded and loaded, the spring's line through them", model_x=fine,
                  model_fine=line(fine))


__all__ = ["ARM_SD_M", "DRAWS", "FOLD_LINKS", "LENGTH_SD_M", "FoldFit", "FreeLink", "Load", "PLACEMENT_SD_M",
           "SIDES", "TILT_SD_DEG", "fit_fold"]
