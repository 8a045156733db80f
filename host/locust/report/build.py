"""Build a report: simulate each configuration, compare with its trials, draw, write.

Everything is computed first; only then is a new folder made (never an existing one) and
``report.html``, ``dashboard.png`` and ``report.json`` written into it, each atomically: a
bad input stops the report before anything is written.
"""

from __future__ import annotations

import contextlib
import math
import shutil
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..errors import ReportError, WriteError
from ..fileio import atomic_write_bytes, atomic_write_json, atomic_write_text, check_can_make, unique_dir
from ..io.run_record import ERROR as REFUSED
from ..params import Provenance, Robot
from ..sweep.views import STUDY_PAGE
from ..tables import for_person
from ..trials.configs import Configuration, configuration
from ..trials.measured import Trial
from ..version import __version__
from . import figures, page
from .checks import VIRTUAL, Notice, collapsed, notices, recorded_on
from .compare import Comparison, compare, ending_of, timing_rows
from .landscape import Landscape, read_landscape
from .predict import predict
from .sidebyside import plan_side_by_side, write_side_by_side
from .spread import spread
from .study import read_front, study_figure, views_page

REPORT_NAME = "report.html"
DASHBOARD_NAME = "dashboard.png"
JSON_NAME = "report.json"


@dataclass(frozen=True)
class ReportResult:
    """What :func:`build_report` wrote and what it computed.

    Attributes
    ----------
    folder : Path
        The new report folder.
    html_path, dashboard_path, json_path : Path
        ``report.html``, ``dashboard.png`` and ``report.json`` in it.
    comparisons : list of Comparison
        One per configuration, in the order given.
    figures : list of str
        The keys of the page's figures, in page order.
    warnings : list of Notice
        The notices about the inputs (:func:`.checks.notices`): printed, on the page, in the JSON.
    side_by_side : list of SideBySide
        With ``side_by_side``, each trial's video or why it has none; empty without it.
    """

    folder: Path
    html_path: Path
    dashboard_path: Path
    json_path: Path
    comparisons: list[Comparison]
    figures: list[str]
    warnings: list[Notice] = field(default_factory=list)   # checks.notices: printed, on the page, in the JSON
    side_by_side: list = field(default_factory=list)    # sidebyside.SideBySide per trial, with --side-by-side


def run_schedule(name: str, trials: list[Trial]) -> dict | None:
    """The schedule the trials' run records share (push_deg, push_s, wait_s, cycles), if any.

    Parameters
    ----------
    name : str
        The configuration's name, for the messages.
    trials : list of Trial
        Its trials; those without a run record are skipped.

    Returns
    -------
    dict or None
        ``push_deg`` [deg], ``push_s`` and ``wait_s`` [s], ``cycles`` (the most any run
        recorded) and ``source`` (the first run record's path); None when no trial has a record.

    Raises
    ------
    ReportError
        A run the robot refused, or runs on different schedules.
    """
    seen = {}
    for t in trials:
        if t.record is None:
            continue
        if t.record.status == REFUSED:   # the robot refused the hop: nothing moved
            raise ReportError(f"configuration {name}: run {t.label} was refused by the robot "
                              f"({t.record.message}); there is no hop to compare with a prediction",
                              "leave that run out of --measured")
        s = t.record.schedule
        key = (float(s.push_deg), float(s.push_ms), float(s.wait_ms))
        seen.setdefault(key, []).append(t)
    if not seen:
        return None
    if len(seen) > 1:
        desc = "; ".join(f"{', '.join(t.label for t in ts)}: push {k[0]:g} deg {k[1]:g} ms, wait {k[2]:g} ms"
                         for k, ts in seen.items())
        raise ReportError(f"configuration {name}: its runs used different schedules ({desc})",
                          "give runs of one schedule per configuration (or name them as separate configurations)")
    (push_deg, push_ms, wait_ms), ts = next(iter(seen.items()))
    return {"push_deg": push_deg, "push_s": push_ms / 1000.0, "wait_s": wait_ms / 1000.0,
            "cycles": max(t.record.schedule.cycles for t in ts), "source": str(ts[0].run_path)}


