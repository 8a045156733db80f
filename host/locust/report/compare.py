"""Measured against predicted: per-hop rows, per-configuration summaries, firmware timing.

Two travels, each with its own name: the **distance** is ``locust sim``'s, the chassis' travel
over the run (:attr:`Comparison.predicted_distance_m`, the very figure ``locust sim`` and
``locust sweep`` print); the **marker travel** is the tracked marker's, from where it stood to
where it rests after each hop, taken the same way from the track and from the simulated marker,
so the two are compared like with like. On a robot that ends each hop on its feet they agree (to
0.5 mm on the seed's leg sets); on one that ends on its back they differ by centimetres, and the
camera sees only the marker's. A **jump** is the marker's highest point above standing in a hop
that ended back on its feet (:mod:`.ending`): a hop that went over, and every one after it, is
no jump.

Across repeated trials a configuration's figure is the mean of the trials' own figures
(marker travel, marker travel per hop, jump) with the sample standard deviation (n - 1) when
there are at least two trials.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ReportError, TrialError
from ..io.run_record import Jitter, jitter, timing_note
from ..trials.measure import MeasuredHop, align, measure_hops
from ..trials.measured import Trial, span_hint
from .ending import ON_ITS_FEET, Ending, marker_ending, simulated_ending
from .predict import Prediction


@dataclass(frozen=True)
class Stat:
    """A figure over repeated trials, in the unit of the values it summarises.

    Attributes
    ----------
    mean : float
        Mean of the finite values (nan when there are none).
    std : float or None
        Sample standard deviation (n - 1); None with fewer than two values.
    n : int
        Number of finite values.
    """

    mean: float
    std: float | None        # None with fewer than two values
    n: int


def stat(values: list[float]) -> Stat:
    """The mean, sample standard deviation and count of the finite values.

    Parameters
    ----------
    values : list of float
        One figure per trial; nan values are left out.

    Returns
    -------
    Stat
        In the values' unit.
    """
    v = np.asarray([x for x in values if math.isfinite(x)], dtype=float)
    if v.size == 0:
        return Stat(math.nan, None, 0)
    return Stat(float(v.mean()), float(v.std(ddof=1)) if v.size >= 2 else None, int(v.size))


@dataclass(frozen=True)
class HopRow:
    """One hop of one trial, measured against predicted; the marker's figures [m].

    Attributes
    ----------
    config : str
        The configuration.
    trial : str
        The trial's label.
    hop : int
        The hop (cycle) number, from 1.
    measured_marker_travel_m, predicted_marker_travel_m : float
        The marker's travel over the hop, rest to rest [m]; nan where the track or the
        simulation has none.
    measured_apex_m, predicted_apex_m : float
        The marker's highest point in the hop above standing [m]; nan where the hop did not end
        on the robot's feet (it went over, or lay on its back: no jump).
    measured_state, predicted_state : str
        How the hop ended: ``on its feet``, ``goes over`` or ``on its back`` (:mod:`.ending`).
    measured_takeoff_speed_m_per_s, predicted_takeoff_speed_m_per_s : float
        The marker's highest speed from the hop's start to its apex [m/s]
        (:func:`locust.trials.measure.measure_hops`); nan where the track or the simulation has none.
    """

    config: str
    trial: str
    hop: int
    measured_marker_travel_m: float
    predicted_marker_travel_m: float
    measured_apex_m: float
    predicted_apex_m: float
    measured_state: str = ""
    predicted_state: str = ""
    measured_takeoff_speed_m_per_s: float = math.nan
    predicted_takeoff_speed_m_per_s: float = math.nan

    @property
    def marker_travel_error_m(self) -> float:
        """Measured minus predicted marker travel over the hop [m]."""
        return self.measured_marker_travel_m - self.predicted_marker_travel_m

    @property
    def apex_error_m(self) -> float:
        """Measured minus predicted apex [m] (nan where either hop is no jump)."""
        return self.measured_apex_m - self.predicted_apex_m


def ending_of(trial: Trial) -> Ending:
    """How a measured trial ended, read off its marker's hops (:func:`.ending.marker_ending`).

    Parameters
    ----------
    trial : Trial
        A trial measured on the prediction's clock (:func:`compare`).

    Returns
    -------
    Ending
    """
    return marker_ending(trial.hops)


def trial_jump_m(trial: Trial) -> float:
    """A measured trial's jump: the highest apex above standing over its hops that ended on the
    robot's feet [m]; nan when none did (a trial that went over in its first hop has no jump).

    Parameters
    ----------
    trial : Trial
        A trial measured on the prediction's clock.

    Returns
    -------
    float
    """
    return jump_of(trial.hops, ending_of(trial))


def jump_of(hops: list[MeasuredHop], ending: Ending) -> float:
    """The highest marker apex above standing over the hops that came back down [m].

    Parameters
    ----------
    hops : list of MeasuredHop
        A marker's hops.
    ending : Ending
        How the run ended (the hop it went over in).

    Returns
    -------
    float
        nan when no such hop has a finite apex.
    """
    apexes = [h.apex_m for h in hops if math.isfinite(h.apex_m) and ending.came_down(h.hop)]
    return max(apexes) if apexes else math.nan


@dataclass(frozen=True)
class Comparison:
    """One configuration's prediction, its trials, and the figures comparing them.

    Attributes
    ----------
    config : str
        The configuration.
    prediction : Prediction
        What the simulation predicts.
    all_trials : list of Trial
        Every trial given, with or without a track; those with one measured (the same
        objects as :attr:`trials`).
    trials : list of Trial
        The trials with a track, measured: each with its ``trace`` on the prediction's clock and
        its ``hops``.
    rows : list of HopRow
        Every measured hop against the predicted one.
    cycles : int
        Cycles simulated.
    period_s : float
        One cycle, push plus wait [s].
    marker_travel, marker_travel_per_hop, jump : Stat
        Measured marker travel over the cycles, its mean per hop, and the jump (highest marker
        apex above standing in a hop that came back down) [m], over the trials.
    """

    config: str
    prediction: Prediction
    all_trials: list[Trial]   # every trial given, with or without a track
    trials: list[Trial]       # those with a track, measured
    rows: list[HopRow]
    cycles: int
    period_s: float
    marker_travel: Stat             # measured marker travel over the cycles
    marker_travel_per_hop: Stat     # its mean per hop
    jump: Stat                      # measured highest marker apex above standing, hops that came back down

    @property
    def predicted_distance_m(self) -> float:
        """``locust sim``'s distance: the chassis' travel over the run [m] (nan when invalid)."""
        return float(self.prediction.result.distance_m) if self.prediction.valid else math.nan

    @property
    def predicted_distance_per_hop_m(self) -> float:
        """``locust sim``'s distance over the cycles [m]: what ``locust sweep``'s landscape draws."""
        return self.predicted_distance_m / self.cycles

    @property
    def predicted_ending(self) -> Ending | None:
        """How the simulated run ended (:func:`.ending.simulated_ending`); None when invalid."""
        return simulated_ending(self.prediction.result, self.prediction.hops) if self.prediction.valid else None

    @property
    def predicted_marker_travel_m(self) -> float:
        """The simulated marker's travel over the cycles, cut and zeroed as a track's hops
        are [m] (the chassis' travel, :attr:`predicted_distance_m`, differs from it on a robot
        that ends on its back)."""
        hops = self.prediction.hops
        return float(sum(h.distance_m for h in hops)) if hops else math.nan

    @property
    def resolution_m(self) -> float:
        """One pixel of the coarsest track, in metres: a difference below it is not measured
        (nan when no track has pixel columns)."""
        px = [m.track.m_per_px for m in self.trials if math.isfinite(m.track.m_per_px)]
        return max(px) if px else math.nan

    @property
    def predicted_marker_travel_per_hop_m(self) -> float:
        """Predicted marker travel per cycle [m]."""
        return self.predicted_marker_travel_m / self.cycles

    @property
    def predicted_jump_m(self) -> float:
        """Highest apex of the tracked marker in the simulation (what a camera would see) over
        the hops that came back down [m]; nan when it went over in its first hop."""
        ending = self.predicted_ending
        return jump_of(self.prediction.hops, ending) if ending is not None else math.nan


def compare(prediction: Prediction, trials: list[Trial], cycles: int, period_s: float) -> Comparison:
    """Measure every trial with a track on the prediction's clock and pair hop by hop.

    Like with like: the predicted hops are the simulated marker's (the same marker as the
    track), measured by the same function from the same zero (where it stood) with the same
    cut (the schedule's cycles, each ending at rest), never the chassis travel of ``run()``
    (which is :attr:`Comparison.predicted_distance_m`, under its own name). A hop that did not
    end on the robot's feet has no apex in the rows: it is no jump.

    Parameters
    ----------
    prediction : Prediction
        The configuration's prediction; its onset latency places the tracks' clock.
    trials : list of Trial
        The configuration's trials; those without a track are kept but not measured.
    cycles : int
        Cycles simulated (a trial with a run record is cut at its own commanded cycles).
    period_s : float
        One cycle, push plus wait [s].

    Returns
    -------
    Comparison
        The pairs and the figures over the trials.

    Raises
    ------
    ReportError
        A track whose start cannot be found (with a units hint where it looks misread).
    """
    latency = prediction.onset_latency_s if prediction.valid else 0.0
    every = [trial if trial.track is None else measured(trial, latency, period_s, cycles) for trial in trials]
    measured_trials = [t for t in every if t.track is not None]
    sim_hops = {h.hop: h for h in prediction.hops}            # the simulated marker's hops
    sim_end = simulated_ending(prediction.result, prediction.hops) if prediction.valid else None
    nan = math.nan
    rows = []
    for m in measured_trials:
        end = ending_of(m)
        for h in m.hops:
            p = sim_hops.get(h.hop)
            p_state = sim_end.state(h.hop) if p and sim_end else ""
            rows.append(HopRow(prediction.config, m.label, h.hop, h.distance_m, p.distance_m if p else nan,
                               h.apex_m if end.came_down(h.hop) else nan,
                               p.apex_m if p and p_state == ON_ITS_FEET else nan,
                               end.state(h.hop) if math.isfinite(h.rest_height_m) else "", p_state,
                               h.takeoff_speed_m_per_s, p.takeoff_speed_m_per_s if p else nan))
    return Comparison(
        config=prediction.config, prediction=prediction, all_trials=every, trials=measured_trials, rows=rows,
        cycles=cycles, period_s=period_s, marker_travel=stat([m.marker_travel_m for m in measured_trials]),
        marker_travel_per_hop=stat([m.marker_travel_per_hop_m for m in measured_trials]),
        jump=stat([trial_jump_m(m) for m in measured_trials]),
    )


def measured(trial: Trial, latency_s: float, period_s: float, cycles: int) -> Trial:
    """``trial`` on the prediction's clock: its marker's trace from its first push (placed
    ``latency_s`` before its first motion, as the prediction's) and its hops cut at the cycles.

    Parameters
    ----------
    trial : Trial
        A trial with a track.
    latency_s : float
        The prediction's delay from the schedule's start to the marker's first motion [s].
    period_s : float
        One cycle, push plus wait [s].
    cycles : int
        Cycles simulated (a trial with a run record is cut at its own commanded cycles).

    Returns
    -------
    Trial
        A copy with ``trace`` and ``hops``.

    Raises
    ------
    ReportError
        A track whose start cannot be found (with a units hint where it looks misread).
    """
    tr = trial.track
    try:
        trace = align(tr.t_s, tr.x_m, tr.y_m, latency_s, where=str(tr.path))
    except TrialError as exc:
        hint = span_hint(tr)        # noise in mm read as metres looks like a robot already moving
        raise ReportError(exc.message, f"{hint}; {exc.hint}" if hint else exc.hint) from None
    return replace(trial, trace=trace, hops=tuple(measure_hops(trace, period_s, trial_cycles(trial, cycles))))


def trial_cycles(trial: Trial, default: int) -> int:
    """The cycles the trial's run record commanded; ``default`` without a record.

    Parameters
    ----------
    trial : Trial
        The trial.
    default : int
        Cycles to use without a run record.

    Returns
    -------
    int
        Number of cycles.
    """
    return trial.record.schedule.cycles if trial.record else default


@dataclass(frozen=True)
class TimingRow:
    """One run record's firmware timing.

    Attributes
    ----------
    config : str
        The configuration.
    trial : str
        The trial's label.
    status : str
        The run's status as recorded.
    phases, phases_expected : int
        Phases recorded, and those the schedule commands.
    firmware : str
        The firmware version (``?`` when unrecorded).
    jitter : Jitter or None
        Phase start errors, measured minus commanded [ms].
    timing_note : str or None
        Why those errors are not the firmware's (a virtual robot's host that stalled), or None.
    """

    config: str
    trial: str
    status: str
    phases: int
    phases_expected: int
    firmware: str
    jitter: Jitter | None        # start errors, ms
    timing_note: str | None = None


def timing_rows(config: str, trials: list[Trial]) -> list[TimingRow]:
    """Phase start errors (measured - commanded, firmware clock) of each run record.

    Recomputed from the record's phases with the device layer's own :func:`jitter`, so a
    record that lost its summary still has one.

    Parameters
    ----------
    config : str
        The configuration.
    trials : list of Trial
        Its trials; those without a run record are skipped.

    Returns
    -------
    list of TimingRow
        One per run record.
    """
    rows = []
    for t in trials:
        rec = t.record
        if rec is None:
            continue
        rows.append(TimingRow(
            config=config, trial=t.label, status=rec.status, phases=len(rec.phases),
            phases_expected=rec.schedule.phases, firmware=rec.firmware_version or "?", jitter=jitter(rec.phases),
            timing_note=timing_note(rec.phases),
        ))
    return rows
