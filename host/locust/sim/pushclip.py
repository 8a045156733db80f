"""Virtual clips of one push for ``locust measure stroke``: ``locust sim --push-clip``.

Two clips of the robot as :mod:`.push` simulates it, each through one fixed camera square
to the legs' plane on the side asked for (the robot's left, from +y, or its right, from -y),
the robot in its cardstock grey with the six stickers of :mod:`.stickers` on that side
(:func:`.still.sticker_model`): the push on the floor (the hop's first push) and the push with
the robot held up. Each runs from :data:`.push.LEAD_S` before the push command to
:data:`AFTER_S` after it ends, one frame every 1/fps on a physics step (the run's step the
largest not above the robot's that divides the frame period, :func:`.push.frame_step_s`).

Beside each ``<stem>.mp4``: ``<stem>.truth.csv`` and ``<stem>.camera.json`` (each sticker's
true pixel per frame and the camera, as :mod:`.clip` writes them) and ``<stem>.crank.csv``
(per frame the time from the push command, the command and the crank's true angle from its
ground link): simulated ground truth, for testing the measurement.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SimError
from ..fileio import atomic_write_text, check_distinct
from ..params import Robot
from .camera import frame_views, side_azimuth_deg
from .clip import ClipRecorder, RenderedClip, check_video_path, sidecar_paths, validate_size
from .push import LEAD_S, PushRun, frame_step_s, simulate_push
from .stickers import STICKERS

AFTER_S = 0.25          # filmed after the push command ends (the return)
DEFAULT_FPS = 240       # a phone's slow motion
SIDE_NAMES = {"L": "left", "R": "right"}


@dataclass(frozen=True)
class PushClip:
    """A rendered push clip and its truth.

    Attributes
    ----------
    clip : RenderedClip
        The MP4 and its two sidecars (stickers' pixels, camera).
    crank_path : Path
        ``<stem>.crank.csv``: the crank's true angle per frame.
    run : PushRun
        The simulated push it shows (every step).
    kind : str
        ``floor`` or ``held``.
    """

    clip: RenderedClip
    crank_path: Path
    run: PushRun
    kind: str


def crank_truth_path(path: Path) -> Path:
    """A push clip's crank sidecar: ``<stem>.crank.csv``.

    Parameters
    ----------
    path : Path
        The clip.

    Returns
    -------
    Path
    """
    return path.with_name(path.stem + ".crank.csv")


def _frames(run: PushRun, fps: int) -> np.ndarray:
    """The kept steps a clip shows: one every 1/fps from LEAD_S before the push to AFTER_S after it."""
    times = -LEAD_S + np.arange(int(round((LEAD_S + run.push_s + AFTER_S) * fps)) + 1) / fps
    idx = np.rint((times - run.t_s[0]) / run.timestep_s).astype(int)
    if idx[0] < 0 or idx[-1] >= len(run.t_s) or np.max(np.abs(run.t_s[idx] - times)) > 1e-6 * run.timestep_s:
        raise SimError(f"the push's steps do not fall on the frames of a {fps} frames/s clip",
                       "choose a frame rate whose period is a whole number of physics steps")
    return idx


def _crank_csv(robot: Robot, run: PushRun, idx: np.ndarray, fps: int) -> str:
    where = "on the floor" if run.kind == "floor" else "held up by its plate"
    lines = [f"# simulated ground truth: MuJoCo push of robot {robot.name!r} {where}, seen from its "
             f"{SIDE_NAMES[run.side]}, {fps} frames/s; t_s from the clip's first frame, t_push_s from the push "
             f"command ({run.push_deg:g} deg for {run.push_s:g} s); crank_deg: the {SIDE_NAMES[run.side]} crank "
             "from its ground link",
             "frame,t_s,t_push_s,command_deg,crank_deg"]
    for k, i in enumerate(idx):
        lines.append(f"{k},{k / fps:.6f},{run.t_s[i]:.6f},{run.command_deg[i]:.4f},{run.crank_deg[i]:.6f}")
    return "\n".join(lines) + "\n"


def _record(robot: Robot, run: PushRun, path: Path, fps: int, width: int, height: int) -> PushClip:
    from .still import outward_y, sticker_model

    model, face_y = sticker_model(robot, None, None, run.side)
    idx = _frames(run, fps)
    reach = np.vstack([p[idx] for p in run.points_m.values()])
    fixed, _ = frame_views(reach, reach[:, 0], robot.geometry.body_length_m, face_y, float(model.vis.global_.fovy),
                           width / height, azimuth_deg=side_azimuth_deg(run.side))
    rec = ClipRecorder(model, path, fps, width, height, "fixed", fixed, robot_name=robot.name, shadows=False,
                       marker_geoms={n: f"sticker_{n}" for n in STICKERS}, toward_y=outward_y(run.side))
    try:
        for k, i in enumerate(idx):
            rec.add_frame(run.qpos[i], k / fps)
    except BaseException:
        rec.abort()
        raise
    clip = rec.finish()
    crank = crank_truth_path(path)
    atomic_write_text(crank, _crank_csv(robot, run, idx, fps))
    return PushClip(clip, crank, run, run.kind)


def render_push_clips(robot: Robot, floor_path: str | os.PathLike | None = None,
                      held_path: str | os.PathLike | None = None, side: str = "L", fps: int = DEFAULT_FPS,
                      width: int = 640, height: int = 480) -> list[PushClip]:
    """Render the floor clip to ``floor_path`` and the held clip to ``held_path`` (either may
    be None), each with its truth sidecars.

    Parameters
    ----------
    robot : Robot
        The robot.
    floor_path, held_path : str or os.PathLike, optional
        The MP4s to write; they and their sidecars must not exist.
    side : str
        The side filmed: ``L`` (the robot's left, the camera at +y) or ``R``.
    fps : int
        Frame rate [1/s].
    width, height : int
        Frame size [px].

    Returns
    -------
    list of PushClip
        Each written clip, the floor's first.

    Raises
    ------
    SimError
        No path, a bad size, side or path, or a push that fails its audit.
    """
    validate_size(fps, width, height)
    side_azimuth_deg(side)
    paths = {kind: None if p is None else check_video_path(p) for kind, p in (("floor", floor_path),
                                                                             ("held", held_path))}
    if not any(paths.values()):
        raise SimError("no push clip to render", "give --push-clip FLOOR.mp4 and/or --push-clip-held HELD.mp4")
    for p in paths.values():
        if p is not None and crank_truth_path(p).exists():
            raise SimError(f"{crank_truth_path(p)} exists already; not overwriting it",
                           "choose another clip name, or move it away")
    check_distinct({f"{kind}{what}": q for kind, p in paths.items() if p is not None
                    for what, q in zip(("", " truth", " camera", " crank"),
                                       (p, *sidecar_paths(p), crank_truth_path(p)))})
    step = frame_step_s(robot, fps)
    return [_record(robot, simulate_push(robot, kind, side, timestep_s=step), p, fps, width, height)
            for kind, p in paths.items() if p is not None]


__all__ = ["AFTER_S", "DEFAULT_FPS", "PushClip", "crank_truth_path", "render_push_clips"]
