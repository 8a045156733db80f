"""What a hinge fit costs with its Jacobian from the swing's variational equations (and the
closed form where the swing is linear) against forward differences of the integrated swing
(one integration a column), side by side in one run, on the real recordings in ../shared:

    python bench/hinge_fit_speed.py [--shared ../shared/data]

Per case: the wall time and the fitted k and b of each way, and the ratio of the times. The
forward differences are the fit as it was: 3e-5 of each solver variable, the swing always
integrated. The machine's load average is printed with the figures (timings move with it).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from locust.calibrate import hinge as hinge_fit
from locust.calibrate.recordings import REAL_TIME, clean_samples, read_table
from locust.io.importing import ImportOptions


def forward_differences(self, q):
    """The Jacobian's dynamic columns as the fit took them before: forward differences of 3e-5."""
    dynamic = list(range(self.DYNAMIC)) + ([len(q) - 1] if len(q) > self.DYNAMIC + self.n_geo else [])
    th = self.angle(q)
    cols = []
    for i in dynamic:
        h = 3e-5 * max(1.0, abs(q[i]))
        step = q.copy()
        step[i] += h
        cols.append((self.angle(step) - th) / h)
    return th, np.column_stack(cols), dynamic


def fit(path: Path, units: str, rig: hinge_fit.HingeRig, coulomb: str, old: bool):
    table = read_table(path, ImportOptions.parse(units), REAL_TIME)
    t, x, y = clean_samples(path, "marker", table.time_s(), *table.marker(), min_samples=20)
    saved = hinge_fit._Swing.angle_derivatives, hinge_fit.is_linear
    if old:
        hinge_fit._Swing.angle_derivatives, hinge_fit.is_linear = forward_differences, lambda params, rig: False
    try:
        start = time.perf_counter()
        result = hinge_fit.fit_hinge(t, x, y, rig, coulomb=coulomb, source=str(path))
        return time.perf_counter() - start, result
    finally:
        hinge_fit._Swing.angle_derivatives, hinge_fit.is_linear = saved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shared", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "data")
    args = parser.parse_args()
    hinge = args.shared / "hinge"
    cases = [
        ("Damping_test.trk, coulomb off", hinge / "Damping_test.trk", "m", hinge_fit.HingeRig(8.5e-7), "off"),
        ("Damping_test.trk, coulomb auto", hinge / "Damping_test.trk", "m", hinge_fit.HingeRig(8.5e-7), "auto"),
        ("film pendulum, in plane, 1e-4 kg*m^2", hinge / "pendulum_transparency_film.csv", "mm",
         hinge_fit.HingeRig(1e-4, "in-plane", 0.002, 0.08), "auto"),
        ("film pendulum, the help's example rig", hinge / "pendulum_transparency_film.csv", "m",
         hinge_fit.HingeRig(8.5e-7), "auto"),
    ]
    print(f"load average {os.getloadavg()[0]:.2f}")
    for name, path, units, rig, coulomb in cases:
        old_s, old = fit(path, units, rig, coulomb, old=True)
        new_s, new = fit(path, units, rig, coulomb, old=False)
        (k_old, b_old), (k_new, b_new) = ([f.estimates[key].value for key in (hinge_fit.STIFFNESS, hinge_fit.DAMPING)]
                                          for f in (old, new))
        print(f"{name}: forward differences {old_s:.2f} s (k {k_old:.6g}, b {b_old:.6g}); variational equations / "
              f"closed form {new_s:.2f} s (k {k_new:.6g}, b {b_new:.6g}); {old_s / new_s:.1f}x")


if __name__ == "__main__":
    main()
