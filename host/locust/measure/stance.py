"""The robot's stance from side photos: ``locust measure stance REST.jpg [PUSH.jpg]``.

Each photo shows the robot from its left side with the ArUco board of ``locust track board``
standing in the plane of the left leg's outer face, and the six stickers of
:mod:`locust.sim.stickers` (found by colour, or given as pixels). The board's detected
corners give the plane's metric frame (``cv2.findHomography``, :mod:`locust.track.board`);
the stickers mapped into it are fitted by least squares (``scipy.optimize.least_squares``)
with the planar model of the robot (:func:`locust.sim.stickers.plate_points`, the four-bar of
:mod:`locust.sim.fourbar`): per photo the plate's place and pitch and the crank's angle from
its ground link, shared by both photos the ground link's angle to the plate and the servo
axis' place along the plate.

The crank's angle in the rest photo is the 0 deg command's plus the servo's give under the
robot's weight; that give is the model's (the measured robot settled on the floor,
:func:`locust.sim.still.rest_pose`) and is taken off to give ``geometry.crank_start_deg``.

Intervals: a parametric bootstrap. Each draw moves every detected board corner by the
board's own reprojection scatter and every sticker by the fit's residual scatter (in
pixels; at least :data:`MIN_STICKER_SD_PX`), fits the plane and the stance again; the 2.5 and
97.5 percentiles of the draws, moved by the fitted value's distance from the draws' median,
are the 95 % interval.
"""

from __future__ import annotations

import datetime
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
from scipy.optimize import least_squares

from ..arucoboard import BoardSpec
from ..calibrate.fitstats import Estimate
from ..errors import GeometryError, MeasureError
from ..fileio import opencv_path
from ..io.trk import PIXEL_CONVENTIONS
from ..params import Provenance, Robot, side_values
from ..sim.stickers import STICKERS, plate_points, to_view
from .tooth import ToothEstimate, crank_tooth

OBLIQUE_LIMIT = 0.05          # the board's scale may differ this much between opposite edges
REACH_LIMIT_M = 0.003         # a sticker this far from any pose of the linkage is refused
MIN_STICKER_SD_PX = 0.1       # the least pixel scatter a sticker's centre is given
BOOTSTRAP_DRAWS = 200
STANCE_KEYS = ("geometry.crank_start_deg", "geometry.ground_angle_deg", "geometry.servo_axis_x_m")
_FAR_M = 1.0                  # residual of a pose the loop cannot close


@dataclass(frozen=True)
class Photo:
    """One photo's points: the stickers (OpenCV pixels) and the board's corners."""

    path: Path
    stickers_px: dict[str, tuple[float, float]]
    corners_px: np.ndarray                 # (N, 2) detected board corners
    corners_m: np.ndarray                  # (N, 2) their places on the board (x right, y up)
    corner_sd_px: float                    # the corners' reprojection scatter
    sources: dict[str, str] = field(default_factory=dict)   # sticker -> "colour" or "given"


