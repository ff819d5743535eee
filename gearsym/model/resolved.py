"""A drivetrain resolved: every declaration checked and parsed, with its kinematics set up.

:class:`ResolvedDrivetrain` turns the components of a :class:`~gearsym.model.drivetrain.Drivetrain` into
bodies with angles, couplings with deflection rows (``r_a psi_a -+ r_b psi_b`` for a mesh, ``psi_b - psi_a``
for a shaft) and external torques split into their mean and harmonics; every error names the component to
fix. Its Lagrangian (:mod:`.lagrangian`) and the phasing of planetary sets (:mod:`.planetary`) are its bases.
"""
from __future__ import annotations

from typing import Optional

import sympy as sp

from ..checks import sign_violation
from .declared import Model
from ..errors import ModelError, suggest
from .symbols import omega, parameter_symbol, phi, t
from .components import Bearing, Body, BodyRef, Coupling, Gear, Harmonic, Mesh, Planet, Torque
from .expressions import ExprLike, parameter_names, to_expr
from .lagrangian import LagrangianForms
from .mesh_orders import MeshOrders
from .planetary import PlanetaryPhasing
from .resolved_faults import ShaftOrderResolution
from .resolved_components import ResolvedBody, ResolvedCoupling, ResolvedForcing
from .stiffness import check_periodic
from .translations import TranslationResolution


