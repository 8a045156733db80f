"""``locust.track`` and ``locust.read_tracks``: marker tracks from a video or a track file, as a table."""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import TrackError
from ..io import trk as trk_io
from ..io.importing import is_project
from ..io.tracks_csv import TracksCsv


@dataclass(frozen=True, eq=False)
class Tracks:
    """Marker tracks: per frame its time, per marker pixels and world metres (x forward, y up).

    ``tracks`` is the typed file contents (:class:`locust.io.tracks_csv.TracksCsv`);
    ``result`` the tracking run behind them (None for tracks read from a file).
    """

    tracks: TracksCsv
    result: object | None = None     # locust.track.runner.TrackResult: the job's, with the files it wrote

    @property
    def markers(self) -> list[str]:
        """The markers' names, in the file's order."""
        return list(self.tracks.markers)

    def positions(self, marker: str) -> tuple[np.ndarray, np.ndarray]:
        """``marker``'s world x and y, NaN where it was not found.

        Parameters
        ----------
        marker : str
            One of :attr:`markers`.

        Returns
        -------
        x_m, y_m : numpy.ndarray
            Per frame, forward and up [m].
        """
        return self.tracks.positions(marker)

    def to_dataframe(self):
        """One row per frame.

        Returns
        -------
        pandas.DataFrame
            ``frame``, ``t_s``, then per marker ``<name>_px``, ``<name>_py`` (pixels, OpenCV
            convention), ``<name>_x_m``, ``<name>_y_m`` (world metres, NaN without a scale),
            ``<name>_ok`` (found in that frame) and its velocity and acceleration
            ``<name>_vx_m_per_s``, ``<name>_vy_m_per_s``, ``<name>_ax_m_per_s2``,
            ``<name>_ay_m_per_s2`` (Tracker's finite differences, :mod:`locust.derivatives`;
            NaN where a neighbour they need is missing), as in a tracks CSV. A file written
            without the velocity columns has them too, after its own.
        """
        import pandas as pd

        t = self.tracks
        cols = {name: t.column(name) for name in t.columns}
        cols["frame"] = t.frame.copy()
        for name in t.markers:
            if f"{name}_ok" in cols:
                cols[f"{name}_ok"] = t.ok[name].copy()
        for name in t.markers_with_positions():
            for kind, values in t.derived(name).items():
                cols.setdefault(f"{name}_{kind}", values)
        return pd.DataFrame(cols)

    def tidy(self):
        """One row per marker per frame (trackpy's habit), with velocity and acceleration.

        Velocity and acceleration are Tracker's finite differences on the world metres
        (:mod:`locust.derivatives`, the tracks CSV's own columns): ``v[i] = (x[i+1] - x[i-1])
        / (t[i+1] - t[i-1])`` and ``a[i]`` twice the quadratic coefficient of the parabola of
        least squares through frames ``i-2 .. i+2``, at a steady frame rate ``(2 x[i-2] -
        x[i-1] - 2 x[i] - x[i+1] + 2 x[i+2]) / (7 dt²)``; NaN at the ends of the clip and
        wherever a frame they read (the frame itself included) lost the marker.

        Returns
        -------
        pandas.DataFrame
            ``frame``, ``t_s``, ``marker``, ``x_px``, ``y_px`` (OpenCV pixels), ``x_m``, ``y_m``,
            ``ok``, ``vx_m_per_s``, ``vy_m_per_s``, ``ax_m_per_s2``, ``ay_m_per_s2``.
        """
        import pandas as pd

        t, parts = self.tracks.t_s, []
        tr = self.tracks
        for name in tr.markers_with_positions():
            x, y = tr.positions(name)
            parts.append(pd.DataFrame({
                "frame": tr.frame, "t_s": t, "marker": name, "x_px": tr.px[name], "y_px": tr.py[name], "x_m": x,
                "y_m": y, "ok": tr.ok[name], **tr.derived(name)}))
        if not parts:
            return pd.DataFrame(columns=["frame", "t_s", "marker", "x_px", "y_px", "x_m", "y_m", "ok", "vx_m_per_s",
                                         "vy_m_per_s", "ax_m_per_s2", "ay_m_per_s2"])
        return pd.concat(parts, ignore_index=True).sort_values(["frame", "marker"], kind="stable",
                                                               ignore_index=True)

    def plot(self):
        """Each marker's world x and y [mm] against time [s].

        Returns
        -------
        matplotlib.figure.Figure
        """
        from matplotlib.figure import Figure

        fig = Figure(figsize=(7, 3.5), layout="constrained")
        ax_x, ax_y = fig.subplots(1, 2)
        for name in self.markers:
            x, y = self.positions(name)
            ax_x.plot(self.tracks.t_s, x * 1000, ".-", ms=3, label=name)
            ax_y.plot(self.tracks.t_s, y * 1000, ".-", ms=3, label=name)
        for ax, what in ((ax_x, "x (forward)"), (ax_y, "y (up)")):
            ax.set_xlabel("t [s]")
            ax.set_ylabel(f"{what} [mm]")
        ax_x.legend(fontsize=8)
        return fig

    def write(self, path: str | Path, overwrite: bool = False) -> Path:
        """Write the tracks CSV (atomic; an existing file only with ``overwrite``).

        Parameters
        ----------
        path : path-like
            The CSV to write.
        overwrite : bool, default False
            Replace an existing file; otherwise it is refused.

        Returns
        -------
        pathlib.Path
            The file written.

        Raises
        ------
        locust.errors.TrackError
            ``path`` exists and ``overwrite`` is False.
        """
        from ..io.tracks_csv import write_tracks_csv

        path = Path(path)
        if path.exists() and not overwrite:
            raise TrackError(f"{path} exists already; not overwriting it", "choose another name, or overwrite=True")
        return write_tracks_csv(path, self.tracks)

    def __repr__(self) -> str:
        t = self.tracks
        lines = [f"Tracks: {t.n_rows} frames, markers {', '.join(t.markers) or 'none'}"]
        for name, ok in t.ok.items():
            lines.append(f"  {name}: found in {int(np.count_nonzero(ok))} of {len(ok)} frames")
        return "\n".join(lines)


