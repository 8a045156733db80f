"""Design sweep and optimisation: checks, storage, resume, schedulers, Optuna."""

from __future__ import annotations

import csv
import json
import math
import random
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from locust.errors import SweepError
from locust.io.robot_toml import load_robot
from locust.params import preset
from locust.sweep.design import design_robot, evaluate, parse_axis, parse_bound, precheck
from locust.sweep.run import best_row, run_sweep
from probing import assert_refused_and_unchanged, invoke, signalled_in_design

LOCUST = [sys.executable, "-c", "from locust.commands import main; main()"]


def read_rows(folder: Path) -> list[dict[str, str]]:
    with open(folder / "results.csv", newline="") as fh:
        return list(csv.DictReader(fh))


# -- parsing ---------------------------------------------------------------------------
@pytest.mark.parametrize("item, fragment", [
    ("scale", "NAME=RANGE"),
    ("scale=0:0.05", "START:STOP:N"),
    ("scale=0:x:3", "not a number"),
    ("scale=0:0.05:2.5", "whole number"),
    ("geometry.nope_m=0:1:3", "no such robot parameter"),
    ("solver.integrator=0:1:3", "not a number"),
])
def test_bad_vary_is_refused_with_reason(item, fragment):
    with pytest.raises(SweepError) as exc:
        parse_axis(item, preset("seed"))
    assert fragment in str(exc.value)


def test_axis_values_are_linspace_inclusive():
    axis = parse_axis("scale=0:0.05:30", preset("seed"))
    values = axis.values()
    assert len(values) == 30 and values[0] == 0.0 and values[-1] == pytest.approx(0.05, abs=1e-15)
    assert values[1] == pytest.approx(0.05 / 29, rel=1e-12)


def test_scale_adds_the_same_length_to_every_link():
    robot = design_robot(preset("seed"), {"scale": 0.02})
    assert robot.link_lengths_m() == pytest.approx((0.06, 0.06, 0.04, 0.08), abs=1e-12)
    assert robot.link_lengths_m() == pytest.approx(preset("large").link_lengths_m(), abs=1e-12)


def test_linkage_that_locks_during_the_push_is_caught_at_the_hand_computed_angle():
    # crank tip to front pivot: d = 0.08 |sin(theta/2)|; coupler 0.005 + leg 0.06 = 0.065
    # closes at -90 deg (d = 5.66 cm) but not past theta = -2 asin(0.065/0.08) = -108.7 deg.
    reason = precheck(design_robot(preset("seed"), {"geometry.coupler_m": 0.005}))
    assert reason is not None and "locks before the push angle" in reason
    assert "crank -109 deg" in reason
    assert precheck(preset("seed")) is None


# -- the sweep -------------------------------------------------------------------------
def test_impossible_linkages_are_rejected_with_reasons_and_never_best(tmp_path):
    # coupler 0.005: locks during the push; 0.155: |coupler - leg| = 9.5 cm > 5.66 cm, cannot
    # close; 0.205: longer than the other three together (14 cm). 0.055 and 0.105 can be built.
    base = preset("seed")
    axis = parse_axis("geometry.coupler_m=0.005:0.205:5", base)
    summary = run_sweep(base, [axis], cycles=1, out=tmp_path / "s", jobs=1)
    rows = {round(r["geometry.coupler_m"], 6): r for r in summary.rows}
    assert len(rows) == 5
    assert not rows[0.005]["valid"] and "locks before the push angle" in rows[0.005]["reason"]
    assert not rows[0.155]["valid"] and "cannot close" in rows[0.155]["reason"]
    assert not rows[0.205]["valid"] and "shorter than the other three" in rows[0.205]["reason"]
    for bad in (0.005, 0.155, 0.205):
        assert math.isnan(rows[bad]["distance_m"])
    best = summary.best
    assert best is not None and best["valid"]
    assert round(best["geometry.coupler_m"], 6) in (0.055, 0.105)
    valid = [r for r in summary.rows if r["valid"]]
    assert best["distance_m"] == max(r["distance_m"] for r in valid)
    # the row is the simulation's own figure
    direct = evaluate(base, {"geometry.coupler_m": best["geometry.coupler_m"]}, 1)
    assert direct["distance_m"] == best["distance_m"]
    assert (tmp_path / "s" / "curve_geometry_coupler_m.png").stat().st_size > 10_000
    meta = json.loads((tmp_path / "s" / "sweep.json").read_text())
    assert meta["best"]["design"] == best["design"] and meta["finished"] is True


