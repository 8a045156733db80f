"""Video decoding and clip settings.

Decoding goes through OpenCV's FFmpeg backend. Bad input is caught here, once, and
turned into a :class:`~locust.errors.TrackError` naming the file and frame: a file that
is not a video, a still image, and a video that ends before its header says it should
(truncated by a copy or a full card).

An image sequence is a video too, as Tracker and ffmpeg take it: a folder of images
(sorted by name), or the first file of a numbered run (``shot00.jpg``, ``shot01.jpg``, ...:
the same name with the number counting up by one, as many as follow without a gap).
It has no frame rate of its own: give ``--fps`` (or the ``.trk``'s frame interval).

A frame's time is the video file's own: phones record at a variable frame rate (frames 15 to
50 ms apart in one clip), and their files say when each frame was taken. Each frame's
timestamp is read as it is decoded (:func:`read_frames`, OpenCV's ``CAP_PROP_POS_MSEC``: the
container's presentation time) and :func:`frame_times_s` keeps ``(frame - start) / fps`` where
the timestamps agree with it (a constant-rate file: the stamps are those times rounded to the
file's time base), else takes the timestamps. A rate given with ``--fps`` (or a Tracker
project's frame interval) spaces the frames evenly, so it is refused for a file whose own
frames are not evenly spaced.
"""

from __future__ import annotations

import os
import queue
import re
import threading
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from ..errors import TrackError
from ..fileio import check_encoded, opencv_path, temp_beside, write_target
from ..io.delimited import MAX_LINES
from ..io.trk import FPS_MAX, FPS_MIN

# FFmpeg's own log lines ("moov atom not found" ...) are noise next to our error
# message; OpenCV reads the level when it opens its first capture, not on import.
os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")


@dataclass(frozen=True)
class VideoInfo:
    """A video file or image sequence as probed.

    Attributes
    ----------
    path : Path
        The path probed: a video file, an image folder or a sequence's first image.
    width_px, height_px : int
        Frame size [px].
    frame_count : int
        Frames in it.
    file_fps : float
        The rate the file states [1/s] (0 for an image sequence, or a file that states none).
    images : tuple of Path
        An image sequence's files, in frame order; empty for a video file.
    """

    path: Path
    width_px: int
    height_px: int
    frame_count: int
    file_fps: float
    images: tuple[Path, ...] = ()  # an image sequence's files, in frame order; () for a video file


def check_fps(fps: float | None) -> float | None:
    """``fps`` as given (None: the file's rate), if a camera can film at it.

    Parameters
    ----------
    fps : float or None
        The rate given [1/s].

    Returns
    -------
    float or None
        ``fps`` unchanged.

    Raises
    ------
    TrackError
        A rate outside what cameras film.
    """
    if fps is not None and not FPS_MIN <= fps <= FPS_MAX:
        raise TrackError(f"--fps {fps:g}: a camera films {FPS_MIN:g} to {FPS_MAX:g} frames/s (times are "
                         "frame / fps: a rate outside that makes them all 0, or hours apart)",
                         "give the true frame rate, e.g. --fps 240 for slow-motion footage")
    return fps


