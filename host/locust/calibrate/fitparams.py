"""The values a fitter fits or holds, and the solver's vector of them.

Each fitter states its values as :class:`FitParameter` s (name, unit, start, physical
bounds, how the solver sees it, or held at a value with its uncertainty and source) in an
ordered :class:`FitParameters`; the solver works on the vector of the free ones, in which
each is of order one:

- ``log``: ``value = reference * exp(x)`` (a positive quantity spanning decades, or one
  known only to a factor: ``reference`` 1, the start, or -1 for a negative one);
- ``linear``: ``value = reference + scale * x`` (``scale``: the value's expected size,
  ``reference`` 0 unless the value is an offset from a known one).

The vocabulary is that of MuJoCo's ``mujoco.sysid`` (``Parameter``/``ParameterDict``:
nominal value, bounds, frozen, ``as_vector``/``update_from_vector``): ``start`` is its
nominal, ``held`` its frozen. A held value keeps its standard uncertainty and its source
so that the fit can carry it (:func:`.fitstats.fixed_covariance`). The statistics stay in
:mod:`.fitstats`: this type hands them the value-space Jacobian (:meth:`FitParameters.to_values_jacobian`)
or the delta-method gradient of a value (:meth:`FitParameters.gradient`), and takes a
solver-space covariance back to the values (:meth:`FitParameters.to_values_covariance`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import CalibrationError

SCALINGS = ("linear", "log")


@dataclass(frozen=True)
class FitParameter:
    """One value of a fit, in its own unit.

    Attributes
    ----------
    name : str
        The value's name (a dotted robot key, or the fitter's own name).
    unit : str
        Its unit, as the fitter reports it ("N*m/rad", "s", "1").
    start : float
        The start (or nominal) value [unit]; the value itself when ``held``.
    lower, upper : float
        Physical bounds [unit] (``-inf``/``inf``: none); for ``log``, both of the sign of
        ``reference``.
    scaling : str
        ``"log"`` (``value = reference * exp(x)``) or ``"linear"`` (``value = reference + scale * x``).
    scale : float
        ``linear``: the value's change per unit of ``x`` [unit], positive.
    reference : float or None
        ``log``: the factor [unit] (default 1); ``linear``: the offset [unit] (default 0).
    held : bool
        Held at ``start`` (not in the solver's vector).
    std : float
        A held value's standard uncertainty [unit] (0: taken as exact).
    source : str
        Where a held value (or the start) comes from.
    """

    name: str
    unit: str
    start: float
    lower: float = -math.inf
    upper: float = math.inf
    scaling: str = "linear"
    scale: float = 1.0
    reference: float | None = None
    held: bool = False
    std: float = 0.0
    source: str = ""

    def __post_init__(self):
        if self.scaling not in SCALINGS:
            raise CalibrationError(f"fit parameter {self.name}: scaling {self.scaling!r} is not one of {SCALINGS}",
                                   "use 'log' for a positive value spanning decades, 'linear' otherwise")
        if not self.scale > 0 or not math.isfinite(self.scale):
            raise CalibrationError(f"fit parameter {self.name}: scale must be positive and finite (got {self.scale})",
                                   "give the value's expected size in its unit")
        if not self.lower <= self.upper:
            raise CalibrationError(f"fit parameter {self.name}: lower bound {self.lower} above upper {self.upper}",
                                   "give the bounds as (lower, upper)")
        if self.scaling == "log":
            ref = self.origin
            if ref == 0 or not math.isfinite(ref):
                raise CalibrationError(f"fit parameter {self.name}: a log-scaled value needs a finite, nonzero "
                                       f"reference (got {ref})", "1, the start value, or -1 for a negative value")
            if not (self.lower / ref >= 0 and self.upper / ref >= 0):
                raise CalibrationError(f"fit parameter {self.name}: log-scaled bounds ({self.lower}, {self.upper}) "
                                       f"must have the sign of its reference {ref}",
                                       "a log-scaled value never changes sign: bound it away from 0")
        if not self.std >= 0:
            raise CalibrationError(f"fit parameter {self.name}: std must be 0 or more (got {self.std})",
                                   "the held value's standard uncertainty, in its unit")

    @property
    def origin(self) -> float:
        """``reference``, or its default: 1 for ``log``, 0 for ``linear``."""
        if self.reference is not None:
            return float(self.reference)
        return 1.0 if self.scaling == "log" else 0.0

    def to_x(self, value: float) -> float:
        """The solver's variable of ``value`` [unit]."""
        if self.scaling == "log":
            return math.log(value / self.origin)
        return (value - self.origin) / self.scale

    def to_value(self, x: float) -> float:
        """The value [unit] of the solver's variable ``x``."""
        if self.scaling == "log":
            return self.origin * math.exp(x)
        return self.origin + self.scale * x

    def derivative(self, x: float) -> float:
        """d value / d x at ``x`` [unit]."""
        return self.origin * math.exp(x) if self.scaling == "log" else self.scale

    def x_bounds(self) -> tuple[float, float]:
        """The bounds in the solver's variable, (low, high)."""
        if self.scaling == "log":
            ends = [_log_or_inf(b / self.origin) for b in (self.lower, self.upper)]
            return min(ends), max(ends)
        return self.to_x(self.lower), self.to_x(self.upper)


def _log_or_inf(ratio: float) -> float:
    return -math.inf if ratio == 0 else math.log(ratio)


class FitParameters:
    """An ordered set of :class:`FitParameter` (unique names): the free ones make the
    solver's vector, in their order.

    Parameters
    ----------
    params : iterable of FitParameter
        The values, free and held, in the order the vector takes the free ones.
    """

    def __init__(self, params: Iterable[FitParameter]):
        self.params: tuple[FitParameter, ...] = tuple(params)
        names = [p.name for p in self.params]
        if len(set(names)) != len(names):
            twice = sorted({n for n in names if names.count(n) > 1})
            raise CalibrationError(f"fit parameters named twice: {', '.join(twice)}", "give each value one name")
        self._free = tuple(p for p in self.params if not p.held)
        self._index = {p.name: i for i, p in enumerate(self._free)}

    def __len__(self) -> int:
        return len(self.params)

    def __iter__(self):
        return iter(self.params)

    def __getitem__(self, name: str) -> FitParameter:
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)

    def __repr__(self) -> str:
        return f"FitParameters(free={list(self.free)}, held={list(self.held)})"

    @property
    def free(self) -> tuple[str, ...]:
        """Names of the fitted values, in the vector's order."""
        return tuple(p.name for p in self._free)

    @property
    def held(self) -> tuple[str, ...]:
        """Names of the values held at their start."""
        return tuple(p.name for p in self.params if p.held)

    @property
    def size(self) -> int:
        """Length of the solver's vector."""
        return len(self._free)

    def index(self, name: str) -> int:
        """Position of the free value ``name`` in the solver's vector."""
        return self._index[name]

    def extended(self, *more: FitParameter) -> FitParameters:
        """These values and ``more`` after them."""
        return FitParameters(self.params + more)

    def as_vector(self, values: Mapping[str, float] | None = None) -> np.ndarray:
        """The solver's vector (size,) of ``values`` [their units] (a free one not given: its start).

        Parameters
        ----------
        values : mapping of str to float, optional
            Values by name; held ones are ignored.

        Returns
        -------
        numpy.ndarray
        """
        values = values or {}
        return np.array([p.to_x(float(values.get(p.name, p.start))) for p in self._free], dtype=float)

    def from_vector(self, x: np.ndarray) -> dict[str, float]:
        """Every value [its unit] at the solver's vector ``x``: the free ones from it, the
        held ones at their start, in the set's order.

        Parameters
        ----------
        x : array_like, shape (size,)

        Returns
        -------
        dict of str to float
        """
        x = np.asarray(x, dtype=float).ravel()
        if len(x) != self.size:
            raise CalibrationError(f"a vector of {len(x)} for {self.size} free values", "one entry per free value")
        out = {}
        for p in self.params:
            out[p.name] = float(p.start) if p.held else p.to_value(float(x[self._index[p.name]]))
        return out

    def free_values(self, x: np.ndarray) -> np.ndarray:
        """The free values [their units] at ``x``, in the vector's order (size,)."""
        x = np.asarray(x, dtype=float).ravel()
        return np.array([p.to_value(float(xi)) for p, xi in zip(self._free, x)])

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The solver's bounds, (low, high), each (size,)."""
        ends = [p.x_bounds() for p in self._free]
        return np.array([e[0] for e in ends], dtype=float), np.array([e[1] for e in ends], dtype=float)

    def near_bound(self, x: np.ndarray, tol: float = 1e-3) -> tuple[bool, ...]:
        """Whether each free value is within ``tol`` of a bound, in the solver's variable."""
        lo, hi = self.bounds()
        x = np.asarray(x, dtype=float).ravel()
        return tuple(bool(v) for v in np.minimum(x - lo, hi - x) < tol)

    def derivatives(self, x: np.ndarray) -> np.ndarray:
        """d value / d x of each free value at ``x`` (size,): the diagonal of the chain rule."""
        x = np.asarray(x, dtype=float).ravel()
        return np.array([p.derivative(float(xi)) for p, xi in zip(self._free, x)])

    def gradient(self, x: np.ndarray, name: str, factor: float = 1.0) -> np.ndarray:
        """Gradient in ``x`` of ``factor * value(name)`` (size,): for
        :meth:`.fitstats.Covariance.estimate` on a covariance of the solver's vector."""
        i = self._index[name]
        grad = np.zeros(self.size)
        grad[i] = factor * self._free[i].derivative(float(np.asarray(x, dtype=float).ravel()[i]))
        return grad

    def to_values_jacobian(self, jac: np.ndarray, x: np.ndarray) -> np.ndarray:
        """A residual Jacobian in ``x`` (n, size) as one in the free values:
        ``d r / d value = (d r / d x) / (d value / d x)``."""
        return np.asarray(jac, dtype=float) / self.derivatives(x)[None, :]

    def to_values_covariance(self, cov_x: np.ndarray, x: np.ndarray) -> np.ndarray:
        """A covariance of the solver's vector (size, size) as one of the free values, to
        first order (the delta method): ``D C D`` with ``D = diag(d value / d x)``."""
        d = self.derivatives(x)
        return np.asarray(cov_x, dtype=float) * np.outer(d, d)

    def held_std(self) -> dict[str, float]:
        """The held values that carry an uncertainty -> their standard uncertainty [unit]."""
        return {p.name: float(p.std) for p in self.params if p.held and p.std > 0}

    def units(self) -> dict[str, str]:
        """Each value's unit."""
        return {p.name: p.unit for p in self.params}
