"""Side-by-side videos (``locust report --side-by-side``): each filmed hop beside the
simulation of its configuration, filmed by the same camera, on the schedule's clock.

For every measured trial with a video and a track the report writes
``<trial>.side_by_side.webm``: left the filmed frames as they are, right the configuration's
simulation rendered at the same size, one output frame per filmed frame, at the file's own
frame rate. A caption on each half says which it is and the frame's time on the schedule's
clock. The page plays each beside it (``<video controls>``, a relative src): VP8 in WebM is
what every browser decodes and this OpenCV encodes at the pace of rendering (MPEG-4 Part 2, the
``mp4v`` of other videos here, no browser plays; VP9 in MP4 takes 60 ms to encode a
1280x360 frame on a laptop core, three times the rendering, where VP8 takes 14 ms).

- **Video**: ``<stem>.mp4`` (or .mov, .avi, .mkv, .m4v) beside the track (``hop.tracks.csv``
  -> ``hop.mp4``), else ``hop.mp4`` in the trial's folder (the track's, else the run record's).
- **Clock**: the track's own ``frame`` and ``t_s`` columns give each video frame's time on
  the track's clock (a track without frame numbers: frame 0 at t = 0, the file's rate); the
  report has put the first push at ``start_s`` on that clock (:func:`.measure.align`, the
  same rule for the measured trace and the prediction), so frame k shows
  ``t = t_track(k) - start_s``. The simulation half shows the rollout the prediction comes
  from (:func:`.predict.predict` with its states kept) at that same t: before the first push
  the robot stands as the settle phase left it (the settle phase itself, the model dropping
  onto its feet, is not shown), after the last cycle it holds its final pose.
- **Camera**: ``<video stem>.camera.json`` (what a simulated video was rendered with: the
  virtual robot's ``locust hop --video``, ``locust sim --video``) gives the simulation the
  filmed camera's intrinsics and pose, per frame for a camera that follows the robot
  (:class:`locust.sim.clip.PoseRenderer`). Without one (a real camera), the simulation is
  filmed by its own fixed camera framed on its hops (:func:`locust.sim.camera.frame_views`)
  at the video's size; the caption and ``report.json`` say the cameras differ, so the halves
  compare motion and timing, not pixels.

The simulation is rendered without shadows, as the virtual robot's video is. Planning
(:func:`plan_side_by_side`: videos probed, cameras read) happens before the report's folder
is made; :func:`write_side_by_side` renders into it, each video atomically, never over a file.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..errors import ReportError, TrackError
from ..io.camera_json import CameraFile, camera_json_beside, read_camera_json
from ..io.tracks_csv import TRACKS_CSV_SUFFIX, TracksCsv, read_track_file
from ..progress import progress
from ..track.export import sidecar_video
from ..track.video import Clip, VideoInfo, encode_video, probe, read_frames
from ..trials.measured import Trial
from .compare import Comparison

SUFFIX = ".side_by_side.webm"
FOURCC = "VP80"                      # VP8: in WebM, every browser plays it (module docstring)
VIDEO_SUFFIXES = (".mp4", ".mov", ".avi", ".mkv", ".m4v")
FOLDER_VIDEO = "hop.mp4"            # what `locust hop --video` is given in a trial folder (locust demo)
OWN_CAMERA = "simulation's fixed camera"
FONT = cv2.FONT_HERSHEY_SIMPLEX


@dataclass(frozen=True)
class Job:
    """One side-by-side video to render, every input checked.

    Attributes
    ----------
    comparison : Comparison
        The trial's configuration.
    measured : Trial
        The trial, its track aligned to the schedule.
    video : VideoInfo
        The filmed video.
    camera : CameraFile or None
        The filmed camera; None: the simulation's own.
    camera_note : str
        Where the camera comes from, or why not from the video.
    frame0 : float
        The frame at t = 0 on the track's clock: ``t_track = (frame - frame0) / fps`` [frames].
    fps : float
        Frames per second of the track's clock [1/s].
    name : str
        The file it is written to in the report's folder (``<trial>.side_by_side.webm``).
    """

    comparison: Comparison
    measured: Trial
    video: VideoInfo
    camera: CameraFile | None        # the filmed camera; None: the simulation's own
    camera_note: str                 # where the camera comes from, or why not from the video
    frame0: float                    # track clock: t_track = (frame - frame0) / fps
    fps: float
    name: str = ""                   # its file in the report's folder, chosen when planned

    @property
    def label(self) -> str:
        """The trial's label."""
        return self.measured.label

    def t_s(self, frame: int) -> float:
        """Frame ``frame``'s time on the schedule's clock (t = 0 at the first push).

        Parameters
        ----------
        frame : int
            A video frame number.

        Returns
        -------
        float
            Its time [s].
        """
        return (frame - self.frame0) / self.fps - self.measured.trace.start_s


