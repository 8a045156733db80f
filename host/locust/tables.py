"""The short tables ``locust sim``, ``locust hop`` and ``locust virtual`` print for a person,
and the figures every command prints (:func:`for_person`, :func:`quantity`).

Lengths in mm, masses in g, angles in deg, times in ms or s; ``--json`` (where a command has
it) stays the machine-readable form in SI units. Each function returns the lines; the command
echoes them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

INDENT = "  "


def table(header: Sequence[str], rows: Sequence[Sequence[str]], indent: str = INDENT) -> list[str]:
    """Columns right-aligned to the wider of the header and its cells, two spaces apart.

    Parameters
    ----------
    header : sequence of str
    rows : sequence of sequence of str
    indent : str
        Before each line.

    Returns
    -------
    list of str
        The header line, then one line per row.
    """
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(header)]
    return [indent + "  ".join(cell.rjust(w) for cell, w in zip(line, widths, strict=True))
            for line in (header, *rows)]


def mm(length_m: float, decimals: int = 2) -> str:
    """A length given in metres, written in mm (``nan`` when it is not finite).

    Parameters
    ----------
    length_m : float
        [m].
    decimals : int

    Returns
    -------
    str
        [mm], without the unit.
    """
    return f"{length_m * 1000:.{decimals}f}" if math.isfinite(length_m) else "nan"


def verdict(valid: bool) -> str:
    """``valid`` or ``INVALID``, as the command line prints a simulation's audit.

    Parameters
    ----------
    valid : bool

    Returns
    -------
    str
    """
    return "valid" if valid else "INVALID"


def outcome_words(outcome: str) -> str:
    """``goes_over`` -> ``goes over`` (locust.sim.outcome's names, for a person).

    Parameters
    ----------
    outcome : str

    Returns
    -------
    str
    """
    return outcome.replace("_", " ")


def sim_lines(r, verbose: bool = False) -> list[str]:
    """``locust sim``: a :class:`locust.sim.result.SimResult` as the verdict, one row per hop,
    the totals, the convergence check and the notes; ``verbose``: the linkage's kinematics too
    (Grashof class and transmission angle: words for the expert, kept out of the first look).

    Parameters
    ----------
    r : locust.sim.result.SimResult
    verbose : bool

    Returns
    -------
    list of str
    """
    said = f"{verdict(r.valid)}, {outcome_words(r.outcome)}" if r.outcome else verdict(r.valid)
    lines = [f"{r.robot_name}: {said} ({r.cycles} cycle{'' if r.cycles == 1 else 's'}, "
             f"time step {r.timestep_s:g} s, "
             f"{r.wall_s:.1f} s wall)"]
    lines += [f"{INDENT}reason: {reason}" for reason in r.reasons]
    if not r.valid:
        return lines
    if verbose:
        lines.append(f"{INDENT}linkage: {r.grashof} (Grashof class), worst transmission angle "
                     f"{r.transmission_deg:.0f} deg (the angle at which the coupler pushes the leg; 90 is best)")
    lines += hop_table([vars(h) for h in r.hops])
    lines.append(totals_line(r.distance_m, r.max_nose_height_m))
    if r.convergence:
        lines.append(INDENT + convergence_line(r.convergence))
    lines += [f"{INDENT}note: {note}" for note in r.notes]
    return lines


def hop_table(hops: list[dict]) -> list[str]:
    """One row per hop (the fields of :class:`locust.sim.hops.Hop`, as a dict): distance, nose
    and centre-of-mass rise above standing in mm, flight in ms.

    Parameters
    ----------
    hops : list of dict
        Lengths in metres, times in seconds.

    Returns
    -------
    list of str
    """
    rows = [[str(h["cycle"]), mm(h["distance_m"]), mm(h["nose_apex_m"]), mm(h["com_apex_m"]),
             f"{h['flight_s'] * 1000:.1f}"] for h in hops]
    return table(["hop", "distance mm", "nose rise mm", "CoM rise mm", "flight ms"], rows)


def totals_line(distance_m: float, max_nose_height_m: float) -> str:
    """The run's whole distance and its highest nose point, in mm.

    Parameters
    ----------
    distance_m, max_nose_height_m : float
        [m].

    Returns
    -------
    str
    """
    return f"{INDENT}total distance {mm(distance_m)} mm; highest nose {mm(max_nose_height_m)} mm above the floor"


def nose_load_line(nose_load_kg: float, total_mass_kg: float) -> str:
    """The standing robot's weight on its nose: what a kitchen scale under the nose reads.

    Parameters
    ----------
    nose_load_kg, total_mass_kg : float
        [kg].

    Returns
    -------
    str
        Both in grams, with how a kitchen scale reads it.
    """
    return (f"{INDENT}standing: {nose_load_kg * 1000:.1f} g of its {total_mass_kg * 1000:.1f} g on the nose "
            "(a kitchen scale under the nose, the feet level with its pan)")


def convergence_line(c: dict) -> str:
    """The time-step check of ``--check-convergence``: the change at half the step.

    Parameters
    ----------
    c : dict
        The check's figures: the half step [s], the changes in distance per hop and in highest
        nose [mm] and relative, and whether they converged.

    Returns
    -------
    str
    """
    said = "converged" if c["converged"] else "NOT converged (within 1 % or 0.1 mm asked)"
    return (f"at half the time step ({c['half_timestep_s']:g} s): distance "
            f"{c['distance_change_mm_per_hop']:.3f} mm per hop ({c['distance_rel_change'] * 100:.2f} %), "
            f"highest nose {c['max_nose_height_change_mm']:.3f} mm ({c['max_nose_height_rel_change'] * 100:.2f} %): "
            f"{said}")


def ensemble_convergence_lines(ec) -> list[str]:
    """``--check-convergence`` with ``--samples``: the draws' shares and percentiles at half the
    step against their intervals, and the draws that flip (:mod:`locust.sim.ensemble`).

    Parameters
    ----------
    ec : locust.sim.ensemble.EnsembleConvergence

    Returns
    -------
    list of str
    """
    said = "converged" if ec.converged else "NOT converged (a share or a percentile outside its interval)"
    lines = [f"{INDENT}the {ec.n} draws at half the time step ({ec.half_timestep_s:g} s): {said}"]
    for sh in ec.shares:
        mark = "" if sh.within else "  OUTSIDE"
        lines.append(f"{INDENT * 2}{outcome_words(sh.outcome):17s} {sh.share * 100:5.1f} % -> "
                     f"{sh.half_share * 100:5.1f} %  (95 % binomial interval {sh.low * 100:.1f}-{sh.high * 100:.1f} %)"
                     f"{mark}")
    for q in ec.quantiles:
        mark = "" if q.within else "  OUTSIDE"
        what = "distance" if q.figure == "distance_m" else "highest nose"
        lines.append(f"{INDENT * 2}{what} {q.q * 100:.0f}th percentile {q.value_m * 1000:8.2f} -> "
                     f"{q.half_value_m * 1000:8.2f} mm  (95 % bootstrap interval {q.low_m * 1000:.2f} to "
                     f"{q.high_m * 1000:.2f} mm){mark}")
    for f in ec.flips:
        a = outcome_words(f.outcome) if f.outcome else "invalid"
        b = outcome_words(f.half_outcome) if f.half_outcome else "invalid"
        lines.append(f"{INDENT * 2}draw {f.draw} {a} at the step, {b} at half of it: on the threshold "
                     "(a single draw's flip, judged by the shares above)")
    return lines


def mean_sd(mean: float, sd: float, scale: float = 1000.0) -> str:
    """``mean +- sd`` to sensible digits: the sd to two significant figures, the mean to the
    same decimal place (a single draw: its value, one decimal). Values in SI times ``scale``.

    Parameters
    ----------
    mean, sd : float
        In SI units.
    scale : float
        Applied to both (1000: metres shown in mm).

    Returns
    -------
    str
    """
    if not math.isfinite(mean):
        return "nan"
    if not math.isfinite(sd):
        return f"{mean * scale:.1f}"
    s = sd * scale
    decimals = max(0, 1 - math.floor(math.log10(s))) if s > 0 else 1
    return f"{mean * scale:.{decimals}f} ± {s:.{decimals}f}"


def spread_lines(spread) -> list[str]:
    """``locust sim --samples``: each outcome's share of the draws and its own figures, mean
    ± sd in mm (never one sd across outcomes: near the threshold the spread is bimodal).

    Parameters
    ----------
    spread : locust.sim.samples.Samples
        The draws' outcomes and figures.

    Returns
    -------
    list of str
    """
    lines = [f"{INDENT}{spread.n} draws of {len(spread.uncertain)} uncertain values ({spread.n_valid} valid):"]
    for name, o in spread.outcomes.items():
        line = f"{INDENT * 2}{outcome_words(name):17s} {o.n:3d} of {spread.n_valid} ({o.share * 100:3.0f} %)"
        if o.n:
            line += (f": distance {mean_sd(o.distance_m.mean, o.distance_m.sd)} mm, highest nose "
                     f"{mean_sd(o.max_nose_height_m.mean, o.max_nose_height_m.sd)} mm")
        lines.append(line)
    return lines


def sensitivity_lines(sens) -> list[str]:
    """The values whose interval reaches another outcome (:mod:`locust.sim.sensitivity`).

    Parameters
    ----------
    sens : locust.sim.sensitivity.Sensitivity

    Returns
    -------
    list of str
    """
    nominal = outcome_words(sens.nominal) if sens.nominal else "invalid"
    deciding = sens.deciding
    if not deciding:
        return [f"{INDENT}no single value at -/+{sens.k_sd:g} sd changes the outcome ({nominal})"]
    lines = [f"{INDENT}decided by (each value alone at -/+{sens.k_sd:g} sd; as given it {nominal}):"]
    for e in deciding:   # each value in the unit a person reads (a length in mm), with its unit
        name, factor, unit = for_person(e.key)
        ends = [f"{v * factor:.4g} {unit} {outcome_words(o) if o else 'invalid'}".replace("  ", " ") for v, o in
                ((e.low_value, e.low_outcome), (e.high_value, e.high_outcome))]
        lines.append(f"{INDENT * 2}{name} (sd {e.sd * factor:g} {unit}".rstrip() + f"): {ends[0]}; {ends[1]}")
    return lines


EXPLAIN_ROWS = 8   # thresholds and tornado bars printed (--json has every one)


def _edge_text(key: str, edge) -> str:
    if edge is None:
        return "none probed"
    sd = f" ({edge.distance_sd:+.1f} sd)" if edge.distance_sd is not None else ""
    what = outcome_words(edge.outcome) if edge.outcome else "invalid"
    return f"{quantity(key, edge.value, 3)}{sd} {what}"


def explain_lines(expl) -> list[str]:
    """``locust sim --explain``: the words, the nearest thresholds and the largest tornado bars.

    Parameters
    ----------
    expl : locust.sim.explain.Explanation

    Returns
    -------
    list of str
    """
    lines = [f"{INDENT}why ({expl.runs} runs of {expl.cycles} cycle{'s' if expl.cycles != 1 else ''}):"]
    lines += [f"{INDENT * 2}{w}" for w in expl.words]
    rows = []
    for t in expl.thresholds[:EXPLAIN_ROWS]:
        sd = quantity(t.key, t.sd, 2) if t.sd else "design"
        rows.append([label(t.key), quantity(t.key, t.value, 4), sd, _edge_text(t.key, t.below),
                     _edge_text(t.key, t.above)])
    lines.append(f"{INDENT}where the outcome changes (each value alone; nearest first):")
    lines += table(["value", "as given", "sd", "below", "above"], rows, indent=INDENT * 2)
    bars = []
    for b in expl.tornado[:EXPLAIN_ROWS]:
        nose, dist = b.swing("nose_rise_m"), b.swing("distance_m")
        bars.append([label(b.key), quantity(b.key, b.sd, 2), f"{nose * 1000:.1f}", f"{dist * 1000:.1f}"])
    if bars:
        lines.append(f"{INDENT}effect of each value at -/+{expl.k_sd:g} sd (first hop's nose rise, distance; largest "
                     "first):")
        lines += table(["value", "sd", "nose rise mm", "distance mm"], bars, indent=INDENT * 2)
    return lines


def plant_lines(summary: dict) -> list[str]:
    """``locust hop --port sim`` and ``locust virtual``: what the virtual robot's plant did
    (the dict its ``close()`` returns: the live MuJoCo model's audited run, one row per push,
    or the recorder's count).

    Parameters
    ----------
    summary : dict

    Returns
    -------
    list of str
    """
    if summary.get("plant") != "mujoco":
        return [f"servo commands recorded: {summary.get('commands', 0)}"]
    rtf = summary["realtime_factor"]
    said = verdict(summary["valid"]) + (f", {outcome_words(summary['outcome'])}" if summary.get("outcome") else "")
    lines = [f"simulated robot: {said} ({summary['sim_time_s']:.3f} s simulated, "
             f"{rtf:.1f}x real time)" if math.isfinite(rtf) else
             f"simulated robot: {said} ({summary['sim_time_s']:.3f} s simulated)"]
    lines += [f"{INDENT}reason: {reason}" for reason in summary["reasons"]]
    if summary["valid"]:
        if summary.get("hops"):
            lines += hop_table(summary["hops"])
        lines.append(totals_line(summary["distance_m"], summary["max_nose_height_m"]))
    if summary.get("video_path"):
        lines.append(f"{INDENT}video: {summary['video_path']} ({summary['frames']} frames)")
    return lines


# -- fitted values, as `locust calibrate` prints them ------------------------------------------
UNIT_SUFFIXES = (   # a key's unit from its name's end (longest first): _nm_ is newton-metres, never nm
    ("_nms_per_rad", "N·m·s/rad"), ("_nm_per_rad", "N·m/rad"), ("_ns_per_m", "N·s/m"), ("_n_per_m", "N/m"),
    ("_rad_per_s", "rad/s"), ("_m_per_s", "m/s"), ("_kg_per_m3", "kg/m³"), ("_kgm2", "kg·m²"), ("_nm2", "N·m²"),
    ("_kg", "kg"), ("_hz", "Hz"), ("_deg", "deg"), ("_mm", "mm"), ("_ms", "ms"), ("_nm", "N·m"), ("_ohm", "Ω"),
    ("_rad", "rad"), ("_us", "µs"), ("_m", "m"), ("_n", "N"), ("_s", "s"), ("_v", "V"),
    ("_a", "A"),
)


# what a person reads of a value in SI (its key's unit): lengths in mm, masses in g, angles in deg
PERSON_UNITS = {"m": (1000.0, "mm"), "m/s": (1000.0, "mm/s"), "kg": (1000.0, "g"), "rad": (180.0 / math.pi, "deg")}


def person_unit(unit: str) -> tuple[float, str]:
    """The factor from an SI unit to the one a person reads it in, and that unit's name.

    Parameters
    ----------
    unit : str
        A unit as :func:`split_unit` names it (``m``, ``kg``, ``N·m/rad``, ...).

    Returns
    -------
    factor, shown : float, str
        ``(1000.0, "mm")`` for ``m``, ``(1000.0, "g")`` for ``kg``, ``(57.29..., "deg")`` for
        ``rad``; any other unit as it is, factor 1.

    Examples
    --------
    >>> person_unit("m"), person_unit("N·m/rad")
    ((1000.0, 'mm'), (1.0, 'N·m/rad'))
    """
    return PERSON_UNITS.get(unit, (1.0, unit))


def for_person(key: str) -> tuple[str, float, str]:
    """A value's key as a person reads it: its name less the unit suffix, the factor from the
    key's unit to the shown one, and the shown unit.

    Parameters
    ----------
    key : str
        A name with a unit suffix (``rms_residual_m``, ``geometry.crank_start_deg``).

    Returns
    -------
    name, factor, unit : str, float, str

    Examples
    --------
    >>> for_person("rms_residual_m")
    ('rms_residual', 1000.0, 'mm')
    """
    name, unit = split_unit(key)
    factor, shown = person_unit(unit)
    return name, factor, shown


# keys whose last part alone would read the same as another's
LABELS = {"schedule.push_deg": "push angle", "schedule.push_s": "push time"}


def label(key: str) -> str:
    """A dotted key's last part less its unit, in words: ``geometry.servo_axis_x_m`` -> ``servo axis x``
    (``schedule.push_deg`` and ``schedule.push_s``: ``push angle``, ``push time``).

    Parameters
    ----------
    key : str

    Returns
    -------
    str
    """
    return LABELS.get(key) or split_unit(key)[0].rpartition(".")[2].replace("_", " ")


def quantity(key: str, value: float, digits: int = 4) -> str:
    """``value`` (in its key's unit) to ``digits`` significant figures in the unit a person
    reads, with the unit: ``scale_m`` 0.0305 -> ``30.50 mm``.

    Parameters
    ----------
    key : str
        The value's name, its unit the suffix.
    value : float
    digits : int

    Returns
    -------
    str
    """
    _, factor, unit = for_person(key)
    return f"{sig(value * factor, digits)} {unit}".rstrip()


def split_unit(key: str) -> tuple[str, str]:
    """``hinge_stiffness_nm_per_rad`` -> (``hinge_stiffness``, ``N·m/rad``); no unit: (key, "").

    Parameters
    ----------
    key : str
        A name with a unit suffix (``_m``, ``_nm_per_rad``, ...).

    Returns
    -------
    name, unit : str
    """
    section, dot, name = key.rpartition(".")
    for suffix, unit in UNIT_SUFFIXES:
        if name.endswith(suffix) and len(name) > len(suffix):
            return section + dot + name[: -len(suffix)], unit
    return key, ""


def sig(value: float, digits: int = 4) -> str:
    """``digits`` significant figures; powers of ten as ``1.458e-4`` below 1e-3 and from 1e5.

    Parameters
    ----------
    value : float
    digits : int

    Returns
    -------
    str
    """
    if not math.isfinite(value) or value == 0:
        return f"{value:g}"
    if 1e-3 <= abs(value) < 1e5:
        return f"{value:#.{digits}g}".rstrip(".")
    mantissa, exp = f"{value:.{digits - 1}e}".split("e")
    return f"{mantissa}e{int(exp)}"


def value_line(key: str, value, unit_of_key: bool = True) -> str:
    """A plain figure with its unit column: numbers to 4 significant figures in the unit a
    person reads (:func:`for_person`: a key in m shown in mm, in kg in g), lists joined.

    Parameters
    ----------
    key : str
        The value's name (a dotted key whose suffix is its unit).
    value : float, list or str
    unit_of_key : bool
        Take the unit from the key's suffix.

    Returns
    -------
    str
    """
    name, factor, unit = for_person(key) if unit_of_key else (key, 1.0, "")
    if isinstance(value, (list, tuple)):
        text = ", ".join(sig(v * factor) if isinstance(v, float) else str(v) for v in value)
    elif isinstance(value, float):
        text = sig(value * factor)
    else:
        text = str(value)
    return f"{name:28s} {text:>10s}  {unit}".rstrip() if len(text) <= 10 else f"{name:28s} {text}  {unit}".rstrip()


def estimate_line(key: str, value: float, std: float | None, ci95=None, note: str = "") -> str:
    """``k = 1.458e-4 N·m/rad ± 0.2 %  (95 %: 1.453e-4 … 1.463e-4)`` as a table row: the key less
    its unit, the value, the unit, one standard deviation as a share of the value, the interval;
    in the unit a person reads (:func:`for_person`: a length in mm, a mass in g).

    Parameters
    ----------
    key : str
        The value's name, its unit the suffix.
    value : float
    std : float or None
        One standard deviation, in the value's unit.
    ci95 : (float, float), optional
        The 95% interval.
    note : str
        Appended.

    Returns
    -------
    str
    """
    name, k, unit = for_person(key)
    head = f"{name:28s} {sig(value * k):>10s}  {unit:10s}"
    if std is None or not math.isfinite(std):
        return f"{head} (undetermined){note}"
    rel = 100 * std / abs(value) if value else math.inf
    spread = f"± {rel:.1f} %" if rel < 10 else f"± {rel:.0f} %" if math.isfinite(rel) else f"± {sig(std * k)}"
    interval = f"  (95 %: {sig(ci95[0] * k)} … {sig(ci95[1] * k)})" if ci95 and None not in ci95 else ""
    return f"{head} {spread}{interval}{note}"