@dataclass(frozen=True)
class Clip:
    """Which frames to read and what time they are.

    ``end`` is inclusive (like Tracker's end frame); ``None`` means the last frame.
    ``fps`` overrides the file's rate (slow-motion footage is often stored at 30 fps
    while filmed at 240 fps). Time is ``t_s = (frame - start) / fps``, zero at the
    clip's first frame, as in Tracker, where the video's own timestamps agree
    (:func:`frame_times_s`); ``fps_given`` (set by :meth:`resolved`) says the rate was given.
    """

    start: int = 0
    end: int | None = None
    step: int = 1
    fps: float | None = None
    fps_given: bool = False

    def resolved(self, info: VideoInfo) -> Clip:
        """The clip on ``info``: ``end`` and ``fps`` filled in, every setting checked.

        Parameters
        ----------
        info : VideoInfo
            The probed video.

        Returns
        -------
        Clip
            With ``end`` and ``fps`` set.

        Raises
        ------
        TrackError
            A step below 1, a start or end outside the video, or no usable frame rate.
        """
        last = info.frame_count - 1
        end = last if self.end is None else self.end
        fps = self.fps if self.fps is not None else info.file_fps
        if self.step < 1:
            raise TrackError(f"--step {self.step}: the step must be 1 or more", "use --step 1 to read every frame")
        if not 0 <= self.start <= last:
            raise TrackError(f"--start {self.start} is outside {info.path.name} (frames 0..{last})",
                             f"choose a start frame between 0 and {last}")
        if not self.start <= end <= last:
            raise TrackError(f"--end {end} is outside frames {self.start}..{last} of {info.path.name}",
                             f"choose an end frame between {self.start} and {last}")
        if info.images and self.fps is None:
            raise TrackError(f"{info.path.name}: an image sequence has no frame rate",
                             "give it with --fps (e.g. --fps 10.1 for frames 99 ms apart), or use "
                             "--calibration-from the Tracker project that opens it")
        check_fps(self.fps)
        if not (fps and np.isfinite(fps) and FPS_MIN <= fps <= FPS_MAX):
            raise TrackError(f"{info.path.name} has no usable frame rate ({fps!r}; a camera films "
                             f"{FPS_MIN:g} to {FPS_MAX:g} frames/s)",
                             "give the real frame rate with --fps, e.g. --fps 240")
        frames = len(range(self.start, end + 1, self.step))
        if frames > MAX_LINES:
            raise TrackError(f"frames {self.start}..{end} step {self.step} of {info.path.name} are {frames:,} frames, "
                             f"more than a track file holds ({MAX_LINES:,} rows: 14 minutes at 240 frames/s)",
                             "track the part of the clip the hops are in (--start, --end), or every few frames "
                             "(--step)")
        return Clip(self.start, end, self.step, float(fps), self.fps_given or self.fps is not None)

    def frames(self) -> range:
        """The frame numbers of a resolved clip.

        Returns
        -------
        range
            From ``start`` to ``end`` inclusive, by ``step``.
        """
        assert self.end is not None, "resolve the clip first"
        return range(self.start, self.end + 1, self.step)

    def time_s(self, frame: int) -> float:
        """A frame's time in a resolved clip, zero at its first frame.

        Parameters
        ----------
        frame : int
            The frame number.

        Returns
        -------
        float
            ``(frame - start) / fps`` [s].
        """
        assert self.fps is not None, "resolve the clip first"
        return (frame - self.start) / self.fps


# Timestamps within a quarter of a frame of (frame - start) / fps are that rate's, rounded to the
# file's time base (a millisecond in Matroska is a quarter of a frame at 240 frames/s); more is
# a frame taken at another time.
EVEN_WITHIN_FRAMES = 0.25
TIMES_EVEN = "t_s = (frame - start) / fps"
TIMES_FROM_FILE = ("t_s = the frame's timestamp in the video file less the start frame's (its frames are not "
                   "evenly spaced: a variable frame rate)")


@dataclass(frozen=True)
class FrameTimes:
    """The times of a clip's frames, and the rule that gave them.

    Attributes
    ----------
    t_s : ndarray
        One per frame of the clip, zero at its first [s].
    rule : str
        :data:`TIMES_EVEN` or :data:`TIMES_FROM_FILE`.
    """

    t_s: np.ndarray
    rule: str

    @property
    def from_file(self) -> bool:
        """Whether the times are the video file's timestamps (its frames not evenly spaced)."""
        return self.rule == TIMES_FROM_FILE