@dataclass(frozen=True)
class SideBySide:
    """What became of one trial: its video written, or why not.

    Attributes
    ----------
    config : str
        The configuration.
    trial : str
        The trial's label.
    video : Path or None
        The filmed video.
    path : Path or None
        The side-by-side video (None: skipped).
    camera : str or None
        ``camera.json`` (the filmed camera) or the simulation's own fixed camera.
    note : str
        Where the camera comes from, or why the trial was skipped.
    frames : int
        Frames written.
    fps : float
        Frame rate of the written video [1/s].
    width_px, height_px : int
        Its size (both halves) [px].
    t0_s : float
        The first frame's time on the schedule's clock [s].
    """

    config: str
    trial: str
    video: Path | None               # the filmed video
    path: Path | None                # the side-by-side video (None: skipped)
    camera: str | None               # "camera.json" (the filmed camera) or OWN_CAMERA
    note: str
    frames: int = 0
    fps: float = math.nan
    width_px: int = 0
    height_px: int = 0
    t0_s: float = math.nan           # the first frame's time on the schedule's clock

    def to_json(self) -> dict:
        """The fields as a JSON object.

        Returns
        -------
        dict
            Each field by name, paths as text.
        """
        return {k: str(v) if isinstance(v, Path) else v for k, v in self.__dict__.items()}


# -- planning: what to render, checked before anything is written ----------------------
@dataclass(frozen=True)
class Plan:
    """The side-by-side videos to render, and the trials that get none.

    Attributes
    ----------
    jobs : list of Job
        To render.
    skipped : list of SideBySide
        No track, no video or no valid simulation, and why.
    """

    jobs: list[Job]                  # to render
    skipped: list[SideBySide]        # no track, no video or no valid simulation, and why


def plan_side_by_side(comps: list[Comparison]) -> Plan:
    """The trials to render and those skipped; an unreadable video stops here (ReportError).

    Parameters
    ----------
    comps : list of Comparison
        The report's configurations.

    Returns
    -------
    Plan
        The jobs, their videos probed and cameras read, and the skipped trials.

    Raises
    ------
    ReportError
        A video that cannot be probed, or one with no frame rate and a track without frame numbers.
    """
    jobs, skipped = [], []
    taken: set[str] = set()
    for c in comps:
        measured = {id(m): m for m in c.trials}
        for trial in c.all_trials:
            m = measured.get(id(trial))
            video = find_video(trial)
            why = ("no track: the first push is found in the track" if m is None
                   else "no video beside its track, nor hop.mp4 in its folder" if video is None
                   else "the simulation failed its audit: nothing to render" if not c.prediction.valid
                   else None)
            if why is not None:
                skipped.append(SideBySide(c.config, trial.label, video, None, None, why))
                continue
            info = _probe(video)
            camera, note = filmed_camera(info)
            frame0, fps = frame_clock(m.track.path, info)
            jobs.append(Job(c, m, info, camera, note, frame0, fps, _name(c.config, trial.label, taken)))
    return Plan(jobs, skipped)


def find_video(trial) -> Path | None:
    """The trial's filmed video: beside its track (``x.tracks.csv`` -> ``x.mp4``), else the
    one its track's sidecar records (``locust track`` writes into an output folder, often
    away from the video), else ``hop.mp4`` in its folder.

    Parameters
    ----------
    trial : Trial
        A measured trial.

    Returns
    -------
    Path or None
        The video; None when there is none.
    """
    folders = []
    if trial.track is not None:
        track = trial.track.path
        stem = track.name[: -len(TRACKS_CSV_SUFFIX)] if track.name.endswith(TRACKS_CSV_SUFFIX) else track.stem
        for suffix in VIDEO_SUFFIXES:
            if (track.parent / (stem + suffix)).is_file():
                return track.parent / (stem + suffix)
        recorded = sidecar_video(track)
        if recorded is not None:
            return recorded
        folders.append(track.parent)
    if trial.run_path is not None:
        folders.append(trial.run_path.parent)
    return next((f / FOLDER_VIDEO for f in folders if (f / FOLDER_VIDEO).is_file()), None)


