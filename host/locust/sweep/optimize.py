"""``run_optimize``: continuous search for the farthest hop with Optuna.

Each trial is a design evaluated exactly as a sweep evaluates it (checked, simulated,
audited). A design that fails is pruned with its reason (``user_attrs["reason"]``) and never
becomes the best. The study lives in a journal file by default (``study.journal`` in the output
folder; several processes may share it), or in any database Optuna's RDB storage takes
(``sqlite:///study.db``, ``postgresql://...``) to share one study between machines.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import SweepError
from ..fileio import atomic_write_json, atomic_write_text, make_folder
from ..params import Robot
from .design import SCALE, Bound, evaluate

RDB_PREFIXES = ("sqlite:", "postgresql", "mysql", "oracle", "mssql")
# what run_optimize writes in its folder; anything else there is someone else's
OWN_FILES = frozenset({"trials.csv", "optimize.json", "history.png", "study.journal", "study.journal.lock"})


def check_folder(folder: Path) -> None:
    """Refuse a folder holding files this command did not write (a user's ``trials.csv``
    included: a folder of ours always has ``optimize.json`` or the study's journal beside it)."""
    if not folder.exists():
        return
    if not folder.is_dir():
        raise SweepError(f"--out {folder} is a file", "give a folder (new, or one `locust optimize` made)")
    names = {p.name for p in folder.iterdir() if not p.name.startswith(".")}
    foreign = sorted(names - OWN_FILES)
    ours = bool(names & {"optimize.json", "study.journal"})
    if foreign or (names and not ours):
        shown = ", ".join((foreign or sorted(names))[:5])
        raise SweepError(f"{folder} holds files `locust optimize` did not write ({shown}); refusing to write there",
                         "choose a new or empty --out folder")


def check_storage(url: str | None) -> None:
    if url is None or url.startswith(RDB_PREFIXES):
        return
    path = url.removeprefix("journal:")
    if "://" in path or not path.strip():
        raise SweepError(f"--storage {url}: not a journal file path nor a database URL Optuna knows",
                         "give a file path (e.g. opt/study.journal) or sqlite:///study.db, postgresql://..., mysql://...")
    parent = Path(path).parent
    if not parent.is_dir():
        raise SweepError(f"--storage {url}: the folder {parent} does not exist", "create it, or give another path")


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


def is_integer(base: Robot, name: str) -> bool:
    """Whether the parameter ``name`` holds whole numbers (schedule.cycles, solver.iterations)."""
    if name == SCALE:
        return False
    value = base.get(name)
    return isinstance(value, int) and not isinstance(value, bool)


@dataclass
class OptimizeSummary:
    study_name: str
    trials: int
    complete: int
    pruned: int
    best: dict[str, Any] | None
    folder: Path


def run_optimize(base: Robot, bounds: list[Bound], trials: int, cycles: int, folder: Path,
                 storage: str | None = None, study_name: str = "locust", seed: int = 0, jobs: int = 1,
                 progress: Callable[[int], None] | None = None) -> OptimizeSummary:
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    check_folder(folder)
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
    try:
        done_before = len(optuna.load_study(study_name=study_name, storage=storage_obj).trials)
    except KeyError:
        done_before = 0
    study = optuna.create_study(study_name=study_name, storage=storage_obj,
                                direction="maximize", load_if_exists=True,
                                sampler=optuna.samplers.TPESampler(seed=seed + done_before))

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
    study.optimize(objective, n_trials=trials, n_jobs=jobs, callbacks=callbacks, catch=())
    return summarise(study, folder)


def summarise(study, folder: Path) -> OptimizeSummary:
    import optuna

    states = optuna.trial.TrialState
    done = [t for t in study.trials if t.state == states.COMPLETE]
    pruned = [t for t in study.trials if t.state == states.PRUNED]
    best = None
    if done:
        t = max(done, key=lambda t: (t.value, -t.number))
        best = {"trial": t.number, "distance_m": t.value, **t.params,
                "max_nose_height_m": t.user_attrs.get("max_nose_height_m")}
    df = study.trials_dataframe(attrs=("number", "state", "value", "params", "user_attrs"))
    atomic_write_text(folder / "trials.csv", df.to_csv(index=False))
    atomic_write_json(folder / "optimize.json", {
        "study": study.study_name, "trials": len(study.trials), "complete": len(done), "pruned": len(pruned),
        "best": best, "pruned_reasons": {t.number: t.user_attrs.get("reason", "") for t in pruned}})
    _plot_history(done, pruned, folder / "history.png")
    return OptimizeSummary(study.study_name, len(study.trials), len(done), len(pruned), best, folder)


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
