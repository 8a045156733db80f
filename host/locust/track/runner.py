"""The frame loop: decode each frame of the clip once, let every marker find itself."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import TrackError
from .calib import Calibration
from .camera import PlaneCalibration
from .color import FrameHSV
from .video import TIMES_EVEN, Clip, VideoInfo, frame_times_s, read_frames


@dataclass
class TrackedMarker:
    """One marker's track over a clip.

    Attributes
    ----------
    name, spec : str
        The marker's name and its spec.
    px, py : ndarray
        Position per frame, OpenCV convention [px]; nan where not found.
    score : ndarray
        The model's score per frame (its meaning is the model's).
    ok : ndarray of bool
        Whether it was found on each frame.
    """

    name: str
    spec: str
    px: np.ndarray
    py: np.ndarray
    score: np.ndarray
    ok: np.ndarray

    def found(self) -> int:
        """Number of frames the marker was found on.

        Returns
        -------
        int
            The count.
        """
        return int(self.ok.sum())


@dataclass
class TrackResult:
    """Tracks of one clip. ``video`` is None for tracks read from a Tracker project."""

    video: VideoInfo | None
    clip: Clip
    frames: np.ndarray
    t_s: np.ndarray
    markers: list[TrackedMarker]
    calibration: Calibration | PlaneCalibration
    source: str = "locust track"
    times: str = TIMES_EVEN        # how ``t_s`` was found (:func:`.video.frame_times_s`)

    def world(self, track: TrackedMarker) -> tuple[np.ndarray, np.ndarray]:
        """A marker's track in world metres through the result's calibration.

        Parameters
        ----------
        track : TrackedMarker
            One of the result's markers.

        Returns
        -------
        x_m, y_m : ndarray
            Position per frame, y up [m].
        """
        return self.calibration.to_world(track.px, track.py, track.name, self.frames)


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
    tracks = [TrackedMarker(m.name, m.spec, *cols[m.name]) for m in models]
    if require_found:
        lost = [t for t in tracks if t.found() == 0]
        if lost:
            raise TrackError(
                f"marker(s) never found in frames {clip.start}..{clip.end} of {info.path.name}: "
                + ", ".join(f"{t.name} ({t.spec})" for t in lost),
                "a colour marker is first taken on a round patch at least 3 px across with at least 0.3 of its "
                "colour's chroma (no sticker of that colour in the picture: nothing): `locust track preview VIDEO` "
                "lists the coloured patches of a frame; else check --color-tol, the template point and frame, or "
                "the ArUco id; --marker NAME=SPEC replaces the default nose/foot colours")
    times = frame_times_s(info, clip, frames, stamps_s)
    return TrackResult(info, clip, frames, times.t_s, tracks, calibration, times=times.rule)
