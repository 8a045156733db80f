"""The report as one self-contained HTML page: figures embedded as base64 PNG, no scripts,
no outside resources (a Content-Security-Policy forbids them, so a browser proves it). The
side-by-side videos (``--side-by-side``) are the one exception, and not an outside one: they
are written beside the page and played from there (``<video controls>``, a relative src; the
policy then allows media from the page's own origin, nothing else).

Every number cell carries ``data-config`` and ``data-field`` so tests and scripts can read
the page's figures back exactly as printed.
"""

from __future__ import annotations

import base64
import html
import math
from dataclasses import dataclass

from .compare import Comparison, TimingRow, ending_of
from .ending import trials_words, words

CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'"
CSP_MEDIA = CSP + "; media-src 'self'"    # with the side-by-side videos beside the page
# a backslash at a line's end joins the next line to it (no newline in the CSS)
STYLE = """
body{font:14px/1.45 system-ui,-apple-system,'DejaVu Sans',sans-serif;\
margin:2em auto;max-width:1180px;color:#222;padding:0 1em}
h1{font-size:1.6em;margin-bottom:.2em}h2{margin-top:1.8em;border-bottom:1px solid #ddd;padding-bottom:.2em}
table{border-collapse:collapse;margin:.6em 0;font-size:13px}\
th,td{border:1px solid #ddd;padding:3px 8px;text-align:right}td{white-space:nowrap}td.l{white-space:normal}
th{background:#f4f4f4}td.l,th.l{text-align:left}tr.invalid td{color:#b00020}
figure{margin:1em 0}figure img,figure video{max-width:100%;border:1px solid #eee}\
figcaption{color:#555;font-size:13px}
.meta{color:#555}.note{color:#555;font-size:13px}code{background:#f6f6f6;padding:0 3px}
ul.warn{background:#fff6e5;border:1px solid #f0c36d;padding:.6em 1em .6em 2.2em}ul.warn li{margin:.2em 0}
"""


@dataclass(frozen=True)
class Figure:
    """One figure of the page.

    Attributes
    ----------
    key : str
        Its id (``fig-<key>`` on the page).
    title, caption : str
        Its title and caption.
    png : bytes
        The image, PNG.
    link : tuple of str, optional
        ``(href, text)``: a page beside the report the caption links to ("" for none).
    """

    key: str
    title: str
    caption: str
    png: bytes
    link: tuple[str, str] | None = None


def esc(value) -> str:
    """``value`` as text, HTML-escaped (quotes included).

    Parameters
    ----------
    value : object
        Anything; ``str()`` is taken.

    Returns
    -------
    str
        Safe in element text and attribute values.
    """
    return html.escape(str(value), quote=True)


def mm(value: float, digits: int = 1) -> str:
    """A length in metres as millimetres (the filmed unit of every hop figure), 0.1 mm by default.

    Parameters
    ----------
    value : float or None
        A length [m].
    digits : int
        Digits after the decimal point.

    Returns
    -------
    str
        The length in mm; ``—`` for None or a non-finite value.
    """
    return f"{value * 1000:.{digits}f}" if value is not None and math.isfinite(value) else "—"


def mm_pm(mean: float, std: float | None) -> str:
    """A mean length, and its standard deviation when there is one, in millimetres.

    Parameters
    ----------
    mean : float
        The mean [m].
    std : float or None
        The standard deviation [m].

    Returns
    -------
    str
        ``12.3 ± 0.4`` [mm]; ``—`` when the mean is not finite.
    """
    if not math.isfinite(mean):
        return "—"
    return mm(mean) + (f" ± {std * 1000:.1f}" if std is not None else "")


def speed(value_m_per_s: float) -> str:
    """A speed in m/s to 0.01 m/s (``—`` when not finite).

    Parameters
    ----------
    value_m_per_s : float
        [m/s].

    Returns
    -------
    str
    """
    return f"{value_m_per_s:.2f}" if math.isfinite(value_m_per_s) else "—"