def _marker_specs(markers: Mapping[str, str] | Sequence[str] | None) -> list[str]:
    from ..track.spec import default_specs

    if markers is None:
        return default_specs()
    if isinstance(markers, Mapping):
        return [f"{name}={spec}" for name, spec in markers.items()]
    return list(markers)


def _calibration(info, scale, origin, angle_deg: float, camera_json, pixels: str = "tracker"):
    from ..io.camera_json import camera_json_beside
    from ..track import calib, camera

    if camera_json is not None and (scale or origin):
        raise TrackError("give camera_json or scale/origin, not both", "one calibration per run")
    if camera_json is not None:
        return camera.load(camera_json, info.width_px, info.height_px)
    beside = camera_json_beside(info.path)
    if scale is None and origin is None and beside.is_file():
        return camera.load(beside, info.width_px, info.height_px)
    m_per_px, source = float("nan"), "none"
    if scale is not None:
        x1, y1, x2, y2, length_m = (float(v) for v in scale)
        m_per_px, source = calib.m_per_px_from_stick(x1, y1, x2, y2, length_m), f"stick {tuple(scale)}"
    return calib.build(info.height_px, m_per_px, calib.typed_px(*origin, pixels) if origin is not None else None,
                       angle_deg, source)


def track_markers(video: str | Path, markers: Mapping[str, str] | Sequence[str] | None = None, *,
          scale: tuple[float, float, float, float, float] | None = None, origin: tuple[float, float] | None = None,
          angle_deg: float = 0.0, camera_json: str | Path | None = None, start: int = 0, end: int | None = None,
          step: int = 1, fps: float | None = None, color_tol: int = 80, search_px: int = 40,
          pixels: str = "tracker", calibration_from: str | Path | None = None, trk: str | Path | None = None,
          overwrite: bool = False, progress: Callable[[int], None] | None = None) -> Tracks:
    """Find markers in every frame of a video (or an image sequence), as Tracker's autotracker would.

    Parameters
    ----------
    video : path-like
        An MP4 (or the first image of a numbered sequence), or a Tracker project (``.trk``,
        ``.trz``) that opens one: its calibration and frame rate are then used.
    markers : dict, optional
        Name -> spec: ``color:#RRGGBB[@X,Y]``, ``template:X,Y@FRAME`` or ``aruco:ID``.
        Default: the robot's nose (``#ff00ff``) and foot (``#00ffff``) colours.
    scale : (x1, y1, x2, y2, length_m), optional
        A calibration stick: two pixels and the distance between them in metres.
    origin : (x, y), optional
        The world origin in pixels (default the centre of the bottom-left pixel).
    angle_deg : float, default 0
        Direction of the world x axis, degrees counter-clockwise from the image's.
    camera_json : path-like, optional
        The pinhole camera of a simulated video; default ``<video>.camera.json`` beside it,
        used when no scale or origin is given (world metres through each marker's plane).
    start, end, step : int
        The frames tracked (``end`` inclusive, default the last).
    fps : float, optional
        The true frame rate, for slow-motion footage; default the file's.
    color_tol, search_px : int
        Colour tolerance (0-255) and the search window's half size (px).
    pixels : {"tracker", "opencv"}, default "tracker"
        Convention of the pixel positions given in ``markers``, ``scale`` and ``origin``:
        Tracker's (origin at the image's top-left corner, as Tracker's table shows them) or
        OpenCV's (origin at the top-left pixel's centre, 0.5 px from Tracker's). The returned
        pixel columns are OpenCV's.
    calibration_from : path-like, optional
        A Tracker project (``.trk``/``.trz``) of the same camera: its calibration (scale,
        origin, axes) and frame rate are used, as ``locust track video --calibration-from``.
    trk : path-like, optional
        Also write the tracks as a Tracker project (``.trk``) that opens the video with the
        clip's timing and calibration, one point mass per marker (``--trk`` of the command).
    overwrite : bool, default False
        Replace an existing ``trk`` file; otherwise it is refused.
    progress : callable, optional
        Called with 1 after each frame.

    Returns
    -------
    Tracks
        ``.to_dataframe()``, ``.positions(marker)``, ``.write(path)``.

    Examples
    --------
    Not run as a doctest: it renders a video and tracks it.

    >>> import locust
    >>> hop = locust.simulate(locust.robot("small"), cycles=1)                     # doctest: +SKIP
    >>> hop.video("hop.mp4", overwrite=True, camera="fixed", width=320, height=240)  # doctest: +SKIP
    >>> locust.track_markers("hop.mp4").to_dataframe()[["t_s", "nose_x_m", "nose_y_m"]]  # doctest: +SKIP
    """
    from ..track.runner import track_video
    from ..track.spec import ModelOptions, parse_markers
    from ..track.video import Clip, probe

    video = Path(video)
    project = _project(video, calibration_from, scale, origin, camera_json)
    if project is not None and fps is None and math.isfinite(project.clip.fps):
        fps = project.clip.fps
    trk = _trk_target(trk, overwrite)
    models = parse_markers(_marker_specs(markers),
                           ModelOptions(color_tol=color_tol, search_half_px=search_px, pixels=pixels))
    opened = trk_io.project_media(project) if project is not None and is_project(video) \
        else contextlib.nullcontext(video)
    with opened as media:
        info = probe(Path(media))
        clip = Clip(start, end, step, fps).resolved(info)
        calibration = project.calibration if project is not None else \
            _calibration(info, scale, origin, angle_deg, camera_json, pixels)
        result = track_video(info, clip, models, calibration, progress=progress)
        if trk is not None:
            from ..track.trk import write_project

            write_project(result, trk, trk_io.media_in_zip(project, trk) if media != video else None)
    return Tracks(result.tracks, result)


