"""SYNTHETIC measured trials for testing reports against known truth.

``write_synthetic_trial`` simulates a "true" robot (any parameter set, e.g. the model with a
different friction), samples its nose like a side camera would (``fps``, a standing lead
before the first push, Gaussian position noise, a few lost frames) and writes what
``locust track`` and ``locust hop`` would have written: ``synthetic.tracks.csv`` (first line
``# synthetic``) and a ``run.json`` built with the device layer's own record types, its
phase start errors drawn at random (labelled synthetic in its ``message``). The truth is
returned: the true robot's nose marker, per hop, as a camera sees it: its travel (at rest at
the end of a cycle minus at its start, :func:`locust.trials.measure.measure_hops`) and its
highest point in the cycle above standing (from the 240 Hz trace the camera samples).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..fileio import make_folder
from ..params import Robot

TRACK_NAME = "synthetic.tracks.csv"


@dataclass(frozen=True)
class SyntheticTruth:
    """The true hops of a synthetic trial and where it was written (SYNTHETIC data).

    Attributes
    ----------
    hop_distance_m : list of float
        Per hop, the true nose marker's travel [m].
    hop_apex_m : list of float
        Per hop, its highest point above standing [m].
    distance_m : float
        Sum of the hop distances [m].
    track_path, run_path : Path
        The written ``synthetic.tracks.csv`` and ``run.json``.
    """

    hop_distance_m: list[float]
    hop_apex_m: list[float]
    distance_m: float
    track_path: Path
    run_path: Path


def simulated_nose(robot: Robot, cycles: int):
    """The true robot's audited result and its nose marker's trace (schedule clock, 240 Hz).

    Parameters
    ----------
    robot : Robot
        The "true" robot.
    cycles : int
        Cycles to simulate.

    Returns
    -------
    result : SimResult
        The audited result (its states dropped).
    trace : Aligned
        The nose marker, t = 0 at the first push [s], from where it stood [m].

    Raises
    ------
    ValueError
        The simulation failed its audit.
    """
    from ..sim.run import run
    from .predict import marker_trace

    result = run(robot, cycles=cycles, keep_states=True)
    if not result.valid:
        raise ValueError(f"the synthetic truth robot's simulation is invalid: {result.reasons}")
    traj, result.trajectory = result.trajectory, None
    return result, marker_trace(traj, "nose")


def write_synthetic_trial(folder: Path, robot: Robot, cycles: int, *, seed: int = 0, fps: float = 30.0,
                          noise_m: float = 0.0005, camera_lead_s: float = 0.25, lost_frames: int = 3,
                          truth=None) -> SyntheticTruth:
    """Write one SYNTHETIC trial into ``folder``: a tracks CSV and a run record.

    Parameters
    ----------
    folder : Path
        Made if missing.
    robot : Robot
        The "true" robot simulated.
    cycles : int
        Cycles to simulate.
    seed : int
        Seed of the noise, the lost frames and the phase start errors.
    fps : float
        The camera's frame rate [1/s].
    noise_m : float
        Standard deviation of the Gaussian position noise [m].
    camera_lead_s : float
        Filmed standing time before the first push [s].
    lost_frames : int
        Frames marked not found, drawn after frame 12.
    truth : tuple, optional
        A :func:`simulated_nose` result to reuse instead of simulating again.

    Returns
    -------
    SyntheticTruth
        The true hops and the written paths.
    """
    from ..io.run_record import COMPLETE, HopSchedule, Phase, RunRecord
    from ..io.run_record import write as write_record
    from ..io.tracks_csv import TracksCsv, write_tracks_csv

    result, trace = truth or simulated_nose(robot, cycles)
    rng = np.random.default_rng(seed)
    t_sched = np.arange(-camera_lead_s, trace.t_s[-1], 1.0 / fps)
    x = np.interp(t_sched, trace.t_s, trace.x_m) + rng.normal(0, noise_m, t_sched.size) + 0.10
    y = np.interp(t_sched, trace.t_s, trace.y_m) + rng.normal(0, noise_m, t_sched.size) + 0.05
    ok = np.ones(t_sched.size, dtype=bool)
    ok[rng.choice(np.arange(12, t_sched.size), size=lost_frames, replace=False)] = False

    nan = np.full(t_sched.size, np.nan)
    tracks = TracksCsv(
        frame=np.arange(t_sched.size), t_s=np.arange(t_sched.size) / fps,
        px={"nose": nan}, py={"nose": nan}, x_m={"nose": np.where(ok, x, np.nan)},
        y_m={"nose": np.where(ok, y, np.nan)}, ok={"nose": ok},
        comments=(f"synthetic: simulated nose of robot {robot.name!r}, {cycles} cycles, {fps:g} frames/s, "
                  f"noise {noise_m * 1000:g} mm sd, seed {seed}",))
    folder = Path(folder)
    make_folder(folder)
    track_path = write_tracks_csv(folder / TRACK_NAME, tracks)

    s = robot.schedule
    sched = HopSchedule(cycles=cycles, push_deg=s.push_deg, push_ms=round(s.push_s * 1000),
                        wait_ms=round(s.wait_s * 1000))
    record = RunRecord(schedule=sched, port="synthetic", status=COMPLETE, firmware_version="synthetic",
                       firmware_status=COMPLETE, message="synthetic run record (random phase start errors)")
    period_us = (sched.push_ms + sched.wait_ms) * 1000
    for c in range(cycles):
        for name, offset_us in (("push", 0), ("wait", sched.push_ms * 1000)):
            commanded = c * period_us + offset_us
            record.add_phase(Phase(c + 1, name, commanded, commanded + int(rng.integers(20, 400))))
    run_path = write_record(record, folder)
    from ..trials.measure import measure_hops

    period_s = s.push_s + s.wait_s
    apex = [float(trace.y_m[(trace.t_s >= c * period_s) & (trace.t_s < (c + 1) * period_s)].max())
            for c in range(cycles)]
    hops = [h.distance_m for h in measure_hops(trace, period_s, cycles)]
    return SyntheticTruth(hops, apex, float(sum(hops)), track_path, run_path)