def pct(err: float, ref: float, resolution_m: float = math.nan) -> str:
    """The error in percent of ``ref``; "within 1 px" when it is smaller than the tracking
    resolution (one pixel, in metres), which no percentage of a small jump can beat.

    Parameters
    ----------
    err : float
        The error [m].
    ref : float
        The reference, the predicted figure [m].
    resolution_m : float
        One pixel at the marker [m]; nan when unknown.

    Returns
    -------
    str
        ``+4.2 %``, ``within 1 px (0.4 mm)``, or ``—`` without a finite, nonzero reference.
    """
    if not (math.isfinite(err) and math.isfinite(ref)) or ref == 0:
        return "—"
    if math.isfinite(resolution_m) and abs(err) < resolution_m:
        return f"within 1 px ({resolution_m * 1000:.1f} mm)"
    return f"{100 * err / abs(ref):+.1f} %"


def td(text: str, config: str | None = None, field: str | None = None, left: bool = False) -> str:
    """One table cell, its text escaped.

    Parameters
    ----------
    text : str
        The cell's text.
    config : str, optional
        Its configuration, as ``data-config``.
    field : str, optional
        What it holds, as ``data-field``.
    left : bool
        Left-aligned and wrapping (class ``l``).

    Returns
    -------
    str
        The ``<td>`` element.
    """
    attrs = "" if not left else ' class="l"'
    if config is not None:
        attrs += f' data-config="{esc(config)}"'
    if field is not None:
        attrs += f' data-field="{esc(field)}"'
    return f"<td{attrs}>{esc(text)}</td>"


def table(headers: list[str], rows: list[str], left_cols: int = 1, id_: str = "",
          groups: list[tuple[str, int]] | None = None) -> str:
    """A table from its headers and ready-made rows.

    Parameters
    ----------
    headers : list of str
        Column headers.
    rows : list of str
        ``<tr>`` elements.
    left_cols : int
        How many leading columns' headers are left-aligned.
    id_ : str
        The table's id; none when empty.
    groups : list of (str, int), optional
        A header row above, each title over its number of columns.

    Returns
    -------
    str
        The ``<table>`` element.
    """
    head = "".join(f'<th class="l">{esc(h)}</th>' if i < left_cols else f"<th>{esc(h)}</th>"
                   for i, h in enumerate(headers))
    over = ("<tr>" + "".join(f'<th colspan="{n}">{esc(t)}</th>' for t, n in groups) + "</tr>") if groups else ""
    ident = f' id="{esc(id_)}"' if id_ else ""
    return f"<table{ident}><thead>{over}<tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>"