def frame_times_s(info: VideoInfo, clip: Clip, frames, stamps_s: dict[int, float]) -> FrameTimes:
    """The times of ``frames`` of a resolved ``clip`` of ``info``, zero at the clip's start,
    as the video file states them (see the module doc).

    Parameters
    ----------
    info : VideoInfo
        The probed video.
    clip : Clip
        The resolved clip.
    frames : sequence of int
        Its frames, in order (the first is ``clip.start``).
    stamps_s : dict of int to float
        Each frame's timestamp in the file [s], as :func:`read_frames` reads it (empty for an
        image sequence, which has none).

    Returns
    -------
    FrameTimes
        ``(frame - start) / fps`` where the file's timestamps agree within
        :data:`EVEN_WITHIN_FRAMES` of a frame, else the timestamps.

    Raises
    ------
    TrackError
        Timestamps that do not increase (a damaged file), or a rate given (``--fps``, a
        Tracker project's) for a file whose frames are not evenly spaced.
    """
    frames = np.asarray(frames, dtype=int)
    even = FrameTimes((frames - clip.start) / clip.fps, TIMES_EVEN)
    if info.images or len(frames) < 2 or any(int(f) not in stamps_s for f in frames):
        return even
    stamps = np.array([stamps_s[int(f)] for f in frames])
    if np.all(stamps == stamps[0]):
        return even   # the file states no times (every frame at 0): frame / fps is all there is
    back = np.flatnonzero(np.diff(stamps) <= 0)
    if back.size:
        k = int(back[0])
        raise TrackError(f"{info.path}: frame {frames[k + 1]} is stamped {stamps[k + 1]:.4f} s, not after frame "
                         f"{frames[k]} ({stamps[k]:.4f} s): the file's clock is damaged, so no frame's time can be "
                         "trusted", "re-copy the video from the camera, or convert it to a constant frame rate "
                         "(e.g. ffmpeg -i IN.mp4 -vf fps=60 OUT.mp4) and track that")
    stamped = stamps - stamps[0]
    if not clip.fps_given:
        off = np.abs(stamped - even.t_s)
        return even if off.max() <= EVEN_WITHIN_FRAMES / clip.fps else FrameTimes(stamped, TIMES_FROM_FILE)
    # a given rate spaces the frames evenly: the file's own must be, at whatever rate it states
    own = (frames - frames[0]) * (stamped[-1] / (frames[-1] - frames[0]))
    off = np.abs(stamped - own)
    interval_s = stamped[-1] / (frames[-1] - frames[0])
    if off.max() > EVEN_WITHIN_FRAMES * interval_s:
        k = int(np.argmax(off))
        gaps_ms = np.diff(stamped) / (np.diff(frames)) * 1000
        raise TrackError(f"{info.path}: a rate of {clip.fps:g} frames/s (--fps, or the Tracker project's frame "
                         "interval) spaces the frames evenly, but the file's own are not: they are "
                         f"{gaps_ms.min():.1f} to {gaps_ms.max():.1f} ms apart, frame {frames[k]} stamped "
                         f"{stamped[k]:.3f} s after frame {frames[0]}, {off[k] * 1000:.0f} ms off even spacing "
                         "(a variable frame rate, as phones record)",
                         "leave out --fps: the file's own timestamps are then the frames' times")
    return even


IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".gif")


def image_sequence(path: Path) -> tuple[Path, ...]:
    """The files of the image sequence ``path`` names (a folder, or the first file of a
    numbered run), in frame order; ``()`` when ``path`` is not an image sequence.

    Parameters
    ----------
    path : Path
        A folder or a file.

    Returns
    -------
    tuple of Path
        The frames' files.
    """
    if path.is_dir():
        return tuple(sorted(p for p in path.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES))
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        return ()
    m = re.fullmatch(r"(.*?)(\d+)", path.stem)
    if not m:
        return (path,)
    head, digits = m.groups()
    files, number = [], int(digits)
    while True:
        name = f"{head}{number:0{len(digits)}d}{path.suffix}"
        candidate = path.with_name(name)
        if not candidate.is_file():
            break
        files.append(candidate)
        number += 1
    return tuple(files)


def read_as_frame(info: VideoInfo, path: Path) -> bool:
    """Whether a file at ``path`` is a frame of the image sequence ``info``, or would be read as
    one by the next run on it: a file of its folder with an image suffix (a folder sequence), or
    its numbered name with another number (``shot07.jpg`` after ``shot00.jpg``). False for a
    video file.

    Parameters
    ----------
    info : VideoInfo
        The probed video or sequence.
    path : Path
        A file about to be written.

    Returns
    -------
    bool
        True when it would be read as a frame.
    """
    if not info.images:
        return False
    path = Path(os.path.abspath(path))
    if path.resolve() in {p.resolve() for p in info.images}:
        return True
    if info.path.is_dir():
        return path.parent.resolve() == info.path.resolve() and path.suffix.lower() in IMAGE_SUFFIXES
    m = re.fullmatch(r"(.*?)(\d+)", info.path.stem)
    return bool(m and path.parent.resolve() == info.path.resolve().parent and path.suffix == info.path.suffix
                and re.fullmatch(re.escape(m[1]) + r"\d+", path.stem))


