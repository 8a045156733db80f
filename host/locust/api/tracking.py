"""``locust.track`` and ``locust.read_tracks``: marker tracks from a video or a track file, as a table."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import TrackError
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


def _marker_specs(markers: Mapping[str, str] | Sequence[str] | None) -> tuple[str, ...]:
    if markers is None:
        return ()   # the robot's nose and foot colours
    if isinstance(markers, Mapping):
        return tuple(f"{name}={spec}" for name, spec in markers.items())
    return tuple(markers)


def _numbers(values: Sequence[float]) -> str:
    """Numbers as the command line writes them (``1.5,2.0``), each exactly (a float's repr)."""
    return ",".join(repr(float(v)) for v in values)


def _scale_text(scale) -> str | None:
    if scale is None or isinstance(scale, str):
        return scale
    *ends, length_m = scale
    return f"{_numbers(ends)}={_numbers([length_m])}"


def _aruco_text(scale_aruco) -> str | None:
    if scale_aruco is None or isinstance(scale_aruco, str):
        return scale_aruco
    marker_id, side_m = scale_aruco
    return f"{int(marker_id)}={_numbers([side_m])}"


def _point_text(point) -> str | None:
    return point if point is None or isinstance(point, str) else _numbers(point)


def _plane_text(points) -> str | None:
    if points is None or isinstance(points, str):
        return points
    return ";".join(f"{_numbers(px)}={_numbers(xy_m)}" for px, xy_m in points)


def _path(value: str | Path | None) -> Path | None:
    return None if value is None else Path(value)


def track_markers(video: str | Path, markers: Mapping[str, str] | Sequence[str] | None = None, *,
                  scale: tuple[float, float, float, float, float] | str | None = None,
                  scale_aruco: tuple[int, float] | str | None = None, aruco_dict: str | None = None,
                  board: str | None = None,
                  plane_points: Sequence[tuple[tuple[float, float], tuple[float, float]]] | str | None = None,
                  origin: tuple[float, float] | str | None = None, angle_deg: float = 0.0,
                  camera_json: str | Path | None = None, calibration_from: str | Path | None = None,
                  start: int = 0, end: int | None = None, step: int = 1, fps: float | None = None,
                  color_tol: int = 80, search_px: int = 40, template_radius_px: int = 8, accept: float = 0.5,
                  likeness: float = 0.5, evolve_percent: float = 20.0, pixels: str = "tracker",
                  out: str | Path | None = None, fmt: str = "csv", overlay: str = "png",
                  trk: str | Path | None = None, overwrite: bool = False,
                  progress: Callable[[int], None] | None = None) -> Tracks:
    """Find markers in every frame of a video (or an image sequence), as Tracker's autotracker would.

    The same job as ``locust track video`` (:func:`locust.track.pipeline.track_job`), with the
    same options: with ``out`` it writes the same files (the tracks CSV, its JSON sidecar and
    the overlay); without, only the tracks are returned (and ``trk`` written, if given).

    Parameters
    ----------
    video : path-like
        An MP4 (or the first image of a numbered sequence, or its folder), or a Tracker project
        (``.trk``, ``.trz``) that opens one: its calibration and frame rate are then used.
    markers : dict or sequence of str, optional
        Name -> spec (or ``"NAME=SPEC"`` strings, as ``--marker``): ``color:#RRGGBB[@X,Y]``,
        ``template:X,Y@FRAME`` or ``aruco:ID[@DICT]``. Default: the robot's nose (``#ff00ff``)
        and foot (``#00ffff``) colours.
    scale : (x1, y1, x2, y2, length_m) or str, optional
        A calibration stick: two pixels and the distance between them in metres
        (``--scale``; the text ``"X1,Y1,X2,Y2=LENGTH_M"`` too).
    scale_aruco : (id, side_m) or str, optional
        An ArUco marker's printed side length [m], measured where it first appears
        (``--scale-aruco``, ``"ID=SIDE_M"``).
    aruco_dict : str, optional
        The ArUco dictionary of ``scale_aruco``; default ``DICT_4X4_50`` (``--aruco-dict``'s).
    board : str, optional
        An ArUco grid board lying in the plane of motion, ``aruco:DICT:COLSxROWS:MARKER_MM:GAP_MM``
        (``--board``; :func:`locust.track.boardsheet.make_board` prints one): world metres in
        that plane, origin at its bottom-left corner, perspective corrected.
    plane_points : sequence of ((px, py), (x_m, y_m)) or str, optional
        Instead of a board: four or more pixels with their measured plane coordinates [m]
        (``--plane-points``, ``"PX,PY=X_M,Y_M;..."``).
    origin : (x, y) or str, optional
        The world origin in pixels (default the centre of the bottom-left pixel).
    angle_deg : float, default 0
        Direction of the world x axis, degrees counter-clockwise from the image's.
    camera_json : path-like, optional
        The pinhole camera of a simulated video; default ``<video>.camera.json`` beside it,
        used when no scale, ArUco scale or origin is given (world metres through each marker's plane).
    calibration_from : path-like, optional
        A Tracker project (``.trk``/``.trz``) of the same camera: its calibration (scale,
        origin, axes) and frame rate are used, as ``locust track video --calibration-from``.
    start, end, step : int
        The frames tracked (``end`` inclusive, default the last).
    fps : float, optional
        The true frame rate, for slow-motion footage; default the file's.
    color_tol : int, default 80
        Colour markers: largest per-channel difference (0-255) still counted as the marker.
    search_px : int, default 40
        Half-size of the search window around each predicted position [px].
    template_radius_px : int, default 8
        Template markers: radius of the circular template [px].
    accept : float, default 0.5
        Template markers: least peak height of a match.
    likeness : float, default 0.5
        Template markers: least correlation of a match with the template (-1 to 1).
    evolve_percent : float, default 20
        Template markers: percent of each accepted match blended into the template.
    pixels : {"tracker", "opencv"}, default "tracker"
        Convention of the pixel positions given in ``markers``, ``scale``, ``origin`` and ``plane_points``:
        Tracker's (origin at the image's top-left corner, as Tracker's table shows them) or
        OpenCV's (origin at the top-left pixel's centre, 0.5 px from Tracker's). The returned
        pixel columns are OpenCV's.
    out : path-like, optional
        Write the tracks file here (a file name, or a folder: ``<video>.tracks.csv`` in it; a
        name ending in ``/`` is a folder, made if missing), with its sidecar and overlay.
    fmt : {"csv", "tracker"}, default "csv"
        The layout of the tracks file written to ``out`` (``--format``).
    overlay : {"png", "video", "none"}, default "png"
        The tracks drawn on the last frame, or on the whole clip, written beside ``out``.
    trk : path-like, optional
        Also write the tracks as a Tracker project (``.trk``) that opens the video with the
        clip's timing and calibration, one point mass per marker (``--trk`` of the command).
    overwrite : bool, default False
        Replace existing outputs (``--force``); otherwise they are refused.
    progress : callable, optional
        Called with 1 after each frame tracked (and each frame drawn, for an overlay video).

    Returns
    -------
    Tracks
        ``.to_dataframe()``, ``.positions(marker)``, ``.write(path)``; ``.result.written``: the
        files written.

    Raises
    ------
    locust.errors.TrackError
        Bad input or options, a marker never found, or an output that may not be written.

    Examples
    --------
    Not run as a doctest: it renders a video and tracks it.

    >>> import locust
    >>> hop = locust.simulate(locust.robot("small"), cycles=1)                     # doctest: +SKIP
    >>> hop.video("hop.mp4", overwrite=True, camera="fixed", width=320, height=240)  # doctest: +SKIP
    >>> locust.track_markers("hop.mp4").to_dataframe()[["t_s", "nose_x_m", "nose_y_m"]]  # doctest: +SKIP
    """
    from ..track.aruco import DEFAULT_DICTIONARY
    from ..track.outputs import out_path
    from ..track.pipeline import TrackOptions, track_job
    from ..track.spec import ModelOptions

    model = ModelOptions(color_tol, search_px, template_radius_px, accept, evolve_percent / 100.0, likeness, pixels)
    options = TrackOptions(
        markers=_marker_specs(markers), model=model, start=start, end=end, step=step, fps=fps,
        scale=_scale_text(scale), scale_aruco=_aruco_text(scale_aruco), aruco_dict=aruco_dict or DEFAULT_DICTIONARY,
        board=board, plane_points=_plane_text(plane_points), camera_json=_path(camera_json), origin=_point_text(origin),
        angle_deg=angle_deg, calibration_from=_path(calibration_from), out=out_path(out), files=out is not None,
        force=overwrite, fmt=fmt, overlay=overlay, trk=_path(trk))
    result = track_job(video, options, bars=_callback_bars(progress))
    return Tracks(result.tracks, result)


def _callback_bars(progress: Callable[[int], None] | None):
    """The job's progress as ``progress(steps)`` calls, whatever the stage."""

    @contextlib.contextmanager
    def bars(length: int, label: str):
        yield progress or (lambda steps: None)

    return bars


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