def summary_table(comps: list[Comparison], labels: dict[str, str], added: dict[str, float]) -> str:
    """Per configuration: how the simulated and the filmed runs ended (:mod:`.ending`), the
    simulation's distance (``locust sim``'s, the chassis over the run), the marker's travel
    predicted and measured with its error, and the jump (highest marker point in a hop that came
    back down) with its error, in mm and percent; then the tracking resolution.

    Parameters
    ----------
    comps : list of Comparison
        The configurations.
    labels : dict of str to str
        The configurations' display names.
    added : dict of str to float
        The length each adds to every link [m].

    Returns
    -------
    str
        The table (id ``summary``) and its note, HTML.
    """
    rows = []
    for c in comps:
        name = c.config
        valid = c.prediction.valid
        ending = c.predicted_ending
        travel_err = c.marker_travel.mean - c.predicted_marker_travel_m
        jump_err = c.jump.mean - c.predicted_jump_m
        cells = [
            td(labels[name], left=True), td(f"+{added[name] * 1000:g}"), td(str(c.marker_travel.n), name, "trials"),
            td(words(ending) if ending else "—", name, "predicted_outcome", left=True),
            td(trials_words([ending_of(m) for m in c.trials]), name, "measured_outcome", left=True),
            td(mm(c.predicted_distance_m), name, "predicted_distance_mm"),
            td(mm(c.predicted_marker_travel_m), name, "predicted_marker_travel_mm"),
            td(mm_pm(c.marker_travel.mean, c.marker_travel.std), name, "measured_marker_travel_mm"),
            td(mm(travel_err), name, "marker_travel_error_mm"),
            td(pct(travel_err, c.predicted_marker_travel_m, c.resolution_m)),
            td(mm(c.predicted_jump_m), name, "predicted_jump_mm"),
            td(mm_pm(c.jump.mean, c.jump.std), name, "measured_jump_mm"),
            td(mm(jump_err), name, "jump_error_mm"), td(pct(jump_err, c.predicted_jump_m, c.resolution_m)),
            td("valid" if valid else "INVALID: " + "; ".join(c.prediction.result.reasons), name, "sim_status",
               left=True),
        ]
        rows.append(f'<tr{"" if valid else " class=invalid"}>{"".join(cells)}</tr>')
    groups = [("", 3), ("how it ended", 2), ("distance (mm)", 1), ("marker travel over the run", 4),
              ("jump: highest marker point above standing, in a hop that came back down", 4), ("", 1)]
    headers = ["configuration", "added (mm)", "trials", "predicted", "measured", "predicted (locust sim)",
               "predicted (mm)", "measured (mm)", "error (mm)", "error", "predicted (mm)", "measured (mm)",
               "error (mm)", "error", "simulation"]
    known = [(labels[c.config], c.resolution_m) for c in comps if math.isfinite(c.resolution_m)]
    note = ("<p class=\"note\">Distance: the robot's travel over the run as <code>locust sim</code> prints it (the "
            "chassis, from the schedule's start to the run's end); the camera follows a marker, whose travel is "
            "compared like with like. A hop that ends with the robot on its back is no jump: its marker's height is "
            "where it lies.")
    if known:
        note += (" Tracking resolution (one pixel at the marker): "
                 + ", ".join(f"{esc(label)} {res * 1000:.3g} mm" for label, res in known)
                 + '; an error smaller than that is not measured and reads "within 1 px".')
    return table(headers, rows, id_="summary", groups=groups) + note + "</p>"


def outcome_table(spreads: dict, labels: dict[str, str]) -> str:
    """Each configuration's draws (``--samples``) by outcome: its share, and its own distance
    (``locust sim``'s, over the run) and highest nose as mean ± sd (one sd across outcomes would
    hide a split), as ``locust sim --samples`` prints them.

    Parameters
    ----------
    spreads : dict of str to Spread or None
        Per configuration, its spread (None ones are left out).
    labels : dict of str to str
        The configurations' display names.

    Returns
    -------
    str
        The table (id ``outcomes``), lengths in mm, HTML.
    """
    rows = []
    for name, sp in spreads.items():
        if sp is None:
            continue
        for outcome, o in sp.outcomes.items():
            cells = [td(labels[name], left=True), td(outcome.replace("_", " "), left=True),
                     td(f"{o.n} of {sp.n_valid} ({o.share * 100:.0f} %)", name, f"outcome_share:{outcome}"),
                     td(mm_pm(o.distance_m.mean, o.distance_m.sd if math.isfinite(o.distance_m.sd) else None)),
                     td(mm_pm(o.max_nose_height_m.mean,
                              o.max_nose_height_m.sd if math.isfinite(o.max_nose_height_m.sd) else None))]
            rows.append(f"<tr>{''.join(cells)}</tr>")
    headers = ["configuration", "outcome", "draws", "distance (mm)", "highest nose above the floor (mm)"]
    return table(headers, rows, left_cols=2, id_="outcomes")


