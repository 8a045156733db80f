"""The coins a student has in a pocket, as the fold test's load (``locust calibrate fold --coin``).

Each mass, diameter and thickness is the issuer's published figure:

- euro cents: Council Regulation (EC) No 975/98 on the denominations and technical
  specifications of euro coins (1 cent 2.30 g, 16.25 mm; 2 cent 3.06 g, 18.75 mm; 5 cent
  3.92 g, 21.25 mm; each 1.67 mm thick);
- US cent, nickel and dime: United States Mint, *Coin Specifications* (2.500 g, 19.05 mm,
  1.52 mm; 5.000 g, 21.21 mm, 1.95 mm; 2.268 g, 17.91 mm, 1.35 mm);
- UK penny: The Royal Mint Museum, *1p Coin Designs and Specifications* (3.56 g, 20.3 mm,
  1.65 mm, copper-plated steel since 1992).

A coin out of a pocket is not its published mass: minting tolerance and wear spread it, so a
named coin's mass is given the standard uncertainty :data:`PUBLISHED_MASS_REL_SD` of it (an
estimate, not a published tolerance). A coin weighed on a 0.01 g scale (``--coin-mass-kg``) is
known to :data:`WEIGHED_SD_KG`, and to be better than the published figure it must be weighed.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import CalibrationError

PUBLISHED_MASS_REL_SD = 0.025          # a circulating coin about its published mass (estimate)
WEIGHED_SD_KG = 1e-5                   # a kitchen scale's 0.01 g
WEIGHED_THICKNESS_M = 0.0016           # a weighed coin's thickness when not named: a small coin's
WEIGHED_THICKNESS_SD_M = 0.0003


@dataclass(frozen=True)
class Coin:
    """A coin: its published mass, size and where they are published."""

    name: str
    mass_kg: float
    diameter_m: float
    thickness_m: float
    source: str

    @property
    def mass_sd_kg(self) -> float:
        """Its mass' standard uncertainty [kg] (:data:`PUBLISHED_MASS_REL_SD`)."""
        return PUBLISHED_MASS_REL_SD * self.mass_kg


_EU = "datasheet:Council Regulation (EC) No 975/98"
_US = "datasheet:United States Mint, Coin Specifications"
_UK = "datasheet:The Royal Mint Museum, 1p Coin Designs and Specifications"
COINS: dict[str, Coin] = {c.name: c for c in (
    Coin("eur-1c", 2.30e-3, 16.25e-3, 1.67e-3, _EU),
    Coin("eur-2c", 3.06e-3, 18.75e-3, 1.67e-3, _EU),
    Coin("eur-5c", 3.92e-3, 21.25e-3, 1.67e-3, _EU),
    Coin("usd-1c", 2.500e-3, 19.05e-3, 1.52e-3, _US),
    Coin("usd-5c", 5.000e-3, 21.21e-3, 1.95e-3, _US),
    Coin("usd-10c", 2.268e-3, 17.91e-3, 1.35e-3, _US),
    Coin("gbp-1p", 3.56e-3, 20.3e-3, 1.65e-3, _UK),
)}


def coin(name: str) -> Coin:
    """A coin by its name (``eur-1c``, ``usd-1c``, ``gbp-1p``, ...).

    Parameters
    ----------
    name : str
        A key of :data:`COINS`.

    Returns
    -------
    Coin

    Raises
    ------
    locust.errors.CalibrationError
        A coin not in the table.
    """
    try:
        return COINS[name]
    except KeyError:
        raise CalibrationError(f"coin {name!r}: not one of {', '.join(COINS)}",
                               "weigh it and give --coin-mass-kg (a 0.01 g scale), or name one of those") from None


__all__ = ["COINS", "PUBLISHED_MASS_REL_SD", "WEIGHED_SD_KG", "Coin", "coin"]