def _probe(video: Path) -> VideoInfo:
    try:
        return probe(video)
    except TrackError as exc:
        raise ReportError(exc.message, exc.hint) from None


def filmed_camera(info: VideoInfo) -> tuple[CameraFile | None, str]:
    """The camera the video was filmed with (its ``camera.json``), or None and why not.

    Parameters
    ----------
    info : VideoInfo
        The probed video.

    Returns
    -------
    camera : CameraFile or None
        The camera, when its file is beside the video, readable and of the video's size.
    note : str
        Where the camera comes from, or why the cameras differ.
    """
    path = camera_json_beside(info.path)
    if not path.is_file():
        return None, f"no {path.name} beside the video: the cameras differ"
    try:
        camera = read_camera_json(path)
    except TrackError as exc:
        return None, f"{exc.message}: the cameras differ"
    if (camera.width_px, camera.height_px) != (info.width_px, info.height_px):
        return None, (f"{path.name} describes a {camera.width_px}x{camera.height_px} camera, the video is "
                      f"{info.width_px}x{info.height_px}: the cameras differ")
    return camera, f"intrinsics and extrinsics of {path.name} ({camera.camera} camera)"


def frame_clock(track_path: Path, info: VideoInfo) -> tuple[float, float]:
    """(frame0, fps) with ``t_track = (frame - frame0) / fps`` for the track's video frames:
    fitted to the track's ``frame`` and ``t_s`` columns; without frame numbers (a Tracker
    export, a plain ``t,x,y`` CSV), frame 0 at t = 0 at the file's rate.

    Parameters
    ----------
    track_path : Path
        The trial's track file.
    info : VideoInfo
        The probed video.

    Returns
    -------
    frame0 : float
        The frame at t = 0 on the track's clock [frames].
    fps : float
        Frames per second [1/s].

    Raises
    ------
    ReportError
        Neither the track's frame numbers nor the file give a frame rate.
    """
    try:
        tracks = read_track_file(track_path)
    except TrackError:
        tracks = None        # a layout only the report's import reads: it has no frame numbers
    if isinstance(tracks, TracksCsv) and tracks.header is not None and "frame" in tracks.header:
        t, f = tracks.t_s.astype(float), tracks.frame.astype(float)
        ok = np.isfinite(t)
        if ok.sum() >= 2 and np.ptp(t[ok]) > 0:
            fps, frame0 = np.polyfit(t[ok], f[ok], 1)
            if fps > 0:
                return float(frame0), float(fps)
    if not (info.file_fps > 0):
        raise ReportError(f"{info.path}: no frame rate, and {track_path} has no frame numbers",
                          "track the video with `locust track` (its CSV numbers the frames)")
    return 0.0, float(info.file_fps)


# -- rendering -----------------------------------------------------------------------
def write_side_by_side(plan: Plan, folder: Path, say: Callable[[str], None] | None = None) -> list[SideBySide]:
    """Render every job into ``folder`` (its ``name``, ``<trial>.side_by_side.webm``, never over a file);
    what became of each trial, the skipped ones (said on ``say``) last.

    Parameters
    ----------
    plan : Plan
        From :func:`plan_side_by_side`.
    folder : Path
        The report's folder.
    say : callable, optional
        Called with a line of text per trial.

    Returns
    -------
    list of SideBySide
        The written videos, then the skipped trials.

    Raises
    ------
    ReportError
        A file of that name exists, or the video cannot be encoded.
    """
    say = say or (lambda msg: None)
    out = []
    for job in plan.jobs:
        path = folder / job.name
        if path.exists():
            raise ReportError(f"{path} exists already; not overwriting it", "write the report into a new folder")
        say(f"side by side: {job.label} ({job.video.frame_count} frames; simulation: "
            f"{job.camera_note if job.camera else OWN_CAMERA + ', ' + job.camera_note})")
        try:
            encode_video(path, _frames(job), float(job.video.file_fps), (2 * job.video.width_px, job.video.height_px),
                         fourcc=FOURCC)
        except TrackError as exc:
            raise ReportError(exc.message, exc.hint) from None
        frames = probe(path).frame_count
        out.append(SideBySide(job.comparison.config, job.label, job.video.path, path,
                              "camera.json" if job.camera else OWN_CAMERA, job.camera_note, frames,
                              float(job.video.file_fps), 2 * job.video.width_px, job.video.height_px, job.t_s(0)))
    for s in plan.skipped:
        say(f"side by side: {s.trial} skipped ({s.note})")
    return out + plan.skipped


