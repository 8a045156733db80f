"""Errors a person can read: a message that quotes what it was given is cut in its middle at
the CLI root, what and where kept; and `locust report` refuses an output folder it cannot
write before any simulation, not after the work."""

from __future__ import annotations

import json
import re

from click.testing import CliRunner

from locust.commands import MAX_ERROR_CHARS, bounded, cli

CELL = "x" * 60_000      # a cell pasted where a number belongs (the 60 KB one-line error)


def error_lines(res) -> list[str]:
    return [ln for ln in res.stderr.splitlines() if ln.startswith(("error:", "  hint:"))]


def test_a_huge_cell_is_cut_in_the_middle_keeping_what_and_where(tmp_path):
    """`calibrate beam` on a CSV whose third line holds 60,000 characters for a position: the
    error named the file, line and column, then quoted all of them (60,098 characters)."""
    path = tmp_path / "beam.csv"
    path.write_text(f"t,x,y\n0,0,0\n0.1,{CELL},0\n")
    res = CliRunner().invoke(cli, ["calibrate", "beam", str(path), "--mass-kg", "0.01", "--no-plot"])
    assert res.exit_code == 2
    error, hint = error_lines(res)
    assert len(error) <= len("error: ") + MAX_ERROR_CHARS + 60
    assert error.startswith(f"error: {path}, line 3: column 'track_x_m' holds 'xxxx")
    assert error.endswith("xxxx', not a number")
    assert re.search(r" … \[58,\d{3} characters left out\] … ", error)
    assert hint == "  hint: fix or delete that line"


def test_a_results_header_of_ten_thousand_columns_is_cut_and_the_hint_kept(tmp_path):
    """`report --sweep` on a results.csv whose header has 10,000 columns: the error listed every
    one (89 KB); the hint, the columns expected, is whole."""
    sweep = tmp_path / "sweep"
    sweep.mkdir()
    (sweep / "sweep.json").write_text(json.dumps({"request": {"base": "small", "cycles": 1, "vary": [
        {"name": "scale", "start": 0.0, "stop": 0.01, "n": 2}]}, "designs": 2}))
    (sweep / "results.csv").write_text(",".join(f"c{i}" for i in range(10_000)) + "\n")
    trial = tmp_path / "small-1"
    trial.mkdir()
    (trial / "run.json").write_text(json.dumps({"status": "complete", "schedule": {
        "cycles": 1, "push_deg": -30, "push_ms": 300, "wait_ms": 1000}, "phases": []}))
    res = CliRunner().invoke(cli, ["report", "--measured", str(trial), "--sweep", str(sweep),
                                   "--out", str(tmp_path / "out")])
    assert res.exit_code == 2
    error, hint = error_lines(res)
    assert error.startswith(f"error: --sweep {sweep}: {sweep / 'results.csv'}: unexpected columns ['c0', 'c1'")
    assert error.endswith("'c9998', 'c9999']") and len(error) <= len("error: ") + MAX_ERROR_CHARS + 60
    assert hint.startswith("  hint: expected design, scale, valid, reason,") and "left out" not in hint
    assert not (tmp_path / "out").exists()


def test_what_is_within_the_limit_is_printed_whole(monkeypatch):
    """An error of 1,150 characters (under the limit) raised inside a command reaches the
    terminal untouched; a text of the limit is itself, one character more is cut to 900 + 240
    of it."""
    from locust.commands import params as params_command
    from locust.errors import ParamsError

    def refuse(*args):
        raise ParamsError("e" * 1150, "h" * 1150)

    monkeypatch.setattr(params_command.robot_toml, "resolve_robot", refuse)
    res = CliRunner().invoke(cli, ["params", "--preset", "small"])
    assert res.exit_code == 2
    assert error_lines(res) == ["error: " + "e" * 1150, "  hint: " + "h" * 1150]
    assert bounded("a" * MAX_ERROR_CHARS) == "a" * MAX_ERROR_CHARS
    cut = bounded("a" * 900 + "b" * 61 + "c" * 240)
    assert cut == "a" * 900 + " … [61 characters left out] … " + "c" * 240


def test_report_refuses_a_folder_it_cannot_write_before_it_simulates(tmp_path, monkeypatch):
    """--out in a read-only folder, or under a file: refused before the first simulation (it
    came after 3.8 s and 7.3 s of them), nothing written."""
    from locust.report import build

    simulated = []
    predict = build.predict
    monkeypatch.setattr(build, "predict", lambda *a, **k: simulated.append(a[0]) or predict(*a, **k))
    trial = tmp_path / "small-1"
    trial.mkdir()
    (trial / "run.json").write_text(json.dumps({"status": "complete", "schedule": {
        "cycles": 1, "push_deg": -30, "push_ms": 300, "wait_ms": 1000}, "phases": []}))
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    (tmp_path / "afile").write_text("mine\n")
    try:
        for out, said in ((locked / "reports", f"error: cannot write in {locked}: the folder is read-only"),
                          (tmp_path / "afile" / "reports", f"error: cannot make {tmp_path / 'afile' / 'reports'}: "
                                                           f"{tmp_path / 'afile'} is a file")):
            res = CliRunner().invoke(cli, ["report", "--measured", str(trial), "--out", str(out)])
            assert res.exit_code == 2 and said in res.stderr, res.output
        assert simulated == []
        assert list(locked.iterdir()) == [] and (tmp_path / "afile").read_text() == "mine\n"
    finally:
        locked.chmod(0o755)
    res = CliRunner().invoke(cli, ["report", "--measured", str(trial), "--out", str(tmp_path / "reports")])
    assert res.exit_code == 0 and simulated == ["small"], res.output      # the control: a folder it can make
