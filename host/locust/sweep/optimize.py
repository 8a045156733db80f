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
from ..fileio import atomic_write_json, atomic_write_text
from ..params import Robot
from .design import Bound, evaluate

RDB_PREFIXES = ("sqlite:", "postgresql", "mysql", "oracle", "mssql")


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


def run_optimize(base: Robot, bounds: list[Bound], trials: int, cycles: int, folder: Path,
                 storage: str | None = None, study_name: str = "locust", seed: int = 0, jobs: int = 1,
                 progress: Callable[[int], None] | None = None) -> OptimizeSummary:
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    folder.mkdir(parents=True, exist_ok=True)
    study = optuna.create_study(study_name=study_name, storage=open_storage(storage, folder),
                                direction="maximize", load_if_exists=True,
                                sampler=optuna.samplers.TPESampler(seed=seed))

    def objective(trial: optuna.Trial) -> float:
        values = {b.name: trial.suggest_float(b.name, b.low, b.high) for b in bounds}
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