def _imread(path: Path) -> np.ndarray | None:
    """One image, BGR (None: not readable as one), by a name OpenCV can take."""
    with opencv_path(path) as name:
        return cv2.imread(name, cv2.IMREAD_COLOR)


def _probe_images(path: Path, files: tuple[Path, ...]) -> VideoInfo:
    if len(files) < 2:
        raise TrackError(f"{path}: a single image, not a video or an image sequence",
                         "give a video file, a folder of frames, or the first file of a numbered run "
                         "(shot00.jpg, shot01.jpg, ...)")
    first = _imread(files[0])
    if first is None:
        raise TrackError(f"{files[0]}: not a readable image", "check the file opens in an image viewer")
    h, w = first.shape[:2]
    return VideoInfo(path, w, h, len(files), 0.0, files)


def probe(path: str | os.PathLike) -> VideoInfo:
    """Open ``path`` (a video file, or an image sequence: see the module doc) and read its
    size, frame count and rate (0 for an image sequence), or raise TrackError.

    Parameters
    ----------
    path : str or os.PathLike
        The video file, image folder or first image.

    Returns
    -------
    VideoInfo
        Its size [px], frame count and rate [1/s].

    Raises
    ------
    TrackError
        A missing, empty or unreadable file, a still image, or a folder without images.
    """
    path = Path(path)
    files = image_sequence(path) if path.exists() else ()
    if files or path.is_dir():
        if not files:
            raise TrackError(f"{path}: a folder without images", "give a folder of numbered frames, or a video file")
        return _probe_images(path, files)
    if not path.is_file():
        raise TrackError(f"{path}: no such file", "check the path of the video")
    if path.stat().st_size == 0:
        raise TrackError(f"{path}: the file is empty", "copy the video again from the camera")
    with opencv_path(path) as name:
        cap = cv2.VideoCapture(name)
    try:
        if not cap.isOpened():
            if zipfile.is_zipfile(path):   # (a Tracker project zip is opened as a project, before this)
                raise TrackError(f"{path}: a zip archive, not a video, and not a Tracker project (no .trk in it)",
                                 f"unpack it (unzip {path.name} -d frames) and give the video in it, or the folder "
                                 "of its frames with --fps")
            raise TrackError(f"{path}: not a readable video (FFmpeg could not open it; "
                             "it is not a video, or a damaged or truncated one)",
                             "check the file plays in a video player; re-copy it from the camera")
        count = cap.get(cv2.CAP_PROP_FRAME_COUNT)
        info = VideoInfo(path, int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)),
                         int(count) if 0 < count < 1e9 else 0, float(cap.get(cv2.CAP_PROP_FPS) or 0.0))
    finally:
        cap.release()
    if info.frame_count < 2 or info.width_px <= 0:
        raise TrackError(f"{path}: not a video (it has {max(info.frame_count, 0)} frames; a still image?)",
                         "give a video file (mp4, avi, mov) of the hop")
    return info