def with_run_schedule(robot: Robot, sched: dict | None) -> Robot:
    """The robot running the schedule its runs recorded (only the values that differ change).

    Parameters
    ----------
    robot : Robot
        The configuration's robot.
    sched : dict or None
        A schedule from :func:`run_schedule`; None leaves the robot as it is.

    Returns
    -------
    Robot
        ``robot`` with ``schedule.push_deg`` [deg], ``schedule.push_s`` and ``schedule.wait_s`` [s]
        set from the run, their source the run record.
    """
    if sched is None:
        return robot
    changed = {f"schedule.{k}": sched[k] for k in ("push_deg", "push_s", "wait_s")
               if not math.isclose(robot.get(f"schedule.{k}"), sched[k], rel_tol=0, abs_tol=1e-9)}
    if not changed:
        return robot
    return robot.with_values(changed, Provenance(source=f"run:{sched['source']}", note="schedule of the measured run"))


def parameter_rows(robot: Robot) -> list[dict]:
    """The robot's parameters as rows of the page's parameter table.

    Parameters
    ----------
    robot : Robot
        The report's base robot.

    Returns
    -------
    list of dict
        One per dotted parameter: ``key``, ``value`` (as text, 6 significant digits, in the unit
        a person reads with that unit: a length in mm, a mass in g), its ``uncertainty`` (as text,
        in the same unit; "" when none), and its provenance's ``source``, ``date`` and ``note``.
    """
    rows = []
    for key, value in robot.flat().items():
        prov = robot.source_of(key)
        _, k, unit = for_person(key)
        shown = (f"{value * k:.6g} {unit}".rstrip() if isinstance(value, float)
                 else f"{value} {unit}".rstrip() if isinstance(value, int) and not isinstance(value, bool)
                 else str(value))
        unc = "" if prov.uncertainty is None else f"± {prov.uncertainty * k:.3g} {unit}".rstrip()
        rows.append({"key": key, "value": shown, "uncertainty": unc, "source": prov.source, "date": prov.date,
                     "note": prov.note})
    return rows