def hop_table(comps: list[Comparison], labels: dict[str, str]) -> str:
    """Every measured hop against the predicted one: how it ended, the marker's travel and its
    apex [mm] (none for a hop that did not end on the robot's feet), with errors, and its
    take-off speed [m/s].

    Parameters
    ----------
    comps : list of Comparison
        The configurations.
    labels : dict of str to str
        The configurations' display names.

    Returns
    -------
    str
        The table (id ``hops``), or a note when no track was given, HTML.
    """
    rows = []
    for c in comps:
        for r in c.rows:
            key = f"{r.trial}#{r.hop}"
            rows.append("<tr>" + "".join([
                td(labels[c.config], left=True), td(r.trial, left=True), td(str(r.hop)),
                td(r.measured_state or "—", c.config, f"hop_measured_state:{key}", left=True),
                td(r.predicted_state or "—", c.config, f"hop_predicted_state:{key}", left=True),
                td(mm(r.measured_marker_travel_m), c.config, f"hop_measured_marker_travel_mm:{key}"),
                td(mm(r.predicted_marker_travel_m), c.config, f"hop_predicted_marker_travel_mm:{key}"),
                td(mm(r.marker_travel_error_m)),
                td(pct(r.marker_travel_error_m, r.predicted_marker_travel_m, c.resolution_m)),
                td(mm(r.measured_apex_m), c.config, f"hop_measured_apex_mm:{key}"),
                td(mm(r.predicted_apex_m), c.config, f"hop_predicted_apex_mm:{key}"),
                td(mm(r.apex_error_m)), td(pct(r.apex_error_m, r.predicted_apex_m, c.resolution_m)),
                # take-off speed: the marker's fastest from the hop's start to its apex (Tracker's v)
                td(speed(r.measured_takeoff_speed_m_per_s), c.config, f"hop_measured_takeoff_speed_m_per_s:{key}"),
                td(speed(r.predicted_takeoff_speed_m_per_s), c.config, f"hop_predicted_takeoff_speed_m_per_s:{key}"),
            ]) + "</tr>")
    if not rows:
        return '<p class="note">No tracks were given: nothing measured to compare hop by hop.</p>'
    groups = [("", 3), ("ended", 2), ("marker travel", 4), ("apex above standing (a hop that came back down)", 4),
              ("take-off speed", 2)]
    headers = ["configuration", "trial", "hop", "measured", "predicted", "measured (mm)", "predicted (mm)",
               "error (mm)", "error", "measured (mm)", "predicted (mm)", "error (mm)", "error",
               "measured (m/s)", "predicted (m/s)"]
    return table(headers, rows, left_cols=2, id_="hops", groups=groups)


def timing_table(rows: list[TimingRow], labels: dict[str, str]) -> str:
    """Each run's phase start errors: mean, sd, largest, latest and earliest [ms].

    Parameters
    ----------
    rows : list of TimingRow
        One per run record.
    labels : dict of str to str
        The configurations' display names.

    Returns
    -------
    str
        The table (id ``timing``), or a note when no run record was given, HTML.
    """
    if not rows:
        return '<p class="note">No run records were given.</p>'
    out = []
    for r in rows:
        def ms(attr: str, j=r.jitter) -> str:
            return f"{getattr(j, attr):.3f}" if j is not None else "—"

        out.append("<tr>" + "".join([
            td(labels[r.config], left=True), td(r.trial, left=True),
            td(f"{r.status}; {r.timing_note}" if r.timing_note else r.status, r.config, f"status:{r.trial}", left=True),
            td(r.firmware),
            td(f"{r.phases}/{r.phases_expected}"), td(ms("mean_ms"), r.config, f"jitter_mean_ms:{r.trial}"),
            td(ms("std_ms")), td(ms("max_abs_ms"), r.config, f"jitter_max_abs_ms:{r.trial}"),
            td(ms("max_late_ms")), td(ms("max_early_ms")),
        ]) + "</tr>")
    headers = ["configuration", "trial", "status", "firmware", "phases", "mean (ms)", "sd (ms)",
               "max |error| (ms)", "max late (ms)", "max early (ms)"]
    return table(headers, out, left_cols=3, id_="timing")


def warnings_list(notices) -> str:
    """The report's warnings (:class:`.checks.Notice`), each with its kind, configuration and trial.

    Parameters
    ----------
    notices : iterable of Notice
        The warnings to list.

    Returns
    -------
    str
        The ``<ul id="warnings">`` element.
    """
    items = "".join(f'<li data-kind="{esc(n.kind)}" data-config="{esc(n.config)}" data-trial="{esc(n.trial)}">'
                    f"{esc(n.message)}</li>" for n in notices)
    return f'<ul class="warn" id="warnings">{items}</ul>'


