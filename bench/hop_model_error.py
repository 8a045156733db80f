"""The hop fit's model error against the plant, measured on the virtual robot.

    python bench/hop_model_error.py OUT_DIR [--seeds 100 101 102]

For each seed a hidden truth is drawn (tests/test_calibrate_hop_coverage.py's
``hidden_truth``: friction, hinge stiffness and servo no-load speed within the ranges the
fit is meant for), Small and Medium hop three cycles on the virtual robot carrying it
(firmware under MicroPython, rendered video, tracked), and ``locust calibrate hop`` fits them
from the seed's values. One JSON line a seed goes to OUT_DIR/model_error.jsonl (truth, fit,
score: kept when a later seed fails); the last lines give, per key, the RMS relative error
over the seeds (bias and spread together: what ``hop.MODEL_ERROR_RELATIVE`` takes), its
mean (the bias), and how many intervals covered with and without their model-error part.
Seeds 100 and up: the coverage test's seeds 0-9 are never used here.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from test_calibrate_hop_coverage import RANGES, film_and_fit, hidden_truth, scored


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--seeds", type=int, nargs="+", default=[100, 101, 102])
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, LOCUST_VIRTUAL_DIR=str(args.out / "virtual"))
    subprocess.run([sys.executable, "-m", "locust.commands", "flash", "--port", "sim"], env=env, check=True,
                   capture_output=True)
    log = args.out / "model_error.jsonl"
    for seed in args.seeds:
        truth = hidden_truth(seed)
        fit = film_and_fit(truth, args.out / f"truth{seed}", env)
        rows = scored(truth, fit)
        with log.open("a") as f:
            f.write(json.dumps({"seed": seed, "truth": truth, "fit": fit, "score": rows}) + "\n")
        print(f"seed {seed} ({fit['wall_s']:.0f} s): " + "; ".join(
            f"{k} {r['truth']:.4g} -> {r['value']:.4g} ({100 * r['relative_error']:+.1f} %)" for k, r in rows.items()),
            flush=True)
    lines = [json.loads(line) for line in log.read_text().splitlines()]
    for key in RANGES:
        errors = [line["score"][key]["relative_error"] for line in lines]
        rms = math.sqrt(sum(e * e for e in errors) / len(errors))
        covered = sum(line["score"][key]["covered"] for line in lines)
        bare = sum(line["score"][key]["covered_without_model"] for line in lines)
        mean = sum(errors) / len(errors)
        print(f"{key}: {len(errors)} truths, RMS relative error {100 * rms:.2f} %, mean {100 * mean:+.2f} %, "
              f"covered {covered} (without the model-error part {bare})")


if __name__ == "__main__":
    main()
