"""The operating speed: which body declares it, how fast every other body and every mesh turns with it.

The speed ratios come from the reduction's rigid-body modes (the motion that deflects nothing); a mesh's
tooth-passing frequency per unit speed is its gear's tooth count times that gear's speed ratio, and the two
gears of a mesh must agree (base radii in the ratio of the teeth).
"""
from __future__ import annotations

import math
from fractions import Fraction
from collections.abc import Mapping
from typing import TYPE_CHECKING

from ..records import record_class
from ..errors import GearsymError, ModelError

if TYPE_CHECKING:  # (types only: the start-up path reads Speed without SymPy)
    from ..model.drivetrain import Drivetrain
    from ..model.resolved_components import ResolvedCoupling

#: how closely a gear pair's radii must follow its tooth counts (both set the same speed ratio)
RATIO_TOLERANCE = 1e-3


@record_class
class Speed:
    """The declared operating speed: the body it drives and the parameter that names it."""

    parameter: str
    body: str
    where: str


def declared_speed(model: Drivetrain) -> Speed | None:
    """The one body that declares the operating speed (``Gear(..., speed='speed')``), or None."""
    declared = [(b.name, b.speed_parameter) for b in model.bodies if b.speed_parameter]
    if len(declared) > 1:
        raise ModelError(f"bodies {', '.join(repr(b) for b, _ in declared)} all declare a speed; declare the "
                         "operating speed on one body (the others follow from the rigid-body mode)", model.name)
    if not declared:
        return None
    body, name = declared[0]
    if not (isinstance(name, str) and name.isidentifier()):
        raise ModelError(f"speed must name a parameter (e.g. speed='speed'), got {name!r}", body)
    return Speed(name, body, f"the speed of {body!r}")


class SpeedRatios:
    """Speeds of bodies and meshes per unit operating speed, at the values of a model's parameters (``values``:
    parameter symbol -> number, in any consistent units)."""

    def __init__(self, nd, speed: Speed | None, values: Mapping):
        self.model, self.speed, self.values = nd, speed, values

    def body(self, body: str) -> float:
        """Speed of ``body`` over the speed of the body that declares the operating speed."""
        rd = self.model.reduction.resolved
        index = {rb.body.name: rb.index for rb in rd.bodies}
        ref = index[self.speed.body]
        for mode in self.model.reduction.rigid_modes:
            u = [float(e.xreplace(self.values)) for e in mode]
            if u[ref] != 0 and u[index[body]] != 0:
                return abs(u[index[body]] / u[ref])
        raise GearsymError(f"{self.model.name}: {body!r} does not turn with {self.speed.body!r} (no rigid-body mode "
                           "joins them), so its speed is not set by the declared speed")

    def relative(self, rc: ResolvedCoupling, end) -> float:
        """The speed of a gear of a mesh relative to the planets' carrier (its own speed without one), per unit
        operating speed."""
        turning = rc.turning[0] if end is rc.a else rc.turning[1]
        if rc.carrier is None or not turning:
            return self.body(end.body.name)
        rd = self.model.reduction.resolved
        index = {rb.body.name: rb.index for rb in rd.bodies}
        ref = index[self.speed.body]
        for mode in self.model.reduction.rigid_modes:
            u = [float(e.xreplace(self.values)) for e in mode]
            if u[ref] != 0:
                return abs(sum(float(c) * x for c, x in zip(turning, u)) / u[ref])
        return self.body(end.body.name)

    def mesh(self, rc: ResolvedCoupling) -> float:
        """A mesh's tooth-passing frequency per unit operating speed (radians per radian of the driving body); a
        planet's mesh turns with the speeds relative to the carrier."""
        rates = []
        for end in (rc.a, rc.b):
            teeth = end.body.tooth_count
            if teeth is not None:
                if not (isinstance(teeth, int) and not isinstance(teeth, bool) and teeth > 0):
                    raise ModelError(f"teeth must be a positive whole number, got {teeth!r}",
                                     f"{type(end.body).__name__} {end.body.name!r}")
                rates.append((end.body.name, teeth * self.relative(rc, end)))
        if not rates:
            raise GearsymError(f"{self.model.name}: mesh {rc.name!r} needs tooth counts to turn the speed into a mesh "
                               f"frequency: declare Gear(..., teeth=N) on {rc.a.body.name!r} and {rc.b.body.name!r}")
        if len(rates) == 2 and not math.isclose(rates[0][1], rates[1][1], rel_tol=RATIO_TOLERANCE):
            raise GearsymError(f"{self.model.name}: mesh {rc.name!r}: the radii make {rates[0][0]!r} and "
                               f"{rates[1][0]!r} turn in a ratio their tooth counts do not (mesh frequencies "
                               f"{rates[0][1]:.6g} and {rates[1][1]:.6g} per unit speed); base radii must be in the "
                               "ratio of the teeth")
        return rates[0][1]

    def forcing(self, reference: ResolvedCoupling) -> float:
        """The forcing frequency (omega's) per unit operating speed; every mesh's order is checked against it."""
        ratio = self.mesh(reference) / float(reference.order)
        for rc in self.model.reduction.resolved.couplings:
            if rc.kind != "mesh" or rc is reference or not any(e.body.tooth_count for e in (rc.a, rc.b)):
                continue
            got = self.mesh(rc) / ratio
            if not math.isclose(got, float(rc.order), rel_tol=RATIO_TOLERANCE):
                fraction = Fraction(got).limit_denominator(10000)
                written = (str(fraction.numerator) if fraction.denominator == 1 else
                           f"sp.Rational({fraction.numerator}, {fraction.denominator})")
                raise GearsymError(f"{self.model.name}: mesh {rc.name!r} is declared with order {rc.order} of the "
                                   f"forcing frequency, but its tooth counts give {got:.6g}: leave order= out (with "
                                   f"teeth on both gears it is derived) or write order={written}")
        return ratio
