"""What one simulation gives: :class:`SimResult`, the audited figures with the rollout behind
them (traces, videos, plots) and, from :func:`locust.simulate`, the robot, the standing load and
the spread over draws."""

from __future__ import annotations

import contextlib
import dataclasses
import html
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import SimError
from ..fileio import write_target
from ..params import Robot
from .hops import Hop
from .rollout import Trajectory


@dataclass
class SimResult:
    """One audited simulation (:func:`locust.sim.run.run`; :func:`locust.simulate` adds the rest):
    its figures (``valid``, ``reasons``, ``distance_m``, ``max_nose_height_m``, ``hops``, ``notes`` ...),
    the robot they belong to (``robot``, named ``robot_name``), the rollout (``trajectory``,
    every step's state), and, with ``samples``, the spread over draws of the uncertain values (``spread``). The
    standing robot's weight on its nose, as a kitchen scale under it reads, is
    ``nose_load_kg`` (of ``total_mass_kg``; :mod:`locust.sim.statics`).

    ``repr`` is a short table in mm and degrees; in a notebook it is an HTML table.
    """

    robot_name: str
    valid: bool
    reasons: list[str]
    distance_m: float
    max_nose_height_m: float
    hops: list[Hop]
    cycles: int
    timestep_s: float
    duration_s: float
    wall_s: float
    loop_residual_max_m: float
    energy_surplus_max_j: float
    servo_work_j: float
    servo_peak_speed_rad_per_s: float = float("nan")     # fastest crank speed during the schedule
    servo_noload_speed_rad_per_s: float = float("nan")   # the servo's top speed (inf: none)
    grashof: str = ""
    transmission_deg: float = float("nan")
    notes: list[str] = field(default_factory=list)
    convergence: dict[str, float] | None = None
    # goes_over / rears_and_returns / stays_low (locust.sim.outcome); None when invalid
    outcome: str | None = None
    # the rollout behind the figures, states included: only with run(..., keep_states=True);
    # never part of the JSON
    trajectory: Trajectory | None = field(default=None, repr=False, compare=False)


    robot: Robot | None = field(default=None, repr=False, compare=False)
    spread: object | None = field(default=None, repr=False, compare=False)   # locust.sim.samples.Samples
    nose_load_kg: float = float("nan")     # standing at the 0 deg command, the nose's share of the weight
    total_mass_kg: float = float("nan")
    sensitivity: object | None = field(default=None, repr=False, compare=False)  # sim.sensitivity.Sensitivity
    explanation: object | None = field(default=None, repr=False, compare=False)  # sim.explain.Explanation
    # with --check-convergence and --samples: the draws at dt/2 (sim.ensemble.EnsembleConvergence)
    ensemble_convergence: object | None = field(default=None, repr=False, compare=False)

    def to_json(self) -> dict:
        """Every figure but the rollout and the robot; from :func:`locust.simulate`, also the standing
        load, with samples each outcome's share and figures (``outcomes``) and the draws
        (``samples``), with a sensitivity, ``sensitivity``, with an explanation, ``explanation``, with
        the draws checked at half the step, ``ensemble_convergence``. NaN
        and inf become null where it is
        written (:func:`locust.fileio.json_text`).

        Returns
        -------
        dict
            The figures by name, in SI units as the field names say.
        """
        out = dataclasses.asdict(dataclasses.replace(self, trajectory=None, robot=None, spread=None, sensitivity=None,
                                                     explanation=None, ensemble_convergence=None))
        for key in ("trajectory", "robot", "spread", "sensitivity", "explanation", "ensemble_convergence"):
            del out[key]
        out = {"robot": out.pop("robot_name"), **out}   # the JSON names the robot by its name
        if self.robot is None:   # a bare run (not locust.simulate's): no standing load was asked for
            del out["nose_load_kg"], out["total_mass_kg"]
        if self.spread is not None:
            sp = self.spread.to_json()
            out.update(outcomes=sp["outcomes"], samples=sp)
        if self.sensitivity is not None:
            out["sensitivity"] = self.sensitivity.to_json()
        if self.explanation is not None:
            out["explanation"] = self.explanation.to_json()
        if self.ensemble_convergence is not None:
            out["ensemble_convergence"] = self.ensemble_convergence.to_json()
        return out

    # -- tables ----------------------------------------------------------------------
    def trace(self):
        """Every physics step of the run as a table.

        Returns
        -------
        pandas.DataFrame
            One row per step: ``t_s`` (seconds from the first push; negative while the robot
            settles), ``nose_x_m``, ``nose_z_m``, ``foot_x_m``, ``foot_z_m`` (the left foot),
            ``com_x_m``, ``com_z_m``, ``chassis_x_m``, ``chassis_z_m`` (world metres, x along the
            floor, z up), ``command_deg`` (the servo command), ``crank_left_deg`` and
            ``crank_right_deg`` (the servo joints, in the command's convention), ``on_floor``.
            ``distance_m`` is ``chassis_x_m`` at the last row less that at the last row before
            ``t_s = 0``; ``max_nose_height_m`` is the largest ``nose_z_m`` from ``t_s = 0`` on.

        Examples
        --------
        >>> import locust
        >>> r = locust.simulate(locust.robot("small"), cycles=1)
        >>> tr = r.trace()
        >>> float(tr.nose_z_m[tr.t_s >= 0].max()) == r.max_nose_height_m
        True
        """
        import pandas as pd

        traj = self._trajectory()
        s, sd, plan = traj.built.sensors, traj.sensordata, traj.plan
        n = len(sd)
        dt = traj.timestep_s
        cols = {"t_s": (np.arange(n) - plan.settle_steps) * dt}
        for name, sl in (("nose", s.nose_pos), ("foot", s.foot_pos), ("com", s.com_pos),
                         ("chassis", s.chassis_pos)):
            cols[f"{name}_x_m"] = sd[:, sl][:, 0]
            cols[f"{name}_z_m"] = sd[:, sl][:, 2]
        cols["command_deg"] = np.degrees(plan.ctrl_rad[:n])
        model = traj.built.model
        for side, act in zip(("left", "right"), traj.built.servo_actuators):
            adr = int(model.jnt_qposadr[model.actuator_trnid[act, 0]])
            # sensor row i is at t = i dt, the state after step i: row 0 is the built pose
            q = np.concatenate(([model.qpos0[adr]], traj.states[:-1, 1 + adr]))
            cols[f"crank_{side}_deg"] = np.degrees(q)
        cols["on_floor"] = sd[:, s.floor_contact][:, 0] > 0.5
        return pd.DataFrame(cols)

    def hop_table(self):
        """The hops as a table: ``cycle``, ``distance_m``, ``nose_apex_m``, ``com_apex_m``, ``flight_s``.

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        return pd.DataFrame([dataclasses.asdict(h) for h in self.hops],
                            columns=["cycle", "distance_m", "nose_apex_m", "com_apex_m", "flight_s"])

    # -- video and figure ------------------------------------------------------------
    def video(self, path: str | os.PathLike, overwrite: bool = False, camera: str = "track", fps: int = 30,
              width: int = 1280, height: int = 720, progress: bool = True):
        """Render this run (the same rollout, not a second one) to an MP4 with its truth sidecars.

        Parameters
        ----------
        path : path-like
            ``<name>.mp4``; beside it go ``<name>.truth.csv`` (the markers' true pixels) and
            ``<name>.camera.json`` (the camera, for :func:`locust.track`).
        overwrite : bool, default False
            False: an existing video or sidecar is refused (:class:`~locust.errors.SimError`).
            True: the three files are rendered aside and then replace the old ones, so a
            notebook cell can be run again.
        camera : {"track", "fixed"}
            Follow the robot, or hold still (for measuring the clip with :func:`locust.track`).
        fps, width, height : int
            Frame rate and size in pixels (even numbers).
        progress : bool, default True
            False: no progress lines on stderr while it renders (a notebook's output).

        Returns
        -------
        locust.sim.clip.RenderedClip
            ``video_path``, ``truth_path``, ``camera_path``, ``frames``.

        Examples
        --------
        >>> import locust
        >>> r = locust.simulate(locust.robot("small"), cycles=1)
        >>> r.video("hop.mp4", overwrite=True, width=320, height=240).frames   # doctest: +SKIP
        """
        from ..progress import silenced

        with contextlib.nullcontext() if progress else silenced():
            return self._video(Path(path), overwrite, camera, fps, width, height)

    def _video(self, path: Path, overwrite: bool, camera: str, fps: int, width: int, height: int):
        from ..sim.clip import render_video, sidecar_paths

        if not self.valid:
            raise SimError(f"not rendering an invalid simulation: {'; '.join(self.reasons)}",
                           "fix the reasons listed first")
        traj = self._trajectory()
        targets = (path, *sidecar_paths(path))
        if not overwrite or not any(p.exists() or p.is_symlink() for p in targets):
            return render_video(self.robot, path, camera=camera, fps=fps, width=width, height=height,
                                trajectory=traj)
        if path.suffix.lower() != ".mp4":
            raise SimError(f"video path {path} does not end in .mp4", "name the video <something>.mp4")
        landing = [write_target(p) for p in targets]   # refuses folders, devices and read-only files
        with tempfile.TemporaryDirectory(prefix=f".{path.stem}.", dir=path.parent) as tmp:
            info = render_video(self.robot, Path(tmp) / path.name, camera=camera, fps=fps, width=width,
                                height=height, trajectory=traj)
            for src, dst in zip((info.video_path, info.truth_path, info.camera_path), landing):
                os.replace(src, dst)
        return dataclasses.replace(info, video_path=path, truth_path=targets[1], camera_path=targets[2])

    def plot(self):
        """Nose and foot against time: height above the floor, and distance along it.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from matplotlib.figure import Figure

        tr = self.trace()
        fig = Figure(figsize=(8, 5.5), layout="constrained")
        ax_z, ax_x = fig.subplots(2, 1, sharex=True)
        for name, colour in (("nose", "#c0309c"), ("foot", "#1f9fb4")):
            ax_z.plot(tr.t_s, tr[f"{name}_z_m"] * 1000, color=colour, label=name)
            ax_x.plot(tr.t_s, (tr[f"{name}_x_m"] - tr[f"{name}_x_m"][tr.t_s < 0].iloc[-1]) * 1000, color=colour,
                      label=name)
        ax_z.set_ylabel("height above the floor [mm]")
        ax_x.set_ylabel("forward from the start [mm]")
        ax_x.set_xlabel("time from the first push [s]")
        ax_z.legend(loc="upper right")
        fig.suptitle(f"{self.robot_name}: {self.distance_m * 1000:.1f} mm in {self.cycles} cycles, highest nose "
                     f"{self.max_nose_height_m * 1000:.1f} mm" if self.valid else f"{self.robot_name}: INVALID")
        return fig

    def _trajectory(self):
        if self.trajectory is None or self.trajectory.states is None:
            raise SimError("this result kept no rollout to trace or render",
                           "simulate it with locust.simulate(robot, keep_states=True)")
        return self.trajectory

    # -- display ---------------------------------------------------------------------
    def _rows(self) -> list[tuple[str, str]]:
        rows = [("valid", f"yes, {self.outcome.replace('_', ' ')}" if self.valid and self.outcome
                 else "yes" if self.valid else "NO: " + "; ".join(self.reasons)),
                ("cycles", f"{self.cycles}  (dt {self.timestep_s:g} s)")]
        if self.valid:
            rows += [("distance", f"{self.distance_m * 1000:.2f} mm"),
                     ("max nose height", f"{self.max_nose_height_m * 1000:.2f} mm"),
                     ("linkage", f"{self.grashof}, transmission {self.transmission_deg:.0f} deg"),
                     ("nose load", f"{self.nose_load_kg * 1000:.1f} g of {self.total_mass_kg * 1000:.1f} g standing")]
        if self.spread is not None:
            from ..tables import spread_lines

            rows += [("draws" if i == 0 else "", line.strip()) for i, line in enumerate(spread_lines(self.spread))]
        if self.sensitivity is not None:
            from ..tables import sensitivity_lines

            rows += [("sensitivity" if i == 0 else "", line.strip())
                     for i, line in enumerate(sensitivity_lines(self.sensitivity))]
        return rows

    def _hop_rows(self) -> list[tuple[str, ...]]:
        return [(str(h.cycle), f"{h.distance_m * 1000:.2f}", f"{h.nose_apex_m * 1000:.2f}",
                 f"{h.com_apex_m * 1000:.2f}", f"{h.flight_s * 1000:.0f}") for h in self.hops]

    HOP_HEAD = ("hop", "distance mm", "nose apex mm", "com apex mm", "flight ms")

    def __repr__(self) -> str:
        lines = [f"SimResult {self.robot_name}"] + [f"  {k:16s} {v}" for k, v in self._rows()]
        if self.hops:
            widths = [max(len(c), *(len(r[i]) for r in self._hop_rows())) for i, c in enumerate(self.HOP_HEAD)]
            lines.append("  " + "  ".join(c.rjust(w) for c, w in zip(self.HOP_HEAD, widths)))
            lines += ["  " + "  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in self._hop_rows()]
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        esc = html.escape
        out = [f"<b>SimResult {esc(self.robot_name)}</b><table>"]
        out += [f"<tr><th style='text-align:left'>{esc(k)}</th><td>{esc(v)}</td></tr>" for k, v in self._rows()]
        out.append("</table>")
        if self.hops:
            out.append("<table><tr>" + "".join(f"<th>{esc(c)}</th>" for c in self.HOP_HEAD) + "</tr>")
            out += ["<tr>" + "".join(f"<td>{esc(c)}</td>" for c in r) + "</tr>" for r in self._hop_rows()]
            out.append("</table>")
        out += [f"<p>note: {esc(n)}</p>" for n in self.notes]
        return "".join(out)


def invalid_result(robot: Robot, reason: str, cycles: int | None = None) -> SimResult:
    """A result for a robot that could not be simulated: invalid, with one reason, every figure nan.

    Parameters
    ----------
    robot : Robot
        The robot.
    reason : str
        Why it was not simulated.
    cycles : int, optional
        Cycles asked for; default the robot's schedule's.

    Returns
    -------
    SimResult
        ``valid`` False, no hops, zero duration.
    """
    nan = float("nan")
    return SimResult(robot_name=robot.name, valid=False, reasons=[reason], distance_m=nan, max_nose_height_m=nan,
                     hops=[], cycles=cycles or robot.schedule.cycles, timestep_s=robot.solver.timestep_s,
                     duration_s=0.0, wall_s=0.0, loop_residual_max_m=nan, energy_surplus_max_j=nan,
                     servo_work_j=nan)