@dataclass(frozen=True)
class StanceResult:
    """What the photos say, each value with its interval."""

    crank_start_deg: Estimate           # geometry.crank_start_deg: the crank at the 0 deg command less its tooth
    ground_angle_deg: Estimate
    servo_axis_x_m: Estimate
    rest_pitch_deg: Estimate            # the plate's leg end above its nose end, at rest
    push_turn_deg: Estimate | None      # the crank's turn for the push command (its sign: the model's)
    push_command_deg: float
    rest_crank_seen_deg: float          # the crank's angle in the rest photo (with the servo's give)
    servo_give_deg: float               # the model's servo give at rest, taken off
    residual_mm: dict[str, dict[str, float]]   # photo -> sticker -> distance from the fitted pose
    sticker_sd_px: float
    corner_sd_px: float
    draws: int
    mirrored: bool
    side: str | None = None             # the side asked for (None: whichever the photos show)
    tooth: ToothEstimate | None = None  # with a side: its crank's tooth
    side_crank_deg: Estimate | None = None   # with a side: its crank from its ground link at the 0 deg command

    def values(self) -> dict[str, Estimate]:
        """The robot values the photos determine: crank start [deg], ground angle [deg] and
        servo axis [m], by dotted name.

        Returns
        -------
        dict of str to locust.calibrate.fitstats.Estimate
        """
        return dict(zip(STANCE_KEYS, (self.crank_start_deg, self.ground_angle_deg, self.servo_axis_x_m)))

    def to_json(self) -> dict:
        """The result as ``locust measure stance --json`` prints it (units as the names say).

        Returns
        -------
        dict
        """
        return {"crank_start_deg": self.crank_start_deg.as_dict(), "ground_angle_deg": self.ground_angle_deg.as_dict(),
                "servo_axis_x_m": self.servo_axis_x_m.as_dict(), "rest_pitch_deg": self.rest_pitch_deg.as_dict(),
                "push_turn_deg": None if self.push_turn_deg is None else self.push_turn_deg.as_dict(),
                "push_command_deg": self.push_command_deg, "rest_crank_seen_deg": self.rest_crank_seen_deg,
                "servo_give_deg": self.servo_give_deg, "residual_mm": self.residual_mm,
                "sticker_sd_px": self.sticker_sd_px, "corner_sd_px": self.corner_sd_px,
                "interval_method": f"parametric bootstrap, {self.draws} draws of the pixel noise and the board's pose",
                "mirrored": self.mirrored, "tooth": None if self.tooth is None else self.tooth.to_json(),
                "side_crank_deg": None if self.side_crank_deg is None else self.side_crank_deg.as_dict()}


# -- the board -------------------------------------------------------------------------
def board_corners(spec: BoardSpec, image_bgr: np.ndarray, path: Path) -> tuple[np.ndarray, np.ndarray, float]:
    """The board's detected corners (px), their board places (m) and their reprojection scatter
    (px, one coordinate); :class:`MeasureError` when it is missing or seen at a slant.

    Parameters
    ----------
    spec : locust.arucoboard.BoardSpec
        The printed board.
    image_bgr : numpy.ndarray
        The photo (OpenCV's BGR).
    path : pathlib.Path
        The photo's file, for messages.

    Returns
    -------
    corners_px : numpy.ndarray
        (N, 2) detected corners [px].
    corners_m : numpy.ndarray
        (N, 2) their places on the board [m], x right, y up.
    sd_px : float
        The reprojection scatter, one coordinate [px].

    Raises
    ------
    locust.errors.MeasureError
        The board is not found, or is seen at too much of a slant.
    """
    from ..track.board import board_view

    view = board_view(spec, image_bgr)
    if view is None:
        raise MeasureError(f"{path.name}: board {spec.text()} not found",
                           "the whole board must be in the photo, sharp and not covered; check --board "
                           "(dictionary, markers, sizes) against the printed one (`locust track board`)")
    _check_square(view.homography, spec, path)
    return view.corners_px, view.corners_m, view.sd_px


def _check_square(H: np.ndarray, spec: BoardSpec, path: Path) -> None:
    """Refuse a photo whose board is foreshortened: a sticker off the board's plane (the
    plate's edge, the leg's face) then reads off by an amount that grows with the slant."""
    from ..track.board import edge_scales

    for (a, b), (sa, sb) in edge_scales(H, spec).items():
        ratio = max(sa, sb) / min(sa, sb) - 1.0
        if ratio > OBLIQUE_LIMIT:
            near, far = (a, b) if sa > sb else (b, a)
            raise MeasureError(
                f"{path.name} is not square to the board: its {near} edge is {ratio * 100:.1f} % larger than "
                f"its {far} edge (at most {OBLIQUE_LIMIT * 100:g} %)",
                "photograph the robot and board from straight in front, the camera's axis square to the board "
                "and at the height of the robot, from at least 40 cm away")