def build_report(robot: Robot, measured: dict[str, list[Trial]], out: Path, *, robot_source: str,
                 cycles: int | None = None, sweep: Path | None = None, added: dict[str, float] | None = None,
                 marker: str = "nose", progress: Callable[[str], None] | None = None,
                 side_by_side: bool = False, samples: int = 0, before: Robot | None = None,
                 study: Path | None = None, explain: bool = False) -> ReportResult:
    """Simulate each configuration, compare it with its trials, and write a new report folder.

    Parameters
    ----------
    robot : Robot
        The robot whose leg sets are the configurations.
    measured : dict of str to list of Trial
        Per configuration (leg-set name), its trials; an empty list predicts only.
    out : Path
        Where the new ``report`` folder is made (never an existing one).
    robot_source : str
        Where ``robot`` came from, as the page names it.
    cycles : int, optional
        Cycles to simulate; default the runs' recorded cycles, else the robot's schedule.
    sweep : Path, optional
        A ``locust sweep`` folder, its landscape drawn with the configurations marked.
    added : dict of str to float, optional
        Per configuration, the length added to every link [m].
    marker : str
        The tracked marker compared with the model's ``marker_<name>`` disc.
    progress : callable, optional
        Called with a line of text at each step.
    side_by_side : bool
        Also write a video of each trial beside the simulation.
    samples : int
        Draws of the robot's uncertain values per configuration (bands and error bars on the
        predictions); 0 for none.
    before : Robot, optional
        The robot before a fit; its predictions are drawn too.
    study : Path, optional
        A ``locust optimize`` folder; its Pareto front is drawn.
    explain : bool
        Explain each configuration's prediction (:mod:`locust.sim.explain`): the tornado of its
        uncertain values, and why it goes over or how close it comes, in the caption.

    Returns
    -------
    ReportResult
        The folder and files written, and the comparisons.

    Raises
    ------
    ReportError
        A bad input (unknown ``added`` name, bad sweep or study folder, refused or mixed runs,
        ``cycles`` beyond the runs'); nothing is written then.
    WriteError
        ``out`` cannot be made (a file in the way, a read-only folder: refused before any
        simulation), or the files could not be written (the new folder is removed).
    """
    check_can_make(out)            # before any simulation: a folder it cannot write fails now, not after the work
    progress = progress or (lambda msg: None)
    added = added or {}
    unknown = sorted(set(added) - set(measured))
    if unknown:
        raise ReportError(f"--added names {', '.join(unknown)}, which no --measured input is",
                          f"configurations given: {', '.join(measured)}")
    land = read_landscape(sweep) if sweep is not None else None   # fail early on a bad sweep folder
    front = read_front(study) if study is not None else None
    views = views_page(front) if front is not None else None
    t0 = time.perf_counter()

    configs, comps, spreads, befores = _simulate(robot, measured, added, cycles, marker, progress, side_by_side,
                                                 samples, before)
    explained = _explain(configs, comps, progress) if explain else {}

    progress("drawing figures")
    figs = _figures(comps, configs, land, spreads, befores)
    if explained:
        from .tornado import tornado_caption, tornado_figure

        labels = {configs[name].label: e for name, e in explained.items()}
        figs.insert(-1, page.Figure("tornado", "What each uncertain value does to the prediction",
                                    tornado_caption(labels), tornado_figure(labels)))
    if front is not None:
        figs.insert(-1, study_figure(front, views is not None))
    dash = figures.dashboard(comps, land, configs)

    timing = [row for c in comps for row in timing_rows(c.config, c.all_trials)]
    warnings = notices(comps) + sweep_notices(land)
    sbs_plan = plan_side_by_side(comps) if side_by_side else None   # videos probed, cameras read: before any write
    html_text = render_html(robot, robot_source, comps, configs, figs, timing, land, marker, warnings, spreads,
                            sbs_plan)
    doc = report_json(robot, robot_source, comps, configs, timing, land, marker, warnings)
    doc["optimize"] = {"folder": str(front.folder), "front": front.front,
                       "views": STUDY_PAGE if views is not None else None} if front is not None else None
    for entry in doc["configurations"]:
        sp, old = spreads.get(entry["name"]), befores.get(entry["name"])
        entry["predicted_spread"] = sp.to_json() if sp is not None else None
        entry["predicted_before_fit"] = old.result.to_json() if old is not None else None
        entry["explanation"] = explained[entry["name"]].to_json() if entry["name"] in explained else None

    folder = unique_dir(out, "report")
    try:
        html_path = atomic_write_text(folder / REPORT_NAME, html_text)
        dash_path = atomic_write_bytes(folder / DASHBOARD_NAME, dash)
        if views is not None:
            atomic_write_text(folder / STUDY_PAGE, views)
        videos = write_side_by_side(sbs_plan, folder, progress) if sbs_plan is not None else []
        if sbs_plan is not None:
            doc["side_by_side"] = [v.to_json() for v in videos]
        json_path = atomic_write_json(folder / JSON_NAME, {**doc, "wall_s": round(time.perf_counter() - t0, 2)})
    except WriteError:   # (a full disk) the new folder, made by this run, is not left half a report
        shutil.rmtree(folder, ignore_errors=True)
        raise
    except BaseException:   # interrupted: what was written is kept; an empty folder is not
        with contextlib.suppress(OSError):
            folder.rmdir()
        raise
    return ReportResult(folder, html_path, dash_path, json_path, comps, [f.key for f in figs],
                        warnings=warnings, side_by_side=videos)


