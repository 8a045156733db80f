"""The frame loop: decode each frame of the clip once, let every marker find itself."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import TrackError
from ..io.tracks_csv import TracksCsv
from .calib import Calibration
from .camera import PlaneCalibration
from .color import FrameHSV
from .video import TIMES_EVEN, Clip, VideoInfo, frame_times_s, read_frames


@dataclass(frozen=True)
class TrackResult:
    """What a tracking run found: the tracks file's contents and how they were made.

    ``video`` is None for tracks read from a Tracker project.

    Attributes
    ----------
    tracks : TracksCsv
        Per frame its number and time, per marker its pixels (OpenCV convention), world
        metres (through ``calibration``) and whether it was found: what the tracks CSV holds.
    specs : dict of str to str
        Per marker, its spec (``color:#ff00ff``, ``tracker:<name>`` ...).
    scores : dict of str to ndarray
        Per marker, its model's score per frame (its meaning is the model's).
    calibration : Calibration or PlaneCalibration
        Pixels to metres.
    clip : Clip
        The frames tracked.
    video : VideoInfo or None
        The video tracked.
    source : str
        What made the tracks, for the sidecar.
    times : str
        How ``tracks.t_s`` was found (:func:`.video.frame_times_s`).
    written : tuple of Path
        The files the job wrote, in order (empty until written).
    """

    tracks: TracksCsv
    specs: dict[str, str]
    scores: dict[str, np.ndarray]
    calibration: Calibration | PlaneCalibration
    clip: Clip
    video: VideoInfo | None = None
    source: str = "locust track"
    times: str = TIMES_EVEN
    written: tuple[Path, ...] = ()

    @classmethod
    def from_pixels(cls, frames: np.ndarray, t_s: np.ndarray, px: dict[str, np.ndarray], py: dict[str, np.ndarray],
                    ok: dict[str, np.ndarray], specs: dict[str, str], scores: dict[str, np.ndarray],
                    calibration: Calibration | PlaneCalibration, clip: Clip, video: VideoInfo | None = None,
                    source: str = "locust track", times: str = TIMES_EVEN) -> TrackResult:
        """A result from the markers' pixels, their world metres through ``calibration``.

        Parameters
        ----------
        frames : ndarray
            The frames' numbers.
        t_s : ndarray
            Their times [s].
        px, py : dict of str to ndarray
            Per marker, its position per frame, OpenCV convention [px]; nan where not found.
        ok : dict of str to ndarray
            Per marker, whether it was found on each frame.
        specs, scores, calibration, clip, video, source, times
            As the attributes.

        Returns
        -------
        TrackResult
            Its tracks in pixels and world metres.
        """
        frames = np.asarray(frames, dtype=int)
        world = {m: calibration.to_world(px[m], py[m], m, frames) for m in px}
        tracks = TracksCsv(frame=frames, t_s=t_s, px=px, py=py, x_m={m: w[0] for m, w in world.items()},
                           y_m={m: w[1] for m, w in world.items()},
                           ok={m: np.asarray(ok[m], dtype=bool) for m in px})
        return cls(tracks, specs, scores, calibration, clip, video, source, times)

    def found(self, marker: str) -> int:
        """Number of frames ``marker`` was found on.

        Parameters
        ----------
        marker : str
            One of ``tracks.markers``.

        Returns
        -------
        int
            The count.
        """
        return int(self.tracks.ok[marker].sum())


def track_video(info: VideoInfo, clip: Clip, models: list, calibration: Calibration | PlaneCalibration,
                progress: Callable[[int], None] | None = None, require_found: bool = True) -> TrackResult:
    """Run every marker model over a resolved ``clip`` of the video ``info``.

    ``progress(1)`` is called after each frame. With ``require_found`` a marker that was
    never found anywhere in the clip raises TrackError (nothing is written then). The
    frames' times are the video file's (:func:`.video.frame_times_s`).

    Parameters
    ----------
    info : VideoInfo
        The probed video.
    clip : Clip
        The resolved clip.
    models : list
        The marker models (:func:`.spec.parse_markers`).
    calibration : Calibration or PlaneCalibration
        Pixels to metres.
    progress : callable, optional
        Called with 1 after each frame.
    require_found : bool
        Refuse a marker never found.

    Returns
    -------
    TrackResult
        Every marker's track on the clip's frames.

    Raises
    ------
    TrackError
        A template's key frame outside the clip, or (with ``require_found``) a marker never found.
    """
    frames = np.array(list(clip.frames()), dtype=int)
    n = len(frames)
    for model in models:  # a template's key frame must be read, or nothing can be matched
        key = getattr(model, "key_frame", None)
        if key is not None and key not in clip.frames():
            raise TrackError(f"marker {model.name}: key frame {key} is not in the clip "
                             f"(frames {clip.start}..{clip.end} step {clip.step})",
                             f"start the clip at or before frame {key} with a step that reaches it")
    frame_hsv = FrameHSV()   # colour markers share each frame's HSV picture
    for model in models:
        if hasattr(model, "frame_hsv"):
            model.frame_hsv = frame_hsv
    cols = {m.name: (np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan), np.zeros(n, bool)) for m in models}
    stamps_s: dict[int, float] = {}
    for i, (frame, image) in enumerate(read_frames(info, clip, stamps_s=stamps_s)):
        for model in models:
            det = model.locate(frame, image)
            px, py, score, ok = cols[model.name]
            px[i], py[i], score[i], ok[i] = det.px, det.py, det.score, det.ok
        if progress:
            progress(1)
    if require_found:
        lost = [m for m in models if not cols[m.name][3].any()]
        if lost:
            raise TrackError(
                f"marker(s) never found in frames {clip.start}..{clip.end} of {info.path.name}: "
                + ", ".join(f"{m.name} ({m.spec})" for m in lost),
                "a colour marker is first taken on a round patch at least 3 px across with at least 0.3 of its "
                "colour's chroma (no sticker of that colour in the picture: nothing): `locust track preview VIDEO` "
                "lists the coloured patches of a frame; else check --color-tol, the template point and frame, or "
                "the ArUco id; --marker NAME=SPEC replaces the default nose/foot colours")
    times = frame_times_s(info, clip, frames, stamps_s)
    px, py, scores, ok = ({m: c[k] for m, c in cols.items()} for k in range(4))
    return TrackResult.from_pixels(frames, times.t_s, px, py, ok, {m.name: m.spec for m in models}, scores,
                                   calibration, clip, video=info, times=times.rule)
