"""The material of a gear: Young's modulus, Poisson's ratio and density, in SI units."""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import GearsymError


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material: ``E`` in Pa, ``nu`` (Poisson's ratio), ``rho`` in kg/m^3."""

    E: float
    nu: float
    rho: float = 7850.0

    def __post_init__(self):
        for name, value in (("Young's modulus E", self.E), ("Poisson's ratio nu", self.nu), ("density rho", self.rho)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise GearsymError(f"material: {name} must be a finite number, got {value!r}")
        if self.E <= 0:
            raise GearsymError(f"material: Young's modulus E must be positive (Pa), got {self.E:g}")
        if not 0.0 <= self.nu < 0.5:
            raise GearsymError(f"material: Poisson's ratio nu must lie in [0, 0.5), got {self.nu:g}")
        if self.rho <= 0:
            raise GearsymError(f"material: density rho must be positive (kg/m^3), got {self.rho:g}")
        object.__setattr__(self, "E", float(self.E))
        object.__setattr__(self, "nu", float(self.nu))
        object.__setattr__(self, "rho", float(self.rho))

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)), Pa."""
        return self.E / (2.0 * (1.0 + self.nu))


#: steel as ISO 6336 takes it: E = 206 000 N/mm^2 and nu = 0.3 (ISO 6336-2's elasticity factor Z_E = 189.8
#: sqrt(N/mm^2) for steel on steel is computed from them); density 7850 kg/m^3, the value models/spur_pair.py uses
STEEL = Material(E=2.06e11, nu=0.3, rho=7850.0)