def _simulate(robot: Robot, measured: dict[str, list[Trial]], added: dict[str, float], cycles: int | None,
              marker: str, progress: Callable[[str], None], side_by_side: bool, samples: int,
              before: Robot | None) -> tuple[dict[str, Configuration], list[Comparison], dict, dict]:
    """Each configuration simulated on its runs' schedule and compared with its trials; with
    ``samples``, its spread over the uncertain values; with ``before``, the robot before the
    fit predicted too. Returns (configs, comparisons, spreads, befores)."""
    configs: dict[str, Configuration] = {}
    comps: list[Comparison] = []
    spreads, befores = {}, {}
    for name, trials in measured.items():
        cfg, sched, n_cycles = _run_configuration(robot, name, trials, added.get(name), cycles)
        configs[name] = cfg
        period = cfg.robot.schedule.push_s + cfg.robot.schedule.wait_s
        progress(f"simulating {cfg.label} ({n_cycles} cycles)")
        pred = predict(name, cfg.robot, n_cycles, marker, keep_states=side_by_side)
        comps.append(compare(pred, trials, n_cycles, period))
        if samples and pred.valid:
            progress(f"simulating {samples} draws of {cfg.label}'s uncertain values")
            spreads[name] = spread(cfg.robot, n_cycles, marker, samples)
        if before is not None:
            old = configuration(before, name, added.get(name))
            befores[name] = predict(name, with_run_schedule(old.robot, sched), n_cycles, marker)
    return configs, comps, spreads, befores


def _explain(configs: dict[str, Configuration], comps: list[Comparison], progress: Callable[[str], None]) -> dict:
    """Each valid configuration's explanation (:func:`locust.sim.explain.explain`), on the cycles
    its prediction ran."""
    from ..sim.explain import explain

    out = {}
    for c in comps:
        cfg = configs[c.config]
        if c.prediction.result.valid:
            progress(f"explaining {cfg.label}")
            out[c.config] = explain(cfg.robot, c.prediction.result.cycles)
    return out


def _run_configuration(robot: Robot, name: str, trials: list[Trial], added_m: float | None,
                       cycles: int | None) -> tuple[Configuration, dict | None, int]:
    """Configuration ``name`` on the schedule its trials ran, that schedule, and the cycles to
    simulate (``cycles``, else the runs', else the robot's; never more than the runs recorded)."""
    cfg = configuration(robot, name, added_m)
    sched = run_schedule(name, trials)
    cfg = Configuration(cfg.name, cfg.added_m, with_run_schedule(cfg.robot, sched))
    if cycles and sched and cycles > sched["cycles"]:
        raise ReportError(f"--cycles {cycles}: the runs of {name} recorded only {sched['cycles']} cycles",
                          f"give --cycles {sched['cycles']} or fewer, or leave it out")
    n_cycles = cycles or (sched["cycles"] if sched else cfg.robot.schedule.cycles)
    return cfg, sched, n_cycles


def _figures(comps: list[Comparison], configs: dict[str, Configuration], land: Landscape | None,
             spreads: dict, befores: dict) -> list[page.Figure]:
    """The page's figures with their captions: overlay, jump, hops, the sweep landscape (with
    a sweep) and the firmware timing."""
    labels = {name: cfg.label for name, cfg in configs.items()}
    names_text = ", ".join(labels.values())
    figs = [
        page.Figure("overlay", f"Marker travel and height vs time: {names_text}",
                    "The nose marker's forward travel from where it stood and its height above standing, in mm, every "
                    "measured trial (solid) and the audited simulation (dashed), on the schedule's clock (t = 0 at the "
                    "first push; grey lines: cycle starts); a run that went over onto its back says so in its "
                    "height panel."
                    + (" Grey band: mean ± 1 sd of the simulation at draws of the robot file's uncertain values."
                       if spreads else "")
                    + (" Dotted red: the simulation on the robot before the fit." if befores else ""),
                    figures.overlay_figure(comps, spreads, befores)),
        page.Figure("jump", f"Jump height, measured against predicted: {names_text}",
                    "Highest marker point above standing in a hop that came back down, in mm; measured bars show the "
                    "mean over trials with ±1 sd error bars where repeated trials exist; hatched bars are the "
                    "simulation's. A run that went over in its first hop has no jump: its place says so.",
                    figures.bars_figure(comps, "jump")),
        page.Figure("hops", f"Each hop, measured against predicted: {names_text}",
                    "Per-hop marker travel and marker apex, in mm, of every trial (dots) and the simulation (dashed); "
                    "an apex only for a hop that came back down.",
                    figures.hops_figure(comps, spreads)),
    ]
    if land is not None:
        figs.append(page.Figure("landscape", f"Sweep landscape with {names_text} marked",
                                figures.landscape_caption(land, comps),
                                figures.landscape_figure(land, comps, configs)))
    figs.append(page.Figure("timing", f"Firmware timing of the runs: {names_text}",
                            "Start of every phase as the firmware measured it, minus the commanded start.",
                            figures.timing_figure(comps)))
    return figs