def test_best_row_ignores_invalid_rows_and_robots_on_their_backs_even_with_larger_numbers():
    rows = [{"design": 0, "valid": False, "outcome": "", "distance_m": 9.0},
            {"design": 1, "valid": True, "outcome": "stays_low", "distance_m": 0.2},
            {"design": 2, "valid": True, "outcome": "rears_and_returns", "distance_m": 0.3},
            {"design": 3, "valid": True, "outcome": "goes_over", "distance_m": 0.5}]
    assert best_row(rows)["design"] == 2
    assert best_row([rows[0], rows[3]]) is None


def test_a_sweep_marks_each_design_s_outcome_and_never_ranks_a_robot_on_its_back(tmp_path):
    # Medium as built goes over at a -40 deg push (it ends on its back, nose about 12 cm up: the
    # highest "jump" of the sweep) and stays on its feet at -15 deg
    base = preset("medium")
    summary = run_sweep(base, [parse_axis("schedule.push_deg=-40:-15:2", base)], cycles=1, out=tmp_path / "s",
                        jobs=1)
    over, low = summary.rows
    assert (over["outcome"], over["flip_share"]) == ("goes_over", 1.0)
    assert low["outcome"] in ("rears_and_returns", "stays_low") and low["flip_share"] == 0.0
    assert over["max_nose_height_m"] > 0.1 > low["max_nose_height_m"]
    assert summary.best["design"] == low["design"]
    assert [r["outcome"] for r in read_rows(tmp_path / "s")] == ["goes_over", low["outcome"]]


def test_a_folder_holding_another_sweep_or_other_files_is_refused(tmp_path):
    base = preset("seed")
    out = tmp_path / "s"
    run_sweep(base, [parse_axis("geometry.coupler_m=0.205:0.21:2", base)], cycles=1, out=out, jobs=1)
    before = (out / "results.csv").read_bytes()
    with pytest.raises(SweepError, match="different sweep"):
        run_sweep(base, [parse_axis("geometry.coupler_m=0.205:0.22:2", base)], cycles=1, out=out, jobs=1)
    assert (out / "results.csv").read_bytes() == before
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    with pytest.raises(SweepError, match="not a sweep folder"):
        run_sweep(base, [parse_axis("scale=0:0.01:2", base)], cycles=1, out=other, jobs=1)
    assert sorted(p.name for p in other.iterdir()) == ["notes.txt"]


# The sweep is killed with SIGKILL by itself, right after its second row reaches the disk: the
# same abrupt death as a kill -9 from outside (no handler, no flush, no cleanup), at a point
# that does not depend on how fast the machine is.
_KILLED_AFTER_TWO_ROWS = """
import os, signal, sys
from locust.io import sweep_store as store
append = store.SweepStore.append
def append_then_die(self, row):
    append(self, row)
    if len(self.done) == 2:
        os.kill(os.getpid(), signal.SIGKILL)
store.SweepStore.append = append_then_die
from locust.commands import main
sys.argv[0] = "locust"
main()
"""