def _name(config: str, label: str, taken: set[str]) -> str:
    """``<trial>.side_by_side.webm``; ``<config>-<trial>...`` when two trials share a label."""
    stem = label if label not in taken else f"{config}-{label}"
    base, n = stem, 2
    while stem in taken:
        stem, n = f"{base}-{n}", n + 1
    taken.add(stem)
    return stem + SUFFIX


def _frames(job: Job) -> Iterator[np.ndarray]:
    """Filmed frame beside simulated frame, captioned, for every frame of the video."""
    from ..sim.clip import PoseRenderer
    from ..sim.run import run

    pred = job.comparison.prediction
    traj = pred.trajectory or run(pred.robot, cycles=job.comparison.cycles, keep_states=True).trajectory
    info = job.video
    w, h = info.width_px, info.height_px
    cameras = filmed_pinholes(job.camera) if job.camera else [own_view(traj, pred.robot, w / h)]
    nq, dt = traj.built.model.nq, traj.timestep_s
    stand, last = max(traj.plan.settle_steps - 1, 0), len(traj.states) - 1
    own = "" if job.camera else " (own camera)"
    poser = PoseRenderer(traj.built.model, w, h, shadows=False)
    try:
        with progress(length=info.frame_count, label=f"side by side {job.label}") as bar:
            for k, filmed in read_frames(info, Clip().resolved(info)):
                t = job.t_s(k)
                # state row i is the state after step i + 1: t = (i + 1 - settle) dt on the schedule's clock
                row = min(max(int(round(t / dt)) + traj.plan.settle_steps - 1, stand), last)
                poser.pose(traj.states[row, 1:1 + nq])
                rgb, _ = poser.render(cameras[min(k, len(cameras) - 1)])
                left = _caption(filmed.copy(), f"filmed  t = {t:+.3f} s")
                right = _caption(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR), f"simulated{own}  t = {t:+.3f} s")
                bar.update(1)
                yield np.hstack([left, right])
    finally:
        poser.close()


def filmed_pinholes(camera: CameraFile) -> list:
    """The camera.json as pinhole cameras: one (fixed) or one per video frame (track).

    Parameters
    ----------
    camera : CameraFile
        The filmed camera.

    Returns
    -------
    list of PinholeCamera
        One per recorded position.
    """
    from ..sim.camera import PinholeCamera

    K = camera.K
    return [PinholeCamera(camera.width_px, camera.height_px, float(K[0, 0]), float(K[1, 1]), float(K[0, 2]),
                          float(K[1, 2]), camera.rotation, np.asarray(p, dtype=float))
            for p in camera.positions_m]


def own_view(traj, robot, aspect: float):
    """The simulation's fixed camera framed on its hops (from standing on), as ``render_video``'s.

    Parameters
    ----------
    traj : Trajectory
        The rollout, with its sensor data.
    robot : Robot
        Its robot (the body length sets the margin).
    aspect : float
        Width over height of the frame.

    Returns
    -------
    PinholeCamera
        The fixed camera.
    """
    from ..sim.camera import frame_views

    s, stand = traj.built.sensors, max(traj.plan.settle_steps - 1, 0)
    sd = traj.sensordata[stand:]
    points = np.vstack([sd[:, s.nose_pos], sd[:, s.foot_pos], sd[:, s.chassis_pos], sd[:, s.com_pos]])
    fixed, _ = frame_views(points, sd[:, s.chassis_pos][:, 0], robot.geometry.body_length_m, 0.0,
                           float(traj.built.model.vis.global_.fovy), aspect)
    return fixed


def _caption(image: np.ndarray, text: str) -> np.ndarray:
    """White text on a black box in the top-left corner, sized to the frame."""
    scale = max(0.35, image.shape[0] / 720)
    thick = max(1, round(scale * 1.5))
    (tw, th), base = cv2.getTextSize(text, FONT, scale, thick)
    pad = max(2, round(4 * scale))
    cv2.rectangle(image, (0, 0), (tw + 2 * pad, th + base + 2 * pad), (0, 0, 0), -1)
    cv2.putText(image, text, (pad, pad + th), FONT, scale, (255, 255, 255), thick, cv2.LINE_AA)
    return image


__all__ = ["SUFFIX", "Job", "Plan", "SideBySide", "find_video", "frame_clock", "plan_side_by_side",
           "write_side_by_side"]
