"""Click parameter types every command shares: numbers that must be finite (and positive).

``click``'s own ``float`` takes ``nan`` and ``inf``; an option given one of them would reach a
fit or a drawing as nonsense, so these refuse it where the command line is read.
"""

from __future__ import annotations

import math

import click


class FiniteFloat(click.ParamType):
    """A finite number; with ``positive``, above zero; with ``low``/``high``, within them."""

    name = "number"

    def __init__(self, positive: bool = False, low: float | None = None, high: float | None = None):
        self.positive = positive
        self.low, self.high = low, high

    def convert(self, value, param, ctx):
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        if self.positive and not number > 0:
            self.fail(f"{value!r} must be above 0", param, ctx)
        if self.low is not None and number < self.low:
            self.fail(f"{value!r} is below {self.low:g}", param, ctx)
        if self.high is not None and number > self.high:
            self.fail(f"{value!r} is above {self.high:g}", param, ctx)
        return number


FINITE = FiniteFloat()
POSITIVE = FiniteFloat(positive=True)