def test_killed_sweep_resumes_without_recomputing(tmp_path):
    out = tmp_path / "s"
    args = ["sweep", "--preset", "seed", "--vary", "geometry.leg_m=0.055:0.07:4", "--cycles", "1",
            "--jobs", "1", "--out", str(out), "--json"]
    killed = subprocess.run([sys.executable, "-c", _KILLED_AFTER_TWO_ROWS, *args], capture_output=True,
                            text=True, timeout=300)
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    done_before = read_rows(out)
    assert [int(r["design"]) for r in done_before] == [0, 1]
    # a line cut short by the kill is dropped, not read as a result
    with open(out / "results.csv", "a") as fh:
        fh.write("3,0.07,Tr")
    rerun = subprocess.run(LOCUST + args, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    report = json.loads(rerun.stdout)
    assert report["resumed"] == 2
    assert report["computed"] == 2
    rows = read_rows(out)
    assert [int(r["design"]) for r in rows] == [0, 1, 2, 3]
    for old in done_before:  # finished rows kept exactly as written
        assert rows[int(old["design"])] == old


def test_schedulers_give_identical_results(tmp_path):
    base = preset("seed")
    axis = parse_axis("geometry.leg_m=0.055:0.07:3", base)
    serial = run_sweep(base, [axis], cycles=1, out=tmp_path / "serial", jobs=1, plots=False)
    pool = run_sweep(base, [axis], cycles=1, out=tmp_path / "pool", jobs=2, plots=False)
    dask = run_sweep(base, [axis], cycles=1, out=tmp_path / "dask", scheduler="dask-local", jobs=2, plots=False)
    assert serial.rows == pool.rows == dask.rows
    files = {(tmp_path / name / "results.csv").read_bytes() for name in ("serial", "pool", "dask")}
    assert len(files) == 1
    assert sum(r["valid"] for r in serial.rows) >= 2


def test_unreachable_dask_scheduler_is_a_clear_error(tmp_path):
    base = preset("seed")
    with pytest.raises(SweepError, match="cannot reach the Dask scheduler"):
        run_sweep(base, [parse_axis("scale=0:0.01:2", base)], cycles=1, out=tmp_path / "s",
                  scheduler="tcp://127.0.0.1:9", jobs=1)


def test_sweep_cli_bad_input_exits_2_without_traceback(tmp_path):
    r = subprocess.run(LOCUST + ["sweep", "--vary", "scale=0:0.05", "--out", str(tmp_path / "x")],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert "START:STOP:N" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "x").exists()


# -- optimisation ----------------------------------------------------------------------
def test_optimize_prunes_invalid_designs_and_keeps_the_study(tmp_path):
    from locust.sweep.optimize import run_optimize

    base = preset("seed")
    # couplers above 0.1166 m cannot close at the start angle (|coupler - leg| > 5.66 cm)
    bounds = [parse_bound("geometry.coupler_m=0.01:0.2", base)]
    first = run_optimize(base, bounds, trials=5, cycles=1, folder=tmp_path / "o", seed=3)
    assert first.trials == 5 and first.complete + first.pruned == 5
    meta = json.loads((tmp_path / "o" / "optimize.json").read_text())
    for reason in meta["pruned_reasons"].values():
        assert reason  # every pruned trial carries its reason
    # seed 3 draws two couplers that cannot close and three that can: a best exists
    assert (first.complete, first.pruned) == (3, 2)
    assert first.best["geometry.coupler_m"] <= 0.1166
    assert precheck(design_robot(base, {"geometry.coupler_m": first.best["geometry.coupler_m"]})) is None
    # the best design as a robot file: its values, and a name that says what it is
    best = load_robot(tmp_path / "o" / "best-distance_per_hop.toml")
    assert best.name == f"optimize best-distance_per_hop of {tmp_path / 'o'}"
    assert best.geometry.coupler_m == first.best["geometry.coupler_m"]
    # the figure optimised is the distance per hop: one cycle here, so the run's distance
    assert evaluate(best, {}, 1)["distance_m"] == first.best["distance_per_hop_m"]
    # the journal keeps the study: --trials is what it should hold, a rerun computes the rest
    again = run_optimize(base, bounds, trials=7, cycles=1, folder=tmp_path / "o", seed=4)
    assert (again.trials, again.computed) == (7, 2)
    assert (tmp_path / "o" / "pareto.png").stat().st_size > 5_000


def test_optimize_on_sqlite_storage(tmp_path):
    from locust.sweep.optimize import run_optimize

    base = preset("seed")
    url = f"sqlite:///{tmp_path / 'study.db'}"
    bounds = [parse_bound("geometry.coupler_m=0.15:0.2", base)]  # all impossible: all pruned
    s = run_optimize(base, bounds, trials=3, cycles=1, folder=tmp_path / "o", storage=url)
    assert (s.trials, s.complete, s.pruned, s.best) == (3, 0, 3, None)
    assert (tmp_path / "study.db").stat().st_size > 0


# -- the seed's experiment, corrected (slow: 2 x 30 designs) ---------------------------
@pytest.mark.slow
def test_seed_scale_sweep_local_and_dask_local_agree(tmp_path):
    outs = []
    for scheduler in ("local", "dask-local"):
        out = tmp_path / scheduler
        r = subprocess.run(LOCUST + ["sweep", "--preset", "seed", "--vary", "scale=0:0.05:30", "--cycles", "3",
                                     "--out", str(out), "--scheduler", scheduler],
                           capture_output=True, text=True, timeout=1200)
        assert r.returncode == 0, r.stderr
        assert (out / "curve_scale.png").stat().st_size > 10_000
        outs.append(read_rows(out))
    assert len(outs[0]) == 30 and outs[0] == outs[1]
    valid = [r for r in outs[0] if r["valid"] == "True"]
    assert valid
    assert max(float(r["max_nose_height_m"]) for r in valid) < 0.30


def test_a_second_sweep_into_a_running_sweeps_folder_is_refused(tmp_path):
    import fcntl

    from locust.io.sweep_store import LOCK

    base = preset("seed")
    axis = parse_axis("geometry.coupler_m=0.205:0.21:2", base)
    out = tmp_path / "s"
    run_sweep(base, [axis], cycles=1, out=out, jobs=1, plots=False)
    with open(out / LOCK, "w") as held:          # as a running sweep holds it
        fcntl.flock(held, fcntl.LOCK_EX)
        with pytest.raises(SweepError, match="another sweep is running"):
            run_sweep(base, [axis], cycles=1, out=out, jobs=1, plots=False)
    # released: the same sweep reopens (everything already done, nothing recomputed)
    again = run_sweep(base, [axis], cycles=1, out=out, jobs=1, plots=False)
    assert (again.resumed, again.computed) == (2, 0)


def test_results_csv_round_trips_through_its_owner_and_only_a_torn_last_line_is_dropped(tmp_path):
    """results.csv is written and read back by locust.io.sweep_store alone: every field comes back
    bit for bit (floats by repr, nan, bools, ints); an interrupt's torn last line is dropped on
    reading, a malformed row anywhere else is an error naming its line."""
    from locust.io.sweep_store import SweepStore, read_results

    rows = [  # SYNTHETIC rows (made-up figures, not simulations)
        {"design": 0, "scale": 0.0, "valid": True, "reason": "", "outcome": "rears_and_returns", "flip_share": 0.125,
         "distance_m": 0.009292704540008771,
         "max_nose_height_m": 0.1 + 0.2, "nose_apex_max_m": 1e-17, "com_apex_max_m": 2.5e-3, "hops": 3,
         "grashof": "change-point", "transmission_deg": 77.15523372599155},
        {"design": 1, "scale": 0.01, "valid": False, "reason": "energy audit failed, twice", "outcome": "",
         "flip_share": math.nan, "distance_m": math.nan,
         "max_nose_height_m": math.nan, "nose_apex_max_m": math.nan, "com_apex_max_m": math.nan, "hops": 0,
         "grashof": "crank-rocker", "transmission_deg": 80.0},
    ]
    request = {"base": "seed", "vary": [{"name": "scale", "start": 0.0, "stop": 0.01, "n": 2}], "cycles": 3}
    store = SweepStore.open(tmp_path / "s", {"request": request}, ["scale"])
    for row in rows:
        store.append(row)
    store.close(True, finished=True)
    back = read_results(tmp_path / "s")
    assert back.axis_names == ["scale"] and back.cycles == 3 and back.base == "seed" and back.finished
    assert back.rows[0] == rows[0]
    assert back.rows[1]["valid"] is False and back.rows[1]["reason"] == "energy audit failed, twice"
    assert all(math.isnan(back.rows[1][k]) for k in ("distance_m", "max_nose_height_m"))

    path = tmp_path / "s" / "results.csv"
    text = path.read_text()
    path.write_text(text + "2,0.02,True,,0.0")            # an interrupt cut the row being appended
    assert [r["design"] for r in read_results(tmp_path / "s").rows] == [0, 1]
    lines = text.splitlines(keepends=True)
    path.write_text(lines[0] + lines[1].replace("True", "Ture") + lines[2])
    with pytest.raises(SweepError, match="line 2: malformed row"):
        read_results(tmp_path / "s")


# -- optimize: storage, settings and interrupts ---------------------------------------
OPT = ["optimize", "--vary", "geometry.coupler_m=0.01:0.2", "--trials", "1", "--cycles", "1", "--seed", "3"]


@pytest.fixture(scope="module")
def journal_text(tmp_path_factory) -> str:
    """A real journal of a two-trial study (one valid, one pruned)."""
    from locust.sweep.optimize import run_optimize

    base = preset("seed")
    folder = tmp_path_factory.mktemp("j") / "o"
    run_optimize(base, [parse_bound("geometry.coupler_m=0.01:0.2", base)], trials=2, cycles=1, folder=folder, seed=3)
    return (folder / "study.journal").read_text()


def _not_journals(journal: str) -> dict[str, bytes]:
    """Files Optuna would append to or choke on: a user's text, binary, JSON that is no journal
    operation, and a real journal cut short or damaged at generated places."""
    rng = random.Random(28)
    cases = {"notes": b"my notes\nsecond line\n", "no-newline": b"x", "binary": bytes(range(256)),
             "latin-1": "caf\xe9\n".encode("latin-1"), "json-list": b"[1, 2]\n",
             "json-no-op": b'{"study_name": "locust"}\n', "op-not-int": b'{"op_code": "0"}\n',
             "first-not-create": journal.split("\n", 1)[1].encode(), "blank-line": ("\n" + journal).encode()}
    ends = [i for i, c in enumerate(journal) if c == "\n"]
    for _ in range(6):   # cut inside a line: a torn last line
        cut = rng.choice([i for i in range(1, len(journal)) if i - 1 not in ends])
        cases[f"torn-at-{cut}"] = journal[:cut].encode()
    for _ in range(4):   # one line's byte replaced in the middle of the file
        at = rng.randrange(ends[0] + 2, ends[-2])
        cases[f"garbled-at-{at}"] = (journal[:at] + "\x00" + journal[at + 1:]).encode()
    return cases


def test_optimize_refuses_a_storage_file_that_is_not_a_whole_journal_and_leaves_it(tmp_path, journal_text,
                                                                                   monkeypatch):
    from locust.sweep import storage

    monkeypatch.setattr(storage, "JOURNAL_RECHECK_S", (0.0,))   # no other process writes these
    for name, data in _not_journals(journal_text).items():
        folder = tmp_path / name
        folder.mkdir()
        (folder / "notes.txt").write_bytes(data)
        assert_refused_and_unchanged(folder, [*OPT, "--out", folder / "o", "--storage", folder / "notes.txt"],
                                     "journal", "notes.txt")
        # the same bytes as the default journal of an --out folder
        (folder / "o").mkdir()
        (folder / "o" / "study.journal").write_bytes(data)
        assert_refused_and_unchanged(folder, [*OPT, "--out", folder / "o"], "journal")


def test_optimize_refuses_a_sqlite_storage_that_is_not_an_optuna_database(tmp_path):
    import sqlite3

    (tmp_path / "notes.db").write_text("my notes\n")
    con = sqlite3.connect(tmp_path / "mine.db")
    con.execute("CREATE TABLE birds (name TEXT)")
    con.commit()
    con.close()
    assert_refused_and_unchanged(tmp_path, [*OPT, "--out", tmp_path / "o", "--storage",
                                            f"sqlite:///{tmp_path / 'notes.db'}"], "not an SQLite database")
    assert_refused_and_unchanged(tmp_path, [*OPT, "--out", tmp_path / "o", "--storage",
                                            f"sqlite:///{tmp_path / 'mine.db'}"], "without Optuna's tables", "birds")


def test_optimize_refuses_to_continue_a_study_with_other_settings(tmp_path):
    out = tmp_path / "o"
    first = invoke([*OPT, "--out", out])
    assert first.exit_code == 0, first.output
    for other, differs in ((["--cycles", "6"], "cycles"), (["--set", "geometry.crank_m=0.041"], "geometry.crank_m"),
                           (["--vary", "geometry.leg_m=0.05:0.09"], "vary"), (["--preset", "large"], "base")):
        assert_refused_and_unchanged(tmp_path, [*OPT, "--out", out, *other], "other settings", differs)
    again = invoke([*OPT[:3], "--trials", "2", *OPT[5:], "--out", out])   # the same settings continue the study
    assert again.exit_code == 0 and "2 trials (1 computed now)" in again.output


# Ctrl-C in the middle of the second trial, delivered by the process to itself: the same
# SIGINT a terminal sends, at a point that does not depend on the machine's speed.
_INTERRUPTED_IN_SECOND_TRIAL = signalled_in_design("SIGINT", 2)


def test_interrupted_optimize_keeps_finished_trials_without_a_traceback(tmp_path):
    out = tmp_path / "o"
    args = [*OPT, "--trials", "4", "--out", str(out)]
    r = subprocess.run([sys.executable, "-c", _INTERRUPTED_IN_SECOND_TRIAL, *args], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 130, r.stderr
    assert "Traceback" not in r.stderr and "KeyboardInterrupt" not in r.stderr
    assert "interrupted" in r.stderr and "1 finished trial kept" in r.stderr
    meta = json.loads((out / "optimize.json").read_text())
    assert meta["trials"] == 2 and meta["complete"] + meta["pruned"] == 1
    rerun = subprocess.run(LOCUST + args, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    # 2 before (1 finished, 1 dropped), and the 3 more that make 4 finished
    assert "5 trials (3 computed now)" in rerun.stdout


# -- sweep: workers, schedulers ---------------------------------------------------------
# A worker kills itself (SIGKILL, as the kernel's out-of-memory killer does) when given design
# 2; the leader, its other worker and the rows already written are untouched.
_WORKER_KILLED_AT_DESIGN_2 = """
import os, signal, sys
from locust.sweep import run
run_task = run.run_task
def run_task_or_die(task):
    if task.design == 2:
        os.kill(os.getpid(), signal.SIGKILL)
    return run_task(task)
run.run_task = run_task_or_die
from locust.commands import main
sys.argv[0] = "locust"
main()
"""


def test_a_killed_worker_is_a_clear_error_and_the_rerun_resumes(tmp_path):
    from locust.sweep.execute import default_jobs

    if default_jobs() < 2:
        pytest.skip("needs two cores: with one, the sweep runs in the leader itself")
    out = tmp_path / "s"
    args = ["sweep", "--preset", "seed", "--vary", "geometry.leg_m=0.055:0.07:4", "--cycles", "1",
            "--jobs", "2", "--out", str(out), "--json"]
    died = subprocess.run([sys.executable, "-c", _WORKER_KILLED_AT_DESIGN_2, *args], capture_output=True,
                          text=True, timeout=300)
    assert died.returncode == 2, died.stderr
    assert "Traceback" not in died.stderr and "BrokenProcessPool" not in died.stderr
    assert "error: a worker process died" in died.stderr and "hint:" in died.stderr and "resume" in died.stderr
    kept = read_rows(out)
    assert {int(r["design"]) for r in kept} <= {0, 1, 3}
    rerun = subprocess.run(LOCUST + args, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stderr
    report = json.loads(rerun.stdout)
    assert (report["resumed"], report["computed"]) == (len(kept), 4 - len(kept))
    rows = read_rows(out)
    assert [int(r["design"]) for r in rows] == [0, 1, 2, 3]
    for old in kept:
        assert rows[int(old["design"])] == old


def test_jobs_are_capped_at_the_designs_and_the_cores_and_the_sweep_says_so(tmp_path):
    from locust.sweep.execute import default_jobs

    base = preset("seed")
    said = []
    s = run_sweep(base, [parse_axis("geometry.coupler_m=0.205:0.21:2", base)], cycles=1, out=tmp_path / "s",
                  jobs=1024, plots=False, say=said.append)
    used = min(2, default_jobs())
    assert said == [f"--jobs 1024: starting {used} worker{'s' * (used != 1)} (2 designs to run, "
                    f"{default_jobs()} cores)"]
    assert json.loads((tmp_path / "s" / "sweep.json").read_text())["last_run"]["jobs"] == used
    assert len(s.rows) == 2


class _Impostor:
    """A TCP server on 127.0.0.1 that is not a Dask scheduler: it greets every connection with
    ``greeting`` (None: says nothing) and then closes it."""

    def __init__(self, greeting: bytes | None):
        import socket
        import threading

        self.greeting = greeting
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):

        self.sock.settimeout(0.2)
        while not self.stop.is_set():
            try:
                conn, _ = self.sock.accept()
            except OSError:
                continue
            with conn:
                if self.greeting is None:
                    self.stop.wait(10)
                else:
                    try:
                        conn.sendall(self.greeting)
                    except OSError:
                        pass

    def close(self):
        self.stop.set()
        self.thread.join()
        self.sock.close()


def _impostor_greetings() -> dict[str, bytes | None]:
    rng = random.Random(28)
    cases: dict[str, bytes | None] = {
        "http": b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n", "ssh": b"SSH-2.0-OpenSSH_9.6\r\n",
        "exabytes": (3 << 60).to_bytes(8, "little") + b"\x01" + b"\x00" * 7, "ones": b"\xff" * 64,
        "short": b"\x3a\x00", "closes": b"",
        # a Dask-shaped header whose frame lengths do not add up
        "inconsistent": (58).to_bytes(8, "little") + (1).to_bytes(8, "little") + (99).to_bytes(8, "little")
        + b"\x00" * 42,
        "silent": None}
    for k in range(4):
        cases[f"random-{k}"] = rng.randbytes(rng.randrange(1, 200))
    return cases


def test_a_scheduler_address_where_no_dask_answers_is_refused_promptly(tmp_path):
    """Each case returns within the probe's few seconds (a hang would hang the test)."""
    for name, greeting in _impostor_greetings().items():
        server = _Impostor(greeting)
        try:
            folder = tmp_path / name
            folder.mkdir()
            (folder / "notes.txt").write_text("mine")
            assert_refused_and_unchanged(folder, ["sweep", "--vary", "scale=0:0.01:2", "--cycles", "1",
                                                  "--scheduler", f"tcp://127.0.0.1:{server.port}",
                                                  "--out", folder / "s"], "Dask scheduler")
        finally:
            server.close()


def test_a_real_dask_scheduler_passes_the_probe_and_its_worker_does_not():
    from dask.distributed import LocalCluster

    from locust.sweep.execute import probe_dask_scheduler

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1",
                      dashboard_address=None) as cluster:
        probe_dask_scheduler(cluster.scheduler_address)   # raises if refused
        # Dask's greeting is not enough: a worker's address is not a scheduler's
        (worker,) = cluster.workers.values()
        with pytest.raises(SweepError, match="a Dask Worker answers there"):
            probe_dask_scheduler(worker.address)


BEST = re.compile(r"best valid design (\d+) \(scale (-?[\d.]+) mm; ([\w ]+)\): distance (-?[\d.]+) mm over the "
                  r"run \((-?[\d.]+) mm per hop\), highest nose (-?[\d.]+) mm above the floor")


def test_sweep_prints_hop_figures_in_mm_like_every_table(tmp_path):
    """Hop figures and the added length in mm (as `locust sim`, `hop` and `virtual`): the best
    design's line is its results.csv row times 1000, to the printed digit; `distance` is over
    the run (locust sim's), the figure per hop says so."""
    res = subprocess.run(LOCUST + ["sweep", "--preset", "seed", "--vary", "scale=0:0.01:2", "--cycles", "2",
                                   "--jobs", "1", "--out", str(tmp_path / "sw")], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    m = BEST.search(res.stdout)
    assert m, res.stdout
    row = list(csv.DictReader((tmp_path / "sw" / "results.csv").open()))[int(m.group(1))]
    assert float(m.group(2)) == pytest.approx(float(row["scale"]) * 1000, abs=0.005)
    assert m.group(3) == row["outcome"].replace("_", " ")
    assert float(m.group(4)) == pytest.approx(float(row["distance_m"]) * 1000, abs=0.005)
    assert float(m.group(5)) == pytest.approx(float(row["distance_m"]) * 1000 / 2, abs=0.005)
    assert float(m.group(6)) == pytest.approx(float(row["max_nose_height_m"]) * 1000, abs=0.005)
    assert " cm" not in res.stdout and "scale=0." not in res.stdout


def test_distance_and_scale_mean_one_thing_in_sweep_and_optimize(tmp_path):
    """The same two designs through `locust sweep` and `locust optimize` (a categorical scale,
    so every trial is one of them): the sweep's distance is over the run, the optimiser's
    distance per hop is that over the cycles (to 1e-12), and both print the added length in mm
    with its unit, the same digits for the same design (before: 0.0305 against 3.05 cm)."""
    args = ["--preset", "small", "--cycles", "2"]
    sweep = subprocess.run(LOCUST + ["sweep", *args, "--vary", "scale=0.0305:0.031:2", "--jobs", "1",
                                     "--out", str(tmp_path / "sw")], capture_output=True, text=True)
    assert sweep.returncode == 0, sweep.stderr
    opt = subprocess.run(LOCUST + ["optimize", *args, "--vary", "scale=0.0305,0.031", "--trials", "4",
                                   "--out", str(tmp_path / "o")], capture_output=True, text=True)
    assert opt.returncode == 0, opt.stderr
    swept = {round(float(r["scale"]), 9): r for r in read_rows(tmp_path / "sw")}
    trials = list(csv.DictReader((tmp_path / "o" / "trials.csv").open()))
    assert "distance_m" not in trials[0] and "distance_per_hop_m" in trials[0]
    for t in trials:
        r = swept[round(float(t["scale"]), 9)]
        if r["outcome"] != "goes_over":     # a design that goes over scores 0 per hop (not a hop)
            assert float(t["distance_per_hop_m"]) == pytest.approx(float(r["distance_m"]) / 2, abs=1e-12)
    best = BEST.search(sweep.stdout)
    m = re.search(r"best-distance_per_hop: trial \d+ \(scale ([\d.]+) mm\): distance per hop (-?[\d.]+) mm",
                  opt.stdout)
    assert best and m, (sweep.stdout, opt.stdout)
    assert m.group(1) == best.group(2)                 # the same design, the same printed mm
    assert float(m.group(2)) == pytest.approx(float(best.group(5)), abs=0.005)
