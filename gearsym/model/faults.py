"""Shaft-order components: what one gear adds to its mesh once per revolution (eccentricity, a tooth fault,
pitting, spacing errors).

Each is declared on a gear with its tooth count (``Gear(..., teeth=Z)``, or ``--teeth`` for a model that
declares none) and added to the drivetrain like any component::

    wheel = model.add(Gear("gear2", inertia="I2", base_radius="r2", teeth=53))
    model.add(ToothFault("crack", wheel, tooth=7, depth="q_crack"))      # the pair of tooth 7 loses q_crack
    model.add(Eccentricity("runout", "gear1", amplitude="e_1", phase="theta_1"))

It becomes a term of the gear's mesh (:mod:`.shaft_orders`): a loss of mesh stiffness, ``k(phi) (1 - loss)``,
or a transmission error, ``g(x - e, eta)``, periodic over the gear's revolution, so that the reduction, the
derivation pages and the generated C carry it, and the system's period becomes that revolution (or the hunting
period, when both gears of a pair have one). Teeth are counted from tau = 0 (:mod:`.shaft_orders`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import sympy as sp

from ..errors import ModelError
from ..geometry import GearPair, crack_loss_along_path
from ..parameters import Constraint
from .components import BodyRef
from .expressions import ExprLike, to_expr
from .shaft_orders import DEFAULT_EDGE, path_coordinate, path_window, shaft_harmonic, tooth_by_tooth, tooth_share
from .stiffness import DEFAULT_CONTACT_RATIO


@dataclass(frozen=True)
class MeshTerms:
    """What shaft-order components add to one mesh, in its mesh phase: the fraction of stiffness lost and the
    transmission error (a length, in the mesh deflection's unit)."""

    loss: sp.Expr = sp.S.Zero
    error: sp.Expr = sp.S.Zero

    def __add__(self, other: "MeshTerms") -> "MeshTerms":
        return MeshTerms(self.loss + other.loss, self.error + other.error)


@dataclass(eq=False, frozen=True)
class ShaftOrderTerm:
    """A term fixed on one gear, repeating once per revolution. ``mesh`` names the mesh it acts in when the gear
    has more than one."""

    name: str
    gear: BodyRef
    mesh: Optional[str] = field(default=None, kw_only=True)

    def terms(self, phi: sp.Expr, teeth: int, where: str) -> MeshTerms:  # pragma: no cover (every kind has one)
        raise NotImplementedError

    def constraints(self) -> dict[str, Constraint]:
        """What the term's parameters may be (a depth that is a parameter: a fraction below 1), by name."""
        return {}

    def _tooth(self, tooth, teeth: int, where: str) -> int:
        if isinstance(tooth, bool) or not isinstance(tooth, int) or not 1 <= tooth <= teeth:
            raise ModelError(f"tooth must be a whole number from 1 to the gear's {teeth} teeth, got {tooth!r}", where)
        return tooth


@dataclass(eq=False, frozen=True)
class ToothFault(ShaftOrderTerm):
    """A local fault of tooth ``tooth`` (a crack, a broken corner): the pair it forms loses the fraction
    ``depth`` of its stiffness while it is in mesh, so the mesh stiffness is ``k(phi) (1 - depth p(w) s_n(phi))`` with
    ``s_n`` the pair's share (:func:`~.shaft_orders.tooth_share`: over ``contact_ratio`` mesh periods, each
    edge rising over ``edge`` of them). ``depth`` is a fraction (0: healthy), a number or a parameter.

    ``along_path``: how the loss runs along the pair's path of contact, p(w) = sum_k c_k w^k with ``along_path`` =
    (c_0, c_1, ...) and w from -1 (the pair comes into mesh) to +1 (it leaves)
    (:func:`~.shaft_orders.path_coordinate`); empty (the default): the same loss all along, p = 1. A root crack's
    loss runs from a few per cent to tens of per cent along the path: :func:`cracked_tooth` declares one from the gear
    geometry (its depth the mean loss, its ``along_path`` the shape, its contact ratio the pair's)."""

    tooth: int = 1
    depth: ExprLike = "q"
    contact_ratio: float = DEFAULT_CONTACT_RATIO
    edge: float = DEFAULT_EDGE
    along_path: tuple = ()

    def __post_init__(self):
        _check_fraction(self.depth, "depth", f"ToothFault {self.name!r}")

    def constraints(self) -> dict[str, Constraint]:
        return _fraction_parameter(self.depth, f"the fraction of the stiffness of the pair of tooth {self.tooth} of "
                                               f"{_gear_name(self.gear)} that its fault takes away")

    def terms(self, phi: sp.Expr, teeth: int, where: str) -> MeshTerms:
        tooth = self._tooth(self.tooth, teeth, where)
        loss = to_expr(self.depth, where) * tooth_share(phi, teeth, tooth, self.contact_ratio, self.edge)
        if self.along_path:
            w = path_coordinate(phi, teeth, tooth, self.contact_ratio)
            shape = sp.Add(*(_coefficient(c, where) * w**k for k, c in enumerate(self.along_path)))
            loss = loss * shape
        return MeshTerms(loss=loss)


def _coefficient(value, where: str) -> sp.Expr:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != value or abs(value) == float("inf"):
        raise ModelError(f"along_path holds polynomial coefficients (finite numbers), got {value!r}", where)
    return sp.Float(f"{float(value):.12g}")


def cracked_tooth(name: str, gear: BodyRef, pair, *, tooth: int, depth, angle, on: int | None = None,
                  origin: str = "critical_section", limit_line: str = "parallel",
                  mesh: Optional[str] = None) -> ToothFault:
    """A :class:`ToothFault` for a root crack from the gear geometry: tooth ``tooth`` of ``gear`` (the model's) is
    tooth of gear ``on`` (1 or 2; default: the one of ``pair`` with the gear's tooth count) of the geometry's
    ``pair`` (:class:`gearsym.GearPair`), cracked ``depth`` deep at ``angle`` to its centre line (m and rad,
    or Quantities; ``origin``, ``limit_line``: :class:`gearsym.geometry.Crack`'s). The fault's depth is the crack's
    mean loss over the path of contact, its ``along_path`` the loss along the path over that mean, its contact ratio
    the pair's: the model's mesh stiffness takes the cracked pair's stiffness phase by phase
    (:class:`gearsym.geometry.CrackLoss`)."""
    where = f"cracked_tooth {name!r}"
    if not isinstance(pair, GearPair):
        raise ModelError(f"needs the gear pair's geometry (gearsym.geometry.gear_pair(...)), got {type(pair).__name__}",
                         where)
    if on is None:
        teeth = getattr(gear, "tooth_count", None)
        matches = [i for i, g in ((1, pair.gear1), (2, pair.gear2)) if g.teeth == teeth]
        if len(matches) != 1:
            raise ModelError(f"say which gear of the pair ({pair.gear1.teeth}/{pair.gear2.teeth} teeth) the tooth is "
                             "on: on=1 or on=2", where)
        on = matches[0]
    loss = crack_loss_along_path(pair, on, depth, angle, origin=origin, limit_line=limit_line)
    return ToothFault(name, gear, tooth=tooth, depth=float(f"{loss.mean:.12g}"), along_path=loss.shape(),
                      contact_ratio=float(f"{pair.contact_ratio:.6f}"), mesh=mesh)


@dataclass(eq=False, frozen=True)
class Spall(ShaftOrderTerm):
    """Pitting or a spall on tooth ``tooth``: the fraction ``width`` of the face width lost over the part of the
    tooth's path of contact from ``start`` to ``end`` (fractions of the path, 0 where it comes into mesh): the pair
    loses that fraction of its stiffness there."""

    tooth: int = 1
    width: ExprLike = "w_spall"
    start: float = 0.3
    end: float = 0.7
    contact_ratio: float = DEFAULT_CONTACT_RATIO
    edge: float = DEFAULT_EDGE

    def __post_init__(self):
        _check_fraction(self.width, "width", f"Spall {self.name!r}")

    def constraints(self) -> dict[str, Constraint]:
        return _fraction_parameter(self.width, f"the fraction of the face width of tooth {self.tooth} of "
                                               f"{_gear_name(self.gear)} that its spall takes away")

    def terms(self, phi: sp.Expr, teeth: int, where: str) -> MeshTerms:
        tooth = self._tooth(self.tooth, teeth, where)
        share = tooth_share(phi, teeth, tooth, self.contact_ratio, self.edge)
        part = path_window(phi, teeth, tooth, self.contact_ratio, self.start, self.end, self.edge)
        return MeshTerms(loss=to_expr(self.width, where) * share * part)


@dataclass(eq=False, frozen=True)
class Eccentricity(ShaftOrderTerm):
    """Eccentricity or run-out of the gear: a transmission error ``amplitude cos(order phi/Z + phase)`` at its
    shaft order ``order`` (1 for eccentricity; run-out also has higher orders), a length."""

    amplitude: ExprLike = "e_ecc"
    phase: ExprLike = 0
    order: int = 1

    def terms(self, phi: sp.Expr, teeth: int, where: str) -> MeshTerms:
        if isinstance(self.order, bool) or not isinstance(self.order, int) or self.order < 1:
            raise ModelError(f"the shaft order must be a whole number of at least 1, got {self.order!r}", where)
        return MeshTerms(error=shaft_harmonic(phi, teeth, self.order, to_expr(self.amplitude, where),
                                              to_expr(self.phase, where)))


@dataclass(eq=False, frozen=True)
class SpacingErrors(ShaftOrderTerm):
    """Tooth spacing (pitch) errors: a transmission error that is ``errors[n - 1]`` while tooth n carries the
    load, blended over the double contact; one value (a length, a number or a parameter) per tooth."""

    errors: tuple = ()
    contact_ratio: float = DEFAULT_CONTACT_RATIO

    def terms(self, phi: sp.Expr, teeth: int, where: str) -> MeshTerms:
        errors = [to_expr(e, where) for e in self.errors]
        if len(errors) != teeth:
            raise ModelError(f"gives {len(errors)} spacing errors for a gear of {teeth} teeth: give one per tooth",
                             where)
        edge = (sp.nsimplify(self.contact_ratio) - 1) / 2
        return MeshTerms(error=tooth_by_tooth(phi, teeth, errors, edge))


#: why a fraction of stiffness lost is below 1: at 1 the pair carries nothing, beyond it it pulls (a negative tooth
#: stiffness, a tensile contact force)
_FRACTION = "0 <= {what} < 1 (0: healthy; at 1 the pair would carry nothing, beyond 1 it would pull)"


def _check_fraction(value: ExprLike, what: str, where: str) -> None:
    """A fraction of stiffness lost given as a number must be in [0, 1)."""
    expr = to_expr(value, where)
    if expr.is_number and not (expr.is_real and 0 <= float(expr) < 1):
        raise ModelError(f"{what} {value!r} is a fraction of the pair's stiffness lost: " + _FRACTION.format(what=what),
                         where)


def _fraction_parameter(value: ExprLike, meaning: str) -> dict[str, Constraint]:
    """A fraction lost given as a parameter: that parameter must be in [0, 1)."""
    expr = to_expr(value, meaning)
    return {expr.name: Constraint(meaning, True, below=1.0)} if isinstance(expr, sp.Symbol) else {}


def _gear_name(gear: BodyRef) -> str:
    return repr(gear if isinstance(gear, str) else gear.name)