class ResolvedDrivetrain(MeshOrders, PlanetaryPhasing, ShaftOrderResolution, TranslationResolution,
                         LagrangianForms):
    """The checked, symbolic view of a :class:`Drivetrain`."""

    def __init__(self, model: Model):  # (a Drivetrain, which resolves itself here)
        self.model = model
        if not model.bodies:
            raise ModelError("the drivetrain has no bodies; add Gear or Disk components", model.name)
        if not model.couplings:
            raise ModelError("the drivetrain has no couplings; join its bodies with Mesh or Shaft", model.name)
        moving = [b for b in model.bodies if not b.fixed]
        if not moving:
            raise ModelError("every body is fixed; a drivetrain needs at least one body that turns", model.name)
        self.bodies = [self._resolve_body(i, b) for i, b in enumerate(moving)]
        self.fixed = [self._resolve_body(None, b) for b in model.bodies if b.fixed]
        self._by_name = {rb.body.name: rb for rb in (*self.bodies, *self.fixed)}
        self.dofs = list(self.bodies)  # the rotations, then the translations of bodies on bearings
        self.translations = self._resolve_bearings(len(self.bodies))
        self.dofs = self.bodies + self.translations
        self.couplings = []
        for c in model.joints:
            self.couplings += self._bearing_couplings(c) if isinstance(c, Bearing) else [self._resolve_coupling(c)]
        self.forcing = [f for tq in model.torques for f in self._resolve_torque(tq)]
        self._check_connected()
        self.couplings = self._with_orders(self.couplings)
        self.couplings = [self._with_planet_phase(rc) for rc in self.couplings]
        self._check_assembly()
        self.couplings = self._with_shaft_terms(self.couplings)
        self.couplings = self._with_geometry_symbols(self.couplings)

    # ---- helpers
    def _default_value(self, expr: sp.Expr) -> Optional[float]:
        """Numeric value of ``expr`` at the declared defaults, or None if any is missing."""
        subs = {}
        for name in parameter_names(expr):
            if name not in self.model._defaults:
                return None
            subs[parameter_symbol(name)] = to_expr(self.model._defaults[name], f"default of {name}")
        try:
            return float(expr.xreplace(subs))
        except TypeError:
            return None

    def _positive(self, value: ExprLike, what: str, where: str, allow_zero: bool = False) -> sp.Expr:
        """Parse ``value`` and reject a non-positive number or default (negative only, with allow_zero)."""
        expr = to_expr(value, where)
        num = float(expr) if expr.is_number else self._default_value(expr)
        must = sign_violation(num, allow_zero) if num is not None else None
        if must:
            shown = expr if expr.is_number else f"{expr} = {num:g} (its default)"
            raise ModelError(f"{what} {must}, got {shown}", where)
        return expr

    def body(self, ref: BodyRef, where: str) -> ResolvedBody:
        name = ref.name if isinstance(ref, Body) else ref
        if not isinstance(name, str) or name not in self._by_name:
            known = list(self._by_name)
            raise ModelError(
                f"joins {name!r}, which is not a body of this drivetrain.{suggest(str(name), known)} "
                f"Add it with model.add(Gear(...)) or Disk(...); bodies: {', '.join(known)}",
                where,
            )
        rb = self._by_name[name]
        if isinstance(ref, Body) and ref is not rb.body:
            raise ModelError(f"refers to a body named {name!r} that was not the one added to the model", where)
        return rb

    # ---- bodies, couplings, torques
    def _resolve_body(self, index: Optional[int], body: Body) -> ResolvedBody:
        where = f"{type(body).__name__} {body.name!r}"
        if index is None:  # fixed: no angle, and an inertia would never be used
            if isinstance(body, Planet):
                raise ModelError("a planet cannot be fixed; fix its carrier instead", where)
            inertia, angle = None, sp.S.Zero
        elif body.inertia is None:
            raise ModelError("needs an inertia (Gear(..., inertia='I1')), or declare it fixed=True if it is held", where)
        else:
            inertia = self._positive(body.inertia, "the moment of inertia", where)
            angle = sp.Function(f"psi_{index + 1}", real=True)(t)
        radius = None
        if isinstance(body, Gear):
            radius = self._positive(body.base_radius, "the base radius", where)
        return ResolvedBody(body, index, angle, inertia, radius)

    def _unit_row(self, rb: ResolvedBody) -> list[sp.Expr]:
        """The row over the degrees of freedom that is this body's angle (zeros for a fixed body)."""
        row = [sp.S.Zero] * len(self.dofs)
        if rb.index is not None:
            row[rb.index] = sp.S.One
        return row

    def _carrier_of(self, a: ResolvedBody, b: ResolvedBody, where: str) -> Optional[ResolvedBody]:
        """The carrier of the one planet of a mesh (None without a planet); other arrangements are refused."""
        planets = [end for end in (a, b) if isinstance(end.body, Planet)]
        if not planets:
            return None
        if len(planets) == 2:
            raise ModelError("joins two planets; meshes between planets (double-planet sets) are not supported", where)
        planet = planets[0]
        other = b if planet is a else a
        if planet.body.carrier is None:
            raise ModelError("needs its carrier: Planet(..., carrier=carrier_body)", f"Planet {planet.body.name!r}")
        carrier = self.body(planet.body.carrier, f"Planet {planet.body.name!r}")
        if carrier is planet or carrier is other:
            raise ModelError(f"{carrier.body.name!r} carries the planet {planet.body.name!r}, so it cannot also mesh "
                             "with it", where)
        if planet.body.internal:
            raise ModelError("a planet has external teeth; the ring gear is the one with internal=True",
                             f"Planet {planet.body.name!r}")
        return carrier

    def _turning(self, end: ResolvedBody, carrier: Optional[ResolvedBody]) -> list[sp.Expr]:
        """The row of the gear's angle relative to the carrier, in its own sense: a planet is counted opposite
        to its carrier, a central gear in the carrier's sense."""
        row = self._unit_row(end)
        if carrier is not None:
            sign = 1 if isinstance(end.body, Planet) else -1
            row = [e + sign * c for e, c in zip(row, self._unit_row(carrier))]
        return row

    def _mesh_rows(self, mesh: Mesh, a: ResolvedBody, b: ResolvedBody, where: str):
        """The deflection row ``r_a phi_a -+ r_b phi_b`` (minus for an external, plus for an internal mesh) in
        the angles phi relative to the carrier, the carrier, and the two relative-angle rows."""
        for end in (a, b):
            if end.radius is None:
                raise ModelError(
                    f"meshes with {end.body.name!r}, a {type(end.body).__name__} without a base radius; "
                    "a mesh needs two Gear bodies",
                    where,
                )
        if a.fixed and b.fixed and not (self.translates(a) or self.translates(b)):
            raise ModelError(f"joins two fixed bodies ({a.body.name!r}, {b.body.name!r}); it could never deflect", where)
        internal = [end.body.name for end in (a, b) if getattr(end.body, "internal", False)]
        if len(internal) == 2:
            raise ModelError("joins two ring gears (internal=True); a ring gear meshes with a pinion or planet", where)
        carrier = self._carrier_of(a, b, where)
        turn_a, turn_b = self._turning(a, carrier), self._turning(b, carrier)
        sign = 1 if internal else -1
        # a planet on its pin: its centre's motion (the carrier's rotation too) is in the projection, so the
        # rotations are the gears' own
        own = carrier is not None and any(isinstance(e.body, Planet) and self.translates(e) for e in (a, b))
        rot_a, rot_b = (self._unit_row(a), self._unit_row(b)) if own else (turn_a, turn_b)
        projection = self._projection(mesh, a, b, carrier, where)
        row = tuple(a.radius * x + sign * b.radius * y + p for x, y, p in zip(rot_a, rot_b, projection))
        return row, carrier, (tuple(turn_a), tuple(turn_b))

    def _resolve_coupling(self, c: Coupling) -> ResolvedCoupling:
        kind = "mesh" if isinstance(c, Mesh) else "shaft"
        where = f"{type(c).__name__} {c.name!r}"
        a, b = (self.body(end, where) for end in c.ends)
        if a is b:
            raise ModelError(f"joins body {a.body.name!r} to itself; a {kind} must join two different bodies", where)
        if isinstance(c, Mesh):
            row, carrier, turning = self._mesh_rows(c, a, b, where)
            order = None if c.order is None else to_expr(c.order, where)  # None: from the teeth (mesh_orders.py)
            if order is not None and not (order.is_number and order.is_positive and order.is_rational):
                raise ModelError(f"the mesh order must be a positive rational number (e.g. order=sp.Rational(19, 61)), "
                                 f"got {order}; leave it out to derive it from the tooth counts", where)
            variation = to_expr(c.variation, where)
            if variation.free_symbols & {t}:
                raise ModelError("the stiffness variation must be written in the mesh phase phi, not in t", where)
            defaults = {
                parameter_symbol(nm): self._default_value(parameter_symbol(nm))
                for nm in parameter_names(variation)
            }
            check_periodic(variation, phi, where, {k: v for k, v in defaults.items() if v is not None})
            return ResolvedCoupling(
                component=c, kind=kind, a=a, b=b, row=row, scale=sp.S.One,
                stiffness=self._positive(c.stiffness, "the mesh stiffness", where),
                damping=self._positive(c.damping, "the mesh damping", where, allow_zero=True),
                backlash=self._positive(c.backlash, "the backlash", where, allow_zero=True),
                variation=variation,
                mesh_phase=(0 if order is None else order * omega * t) + to_expr(c.phase, where),
                order=sp.S.Zero if order is None else order, carrier=carrier, turning=turning,
            )
        if a.fixed and b.fixed:
            raise ModelError(f"joins two fixed bodies ({a.body.name!r}, {b.body.name!r}); it could never twist", where)
        row = [y - x for x, y in zip(self._unit_row(a), self._unit_row(b))]
        if c.radius is not None:
            scale = self._positive(c.radius, "the shaft's coordinate radius", where)
        elif a.radius is not None:
            scale = a.radius
        elif b.radius is not None:
            scale = b.radius
        else:
            raise ModelError(
                "joins two disks, so there is no gear radius to scale its twist to a length; "
                "give Shaft(..., radius=...)",
                where,
            )
        return ResolvedCoupling(
            component=c, kind=kind, a=a, b=b, row=tuple(row), scale=scale,
            stiffness=self._positive(c.stiffness, "the shaft stiffness", where, allow_zero=True),
            damping=self._positive(c.damping, "the shaft damping", where, allow_zero=True),
            backlash=sp.S.Zero, variation=sp.S.One, mesh_phase=sp.S.Zero,
        )

    def _resolve_torque(self, tq: Torque) -> list[ResolvedForcing]:
        where = f"Torque {tq.name!r}"
        body = self.body(tq.on, where)
        sign = -1 if tq.load else 1
        terms = []
        mean = to_expr(tq.mean, where)
        if mean != 0:
            terms.append(ResolvedForcing(tq, body, sign * mean, 0, sp.S.Zero, None))
        for h in tq.harmonics:
            if not isinstance(h, Harmonic):
                raise ModelError(f"harmonics must be Harmonic(...) objects, got {h!r}", where)
            if not (isinstance(h.order, int) and h.order >= 1):
                raise ModelError(f"a harmonic's order must be a whole number >= 1, got {h.order!r}", where)
            amp = to_expr(h.amplitude, where)
            if amp != 0:
                terms.append(ResolvedForcing(tq, body, sign * amp, h.order, to_expr(h.phase, where), h.group))
        return terms

    def _check_connected(self) -> None:
        """Every body must be loaded by some coupling (a carrier is, through its planets' meshes)."""
        used = {i for rc in self.couplings for i, e in enumerate(rc.row) if e != 0}
        ends = {end.body.name for rc in self.couplings if rc.kind != "bearing" for end in (rc.a, rc.b)}
        for rb in (*self.bodies, *self.fixed):
            if (rb.index not in used) if rb.index is not None else (rb.body.name not in ends):
                raise ModelError(
                    "is not connected to anything; join it with a Mesh or Shaft, or remove it",
                    f"{type(rb.body).__name__} {rb.body.name!r}",
                )
        for f in self.forcing:
            if f.body.fixed:
                raise ModelError(f"acts on {f.body.body.name!r}, which is fixed: a torque on a held body does no work",
                                 f"Torque {f.torque.name!r}")