def _notes(comps: list[Comparison], land: Landscape | None, robot: Robot, marker: str) -> str:
    items = [
        "Predicted distance: locust sim's, locust.sim.run.run()'s chassis travel from the schedule's start to the "
        "end of the run, the figure locust sim and locust sweep print. Marker travel: the model's "
        f"{marker} marker in the same audited rollout, cut into hops and zeroed exactly as the track is, "
        "against the track's; the two travels agree on a robot that ends each hop on its feet and differ by "
        "centimetres on one that ends on its back.",
        "How a run ended: the simulation's outcome is locust sim's (the plate turned more than 45 deg nose up "
        "at the end of a cycle: on its back); a track's, where its marker rests: more than 30 mm above where it "
        "stood at the end of a cycle is on its back. A hop that went over, and every one after it, is no jump.",
        f"Predicted heights are those of the model's {marker} marker (the disc the camera follows, where the "
        f"sticker goes), from the same rollout: a point on a pitching body rises by its own amount, so the "
        f"model's {marker} site would not be the same point.",
        f"Measured figures come from the {marker} track. The schedule's start is placed by the same rule in "
        "both: the marker's first motion of more than 3 mm from where it stood, with the simulated delay "
        "between the first push and that motion; nothing is fitted to make them agree.",
        "Marker travel of a hop: marker x at rest at the end of a cycle minus at its start; apex: highest marker "
        "point in the cycle above the standing height; take-off speed: the marker's highest speed from the "
        "cycle's start to its apex (Tracker's central difference), in m/s. Errors are measured minus predicted; "
        "± is one sample standard deviation over repeated trials. Every length is in mm.",
    ]
    for c in comps:
        r = c.prediction.result
        if not r.valid:
            items.append(f"{c.config}: the simulation failed its audit ({'; '.join(r.reasons)}): no prediction.")
        for note in getattr(r, "notes", []):
            items.append(f"{c.config} simulation: {note}")
        for m in c.trials:
            gaps = [h.hop for h in m.hops if not math.isfinite(h.distance_m)]   # marker travel unseen
            if gaps:
                items.append(f"{c.config} {m.label}: the track does not cover hop(s) "
                             f"{', '.join(map(str, gaps))}.")
        if not c.trials:
            items.append(f"{c.config}: no track given, prediction only.")
    if land is not None and land.base != robot.name:
        items.append(f"The sweep's base robot is {land.base!r}, the report's is {robot.name!r}: the landscape "
                     "may not be the same robot.")
    return "<ul class=\"note\">" + "".join(f"<li>{page.esc(i)}</li>" for i in items) + "</ul>"


def sweep_notices(land: Landscape | None) -> list[Notice]:
    """A warning when the sweep's landscape is not all of it: the sweep is still being written
    (read as it stood), or it stopped short.

    Parameters
    ----------
    land : Landscape or None

    Returns
    -------
    list of Notice
        None or one, of kind ``sweep-unfinished``.
    """
    if land is None or land.finished:
        return []
    state = ("is still running (read as it stood; report again when it ends)" if land.running
             else "did not finish (rerun the same `locust sweep` to resume it)")
    of = f"{land.designs} of the {land.planned} designs it plans" if land.planned else f"{land.designs} designs"
    text = f"the sweep in {land.folder} {state}: the landscape shows only {of}"
    return [Notice("sweep-unfinished", "", "", text, text)]