def read_frames(info: VideoInfo, clip: Clip, prefetch: int = 8,
                stamps_s: dict[int, float] | None = None) -> Iterator[tuple[int, np.ndarray]]:
    """Yield ``(frame_index, bgr_image)`` for every frame of a resolved ``clip``.

    Frames are decoded in order (seeking is inexact in many codecs); skipped frames are
    grabbed without conversion. Decoding runs in a thread ``prefetch`` frames ahead of
    the caller (OpenCV releases the GIL while it decodes), so tracking a frame overlaps
    decoding the next ones. Raises TrackError if the file ends early.

    Parameters
    ----------
    info : VideoInfo
        The probed video.
    clip : Clip
        The resolved clip.
    prefetch : int
        Frames decoded ahead.
    stamps_s : dict of int to float, optional
        Filled, frame by frame before each is yielded, with its timestamp in the video file
        [s] (a video file's presentation time; an image sequence has none): what
        :func:`frame_times_s` takes.

    Yields
    ------
    frame : int
        The frame number.
    image : ndarray
        The frame, BGR.
    """
    out: queue.Queue = queue.Queue(maxsize=max(prefetch, 1))
    stop = threading.Event()

    def put(item) -> bool:
        while not stop.is_set():
            try:
                out.put(item, timeout=0.1)
                return True
            except queue.Full:
                continue
        return False

    def decode_images() -> None:
        for frame in clip.frames():
            image = _imread(info.images[frame]) if frame < len(info.images) else None
            if image is None or image.shape[:2] != (info.height_px, info.width_px):
                put(_EndedEarly(frame))
                return
            if not put((frame, image)):
                return
        put(None)

    def decode() -> None:
        if info.images:
            return decode_images()
        with opencv_path(info.path) as name:
            cap = cv2.VideoCapture(name)
        try:
            index = 0
            for frame in clip.frames():
                while index < frame:
                    if not cap.grab():
                        put(_EndedEarly(index))
                        return
                    index += 1
                ok, image = cap.read()
                if not ok or image is None:
                    put(_EndedEarly(index))
                    return
                index += 1
                if stamps_s is not None:
                    stamps_s[frame] = cap.get(cv2.CAP_PROP_POS_MSEC) / 1000.0
                if not put((frame, image)):
                    return
            put(None)
        finally:
            cap.release()

    worker = threading.Thread(target=decode, name=f"decode {info.path.name}", daemon=True)
    worker.start()
    try:
        while True:
            item = out.get()
            if item is None:
                return
            if isinstance(item, _EndedEarly):
                _ended_early(info, item.index)
            yield item
    finally:
        stop.set()
        worker.join()


@dataclass(frozen=True)
class _EndedEarly:
    index: int


def read_frame(info: VideoInfo, frame: int) -> np.ndarray:
    """One decoded frame (for overlays and calibration).

    Parameters
    ----------
    info : VideoInfo
        The probed video.
    frame : int
        The frame number.

    Returns
    -------
    ndarray
        The frame, BGR.

    Raises
    ------
    TrackError
        The frame cannot be read.
    """
    for _, image in read_frames(info, Clip(frame, frame, 1, 1.0)):
        return image
    raise TrackError(f"{info.path}: frame {frame} could not be read")  # pragma: no cover


def _ended_early(info: VideoInfo, index: int) -> None:
    if info.images:
        raise TrackError(f"{info.images[index]}: not readable, or not {info.width_px}x{info.height_px} "
                         "like the first image of the sequence",
                         f"replace that frame, or track the frames before it with --end {max(index - 1, 0)}")
    raise TrackError(f"{info.path}: decoding stopped at frame {index}, but the file says it has "
                     f"{info.frame_count} frames: the video is truncated or damaged",
                     f"re-copy the file, or track the readable part with --end {max(index - 1, 0)}")


def encode_video(path: Path, frames, fps: float, size: tuple[int, int], fourcc: str = "mp4v") -> Path:
    """Encode ``frames`` (an iterable of BGR images) to ``path`` atomically.

    Parameters
    ----------
    path : Path
        The video to write.
    frames : iterable of ndarray
        BGR images of ``size``.
    fps : float
        Frame rate [1/s].
    size : tuple of int
        (width, height) [px].
    fourcc : str
        The codec's four-character code.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    TrackError
        OpenCV cannot open an encoder for it.
    WriteError
        The written video does not read back whole.
    """
    path = Path(path)
    target = write_target(path)   # a link in the folder: its target; one out of it: refused
    fd, tmp = temp_beside(target, suffix=path.suffix)
    os.close(fd)
    with opencv_path(tmp) as name:
        writer = cv2.VideoWriter(name, cv2.VideoWriter_fourcc(*fourcc), fps, size)
    if fourcc == "MJPG":
        writer.set(cv2.VIDEOWRITER_PROP_QUALITY, 90)
    try:
        if not writer.isOpened():
            raise TrackError(f"OpenCV cannot encode {fourcc} to {path}",
                             "check the folder is writable and the codec name")
        written = 0
        for frame in frames:
            writer.write(frame)
            written += 1
        writer.release()
        check_encoded(tmp, written, path)
        os.replace(tmp, target)
    except BaseException:
        writer.release()
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
