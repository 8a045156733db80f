"""``run_optimize``: continuous search for the farthest hop with Optuna.

Each trial is a design evaluated exactly as a sweep evaluates it (checked, simulated,
audited). A design that fails is pruned with its reason (``user_attrs["reason"]``) and never
becomes the best. The study lives in a journal file by default (``study.journal`` in the output
folder; several processes may share it), or in any database Optuna's RDB storage takes
(``sqlite:///study.db``, ``postgresql://...``) to share one study between machines.

A study records what it searches (the base robot's values, the ranges, the cycles) as its user
attribute ``locust``: a rerun with other settings is refused, never ranked against it. A storage
file that is not an Optuna journal or database (a user's notes, a damaged journal) is refused
and left as it is. The best design is written as a robot file, ``best.toml``.
"""

from __future__ import annotations

import json
import math
import sqlite3
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import SweepError
from ..fileio import atomic_write_json, atomic_write_text, make_folder
from ..params import Robot, save_robot
from .design import Bound, design_robot, evaluate, is_integer
from .journal import full_disk

RDB_PREFIXES = ("sqlite:", "postgresql", "mysql", "oracle", "mssql")
# what run_optimize writes in its folder; anything else there is someone else's
OWN_FILES = frozenset({"trials.csv", "optimize.json", "history.png", "best.toml", "study.journal",
                       "study.journal.lock"})
# a journal saved by --repair before its torn line was cut (sweep/journal.py)
TORN_PREFIX = "study.journal.torn-"
# the study's user attribute holding what it searches
SETTINGS_ATTR = "locust"
SQLITE_MAGIC = b"SQLite format 3\x00"
# pauses before reading a journal again when its last line is cut short (a process sharing the
# study may be writing it): 1.7 s in all before it is taken for a damaged one
JOURNAL_RECHECK_S = (0.0, 0.2, 0.5, 1.0)


def check_folder(folder: Path) -> None:
    """Refuse a folder holding files this command did not write (a user's ``trials.csv``
    included: a folder of ours always has ``optimize.json`` or the study's journal beside it)."""
    if not folder.exists():
        return
    if not folder.is_dir():
        raise SweepError(f"--out {folder} is a file", "give a folder (new, or one `locust optimize` made)")
    names = {p.name for p in folder.iterdir() if not p.name.startswith(".")}
    foreign = sorted(n for n in names - OWN_FILES if not n.startswith(TORN_PREFIX))
    ours = bool(names & {"optimize.json", "study.journal"})
    if foreign or (names and not ours):
        shown = ", ".join((foreign or sorted(names))[:5])
        raise SweepError(f"{folder} holds files `locust optimize` did not write ({shown}); refusing to write there",
                         "choose a new or empty --out folder")


def check_storage(url: str | None) -> None:
    if url is None or url.startswith(RDB_PREFIXES):
        if url is not None and url.startswith("sqlite:///"):
            check_sqlite_file(Path(url.removeprefix("sqlite:///")), url)
        return
    path = url.removeprefix("journal:")
    if "://" in path or not path.strip():
        raise SweepError(f"--storage {url}: not a journal file path nor a database URL Optuna knows",
                         "give a file path (e.g. opt/study.journal) or sqlite:///study.db, postgresql://..., mysql://...")
    parent = Path(path).parent
    if not parent.is_dir():
        raise SweepError(f"--storage {url}: the folder {parent} does not exist", "create it, or give another path")
    check_journal_file(Path(path))