def _video_caption(job, labels: dict[str, str]) -> str:
    """What a side-by-side video shows, and through which camera the simulation is filmed."""
    camera = "the filmed camera" if job.camera else "its own fixed camera (the cameras differ)"
    return (f"{labels[job.comparison.config]} {job.label}, filmed (left) beside the simulation (right) on the "
            f"schedule's clock, the simulation through {camera}: {job.camera_note}")


def _track_reading(t) -> str:
    """How a trial's track was read: ``metres``, ``cm -> m, mirrored``."""
    if t.track is None:
        return "—"
    return ("metres" if t.track.units == "m" else f"{t.track.units} -> m") + (", mirrored" if t.track.mirrored else "")


def render_html(robot: Robot, robot_source: str, comps, configs, figs, timing, land, marker: str,
                warnings: Sequence[Notice] = (), spreads: dict | None = None, side_by_side=None) -> str:
    """The report page.

    Parameters
    ----------
    robot : Robot
        The report's base robot.
    robot_source : str
        Where it came from.
    comps : list of Comparison
        One per configuration.
    configs : dict of str to Configuration
        The configurations by name.
    figs : list of Figure
        The page's figures, in order.
    timing : list of TimingRow
        The firmware timing rows of every run.
    land : Landscape or None
        The sweep landscape, if any.
    marker : str
        The tracked marker's name.
    warnings : sequence of Notice
        Shown at the top, collapsed (:func:`.checks.collapsed`).
    spreads : dict of str to Spread, optional
        Per configuration, its spread over the draws; adds the outcome table.
    side_by_side : sidebyside.Plan, optional
        The side-by-side videos to be written beside the page: each played in it.

    Returns
    -------
    str
        The whole HTML page.
    """
    labels = {n: c.label for n, c in configs.items()}
    added = {n: c.added_m for n, c in configs.items()}
    inputs = []
    for c in comps:
        for t in c.all_trials:
            where, why = recorded_on(t.record)
            inputs.append("<tr>" + page.td(labels[c.config], left=True) + page.td(t.label, left=True)
                          + page.td(str(t.track.path) if t.track else "—", left=True)
                          + page.td(str(t.run_path) if t.run_path else "—", left=True)
                          + page.td(t.config_from, c.config, f"config_from:{t.label}", left=True)
                          + page.td(where or "—", c.config, f"recorded_on:{t.label}", left=True)
                          + page.td(_track_reading(t), left=True) + "</tr>")
    sections = [("Warnings", page.warnings_list(collapsed(warnings)))] if warnings else []
    sections += [
        ("Summary", page.summary_table(comps, labels, added)),
        *([("Outcome over the draws", page.outcome_table(spreads, labels))] if spreads else []),
        ("Figures", "".join(page.figure_html(f) for f in figs)),
        *([("Side by side", page.videos_html([(j.name, _video_caption(j, labels)) for j in side_by_side.jobs],
                                             [f"{s.trial}: {s.note}" for s in side_by_side.skipped]))]
          if side_by_side is not None else []),
        ("Per-hop errors", page.hop_table(comps, labels)),
        ("Firmware timing", page.timing_table(timing, labels)),
        ("Parameters", f"<p class=\"note\">Robot {page.esc(robot.name)} from {page.esc(robot_source)}; each "
                       "configuration adds its length to all four links. Values are shown in mm, g and deg; the "
                       "dotted names are those of <code>--set</code> and <code>locust params</code>, whose values are "
                       "in the unit each name ends in.</p>"
                       + page.links_table([(labels[n], c.robot.link_lengths_m()) for n, c in configs.items()])
                       + page.params_table(parameter_rows(robot))),
        ("Inputs", page.table(["configuration", "trial", "track", "run record", "configuration from", "recorded on",
                               "track read in"], inputs, left_cols=7, id_="inputs")),
        ("How the numbers are made", _notes(comps, land, robot, marker)),
    ]
    meta = [f"robot: {robot.name} ({robot_source})",
            f"configurations: {', '.join(labels.values())}; cycles: "
            + ", ".join(f"{labels[c.config]} {c.cycles}" for c in comps),
            f"generated {time.strftime('%Y-%m-%d %H:%M:%S %z')} by locust {__version__}"]
    trials = [t for c in comps for t in c.all_trials]
    virtual = [t for t in trials if recorded_on(t.record)[0] == VIRTUAL]
    if virtual:
        meta.insert(1, f"measured trials: {len(virtual)} of {len(trials)} recorded on the virtual robot "
                       "(the simulated robot, not the physical one)")
    return page.page("Simulation against measurement", meta, sections,
                     media=side_by_side is not None and bool(side_by_side.jobs))