# -- the stickers ----------------------------------------------------------------------
def find_stickers(image_bgr: np.ndarray, path: Path, given: dict[str, tuple[float, float]]) \
        -> tuple[dict[str, tuple[float, float]], dict[str, str]]:
    """Each sticker's centre (OpenCV px): ``given`` ones as they are, the others found by their
    colour (:mod:`locust.track.color`).

    Parameters
    ----------
    image_bgr : numpy.ndarray
        The photo (OpenCV's BGR).
    path : pathlib.Path
        The photo's file, for messages.
    given : dict of str to (float, float)
        Sticker -> its centre [px], given instead of found.

    Returns
    -------
    centres : dict of str to (float, float)
        Sticker -> centre [px].
    sources : dict of str to str
        Sticker -> ``colour`` or ``given``.

    Raises
    ------
    locust.errors.MeasureError
        A sticker is not found by its colour.
    """
    from ..markers import STICKER_COLOURS
    from ..track.color import ColorMarker, parse_hex

    out, sources = {}, {}
    for name in STICKERS:
        if name in given:
            out[name], sources[name] = given[name], "given"
            continue
        colour = STICKER_COLOURS[name][0]
        found = ColorMarker(name, f"color:{colour}", parse_hex(colour)).locate(0, image_bgr)
        if not found.ok:
            raise MeasureError(f"{path.name}: the {name} sticker ({colour}, {STICKER_COLOURS[name][1]}) is not found",
                               f"stick it there, or give its pixel: --point {name}=X,Y (docs/measure.md)")
        out[name], sources[name] = (float(found.px), float(found.py)), "colour"
    return out, sources


def read_photo(path: Path, spec: BoardSpec, given: dict[str, tuple[float, float]]) -> Photo:
    """A photo's board corners and stickers (``given``: OpenCV pixels that replace colour).

    Parameters
    ----------
    path : pathlib.Path
        A PNG or JPEG.
    spec : locust.arucoboard.BoardSpec
        The printed board in the photo.
    given : dict of str to (float, float)
        Sticker -> its centre [px].

    Returns
    -------
    Photo

    Raises
    ------
    locust.errors.MeasureError
        Not a readable image, no board, or a sticker not found.
    """
    with opencv_path(path) as name:
        image = cv2.imread(name, cv2.IMREAD_COLOR)
    if image is None:
        raise MeasureError(f"{path}: not a readable image", "give a photo or a video frame as PNG or JPEG")
    corners_px, corners_m, corner_sd = board_corners(spec, image, path)
    stickers, sources = find_stickers(image, path, given)
    return Photo(path, stickers, corners_px, corners_m, corner_sd, sources)


def model_servo_give(robot: Robot, side: str = "L"):
    """The servo's give at rest as the model has it, for a stance (the measured robot settled
    on the floor at the 0 deg command, :func:`locust.sim.still.rest_pose`), in degrees.

    Parameters
    ----------
    robot : Robot
        The robot measured.
    side : str
        The side photographed: ``L`` or ``R``; its crank is the one given, the other keeps its
        place relative to it (the teeth of the robot file).

    Returns
    -------
    callable
        ``give(crank_deg, ground_angle_deg, servo_axis_x_m)`` -> the side's give [deg], its
        crank at ``crank_deg`` from its ground link.
    """
    from ..sim.still import rest_pose

    tooth = side_values(robot, side).crank_start_deg - robot.geometry.crank_start_deg

    def give(crank_deg: float, ground_angle_deg: float, servo_axis_x_m: float) -> float:
        values = dict(zip(STANCE_KEYS, (crank_deg - tooth, ground_angle_deg, servo_axis_x_m)))
        return rest_pose(robot.with_values(values), side).servo_deg
    return give