def check_journal_file(path: Path) -> None:
    """Refuse (:class:`SweepError`) an existing file that is not a whole Optuna journal: one JSON
    operation per line, the first creating a study, the last ending with its newline. Optuna
    would append to anything (a user's notes) and cannot read a damaged one back."""
    if not path.exists() or (path.is_file() and path.stat().st_size == 0):
        return
    hint = "give --storage a new file path (or a new --out folder); this file is left as it is"
    if not path.is_file():
        raise SweepError(f"{path} is not a file; refusing it as an Optuna journal", hint)
    for wait_s in JOURNAL_RECHECK_S:   # another process sharing the study may be appending a line
        time.sleep(wait_s)
        try:
            text = path.read_bytes().decode("utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise SweepError(f"{path}: not an Optuna journal (not UTF-8 text: {exc})", hint) from None
        lines = text.split("\n")
        if not lines[-1]:
            break
    if lines[-1]:
        raise SweepError(f"{path}: a damaged Optuna journal (its last line is cut short, as a full disk leaves it)",
                         "rerun the same command with --repair: it saves the file beside it and cuts the torn "
                         "line, keeping every whole trial; or " + hint)
    for k, line in enumerate(lines[:-1]):
        try:
            op = json.loads(line)
        except ValueError:
            op = None
        if not isinstance(op, dict) or not isinstance(op.get("op_code"), int) or (k == 0 and op["op_code"] != 0):
            what = "a damaged Optuna journal" if k else "not an Optuna journal"
            raise SweepError(f"{path}, line {k + 1}: {what} (each line must be one Optuna operation in JSON)",
                             hint)


def check_sqlite_file(path: Path, url: str) -> None:
    """Refuse an existing file that is not an SQLite database holding Optuna's tables (or none):
    Optuna would add its tables to someone else's database, or fail on a text file."""
    if not path.exists():
        return
    hint = "give a new database file (sqlite:///new.db); this file is left as it is"
    try:
        with open(path, "rb") as fh:
            magic = fh.read(len(SQLITE_MAGIC))
    except OSError as exc:
        raise SweepError(f"--storage {url}: cannot read {path} ({exc.strerror})", hint) from None
    if path.stat().st_size == 0:
        return
    if magic != SQLITE_MAGIC:
        raise SweepError(f"--storage {url}: {path} is not an SQLite database", hint)
    try:
        con = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
        try:
            tables = {r[0] for r in con.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        finally:
            con.close()
    except sqlite3.Error as exc:
        raise SweepError(f"--storage {url}: {path} cannot be read as a database ({exc})", hint) from None
    if tables and "studies" not in tables:
        raise SweepError(f"--storage {url}: {path} is a database without Optuna's tables "
                         f"({', '.join(sorted(tables)[:4])})", hint)


def settings(base: Robot, bounds: list[Bound], cycles: int) -> dict[str, Any]:
    """What a study searches, as JSON holds it: a rerun must ask for exactly this."""
    return json.loads(json.dumps({"base": base.name, "parameters": base.flat(),
                                  "vary": [{"name": b.name, "low": b.low, "high": b.high} for b in bounds],
                                  "cycles": cycles}))


def check_settings(study, wanted: dict[str, Any], where: str) -> None:
    """Refuse to continue a study that searches something else (or that this tool did not make)."""
    held = study.user_attrs.get(SETTINGS_ATTR)
    hint = "give a new --out folder (or --storage / --study), or rerun the exact command that made it"
    if held is None:
        raise SweepError(f"{where}: study {study.study_name!r} was not made by `locust optimize`", hint)
    if held != wanted:
        diff = [k for k in ("base", "vary", "cycles") if held.get(k) != wanted.get(k)]
        params = held.get("parameters") or {}
        diff += [k for k, v in wanted["parameters"].items() if params.get(k) != v][:3]
        raise SweepError(f"{where}: study {study.study_name!r} searches other settings ({', '.join(diff) or 'ranges'} "
                         "differ); its trials cannot be ranked against these", hint)


def open_storage(url: str | None, folder: Path):
    import optuna
    from optuna.storages import JournalStorage
    from optuna.storages.journal import JournalFileBackend

    if url is None:
        return JournalStorage(JournalFileBackend(str(folder / "study.journal")))
    if url.startswith(RDB_PREFIXES):
        try:
            return optuna.storages.RDBStorage(url)
        except Exception as exc:  # sqlalchemy raises many kinds
            raise SweepError(f"--storage {url}: cannot open ({exc.__class__.__name__}: {exc})",
                             "check the URL, e.g. sqlite:///study.db; the database driver must be installed") from None
    path = url.removeprefix("journal:")
    return JournalStorage(JournalFileBackend(path))


@dataclass
class OptimizeSummary:
    study_name: str
    trials: int
    complete: int
    pruned: int
    best: dict[str, Any] | None
    folder: Path
    interrupted: bool = False
    best_robot: Path | None = None    # best.toml, the best design as a robot file


def run_optimize(base: Robot, bounds: list[Bound], trials: int, cycles: int, folder: Path,
                 storage: str | None = None, study_name: str = "locust", seed: int = 0, jobs: int = 1,
                 progress: Callable[[int], None] | None = None) -> OptimizeSummary:
    import optuna

    # a trial's failure (an interrupt included) is reported by the caller, not logged with its traceback
    optuna.logging.set_verbosity(optuna.logging.ERROR)
    check_folder(folder)
    if storage is None:
        check_journal_file(folder / "study.journal")
    check_storage(storage)
    integers = {b.name for b in bounds if is_integer(base, b.name)}
    for b in bounds:
        if b.name in integers and math.floor(b.high) < math.ceil(b.low):
            raise SweepError(f"--vary {b.name}={b.low:g}:{b.high:g} holds no whole number, and {b.name} is one",
                             f"give a range with at least one integer, e.g. {b.name}={math.floor(b.low)}:"
                             f"{math.floor(b.low) + 2}")
    make_folder(folder)
    storage_obj = open_storage(storage, folder)
    # a resumed study must not draw its first samples again: the sampler's seed moves on with
    # the number of trials the study already holds
    wanted = settings(base, bounds, cycles)
    where = storage or str(folder / "study.journal")
    try:
        held = optuna.load_study(study_name=study_name, storage=storage_obj)
    except KeyError:
        held = None
    if held is not None:
        check_settings(held, wanted, where)
    done_before = len(held.trials) if held is not None else 0
    study = optuna.create_study(study_name=study_name, storage=storage_obj,
                                direction="maximize", load_if_exists=True,
                                sampler=optuna.samplers.TPESampler(seed=seed + done_before))
    if held is None:
        study.set_user_attr(SETTINGS_ATTR, wanted)

    def suggest(trial: optuna.Trial, b: Bound) -> float | int:
        if b.name in integers:
            return trial.suggest_int(b.name, math.ceil(b.low), math.floor(b.high))
        return trial.suggest_float(b.name, b.low, b.high)

    def objective(trial: optuna.Trial) -> float:
        values = {b.name: suggest(trial, b) for b in bounds}
        row = evaluate(base, values, cycles)
        for key in ("max_nose_height_m", "nose_apex_max_m", "com_apex_max_m"):
            if math.isfinite(row[key]):
                trial.set_user_attr(key, row[key])
        if not row["valid"]:
            trial.set_user_attr("reason", row["reason"])
            raise optuna.TrialPruned(row["reason"])
        return row["distance_m"]

    callbacks = [lambda study, trial: progress(1)] if progress else []
    try:
        study.optimize(objective, n_trials=trials, n_jobs=jobs, callbacks=callbacks, catch=())
    except KeyboardInterrupt:   # the trial under way is dropped (FAIL); every finished one is kept
        return summarise(study, folder, base, interrupted=True)
    except (OSError, AssertionError) as exc:   # Optuna's own assertion fails after its write did
        full = full_disk(exc)
        if full is None:
            raise
        raise SweepError(f"{where}: the disk is full ({full.strerror}) while the study was written: the trial "
                         "under way is lost, every finished one is kept in it",
                         "free some space on that disk, then rerun the same command with --repair (it saves the "
                         "study as it is and cuts a line the full disk left torn)") from None
    return summarise(study, folder, base)


def summarise(study, folder: Path, base: Robot, interrupted: bool = False) -> OptimizeSummary:
    import optuna

    states = optuna.trial.TrialState
    done = [t for t in study.trials if t.state == states.COMPLETE]
    pruned = [t for t in study.trials if t.state == states.PRUNED]
    best = None
    if done:
        t = max(done, key=lambda t: (t.value, -t.number))
        best = {"trial": t.number, "distance_m": t.value, **t.params,
                "max_nose_height_m": t.user_attrs.get("max_nose_height_m")}
    best_robot = None
    if best is not None:
        robot = design_robot(base, dict(t.params)).renamed(f"optimize best of {folder}")
        best_robot = save_robot(robot, folder / "best.toml")
    df = study.trials_dataframe(attrs=("number", "state", "value", "params", "user_attrs"))
    atomic_write_text(folder / "trials.csv", df.to_csv(index=False))
    atomic_write_json(folder / "optimize.json", {
        "study": study.study_name, "settings": study.user_attrs.get(SETTINGS_ATTR),
        "trials": len(study.trials), "complete": len(done), "pruned": len(pruned),
        "best": best, "best_robot": best_robot,
        "pruned_reasons": {t.number: t.user_attrs.get("reason", "") for t in pruned}})
    _plot_history(done, pruned, folder / "history.png")
    return OptimizeSummary(study.study_name, len(study.trials), len(done), len(pruned), best, folder,
                           interrupted, best_robot)


def _plot_history(done, pruned, path: Path) -> None:
    from ..plotting import pyplot, save_png

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4))
    if done:
        xs = [t.number for t in done]
        ys = [t.value * 100 for t in done]
        best = [max(ys[: i + 1]) for i in range(len(ys))]
        ax.plot(xs, ys, "o", ms=4, color="#1f77b4", label="valid trial")
        ax.step(xs, best, where="post", color="#ff7f0e", label="best so far")
    if pruned:
        ax.plot([t.number for t in pruned], [0] * len(pruned), "x", color="#d62728", label="pruned: invalid design")
    ax.set_xlabel("trial")
    ax.set_ylabel("distance (cm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save_png(fig, path)
