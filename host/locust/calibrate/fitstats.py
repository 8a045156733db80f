"""Confidence intervals of a least-squares fit from its Jacobian.

:func:`covariance`: ``s^2 (J^T J)^-1`` with ``s^2 = SSR / (n - p)`` (the residual variance),
valid near the optimum when the residuals are independent with equal variance; 95% intervals
use Student's t with ``n - p`` degrees of freedom.

:func:`cluster_covariance`: when residuals are correlated within groups (the frames of one
hop), the cluster-robust ("sandwich") covariance ``c B (sum_g J_g^T r_g r_g^T J_g) B`` with
``B = (J^T J)^-1`` and the small-sample factor ``c = G/(G-1) (n-1)/(n-p)`` (CR1; Cameron &
Miller, J. Human Resources 50, 2015), with Student's t on ``G - 1`` degrees of freedom for
``G`` clusters. A systematic shift of the parameters (the fit's own time step: its change
when the step is halved) may be added as a type-B standard uncertainty: combined in
quadrature, the t factor then takes the Welch-Satterthwaite effective degrees of freedom
(GUM, JCGM 100:2008, G.4). So may the uncertainties of values the fit holds fixed
(:func:`fixed_covariance`: taken from earlier calibrations, they are not exact), and a
model error measured apart (``Covariance.model``: what the fit's model misses of the plant,
found by fitting recordings of known truth), each a type-B part likewise.

:func:`serial_covariance`: for residuals in time order, the same inflated by the AR(1)
factor ``(1 + rho)/(1 - rho)`` of their lag-1 autocorrelation ``rho`` when that is above
what independent residuals give (effective sample size; e.g. Wilks, Statistical Methods in
the Atmospheric Sciences, 5.2.4).

Derived quantities (stiffness from frequency, ...) get theirs by first-order propagation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats


@dataclass(frozen=True)
class Estimate:
    """One fitted quantity: value, standard error (1 sigma) and 95% interval.

    Attributes
    ----------
    value : float
        The estimate [the quantity's unit].
    std : float
        Its standard uncertainty [same unit]; inf when the data do not determine it.
    ci95_low, ci95_high : float
        The 95% interval [same unit].
    std_numerical : float or None
        The part of ``std`` from the numerics [same unit] (None: not assessed).
    std_fixed : float or None
        The part from the uncertainties of values held fixed [same unit] (None: none).
    """

    value: float
    std: float          # one standard deviation, in the value's own unit (inf: not determined)
    ci95_low: float
    ci95_high: float
    std_numerical: float | None = None   # the part of ``std`` from the numerics (None: not assessed)
    std_fixed: float | None = None       # the part from the uncertainties of values held fixed (None: none)
    std_model: float | None = None       # the part from a measured model error (None: none)

    @property
    def ci95(self) -> tuple[float, float]:
        """The 95% interval, (low, high)."""
        return (self.ci95_low, self.ci95_high)

    @property
    def relative_std(self) -> float:
        """``std / |value|`` (dimensionless; inf when the value is 0)."""
        return self.std / abs(self.value) if self.value else float("inf")

    def as_dict(self) -> dict[str, float | list[float]]:
        """For JSON output: an undetermined std or bound stays ``inf``/``nan`` here and is
        written ``null`` (:func:`locust.fileio.json_text`).

        Returns
        -------
        dict
            ``value``, ``std``, ``ci95`` ([low, high]) and, where assessed, ``std_numerical``
            and ``std_fixed``, all in the quantity's unit.
        """
        out = {"value": self.value, "std": self.std, "ci95": [self.ci95_low, self.ci95_high]}
        if self.std_numerical is not None:
            out["std_numerical"] = self.std_numerical
        if self.std_fixed is not None:
            out["std_fixed"] = self.std_fixed
        if self.std_model is not None:
            out["std_model"] = self.std_model
        return out


@dataclass(frozen=True)
class Covariance:
    """Parameter covariance of a fit, the degrees of freedom of its t factor and, where
    assessed, the numerical shift of the parameters (added as a type-B uncertainty).

    Attributes
    ----------
    matrix : numpy.ndarray, shape (p, p)
        Covariance of the parameters [products of their units]; inf in the rows and columns
        of those the data do not determine.
    dof : int
        Degrees of freedom of the Student-t factor.
    shift : numpy.ndarray, shape (p,), or None
        Systematic shift of each parameter [its unit] (e.g. the fit's time step halved).
    method : str
        How the covariance was computed, for the report.
    fixed : numpy.ndarray, shape (p, p), or None
        Covariance carried in from values held fixed (:func:`fixed_covariance`).
    """

    matrix: np.ndarray
    dof: int
    shift: np.ndarray | None = None     # systematic shift of each parameter (e.g. dt -> dt/2)
    method: str = "s^2 (J^T J)^-1, t(n-p)"
    fixed: np.ndarray | None = None     # covariance carried in from values held fixed (fixed_covariance)
    model: np.ndarray | None = None     # covariance of a measured model error (the model is not the plant)

    def estimate(self, value: float, grad: np.ndarray) -> Estimate:
        """The interval of a quantity ``f(params)``, by first-order propagation.

        Parameters
        ----------
        value : float
            ``f`` at the optimum [its unit].
        grad : array_like, shape (p,)
            Its gradient in the parameters [its unit per each parameter's].

        Returns
        -------
        Estimate
            With ``shift`` or ``fixed`` set, their parts combined in quadrature and the t
            factor on the Welch-Satterthwaite degrees of freedom.
        """
        grad = np.asarray(grad, dtype=float)
        used = grad != 0
        sub = self.matrix[np.ix_(used, used)]
        var = float(grad[used] @ sub @ grad[used]) if used.any() else 0.0
        std = float(np.sqrt(max(var, 0.0))) if np.all(np.isfinite(sub)) else float("inf")
        dof, numerical, fixed, model = float(self.dof), None, None, None
        if self.shift is not None:
            numerical = abs(float(grad[used] @ self.shift[used])) if used.any() else 0.0
        if self.fixed is not None:
            part = self.fixed[np.ix_(used, used)]
            fixed = float(np.sqrt(max(float(grad[used] @ part @ grad[used]), 0.0))) if used.any() else 0.0
        if self.model is not None:
            part = self.model[np.ix_(used, used)]
            model = float(np.sqrt(max(float(grad[used] @ part @ grad[used]), 0.0))) if used.any() else 0.0
        if numerical is not None or fixed is not None or model is not None:
            combined = math.sqrt(std ** 2 + (numerical or 0.0) ** 2 + (fixed or 0.0) ** 2 + (model or 0.0) ** 2)
            # Welch-Satterthwaite: a type-B part counts with infinite degrees of freedom
            dof = dof * (combined / std) ** 4 if 0 < std < math.inf else math.inf
            std = combined
        k = t95(dof)
        return Estimate(float(value), std, float(value - k * std), float(value + k * std), numerical, fixed, model)

    def parameter(self, values: np.ndarray, i: int) -> Estimate:
        """The interval of one parameter.

        Parameters
        ----------
        values : array_like, shape (p,)
            The parameters at the optimum [their units].
        i : int
            The parameter's index.

        Returns
        -------
        Estimate
            As :meth:`estimate` with a unit gradient.
        """
        grad = np.zeros(len(values))
        grad[i] = 1.0
        return self.estimate(float(values[i]), grad)


def t95(dof: float) -> float:
    """Two-sided 95% Student-t factor.

    Parameters
    ----------
    dof : float
        Degrees of freedom (below 1: taken as 1; above 1e6 or inf: the normal's).

    Returns
    -------
    float
        The factor k with P(|t| < k) = 0.95 (1.96 for the normal).
    """
    if dof > 1e6:
        return float(stats.norm.ppf(0.975))
    return float(stats.t.ppf(0.975, max(float(dof), 1.0)))


def covariance(jac: np.ndarray, residual: np.ndarray) -> Covariance:
    """Covariance ``s^2 (J^T J)^-1`` from the residual Jacobian.

    A parameter the data cannot determine (a zero Jacobian column, or one that loads on a
    direction with a vanishing singular value) gets infinite variance.

    Parameters
    ----------
    jac : array_like, shape (n, p)
        d residual / d params at the optimum [the residual's unit per each parameter's].
    residual : array_like, shape (n,)
        The residuals at the optimum.

    Returns
    -------
    Covariance
        With ``n - p`` degrees of freedom (at least 1).
    """
    jac = np.asarray(jac, dtype=float)
    residual = np.asarray(residual, dtype=float).ravel()
    n, p = jac.shape
    dof = max(n - p, 1)
    bread, undetermined = _inverse_normal(jac)
    cov = bread * (float(residual @ residual) / dof)
    return Covariance(_mark(cov, undetermined), dof)


def serial_covariance(jac: np.ndarray, residual: np.ndarray) -> tuple[Covariance, float]:
    """:func:`covariance` for residuals in time order that may be serially correlated (a
    track's jitter, a model that misses a slow drift), and their lag-1 autocorrelation rho.

    Correlated residuals carry less information than as many independent ones: for a
    first-order autoregressive residual the variance of a slowly varying fit grows by
    ``(1 + rho)/(1 - rho)`` and the effective number of samples falls by the same factor.
    Where rho is above what independent residuals give (``2/sqrt(n)``, about the one-sided
    97.7 % point) the covariance is multiplied by that factor and the t factor takes
    ``n_eff - p`` degrees of freedom; otherwise it is :func:`covariance`'s.

    Parameters
    ----------
    jac : array_like, shape (n, p)
        d residual / d params at the optimum.
    residual : array_like, shape (n,)
        The residuals at the optimum, in time order.

    Returns
    -------
    tuple of (Covariance, float)
        The covariance and rho (dimensionless; capped at 0.99 when it is used).
    """
    base = covariance(jac, residual)
    r = np.asarray(residual, dtype=float).ravel()
    r = r - r.mean()
    power = float(r @ r)
    rho = float(r[1:] @ r[:-1]) / power if power > 0 else 0.0
    n, p = np.shape(jac)
    if rho <= 2 / math.sqrt(n):
        return base, rho
    rho = min(rho, 0.99)
    factor = (1 + rho) / (1 - rho)
    dof = max(int(n / factor) - p, 1)
    method = f"s^2 (J^T J)^-1 x (1+rho)/(1-rho), residual autocorrelation rho={rho:.3g}, t(n_eff-p)"
    return Covariance(base.matrix * factor, dof, method=method), rho


def cluster_covariance(jac: np.ndarray, residual: np.ndarray, clusters: np.ndarray,
                       shift: np.ndarray | None = None, fixed: np.ndarray | None = None) -> Covariance:
    """Cluster-robust (CR1) covariance, residuals correlated within each cluster label of
    ``clusters`` (n,), independent between clusters; ``shift`` (p,): a systematic shift of
    the parameters, and ``fixed`` (p, p): the covariance carried in from values held fixed
    (:func:`fixed_covariance`), both added as type-B uncertainties. Fewer clusters than one
    more than the parameters determine nothing: every variance is then infinite.

    Parameters
    ----------
    jac : array_like, shape (n, p)
        d residual / d params at the optimum.
    residual : array_like, shape (n,)
        The residuals at the optimum.
    clusters : array_like, shape (n,)
        Each residual's cluster label.
    shift : array_like, shape (p,), optional
        Systematic shift of each parameter [its unit].
    fixed : array_like, shape (p, p), optional
        Covariance carried in from values held fixed.

    Returns
    -------
    Covariance
        With ``G - 1`` degrees of freedom (at least 1) for ``G`` clusters.
    """
    jac = np.asarray(jac, dtype=float)
    residual = np.asarray(residual, dtype=float).ravel()
    clusters = np.asarray(clusters).ravel()
    n, p = jac.shape
    labels = np.unique(clusters)
    g = len(labels)
    bread, undetermined = _inverse_normal(jac)
    scores = np.array([jac[clusters == c].T @ residual[clusters == c] for c in labels]).reshape(g, p)
    factor = g / max(g - 1, 1) * (n - 1) / max(n - p, 1)
    cov = factor * bread @ (scores.T @ scores) @ bread
    if g <= p:
        undetermined = np.ones(p, dtype=bool)
    return Covariance(_mark(cov, undetermined), max(g - 1, 1), shift,
                      f"cluster-robust (CR1) over {g} clusters, t({max(g - 1, 1)})", fixed)


def fixed_covariance(jac: np.ndarray, jac_fixed: np.ndarray, std_fixed: np.ndarray) -> np.ndarray:
    """What the uncertainties of values held fixed in a fit do to the fitted ones (p, p).

    A held value ``q`` off by ``dq`` moves the optimum, to first order, by
    ``G dq`` with ``G = -(J^T J)^-1 J^T J_q`` (``jac_fixed`` (n, q): the residual's
    derivative in each held value, ``std_fixed`` (q,): their standard uncertainties, taken
    as independent): the fitted values' covariance from them is ``G diag(std^2) G^T``. A
    fit that takes its other values from earlier calibrations carries their uncertainty in
    this way instead of treating them as exact (GUM, JCGM 100:2008, 5.1).

    Parameters
    ----------
    jac : array_like, shape (n, p)
        d residual / d fitted values at the optimum.
    jac_fixed : array_like, shape (n, q)
        d residual / d held values.
    std_fixed : array_like, shape (q,)
        Standard uncertainties of the held values [their units].

    Returns
    -------
    numpy.ndarray, shape (p, p)
        Covariance of the fitted values from the held ones [products of their units]; 0 in
        the rows of undetermined values.
    """
    jac = np.asarray(jac, dtype=float)
    bread, undetermined = _inverse_normal(jac)
    gain = -bread @ (jac.T @ np.asarray(jac_fixed, dtype=float))
    gain[undetermined] = 0.0
    return (gain * np.asarray(std_fixed, dtype=float) ** 2) @ gain.T


def linear_shift(jac: np.ndarray, delta_residual: np.ndarray) -> np.ndarray:
    """The parameters' first-order (Gauss-Newton) shift when the residual changes by
    ``delta_residual`` at fixed parameters: ``-(J^T J)^-1 J^T dr`` (0 where undetermined).

    Parameters
    ----------
    jac : array_like, shape (n, p)
        d residual / d params at the optimum.
    delta_residual : array_like, shape (n,)
        The residual's change [the residual's unit].

    Returns
    -------
    numpy.ndarray, shape (p,)
        The shift of each parameter [its unit].
    """
    jac = np.asarray(jac, dtype=float)
    bread, undetermined = _inverse_normal(jac)
    shift = -bread @ (jac.T @ np.asarray(delta_residual, dtype=float).ravel())
    return np.where(undetermined, 0.0, shift)


def _inverse_normal(jac: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(J^T J)^-1`` by SVD, and which parameters it leaves undetermined (a zero column, or
    one that loads on a direction with a vanishing singular value)."""
    # Scale the columns first so parameters of very different size (kp ~ 1, kv ~ 0.01)
    # do not swamp the condition number; the scaling is undone on the result.
    norms = np.linalg.norm(jac, axis=0)
    safe = np.where(norms > 0, norms, 1.0)
    _, sv, vt = np.linalg.svd(jac / safe, full_matrices=False)
    tiny = sv < 1e-8 * max(float(sv.max(initial=0.0)), 1e-300)
    inv_sv2 = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, sv) ** 2)
    bread = ((vt.T * inv_sv2) @ vt) / np.outer(safe, safe)
    undetermined = (norms == 0) | (np.abs(vt[tiny]).max(axis=0, initial=0.0) > 1e-3)
    return bread, undetermined


def _mark(cov: np.ndarray, undetermined: np.ndarray) -> np.ndarray:
    cov = cov.copy()
    cov[undetermined, :] = np.inf
    cov[:, undetermined] = np.inf
    return cov