def to_plane(corners_px: np.ndarray, corners_m: np.ndarray, points_px: np.ndarray) -> np.ndarray:
    """Pixels -> board plane (m) through the homography of the board's corners.

    Parameters
    ----------
    corners_px : numpy.ndarray
        (N, 2) board corners [px].
    corners_m : numpy.ndarray
        (N, 2) their places on the board [m].
    points_px : numpy.ndarray
        (M, 2) points [px].

    Returns
    -------
    numpy.ndarray
        (M, 2) the points on the board's plane [m].
    """
    H, _ = cv2.findHomography(corners_px, corners_m, 0)
    return cv2.perspectiveTransform(np.asarray(points_px, float)[None], H)[0]


# -- the fit ---------------------------------------------------------------------------
def _predict(robot: Robot, p: np.ndarray, n_photos: int, mirrored: bool) -> np.ndarray:
    g = robot.geometry
    ground, axis = p[0], p[1]
    out = []
    for k in range(n_photos):
        x0, y0, pitch, crank = p[2 + 4 * k: 6 + 4 * k]
        out.append(to_view(plate_points(g, crank, ground, axis), x0, y0, pitch, mirrored))
    return np.vstack(out)


def _residuals(p, robot, observed, mirrored):
    try:
        return (_predict(robot, p, len(observed) // len(STICKERS), mirrored) - observed).ravel()
    except GeometryError:
        return np.full(observed.size, _FAR_M)


def _start(robot: Robot, observed: np.ndarray, mirrored: bool, ground: float) -> np.ndarray:
    """A start for one photo set: each plate placed on its nose and tail stickers, each crank
    pointing from the axis sticker to the crank sticker as the ground angle ``ground`` has it."""
    g = robot.geometry
    n = len(STICKERS)
    p = [ground, g.servo_axis_x_m]
    nose_m = plate_points(g, g.crank_start_deg, ground, g.servo_axis_x_m)[0]
    for k in range(len(observed) // n):
        nose, tail, axis, tip = observed[n * k: n * k + 4]
        d = tail - nose
        pitch = math.degrees(math.atan2(d[1], d[0])) - (180.0 if mirrored else 0.0)
        at_nose = to_view(nose_m[None], 0.0, 0.0, pitch, mirrored)[0]
        # the crank in the view, turned back into the plate frame, then into the four-bar's
        c, s = math.cos(math.radians(pitch)), math.sin(math.radians(pitch))
        u = np.array([c * (tip - axis)[0] + s * (tip - axis)[1], -s * (tip - axis)[0] + c * (tip - axis)[1]])
        plate = np.array([-u[0] if mirrored else u[0], -u[1]])
        crank = math.degrees(math.atan2(plate[1], plate[0])) + ground
        p += [nose[0] - at_nose[0], nose[1] - at_nose[1], pitch, crank]
    return np.array(p)


def fit_points(robot: Robot, observed: np.ndarray, start: tuple[np.ndarray, bool] | None = None) \
        -> tuple[np.ndarray, bool, float]:
    """Least-squares stance for stacked plane points (6 per photo, STICKERS order), metres.

    Returns the parameters ``[ground_deg, axis_m, (x0_m, y0_m, pitch_deg, crank_deg) per photo]``,
    whether the photo is mirrored (taken from the robot's right) and the residual sum of squares.
    Without ``start`` both sides and a spread of ground angles are tried, each crank started
    where its stickers point.

    Parameters
    ----------
    robot : Robot
        The robot measured (its links and sticker places).
    observed : numpy.ndarray
        The stickers on the board's plane [m], 6 per photo.
    start : (numpy.ndarray, bool), optional
        Parameters and mirroring to start from.

    Returns
    -------
    params : numpy.ndarray
        ``[ground_deg, axis_m, (x0_m, y0_m, pitch_deg, crank_deg) per photo]``.
    mirrored : bool
        Whether the photos were taken from the robot's right.
    ssr_m2 : float
        The residual sum of squares [m²].
    """
    if start is not None:
        sol = least_squares(_residuals, start[0], args=(robot, observed, start[1]), x_scale="jac")
        return _wrapped(sol.x), start[1], float(np.sum(sol.fun ** 2))
    best = None
    for mirrored in (False, True):
        for ground in (-30.0, 0.0, 30.0):
            sol = least_squares(_residuals, _start(robot, observed, mirrored, ground),
                                args=(robot, observed, mirrored), x_scale="jac")
            cost = float(np.sum(sol.fun ** 2))
            if best is None or cost < best[2]:
                best = (_wrapped(sol.x), mirrored, cost)
    return best


def _wrapped(p: np.ndarray) -> np.ndarray:
    """The angles (ground, each pitch and crank) in [-180, 180)."""
    p = p.copy()
    for i in [0, *range(4, len(p), 4), *range(5, len(p), 4)]:
        p[i] = (p[i] + 180.0) % 360.0 - 180.0
    return p


def _per_point_m(robot: Robot, p: np.ndarray, observed: np.ndarray, mirrored: bool) -> np.ndarray:
    return np.linalg.norm(_predict(robot, p, len(observed) // len(STICKERS), mirrored) - observed, axis=1)


def _check_reach(robot: Robot, photos: list[Photo], observed: np.ndarray, p: np.ndarray, mirrored: bool) -> None:
    """Refuse points no pose of this linkage reaches: the sticker whose removal lets the others
    fit best is named, with its distance from the pose the others give."""
    dist = _per_point_m(robot, p, observed, mirrored)
    if dist.max() <= REACH_LIMIT_M:
        return
    n = len(STICKERS)
    worst = None
    for k in range(len(observed)):
        keep = np.ones(len(observed), bool)
        keep[k] = False
        weights = keep.astype(float)

        def res(q, k=k, weights=weights):
            r = _residuals(q, robot, observed, mirrored).reshape(-1, 2)
            return (r * weights[:, None]).ravel()

        sol = least_squares(res, p, x_scale="jac")
        off = float(_per_point_m(robot, sol.x, observed, mirrored)[k])
        rest = float(np.max(np.delete(_per_point_m(robot, sol.x, observed, mirrored), k)))
        if worst is None or rest < worst[2]:
            worst = (k, off, rest)
    k, off, rest = worst
    photo, name = photos[k // n], STICKERS[k % n]
    g = robot.geometry
    raise MeasureError(
        f"{photo.path.name}: the {name} sticker is {off * 1000:.1f} mm from where any pose of this linkage puts it "
        f"(links {g.ground_m * 1000:g}/{g.crank_m * 1000:g}/{g.coupler_m * 1000:g}/{g.leg_m * 1000:g} mm; the other "
        f"stickers fit within {rest * 1000:.1f} mm; at most {REACH_LIMIT_M * 1000:g} mm)",
        f"check where the {name} sticker sits (docs/measure.md), the link lengths (--preset, --set geometry.*_m) "
        f"and that it was found where it is (--point {name}=X,Y gives it by hand)")


def _plane_points(photo: Photo, corner_noise: np.ndarray | None = None,
                  sticker_noise: np.ndarray | None = None) -> np.ndarray:
    corners = photo.corners_px if corner_noise is None else photo.corners_px + corner_noise
    px = np.array([photo.stickers_px[n] for n in STICKERS])
    if sticker_noise is not None:
        px = px + sticker_noise
    return to_plane(corners, photo.corners_m, px)


def _m_per_px(photo: Photo) -> float:
    from ..track.board import scale_px_per_m

    H, _ = cv2.findHomography(photo.corners_m, photo.corners_px, 0)
    centre = photo.corners_m.mean(axis=0)
    return 1.0 / scale_px_per_m(H, float(centre[0]), float(centre[1]))


def _pitch_deg(robot: Robot, p: np.ndarray, mirrored: bool) -> float:
    """The plate's leg end above its nose end in the first photo (the rest photo)."""
    pts = _predict(robot, p[:6], 1, mirrored)
    d = pts[1] - pts[0]
    return math.degrees(math.atan2(d[1], abs(d[0])))


def _estimate(value: float, draws: np.ndarray) -> Estimate:
    lo, hi = np.percentile(draws, [2.5, 97.5])
    shift = value - float(np.median(draws))
    return Estimate(value, float(np.std(draws, ddof=1)), float(lo + shift), float(hi + shift))


def fit_stance(robot: Robot, photos: list[Photo], servo_give_deg, draws: int = BOOTSTRAP_DRAWS,
               seed: int = 0, side: str | None = None) -> StanceResult:
    """Fit the stance to one photo (rest) or two (rest, push); ``servo_give_deg(crank_deg,
    ground_angle_deg, servo_axis_x_m)`` is the servo's give at rest, as the model has it.

    ``side``: the photos must show that side (``L``: the robot's left, ``R``: its right, a
    mirrored view), and its crank's tooth is found (:mod:`.tooth`); None: whichever side they
    show, the left crank's place taken as the robot's ``geometry.crank_start_deg``.

    Parameters
    ----------
    robot : Robot
        The robot measured.
    photos : list of Photo
        The rest photo, and optionally the push photo.
    servo_give_deg : callable
        See above (:func:`model_servo_give`).
    draws : int
        Bootstrap draws for the intervals.
    seed : int
        The bootstrap's seed.
    side : str, optional
        ``L`` or ``R``: the side the photos must show.

    Returns
    -------
    StanceResult
        Crank start and ground angle [deg], servo axis [m], each with its interval.

    Raises
    ------
    MeasureError
        A sticker no pose reaches, or photos of the other side than ``side``.
    """
    observed = np.vstack([_plane_points(ph) for ph in photos])
    p, mirrored, rss = fit_points(robot, observed)
    _check_side(photos[0], mirrored, side)
    _check_reach(robot, photos, observed, p, mirrored)
    n_obs, n_par = observed.size, len(p)
    m_per_px = float(np.mean([_m_per_px(ph) for ph in photos]))
    sticker_sd = max(math.sqrt(rss / max(n_obs - n_par, 1)) / m_per_px, MIN_STICKER_SD_PX)
    corner_sd = max(float(np.sqrt(np.mean([ph.corner_sd_px ** 2 for ph in photos]))), MIN_STICKER_SD_PX)
    rng = np.random.default_rng(seed)
    boot = []
    for _ in range(draws):
        obs = np.vstack([_plane_points(ph, rng.normal(0.0, corner_sd, ph.corners_px.shape),
                                       rng.normal(0.0, sticker_sd, (len(STICKERS), 2))) for ph in photos])
        q, _, _ = fit_points(robot, obs, (p, mirrored))
        boot.append([q[0], q[1], q[5], _pitch_deg(robot, q, mirrored),
                     q[9] - q[5] if len(photos) > 1 else math.nan])
    boot = np.array(boot)
    give = servo_give_deg(p[5], p[0], p[1])
    give = servo_give_deg(p[5] - give, p[0], p[1])
    residual = {ph.path.name: {n: float(d) * 1000.0 for n, d in zip(STICKERS, dist)}
                for ph, dist in zip(photos, _per_point_m(robot, p, observed, mirrored).reshape(len(photos), -1))}
    crank = _estimate(p[5] - give, boot[:, 2] - give)
    teeth = side_values(robot, side or "L").crank_start_deg - robot.geometry.crank_start_deg
    return StanceResult(
        crank_start_deg=_estimate(p[5] - give - teeth, boot[:, 2] - give - teeth),
        ground_angle_deg=_estimate(p[0], boot[:, 0]),
        servo_axis_x_m=_estimate(p[1], boot[:, 1]),
        rest_pitch_deg=_estimate(_pitch_deg(robot, p, mirrored), boot[:, 3]),
        push_turn_deg=_estimate(p[9] - p[5], boot[:, 4]) if len(photos) > 1 else None,
        push_command_deg=robot.schedule.push_deg, rest_crank_seen_deg=float(p[5]), servo_give_deg=float(give),
        residual_mm=residual, sticker_sd_px=sticker_sd, corner_sd_px=corner_sd, draws=draws, mirrored=mirrored,
        side=side, tooth=None if side is None else crank_tooth(robot, side, crank),
        side_crank_deg=None if side is None else crank)


def _check_side(photo: Photo, mirrored: bool, side: str | None) -> None:
    """Refuse photos of the other side than ``side`` (the right's view is the left's mirrored)."""
    if side is None or mirrored == (side == "R"):
        return
    seen, want = ("right", "left") if mirrored else ("left", "right")
    raise MeasureError(f"{photo.path.name} shows the robot's {seen} side, not its {want}: the stickers fit the "
                       f"{seen} leg's view (its nose on the {'right' if mirrored else 'left'} of its tail)",
                       f"photograph the robot from its {want}, the stickers on the {want} leg and the board in its "
                       f"plane, or give --side {seen}")


def given_points(items: Sequence[str], convention: str, option: str) -> dict[str, tuple[float, float]]:
    """Stickers' pixels given as ``NAME=X,Y`` (``--point``), in OpenCV's convention (Tracker's
    pixels are half a pixel further right and down).

    Parameters
    ----------
    items : sequence of str
        The ``NAME=X,Y`` texts.
    convention : str
        A key of :data:`locust.io.trk.PIXEL_CONVENTIONS`: ``tracker`` or ``opencv``.
    option : str
        The option they were given with, for messages.

    Returns
    -------
    dict of str to (float, float)
        Each sticker's pixel [px], OpenCV's convention.

    Raises
    ------
    MeasureError
        A text not of the form, or a name that is not a sticker's.
    """
    shift = PIXEL_CONVENTIONS[convention]
    out = {}
    for item in items:
        m = re.fullmatch(r"\s*(\w+)\s*=\s*([-+]?[\d.]+)\s*,\s*([-+]?[\d.]+)\s*", item)
        if not m or m.group(1) not in STICKERS:
            raise MeasureError(f"{option} {item!r} is not NAME=X,Y with NAME one of {', '.join(STICKERS)}",
                               f"e.g. {option} knee=412.5,633")
        try:
            out[m.group(1)] = (float(m.group(2)) + shift, float(m.group(3)) + shift)
        except ValueError:
            raise MeasureError(f"{option} {item!r}: X and Y must be numbers of pixels",
                               f"e.g. {option} knee=412.5,633") from None
    return out


def with_stance(robot: Robot, result: StanceResult, rest: Path) -> Robot:
    """``robot`` with the values the photos determine in place, each with its interval and
    where it came from (the rest photo, today).

    Parameters
    ----------
    robot : Robot
        The robot measured.
    result : StanceResult
        The fit.
    rest : Path
        The rest photo.

    Returns
    -------
    Robot
        The robot as measured.
    """
    today = datetime.date.today().isoformat()
    for key, est in result.values().items():
        lo, hi = est.ci95
        robot = robot.with_values({key: est.value}, Provenance(
            source=f"measured:{rest.name}", uncertainty=est.std, date=today,
            note=f"95% interval [{lo:.5g}, {hi:.5g}], parametric bootstrap of the pixel noise and the board's "
                 f"pose ({result.draws} draws); locust measure stance"))
    return robot


__all__ = ["BOOTSTRAP_DRAWS", "OBLIQUE_LIMIT", "Photo", "REACH_LIMIT_M", "STANCE_KEYS", "StanceResult",
           "board_corners", "find_stickers", "fit_points", "fit_stance", "given_points", "model_servo_give",
           "read_photo", "to_plane", "with_stance"]
