"""Confidence intervals of a least-squares fit from its Jacobian.

The covariance of the fitted parameters is ``s^2 (J^T J)^-1`` with ``s^2 = SSR / (n - p)``
(the residual variance), valid near the optimum when the residuals are independent with
equal variance. 95% intervals use Student's t with ``n - p`` degrees of freedom; derived
quantities (stiffness from frequency, ...) get theirs by first-order propagation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats


@dataclass(frozen=True)
class Estimate:
    """One fitted quantity: value, standard error (1 sigma) and 95% interval."""

    value: float
    std: float          # one standard deviation, in the value's own unit (inf: not determined)
    ci95_low: float
    ci95_high: float

    @property
    def relative_std(self) -> float:
        return self.std / abs(self.value) if self.value else float("inf")

    def as_dict(self) -> dict[str, float | list[float]]:
        """For JSON output: an undetermined std or bound stays ``inf``/``nan`` here and is
        written ``null`` (:func:`locust.fileio.json_text`)."""
        return {"value": self.value, "std": self.std, "ci95": [self.ci95_low, self.ci95_high]}


@dataclass(frozen=True)
class Covariance:
    """Parameter covariance of a fit and its residual degrees of freedom."""

    matrix: np.ndarray
    dof: int

    def estimate(self, value: float, grad: np.ndarray) -> Estimate:
        """A quantity ``f(params)`` with gradient ``grad`` at the optimum."""
        grad = np.asarray(grad, dtype=float)
        used = grad != 0
        sub = self.matrix[np.ix_(used, used)]
        var = float(grad[used] @ sub @ grad[used]) if used.any() else 0.0
        std = float(np.sqrt(max(var, 0.0))) if np.all(np.isfinite(sub)) else float("inf")
        k = t95(self.dof)
        return Estimate(float(value), std, float(value - k * std), float(value + k * std))

    def parameter(self, values: np.ndarray, i: int) -> Estimate:
        grad = np.zeros(len(values))
        grad[i] = 1.0
        return self.estimate(float(values[i]), grad)


def t95(dof: int) -> float:
    """Two-sided 95% Student-t factor for ``dof`` degrees of freedom."""
    return float(stats.t.ppf(0.975, max(int(dof), 1)))


def covariance(jac: np.ndarray, residual: np.ndarray) -> Covariance:
    """Covariance from the residual Jacobian ``jac`` (n, p) = d(residual)/d(params).

    A parameter the data cannot determine (a zero Jacobian column, or one that loads on a
    direction with a vanishing singular value) gets infinite variance.
    """
    jac = np.asarray(jac, dtype=float)
    residual = np.asarray(residual, dtype=float).ravel()
    n, p = jac.shape
    dof = max(n - p, 1)
    s2 = float(residual @ residual) / dof
    # Scale the columns first so parameters of very different size (kp ~ 1, kv ~ 0.01)
    # do not swamp the condition number; the scaling is undone on the covariance.
    norms = np.linalg.norm(jac, axis=0)
    safe = np.where(norms > 0, norms, 1.0)
    _, sv, vt = np.linalg.svd(jac / safe, full_matrices=False)
    tiny = sv < 1e-8 * max(float(sv.max(initial=0.0)), 1e-300)
    inv_sv2 = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, sv) ** 2)
    cov = ((vt.T * inv_sv2) @ vt) * s2 / np.outer(safe, safe)
    undetermined = (norms == 0) | (np.abs(vt[tiny]).max(axis=0, initial=0.0) > 1e-3)
    cov[undetermined, :] = np.inf
    cov[:, undetermined] = np.inf
    return Covariance(cov, dof)