def _project(video: Path, calibration_from, scale, origin, camera_json):
    """The Tracker project whose calibration is used: ``video`` itself when it is one, else
    ``calibration_from``; refused beside another calibration."""
    if is_project(video):
        if calibration_from is not None:
            raise TrackError("the video is a Tracker project: its calibration is used, leave out calibration_from",
                             "or give the video itself")
        project = trk_io.read_project(video)
    else:
        project = trk_io.read_project(calibration_from) if calibration_from is not None else None
    if project is not None and (scale is not None or origin is not None or camera_json is not None):
        raise TrackError("a Tracker project's calibration, or scale/origin/camera_json, not both",
                         "one calibration per run")
    return project


def _trk_target(trk: str | Path | None, overwrite: bool) -> Path | None:
    if trk is None:
        return None
    trk = Path(trk)
    if trk.suffix.lower() != ".trk":
        raise TrackError(f"trk={str(trk)!r}: a Tracker project is written as a .trk file", "e.g. trk='redo.trk'")
    if trk.exists() and not overwrite:
        raise TrackError(f"{trk} exists", "give another trk path, or overwrite=True to replace it")
    return trk


def read_tracks(path: str | Path, units: str = "m", rename: Mapping[str, str] | Sequence[str] = (),
                mirror: bool = False) -> Tracks:
    """Read a track file: a ``locust track`` CSV, a Tracker project (.trk/.trz) or text export, or a t,x,y CSV.

    Parameters
    ----------
    path : path-like
    units : {"m", "cm", "mm"}, default "m"
        The unit of a file's positions (a Tracker project carries its own).
    rename : dict, optional
        Marker names to change, e.g. ``{"mass A": "nose"}``.
    mirror : bool, default False
        Flip x (a hop filmed going left).

    Returns
    -------
    Tracks

    Examples
    --------
    From the repository's root:

    >>> import locust
    >>> locust.read_tracks("calibration/recordings/synthetic_beam.csv").markers
    ['tip']
    """
    from ..io.importing import import_tracks

    return Tracks(import_tracks(path, units, rename, mirror))


__all__ = ["Tracks", "read_tracks", "track_markers"]
