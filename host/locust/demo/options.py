"""What a demo is asked for: its folder and sizes, the same whether ``locust demo`` or
:func:`locust.run_demo` asks.

The command's options take their defaults and ranges from here (:data:`RANGES`), so the two
doors refuse and accept the same values; this module imports nothing heavy, for ``locust demo
--help`` starts quickly.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import ReportError

# the sizes a demo accepts, each (lowest, highest): beyond them it takes longer than a demo
# should (6 cycles, 5 trials) or shows nothing (a sweep of fewer than 2 designs)
RANGES: dict[str, tuple[int, int]] = {"cycles": (1, 6), "trials": (1, 5), "designs": (2, 61), "jobs": (1, 64)}


@dataclass(frozen=True)
class DemoOptions:
    """One demo's options, as ``locust demo`` takes them.

    Attributes
    ----------
    out : pathlib.Path
        Parent folder; the demo goes into a new ``run/`` (``run-2/``, ...) inside.
    cycles : int
        Hop cycles per trial (and per design of the sweep).
    trials : int
        Hops filmed per leg set.
    designs : int
        Designs in the sweep: scale from 0 to 30 mm added to every link.
    jobs : int or None
        Sweep workers, and hops filmed at once up to two; None: every local core.
    fit_hops : bool
        Fit what the bench cannot reach from the filmed hops of Medium and Large.

    Raises
    ------
    locust.errors.ReportError
        A size that is not a whole number in its range (:data:`RANGES`).
    """

    out: Path = Path("demo-out")
    cycles: int = 3
    trials: int = 2
    designs: int = 7
    jobs: int | None = None
    fit_hops: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "out", Path(self.out))
        for name, (low, high) in RANGES.items():
            value = getattr(self, name)
            if value is None and name == "jobs":
                continue
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                raise ReportError(f"demo: {name}={value!r} is not a whole number from {low} to {high}",
                                  f"give {name} as an int in {low}..{high} (`locust demo --help` says what each does)")
        if not isinstance(self.fit_hops, bool):
            raise ReportError(f"demo: fit_hops={self.fit_hops!r} is not True or False",
                              "give fit_hops=True to fit the filmed hops, False to leave that stage out")


DEFAULTS = DemoOptions()    # what `locust demo` without options does
