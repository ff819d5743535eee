"""A drivetrain declared from components; its Lagrangian and equations of motion.

Like ``sympy.physics.mechanics.System``: declare bodies, couplings and torques,
then call :meth:`Drivetrain.form_eoms`. Declarations are checked when the
drivetrain is resolved (at the first derivation), so a model file can add
components in any order; every error names the component to fix.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import Optional

import sympy as sp

from ..backlash import G
from ..checks import sign_violation
from ..errors import ModelError, suggest
from ..symbols import omega, parameter_symbol, phi, t
from .components import Body, BodyRef, Coupling, Gear, Harmonic, Mesh, Planet, Shaft, Torque
from .expressions import ExprLike, parameter_names, to_expr
from .stiffness import check_periodic


@dataclass(frozen=True)
class ResolvedBody:
    body: Body
    index: Optional[int]  # 0-based position among the moving bodies (the paper's psi_{index+1}); None if fixed
    angle: sp.Expr  # psi_i(t); 0 for a fixed body
    inertia: Optional[sp.Expr]  # None for a fixed body
    radius: Optional[sp.Expr]

    @property
    def fixed(self) -> bool:
        return self.index is None


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
    carrier: Optional[ResolvedBody] = None  # the carrier of a mesh with a planet
    turning: tuple[tuple[sp.Expr, ...], tuple[sp.Expr, ...]] = ((), ())  # rows: each gear's angle relative to the carrier
    planet_phase: sp.Expr = sp.S.Zero  # the part of the mesh phase a planet's position gives (Parker & Lin 2004)

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
        from ..physical.scales import check_length_scale

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


def _whole_turns_removed(angle: sp.Expr) -> sp.Expr:
    """``angle`` moved into [0, 2 pi) (a mesh phase is 2 pi-periodic), exactly for rational multiples of pi."""
    turns = angle / (2 * sp.pi)
    return 2 * sp.pi * (turns - sp.floor(turns))


class ResolvedDrivetrain:
    """The checked, symbolic view of a :class:`Drivetrain`."""

    def __init__(self, model: Drivetrain):
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
        self.couplings = [self._resolve_coupling(c) for c in model.couplings]
        self.forcing = [f for tq in model.torques for f in self._resolve_torque(tq)]
        self._check_connected()
        self.couplings = [self._with_planet_phase(rc) for rc in self.couplings]
        self._check_assembly()

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
        """The row of psi that is this body's angle (zeros for a fixed body)."""
        row = [sp.S.Zero] * len(self.bodies)
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

    def _mesh_rows(self, a: ResolvedBody, b: ResolvedBody, where: str):
        """The deflection row ``r_a phi_a -+ r_b phi_b`` (minus for an external, plus for an internal mesh) in
        the angles phi relative to the carrier, the carrier, and the two relative-angle rows."""
        for end in (a, b):
            if end.radius is None:
                raise ModelError(
                    f"meshes with {end.body.name!r}, a {type(end.body).__name__} without a base radius; "
                    "a mesh needs two Gear bodies",
                    where,
                )
        if a.fixed and b.fixed:
            raise ModelError(f"joins two fixed bodies ({a.body.name!r}, {b.body.name!r}); it could never deflect", where)
        internal = [end.body.name for end in (a, b) if getattr(end.body, "internal", False)]
        if len(internal) == 2:
            raise ModelError("joins two ring gears (internal=True); a ring gear meshes with a pinion or planet", where)
        carrier = self._carrier_of(a, b, where)
        turn_a, turn_b = self._turning(a, carrier), self._turning(b, carrier)
        sign = 1 if internal else -1
        row = tuple(a.radius * x + sign * b.radius * y for x, y in zip(turn_a, turn_b))
        return row, carrier, (tuple(turn_a), tuple(turn_b))

    def _resolve_coupling(self, c: Coupling) -> ResolvedCoupling:
        kind = "mesh" if isinstance(c, Mesh) else "shaft"
        where = f"{type(c).__name__} {c.name!r}"
        a, b = (self.body(end, where) for end in c.ends)
        if a is b:
            raise ModelError(f"joins body {a.body.name!r} to itself; a {kind} must join two different bodies", where)
        if isinstance(c, Mesh):
            row, carrier, turning = self._mesh_rows(a, b, where)
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
                component=c, kind=kind, a=a, b=b, row=row, scale=sp.S.One,
                stiffness=self._positive(c.stiffness, "the mesh stiffness", where),
                damping=self._positive(c.damping, "the mesh damping", where, allow_zero=True),
                backlash=self._positive(c.backlash, "the backlash", where, allow_zero=True),
                variation=variation,
                mesh_phase=order * omega * t + to_expr(c.phase, where),
                order=order, carrier=carrier, turning=turning,
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
        ends = {end.body.name for rc in self.couplings for end in (rc.a, rc.b)}
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

    # ---- planetary sets: mesh phasing and assembly (Parker & Lin 2004)
    def _planet_and_central(self, rc: ResolvedCoupling) -> tuple[ResolvedBody, ResolvedBody]:
        return (rc.a, rc.b) if isinstance(rc.a.body, Planet) else (rc.b, rc.a)

    def _position(self, planet: ResolvedBody) -> sp.Expr:
        where = f"Planet {planet.body.name!r}"
        position = to_expr(planet.body.position, where)
        if not position.is_number:
            raise ModelError(f"the position must be a number (an angle in radians, e.g. '2*pi/3'), got {position}",
                             where)
        return position

    def _with_planet_phase(self, rc: ResolvedCoupling) -> ResolvedCoupling:
        """A planet's mesh at the position psi_n sees the central gear's teeth that its reference position
        saw when the central gear was psi_n behind (relative to the carrier): its mesh phase is shifted by
        ``-s Z psi_n``, ``s`` the sign of the central gear's rotation relative to the carrier (Parker & Lin
        2004's gamma_sn = +-Z_s psi_n/2pi, gamma_rn = -+Z_r psi_n/2pi, in mesh periods)."""
        if rc.kind != "mesh" or rc.carrier is None:
            return rc
        planet, central = self._planet_and_central(rc)
        position = self._position(planet)
        if position == 0:
            return rc
        teeth = central.body.tooth_count
        if teeth is None:
            raise ModelError(f"planet {planet.body.name!r} sits at {position}, so the mesh phase needs the teeth of "
                             f"{central.body.name!r}: Gear(..., teeth=N)", f"Mesh {rc.name!r}")
        shift = _whole_turns_removed(-self._nominal_sign(rc, central) * teeth * position)
        return replace(rc, mesh_phase=rc.mesh_phase + shift, planet_phase=shift)

    @cached_property
    def _nominal_motion(self) -> Optional[list[float]]:
        """The steady rotation of a train with one rigid-body mode, oriented so that its input (the body that
        declares the speed, else the first driven body, else the first body) turns forward; None otherwise."""
        rows = sp.Matrix([list(rc.row) for rc in self.couplings])
        modes = rows.xreplace(self._numeric_values()).nullspace()
        if len(modes) != 1:
            return None
        u = [float(e) for e in modes[0]]
        driven = [f.body for f in self.forcing if f.amplitude.could_extract_minus_sign() is False and f.order == 0]
        inputs = [rb for rb in self.bodies if rb.body.speed_parameter] + driven + self.bodies
        reference = next(rb for rb in inputs if abs(u[rb.index]) > 1e-12)
        return [x if u[reference.index] > 0 else -x for x in u]

    def _nominal_sign(self, rc: ResolvedCoupling, central: ResolvedBody) -> int:
        """Sign of the central gear's rotation relative to the carrier in the steady motion. With several
        rigid-body modes (a differential) the kinematics leave it open; then the sun (an external central gear)
        is taken to turn forward relative to the carrier and a ring backward, as with the ring held."""
        motion = self._nominal_motion
        if motion is None:
            return -1 if getattr(central.body, "internal", False) else 1
        turning = rc.turning[0] if central is rc.a else rc.turning[1]
        rate = sum(float(e) * u for e, u in zip(turning, motion))
        if abs(rate) < 1e-12:
            raise ModelError(f"{central.body.name!r} does not turn relative to the carrier in the steady motion, so "
                             "the mesh has no frequency", f"Mesh {rc.name!r}")
        return 1 if rate > 0 else -1

    def _numeric_values(self) -> dict[sp.Symbol, sp.Expr]:
        """Numbers for the radii in the deflection rows: declared defaults and physical values, else generic
        positive ones (the signs of rates in a gear train do not depend on the radii's exact values)."""
        import random

        rng = random.Random(7)
        free = sorted({s for rc in self.couplings for e in rc.row for s in e.free_symbols}, key=str)
        out = {}
        for s in free:
            value = self._default_value(s)
            if value is None and s.name in self.model._physical:
                value = float(self.model._physical[s.name].to_base_units().magnitude)
            out[s] = sp.Rational(value) if value is not None else sp.Rational(rng.randint(11, 97), rng.randint(11, 97))
        return out

    def _check_assembly(self) -> None:
        """A planet that meshes with a sun and a ring with teeth fits only where (Z_s + Z_r) psi / 2 pi is whole."""
        by_planet: dict[str, dict[str, int]] = {}
        for rc in self.couplings:
            if rc.kind != "mesh" or rc.carrier is None:
                continue
            planet, central = self._planet_and_central(rc)
            if central.body.tooth_count is not None:
                kind = "ring" if getattr(central.body, "internal", False) else "sun"
                by_planet.setdefault(planet.body.name, {})[kind] = central.body.tooth_count
        for name, teeth in by_planet.items():
            if set(teeth) != {"sun", "ring"}:
                continue
            planet = self._by_name[name]
            turns = (teeth["sun"] + teeth["ring"]) * self._position(planet) / (2 * sp.pi)
            if abs(float(turns) - round(float(turns))) > 1e-9:
                step = sp.nsimplify(360 / sp.Integer(teeth["sun"] + teeth["ring"]))
                raise ModelError(
                    f"cannot be assembled at {self._position(planet)} rad: (Z_sun + Z_ring) position / 2 pi = "
                    f"{float(turns):.6g} is not a whole number; place it at a multiple of 360/(Z_sun + Z_ring) = "
                    f"{step} degrees", f"Planet {name!r}")

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
