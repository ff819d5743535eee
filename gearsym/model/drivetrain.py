"""A drivetrain declared from components; its Lagrangian and equations of motion.

Like ``sympy.physics.mechanics.System``: declare bodies, couplings and torques,
then call :meth:`Drivetrain.form_eoms`. Declarations are checked when the
drivetrain is resolved (at the first derivation), so a model file can add
components in any order; every error names the component to fix.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Optional, Union

import sympy as sp

from ..backlash import G
from ..checks import sign_violation
from ..errors import ModelError, suggest
from ..symbols import omega, parameter_symbol, phi, t
from .components import Body, BodyRef, Coupling, Disk, Gear, Harmonic, Mesh, Shaft, Torque
from .expressions import ExprLike, parameter_names, to_expr
from .stiffness import check_periodic


@dataclass(frozen=True)
class ResolvedBody:
    body: Body
    index: int  # 0-based position; the paper's psi_{index+1}
    angle: sp.Expr  # psi_i(t)
    inertia: sp.Expr
    radius: Optional[sp.Expr]


@dataclass(frozen=True)
class ResolvedCoupling:
    """A mesh or shaft with its expressions parsed and its kinematics set up."""

    component: Coupling
    kind: str  # "mesh" | "shaft"
    a: ResolvedBody
    b: ResolvedBody
    row: tuple[sp.Expr, ...]  # J: deflection = sum(row[i] * psi_i)
    scale: sp.Expr  # relative coordinate = scale * deflection
    stiffness: sp.Expr  # mean stiffness (kZ) or torsional stiffness (kS)
    damping: sp.Expr
    backlash: sp.Expr  # eta (0 for shafts)
    variation: sp.Expr  # k(phi) shape (1 for shafts)
    mesh_phase: sp.Expr  # phi as a function of t (0 for shafts)
    order: sp.Expr = sp.S.Zero  # mesh frequency / forcing frequency (0 for shafts)

    @property
    def name(self) -> str:
        return self.component.name


@dataclass(frozen=True)
class ResolvedForcing:
    """One term of an external torque: sign * amplitude * timefn(t) on a body."""

    torque: Torque
    body: ResolvedBody
    amplitude: sp.Expr  # signed (load torques enter with -1)
    order: int  # 0 for the mean
    phase: sp.Expr
    group: Optional[str]

    @property
    def time_function(self) -> sp.Expr:
        return sp.S.One if self.order == 0 else sp.cos(self.order * omega * t + self.phase)


class Drivetrain:
    """A torsional drivetrain: bodies, meshes, shafts and external torques."""

    def __init__(self, name: str, title: str = "", description: str = ""):
        if not name.isidentifier():
            raise ModelError("a model name must be a Python identifier, e.g. 'flexible_shaft'", repr(name))
        self.name = name
        self.title = title or name
        self.description = description
        self.bodies: list[Body] = []
        self.couplings: list[Coupling] = []
        self.torques: list[Torque] = []
        self._defaults: dict[str, ExprLike] = {}
        self._descriptions: dict[str, str] = {}
        self._initial: dict[str, float] = {}
        self._physical: dict = {}  # name -> pint Quantity (gearsym.physical), read when set
        self._length_scale = "static"
        self.version = 0  # bumped by every change, so derived results can be cached safely

    def _changed(self) -> None:
        self.version += 1
        self.__dict__.pop("resolved", None)

    # ----------------------------------------------------------------- declaring
    def add(self, component):
        """Add a component; returns it, so ``g1 = model.add(Gear(...))`` reads naturally."""
        self._changed()
        names = {c.name for c in (*self.bodies, *self.couplings, *self.torques)}
        if not getattr(component, "name", None) or not isinstance(component.name, str):
            raise ModelError("every component needs a name (a non-empty string)", repr(component))
        if component.name in names:
            raise ModelError("a component with this name was already added; names must be unique", component.name)
        if isinstance(component, Body):
            self.bodies.append(component)
        elif isinstance(component, (Mesh, Shaft)):
            self.couplings.append(component)
        elif isinstance(component, Torque):
            self.torques.append(component)
        else:
            raise ModelError(
                f"cannot add a {type(component).__name__}; add Gear, Disk, Mesh, Shaft or Torque",
                getattr(component, "name", None),
            )
        return component

    def set_defaults(self, **values: ExprLike) -> "Drivetrain":
        """Default values of the model's parameters (checked against the reduced model's parameters)."""
        self._changed()
        self._defaults.update(values)
        return self

    def set_physical(self, **values) -> "Drivetrain":
        """Physical values of the component parameters, with their units: ``I1="2.1e-3 kg*m^2"``,
        ``kZ="2e8 N/m"``, ``speed="3000 rpm"`` (strings read by the safe quantity parser, or pint Quantities;
        a plain number is dimensionless). The engine's nondimensional values are then derived from them
        (:class:`gearsym.physical.Scaling`), and its results carried back to these units."""
        from ..physical.units import as_quantity  # pint only for models with physical values

        self._changed()
        for name, value in values.items():
            self._physical[name] = as_quantity(value, f"{self.name}: set_physical {name}")
        return self

    def set_length_scale(self, scale) -> "Drivetrain":
        """The length unit of the nondimensional model: ``"static"`` (the static deflection of the first mesh
        under the mean load: B0 = 1, the paper's convention), ``"backlash"`` (half the first mesh's backlash)
        or a length (``"1 um"``)."""
        from ..physical.scaling import check_length_scale

        self._changed()
        self._length_scale = check_length_scale(scale, f"{self.name}: set_length_scale")
        return self

    @property
    def physical(self) -> dict:
        """The declared physical values (name -> pint Quantity)."""
        return dict(self._physical)

    @property
    def length_scale(self):
        return self._length_scale

    def set_initial_state(self, **values: float) -> "Drivetrain":
        """Default initial state of the reduced model (e.g. the paper's x=-2, v=-0.5); others start at 0."""
        self._initial.update({k: float(v) for k, v in values.items()})
        return self

    @property
    def initial_state(self) -> dict[str, float]:
        return dict(self._initial)

    def describe(self, **descriptions: str) -> "Drivetrain":
        """One-line descriptions of parameters, shown in the derivation docs."""
        self._changed()
        self._descriptions.update(descriptions)
        return self

    @property
    def defaults(self) -> dict[str, ExprLike]:
        return dict(self._defaults)

    @property
    def descriptions(self) -> dict[str, str]:
        return dict(self._descriptions)

    # ----------------------------------------------------------------- resolving
    @cached_property
    def resolved(self) -> "ResolvedDrivetrain":
        return ResolvedDrivetrain(self)

    def form_lagrangian(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """Kinetic energy T, potential energy V and Rayleigh dissipation R."""
        r = self.resolved
        return r.kinetic_energy, r.potential_energy, r.dissipation

    def form_eoms(self) -> list[sp.Eq]:
        """Lagrange's equations d/dt dL/dpsi' - dL/dpsi + dR/dpsi' = Q, one per body."""
        return self.resolved.equations_of_motion

    def __repr__(self) -> str:
        return (
            f"Drivetrain({self.name!r}: {len(self.bodies)} bodies, "
            f"{len(self.couplings)} couplings, {len(self.torques)} torques)"
        )


class ResolvedDrivetrain:
    """The checked, symbolic view of a :class:`Drivetrain`."""

    def __init__(self, model: Drivetrain):
        self.model = model
        if not model.bodies:
            raise ModelError("the drivetrain has no bodies; add Gear or Disk components", model.name)
        if not model.couplings:
            raise ModelError("the drivetrain has no couplings; join its bodies with Mesh or Shaft", model.name)
        self.bodies = [self._resolve_body(i, b) for i, b in enumerate(model.bodies)]
        self._by_name = {rb.body.name: rb for rb in self.bodies}
        self.couplings = [self._resolve_coupling(c) for c in model.couplings]
        self.forcing = [f for tq in model.torques for f in self._resolve_torque(tq)]
        self._check_connected()

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
    def _resolve_body(self, index: int, body: Body) -> ResolvedBody:
        where = f"{type(body).__name__} {body.name!r}"
        inertia = self._positive(body.inertia, "the moment of inertia", where)
        radius = None
        if isinstance(body, Gear):
            radius = self._positive(body.base_radius, "the base radius", where)
        angle = sp.Function(f"psi_{index + 1}", real=True)(t)
        return ResolvedBody(body, index, angle, inertia, radius)

    def _resolve_coupling(self, c: Coupling) -> ResolvedCoupling:
        kind = "mesh" if isinstance(c, Mesh) else "shaft"
        where = f"{type(c).__name__} {c.name!r}"
        a, b = (self.body(end, where) for end in c.ends)
        if a is b:
            raise ModelError(f"joins body {a.body.name!r} to itself; a {kind} must join two different bodies", where)
        n = len(self.bodies)
        row = [sp.S.Zero] * n
        if isinstance(c, Mesh):
            for end in (a, b):
                if end.radius is None:
                    raise ModelError(
                        f"meshes with {end.body.name!r}, a {type(end.body).__name__} without a base radius; "
                        "a mesh needs two Gear bodies",
                        where,
                    )
            row[a.index], row[b.index] = a.radius, -b.radius
            order = to_expr(c.order, where)
            if not (order.is_number and order.is_positive and order.is_rational):
                raise ModelError(f"the mesh order must be a positive rational number, got {order}", where)
            variation = to_expr(c.variation, where)
            if variation.free_symbols & {t}:
                raise ModelError("the stiffness variation must be written in the mesh phase phi, not in t", where)
            defaults = {
                parameter_symbol(nm): self._default_value(parameter_symbol(nm))
                for nm in parameter_names(variation)
            }
            check_periodic(variation, phi, where, {k: v for k, v in defaults.items() if v is not None})
            return ResolvedCoupling(
                component=c, kind=kind, a=a, b=b, row=tuple(row), scale=sp.S.One,
                stiffness=self._positive(c.stiffness, "the mesh stiffness", where),
                damping=self._positive(c.damping, "the mesh damping", where, allow_zero=True),
                backlash=self._positive(c.backlash, "the backlash", where, allow_zero=True),
                variation=variation,
                mesh_phase=order * omega * t + to_expr(c.phase, where),
                order=order,
            )
        row[a.index], row[b.index] = sp.S.NegativeOne, sp.S.One
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
        used = {rc.a.index for rc in self.couplings} | {rc.b.index for rc in self.couplings}
        for rb in self.bodies:
            if rb.index not in used:
                raise ModelError(
                    "is not connected to anything; join it with a Mesh or Shaft, or remove it",
                    f"{type(rb.body).__name__} {rb.body.name!r}",
                )

    # ---- kinematics and energies
    @property
    def angles(self) -> list[sp.Expr]:
        return [rb.angle for rb in self.bodies]

    def deflection(self, rc: ResolvedCoupling) -> sp.Expr:
        """Mesh deflection r_a psi_a - r_b psi_b, or shaft twist psi_b - psi_a."""
        return sum((c * q for c, q in zip(rc.row, self.angles)), sp.S.Zero)

    def stiffness_at(self, rc: ResolvedCoupling) -> sp.Expr:
        """The mesh stiffness as a function of time, kZ(t), kept opaque so equations stay readable.

        Its definition is :meth:`stiffness_definition`; a shaft's stiffness is constant.
        """
        if rc.kind == "shaft":
            return rc.stiffness
        shared = sum(1 for other in self.couplings if other.kind == "mesh" and other.stiffness == rc.stiffness) > 1
        plain = isinstance(rc.stiffness, sp.Symbol) and not shared
        base = rc.stiffness.name if isinstance(rc.stiffness, sp.Symbol) else "kZ"
        return sp.Function(base if plain else f"{base}_{rc.name}", real=True)(t)

    def stiffness_definition(self, rc: ResolvedCoupling) -> sp.Expr:
        """kZ(t) = kZ * k(phi(t)) with the declared variation k and mesh phase phi."""
        return rc.stiffness * rc.variation.subs(phi, rc.mesh_phase)

    def potential_of(self, rc: ResolvedCoupling) -> sp.Expr:
        d = self.deflection(rc)
        if rc.kind == "mesh":
            return self.stiffness_at(rc) * G(d, rc.backlash)
        return rc.stiffness * d**2 / 2

    def dissipation_of(self, rc: ResolvedCoupling) -> sp.Expr:
        return rc.damping * sp.diff(self.deflection(rc), t) ** 2 / 2

    @cached_property
    def kinetic_energy(self) -> sp.Expr:
        return sum((rb.inertia * sp.diff(rb.angle, t) ** 2 / 2 for rb in self.bodies), sp.S.Zero)

    @cached_property
    def potential_energy(self) -> sp.Expr:
        return sum((self.potential_of(rc) for rc in self.couplings), sp.S.Zero)

    @cached_property
    def dissipation(self) -> sp.Expr:
        return sum((self.dissipation_of(rc) for rc in self.couplings), sp.S.Zero)

    @cached_property
    def generalized_forces(self) -> list[sp.Expr]:
        """Q_i from the virtual work of the external torques, delta W = sum M_j delta psi_j."""
        q = [sp.S.Zero] * len(self.bodies)
        for f in self.forcing:
            q[f.body.index] += f.amplitude * f.time_function
        return q

    def lagrange_lhs(self, lagrangian: sp.Expr, dissipation: sp.Expr) -> list[sp.Expr]:
        """d/dt dL/dpsi' - dL/dpsi + dR/dpsi' for each body."""
        out = []
        for q in self.angles:
            qd = sp.diff(q, t)
            lhs = sp.diff(sp.diff(lagrangian, qd), t) - sp.diff(lagrangian, q) + sp.diff(dissipation, qd)
            out.append(sp.Add(*(sp.factor_terms(term) for term in sp.Add.make_args(lhs))))
        return out

    @cached_property
    def equations_of_motion(self) -> list[sp.Eq]:
        lagrangian = self.kinetic_energy - self.potential_energy
        lhs = self.lagrange_lhs(lagrangian, self.dissipation)
        return [sp.Eq(l, r) for l, r in zip(lhs, self.generalized_forces)]

    def coupling_forces(self, rc: ResolvedCoupling) -> list[sp.Expr]:
        """Generalized forces of one coupling alone: -(dV_c/dpsi + dR_c/dpsi')."""
        return [-e for e in self.lagrange_lhs(-self.potential_of(rc), self.dissipation_of(rc))]

    @cached_property
    def mass_matrix(self) -> sp.Matrix:
        acc = [sp.diff(q, t, 2) for q in self.angles]
        return sp.Matrix([[sp.expand(eq.lhs).coeff(a) for a in acc] for eq in self.equations_of_motion])
