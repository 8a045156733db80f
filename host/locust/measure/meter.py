"""A multimeter's accuracy, as its manual states it: ``±(P % of the reading + N digits)``.

The two parts err differently. The percentage is the range's gain error: the same for every
reading taken on one range of one meter, so it cancels in a ratio of two such readings (the
plug's sag at stall against its voltage at rest) and counts in full in a reading used alone.
The digits are the last digit's counts of offset, noise and rounding: independent from one
reading to the next. Each is taken as uniform over its bound, one standard deviation being the
bound over sqrt(3). :meth:`MeterSpec.reading` makes a reading a meter of that spec could give
(the virtual robot's, for tests with known truth).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..errors import MeasureError

SQRT3 = math.sqrt(3.0)
SPEC = re.compile(r"^\s*(?P<percent>\d+(?:\.\d+)?)\s*%\s*\+\s*(?P<digits>\d+(?:\.\d+)?)\s*$")


@dataclass(frozen=True)
class MeterSpec:
    """One range of a multimeter: ``±(percent % of the reading + digits × resolution)``.

    Attributes
    ----------
    percent : float
        Of the reading [%].
    digits : float
        Counts of the last digit.
    resolution : float
        The last digit, in the reading's unit (0.01 V on a 20 V range).
    """

    percent: float
    digits: float
    resolution: float

    @classmethod
    def parse(cls, text: str, resolution: float, what: str = "--accuracy") -> MeterSpec:
        """A spec from its manual's words, ``0.5%+2``.

        Parameters
        ----------
        text : str
            ``P%+N``: P percent of the reading plus N digits.
        resolution : float
            The range's last digit (> 0), in the reading's unit.
        what : str
            The option it came from, for the error.

        Returns
        -------
        MeterSpec

        Raises
        ------
        locust.errors.MeasureError
            Text not of that form, or a resolution that is not a positive number.
        """
        match = SPEC.match(text or "")
        if match is None:
            raise MeasureError(f"{what} {text!r} is not a meter's accuracy",
                               "give it as the meter's manual does for the range used: P%+N, e.g. 0.5%+2 "
                               "(0.5 % of the reading plus 2 counts of the last digit)")
        if not (math.isfinite(resolution) and resolution > 0):
            raise MeasureError(f"the meter's last digit must be a positive number, not {resolution:g}",
                               "give the range's resolution: 0.01 V on a 20 V range, 0.01 A on a 10 A range")
        return cls(float(match["percent"]), float(match["digits"]), float(resolution))

    def gain_sd(self, reading: float) -> float:
        """The percentage's part of a reading's error, one sd, in the reading's unit."""
        return self.percent / 100.0 * abs(reading) / SQRT3

    @property
    def digits_sd(self) -> float:
        """The digits' part of a reading's error, one sd, in the reading's unit."""
        return self.digits * self.resolution / SQRT3

    def sd(self, reading: float) -> float:
        """A reading's whole error used alone (gain and digits), one sd, in its unit."""
        return math.hypot(self.gain_sd(reading), self.digits_sd)

    def describe(self) -> str:
        """``±(0.5 % + 2 digits), last digit 0.01``."""
        return f"±({self.percent:g} % + {self.digits:g} digits), last digit {self.resolution:g}"

    def reading(self, true: float, rng: np.random.Generator, gain: float | None = None) -> float:
        """What a meter of this spec could show for ``true``: a gain error, an offset of the last
        digit's counts, rounded to the last digit; within the spec's bound.

        Parameters
        ----------
        true : float
            The true value, in the reading's unit.
        rng : numpy.random.Generator
            Draws the offset (and the gain, when not given).
        gain : float, optional
            The range's gain error (a fraction, within ±percent/100), shared by readings of one
            range; drawn when not given.

        Returns
        -------
        float
            The reading, a whole number of last digits.
        """
        bound = self.percent / 100.0
        g = rng.uniform(-bound, bound) if gain is None else gain
        offset = rng.uniform(-1.0, 1.0) * max(self.digits - 0.5, 0.0) * self.resolution
        counts = round((true * (1.0 + g) + offset) / self.resolution)
        return float(f"{counts * self.resolution:.12g}")   # as the display shows it: 5.02, not 5.0200000000000005


__all__ = ["MeterSpec"]