def params_table(param_rows: list[dict]) -> str:
    """The robot's parameters with value, uncertainty (1 sd) and source, each in the unit a
    person reads (:func:`locust.report.build.parameter_rows`).

    Parameters
    ----------
    param_rows : list of dict
        Rows as :func:`locust.report.build.parameter_rows` makes them.

    Returns
    -------
    str
        The table (id ``params``), HTML.
    """
    rows = []
    for p in param_rows:
        rows.append("<tr>" + "".join([
            td(p["key"], left=True), td(p["value"], None, f"param:{p['key']}"),
            td(p["uncertainty"]), td(p["source"], left=True), td(p["date"] or "", left=True),
            td(p["note"] or "", left=True),
        ]) + "</tr>")
    return table(["parameter", "value", "uncertainty (1 sd)", "source", "date", "note"], rows, id_="params")


def links_table(link_rows: list[tuple[str, tuple[float, float, float, float]]]) -> str:
    """Each configuration's four link lengths [mm].

    Parameters
    ----------
    link_rows : list of (str, tuple of float)
        Display name and (ground, crank, coupler, leg) lengths [m].

    Returns
    -------
    str
        The table (id ``links``), HTML.
    """
    rows = ["<tr>" + td(name, left=True) + "".join(td(f"{v * 1000:.1f}") for v in links) + "</tr>"
            for name, links in link_rows]
    return table(["configuration", "ground (mm)", "crank (mm)", "coupler (mm)", "leg (mm)"], rows, id_="links")


def figure_html(fig: Figure) -> str:
    """A figure, its PNG embedded as base64, with its title and caption.

    Parameters
    ----------
    fig : Figure
        The figure.

    Returns
    -------
    str
        The ``<figure id="fig-<key>">`` element.
    """
    data = base64.b64encode(fig.png).decode("ascii")
    link = f' <a href="{esc(fig.link[0])}">{esc(fig.link[1])}</a>' if fig.link else ""
    return (f'<figure id="fig-{esc(fig.key)}"><img src="data:image/png;base64,{data}" alt="{esc(fig.title)}">'
            f"<figcaption><b>{esc(fig.title)}.</b> {esc(fig.caption)}{link}</figcaption></figure>")


def videos_html(videos: list[tuple[str, str]], skipped: list[str]) -> str:
    """The side-by-side videos, each played in the page from the file beside it.

    Parameters
    ----------
    videos : list of (str, str)
        Each video's file name in the report's folder (the src, relative to the page) and its caption.
    skipped : list of str
        The trials that have none, and why.

    Returns
    -------
    str
        A ``<figure class="video">`` per video, then the skipped trials, HTML.
    """
    out = "".join(f'<figure class="video"><video controls preload="metadata" src="{esc(name)}"></video>'
                  f"<figcaption><b>{esc(name)}</b>: {esc(caption)}.</figcaption></figure>" for name, caption in videos)
    if skipped:
        out += '<ul class="note">' + "".join(f"<li>{esc(s)}</li>" for s in skipped) + "</ul>"
    return out or '<p class="note">No trial has a video.</p>'


def page(title: str, meta_lines: list[str], sections: list[tuple[str, str]], media: bool = False) -> str:
    """The whole page: title, meta lines, then each section under its heading.

    Parameters
    ----------
    title : str
        The page's title.
    meta_lines : list of str
        Lines under the title, escaped.
    sections : list of (str, str)
        Heading and HTML content.
    media : bool
        The page plays videos beside it (:func:`videos_html`): its policy allows media from its
        own origin.

    Returns
    -------
    str
        The HTML document, with its Content-Security-Policy.
    """
    meta = "".join(f"<div>{esc(line)}</div>" for line in meta_lines)
    body = "".join(f"<h2>{esc(h)}</h2>{content}" for h, content in sections)
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f'<meta http-equiv="Content-Security-Policy" content="{CSP_MEDIA if media else CSP}">'
            f"<title>{esc(title)}</title><style>{STYLE}</style></head>"
            f"<body><h1>{esc(title)}</h1><div class=\"meta\">{meta}</div>{body}</body></html>\n")