def _trial_json(t) -> dict:
    where, why = recorded_on(t.record)
    return {"label": t.label, "track": str(t.track.path) if t.track else None,
            "run": str(t.run_path) if t.run_path else None, "config_from": t.config_from,
            "recorded_on": where, "recorded_on_because": why,
            "track_units": t.track.units if t.track else None, "track_mirrored": t.track.mirrored if t.track else None}


def report_json(robot: Robot, robot_source: str, comps, configs, timing, land, marker: str,
                warnings: Sequence[Notice] = ()) -> dict:
    """The content of ``report.json`` (without its ``wall_s``).

    Parameters
    ----------
    robot : Robot
        The report's base robot.
    robot_source : str
        Where it came from.
    comps : list of Comparison
        One per configuration.
    configs : dict of str to Configuration
        The configurations by name.
    timing : list of TimingRow
        The firmware timing rows of every run.
    land : Landscape or None
        The sweep landscape, if any.
    marker : str
        The tracked marker's name.
    warnings : sequence of Notice
        The notices about the inputs.

    Returns
    -------
    dict
        Robot, version, marker, sweep, warnings, and per configuration its added length
        [m], link lengths [m], predicted and measured figures [m] (``predicted_distance_m`` is
        ``locust sim``'s distance, ``*_marker_travel_m`` the marker's), how each run ended and
        hop rows; NaN is left for the writer to turn into null.
    """
    out = {"robot": robot.name, "robot_source": robot_source, "locust_version": __version__, "marker": marker,
           "sweep": str(land.folder) if land else None, "warnings": [w.to_json() for w in warnings],
           "configurations": []}
    for c in comps:
        cfg = configs[c.config]
        out["configurations"].append({
            "name": c.config, "added_m": cfg.added_m, "cycles": c.cycles, "period_s": c.period_s,
            "link_lengths_m": list(cfg.robot.link_lengths_m()),
            "predicted": c.prediction.result.to_json(),
            "predicted_distance_m": c.predicted_distance_m,     # locust sim's: the chassis over the run
            "predicted_outcome": ending.to_json() if (ending := c.predicted_ending) else None,
            "predicted_marker_travel_m": c.predicted_marker_travel_m,
            "predicted_jump_m": c.predicted_jump_m,
            "predicted_marker_hops": [asdict(h) for h in c.prediction.hops],
            "onset_latency_s": c.prediction.onset_latency_s,
            "measured": {"trials": c.marker_travel.n, "marker_travel_m": asdict(c.marker_travel),
                         "marker_travel_per_hop_m": asdict(c.marker_travel_per_hop), "jump_m": asdict(c.jump),
                         "outcomes": [{"trial": m.label, **ending_of(m).to_json()} for m in c.trials]},
            "hops": [{**asdict(r), "marker_travel_error_m": r.marker_travel_error_m, "apex_error_m": r.apex_error_m}
                     for r in c.rows],
            "trials": [_trial_json(t) for t in c.all_trials],
        })
    out["timing"] = [asdict(r) for r in timing]
    return out   # written by atomic_write_json: NaN/inf become null there
