"""Gears on bearings: bodies whose centres translate, the frame their translations are written in, the sense
each body's angle is counted in, and a mesh's line of action.

:class:`TranslationResolution` is a base of :class:`~gearsym.model.resolved.ResolvedDrivetrain`. A body on a
:class:`~gearsym.model.components.Bearing` gets its centre's translations as degrees of freedom (after every
rotation), each with the body's mass:

* in the fixed frame (x, y) for a drivetrain without translating planets (Kahraman & Singh's lateral-torsional
  pair);
* in the carrier's frame when planets translate (Lin & Parker 1999): a planet's radial and tangential
  displacement from its nominal position, the central members' x and y in axes that turn with the carrier at
  its nominal speed, so that every line of action keeps its direction.

Senses. The two gears of a mesh are counted in opposite senses, a shaft's ends and a carrier with its central
gears in one sense, a planet opposite to its carrier (the torsional models' conventions). In the frame the first
body of each connected train turns counterclockwise; the others follow.

The line of action of a mesh is the line along which gear a's contact point moves when its angle increases, on
the flank that this motion closes (the drive flank, where the deflection is positive): with ``beta`` the direction
of the pitch point seen from a's centre and ``s`` a's sense, ``n = beta + s (pi/2 - alpha)`` for external teeth
and ``beta + s (pi/2 + alpha)`` for a ring's. The mesh deflection adds ``n . (d_a - d_b)`` to the rotations'
part, ``d`` the centres' displacements. The back flank (beyond the backlash) is taken on the same line: the
one-line contact of Kahraman & Singh's and Lin & Parker's models.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Optional

import sympy as sp

from ..errors import ModelError
from .symbols import t
from .components import Bearing, Body, Mesh, Planet, Shaft
from .expressions import to_expr
from .linear_algebra import named_generators
from .resolved_components import ResolvedBody, ResolvedCoupling

#: the name of the carrier's nominal speed (rad/s, counterclockwise in the frame) in the frame terms
CARRIER_SPEED = "Omega_c"
_DIRECTIONS = {"xy": ("x", "y"), "x": ("x",), "y": ("y",)}


@dataclass(frozen=True)
class Centre:
    """A body's centre: its translations (degrees of freedom) and the unit vector, in the frame's axes, each one
    moves it along."""

    body: Body
    translations: tuple[ResolvedBody, ...]
    axes: tuple[tuple[sp.Expr, sp.Expr], ...]
    handedness: int  # +1 if (first, second) axes turn counterclockwise, -1 if clockwise (a planet's, by its carrier)

    def displacement(self) -> tuple[sp.Expr, sp.Expr]:
        x = sp.Add(*(a[0] * d.angle for d, a in zip(self.translations, self.axes)))
        y = sp.Add(*(a[1] * d.angle for d, a in zip(self.translations, self.axes)))
        return x, y


def _trig(expr: sp.Expr) -> sp.Expr:
    """A projection as a polynomial in the sines and cosines of the declared angles (their coefficients exact)."""
    return sp.expand(sp.expand_trig(expr))


class TranslationResolution:
    """Bearings, translations, senses and lines of action of a resolved drivetrain (see the module)."""

    # ------------------------------------------------------------------ bearings and translations
    def _resolve_bearings(self, first_index: int) -> list[ResolvedBody]:
        """The translations of every body on a bearing (indices from ``first_index``); sets ``self.centres``
        (body name -> :class:`Centre`), ``self.frame`` ("fixed" or "carrier") and ``self.frame_carrier``."""
        model = self.model
        self.centres: dict[str, Centre] = {}
        self.frame, self.frame_carrier = "fixed", None
        bearings = list(model.bearings)
        seen: dict[str, str] = {}
        for bearing in bearings:
            where = f"Bearing {bearing.name!r}"
            rb = self.body(bearing.on, where)
            if rb.body.name in seen:
                raise ModelError(f"{rb.body.name!r} already sits on bearing {seen[rb.body.name]!r}; declare one "
                                 "bearing per body (stiffness per direction with stiffness_y)", where)
            seen[rb.body.name] = bearing.name
            if bearing.directions not in _DIRECTIONS:
                raise ModelError(f"directions must be 'xy', 'x' or 'y', got {bearing.directions!r}", where)
        carriers = {self.body(b.on, "").body.carrier for b in bearings if isinstance(self.body(b.on, "").body, Planet)}
        if len(carriers) > 1:
            raise ModelError("planets on bearings ride on more than one carrier; one carrier frame per drivetrain is "
                             "supported", model.name)
        if carriers:
            carrier_ref = carriers.pop()
            self.frame, self.frame_carrier = "carrier", self.body(carrier_ref, "the planets' carrier")
        # (the senses of rotation place the lines of action of gears on bearings; a drivetrain without bearings
        # needs none, and its closed loops of meshes are checked where its couplings are resolved)
        self._senses = self._rotation_senses() if bearings else {}
        out: list[ResolvedBody] = []
        for bearing in bearings:
            rb = self.body(bearing.on, f"Bearing {bearing.name!r}")
            out += self._translations_of(bearing, rb, first_index + len(out))
        return out

    def _translations_of(self, bearing: Bearing, rb: ResolvedBody, index: int) -> list[ResolvedBody]:
        body = rb.body
        if body.mass is None:
            raise ModelError(f"sits on a bearing, so its centre translates: give it a mass ({type(body).__name__}"
                             f"(..., mass='m_{body.name}'))", f"{type(body).__name__} {body.name!r}")
        mass = self._positive(body.mass, "the mass", f"{type(body).__name__} {body.name!r}")
        directions = _DIRECTIONS[bearing.directions]
        if isinstance(body, Planet):
            phi = self._planet_angle(rb)
            sense = self._carrier_sense(rb)
            basis = {"x": ("radial", (sp.cos(phi), sp.sin(phi))),
                     "y": ("tangential", (-sense * sp.sin(phi), sense * sp.cos(phi)))}
            names = {"x": f"xi_{body.name}", "y": f"eta_{body.name}"}
            handedness = sense
        else:
            basis = {"x": ("x", (sp.S.One, sp.S.Zero)), "y": ("y", (sp.S.Zero, sp.S.One))}
            names = {"x": f"X_{body.name}", "y": f"Y_{body.name}"}
            handedness = 1
        translations, axes = [], []
        for k, direction in enumerate(directions):
            motion, axis = basis[direction]
            function = sp.Function(names[direction], real=True)(t)
            translations.append(ResolvedBody(body, index + k, function, mass, None, motion))
            axes.append(axis)
        self.centres[body.name] = Centre(body, tuple(translations), tuple(axes), handedness)
        return translations

    def _planet_angle(self, planet: ResolvedBody) -> sp.Expr:
        """A planet's position as an angle in the frame (its position is counted in its carrier's sense)."""
        return self._carrier_sense(planet) * self._position(planet)

    def _carrier_sense(self, planet: ResolvedBody) -> int:
        carrier = planet.body.carrier
        name = carrier.name if isinstance(carrier, Body) else carrier
        return self._senses.get(name, 1)

    # ------------------------------------------------------------------ senses
    def _rotation_senses(self) -> dict[str, int]:
        """Each body's sense in the frame (+1 counterclockwise), from the counting conventions (module doc)."""
        model = self.model
        edges: dict[str, list[tuple[str, int, str]]] = {b.name: [] for b in model.bodies}

        def join(a, b, relation: int, why: str) -> None:
            na, nb = (x.name if isinstance(x, Body) else x for x in (a, b))
            if na in edges and nb in edges:
                edges[na].append((nb, relation, why))
                edges[nb].append((na, relation, why))

        for c in model.couplings:
            if isinstance(c, Mesh):
                join(c.gear_a, c.gear_b, -1, f"Mesh {c.name!r}")
            elif isinstance(c, Shaft):
                join(c.a, c.b, 1, f"Shaft {c.name!r}")
        for b in model.bodies:
            if isinstance(b, Planet) and b.carrier is not None:
                join(b, b.carrier, -1, f"Planet {b.name!r} on its carrier")
        senses: dict[str, int] = {}
        for start in (b.name for b in model.bodies):
            if start in senses:
                continue
            senses[start] = 1
            stack = [start]
            while stack:
                here = stack.pop()
                for there, relation, why in edges[here]:
                    want = senses[here] * relation
                    if there not in senses:
                        senses[there] = want
                        stack.append(there)
                    elif senses[there] != want:
                        raise ModelError(f"the senses of rotation contradict each other around {there!r} (an odd loop "
                                         "of meshes): no gear train turns so", why)
        return senses

    # ------------------------------------------------------------------ lines of action
    def _centre_of(self, rb: ResolvedBody, carrier: Optional[ResolvedBody]) -> tuple[sp.Expr, sp.Expr]:
        """A body's centre displacement in the frame: its translations, a planet without bearing carried by its
        carrier's centre (its rotation with the carrier is in the relative angles), zero otherwise."""
        centre = self.centres.get(rb.body.name)
        if centre is not None:
            return centre.displacement()
        if isinstance(rb.body, Planet) and carrier is not None and carrier.body.name in self.centres:
            return self.centres[carrier.body.name].displacement()
        return sp.S.Zero, sp.S.Zero

    def translates(self, rb: ResolvedBody) -> bool:
        return rb.body.name in self.centres

    def _line_of_action(self, c: Mesh, a: ResolvedBody, b: ResolvedBody, where: str) -> sp.Expr:
        """The angle of the mesh's line of action in the frame (module doc)."""
        alpha = to_expr(c.pressure_angle, where)
        internal_a = getattr(a.body, "internal", False)
        internal_b = getattr(b.body, "internal", False)
        planets = [end for end in (a, b) if isinstance(end.body, Planet)]
        if planets:
            if c.centres is not None:
                raise ModelError("a planet's mesh lies where the planet is: its line of centres follows from the "
                                 "planet's position, so give no centres=", where)
            phi = self._planet_angle(planets[0])
            pitch = phi if planets[0] is not a or internal_b else phi + sp.pi
        else:
            centres = to_expr(c.centres if c.centres is not None else 0, where)
            pitch = centres + sp.pi if internal_b else centres
        sense = self._senses.get(a.body.name, 1)
        return pitch + sense * (sp.pi / 2 + alpha if internal_a else sp.pi / 2 - alpha)

    def _projection(self, c: Mesh, a: ResolvedBody, b: ResolvedBody, carrier: Optional[ResolvedBody],
                    where: str) -> list[sp.Expr]:
        """The row of ``n . (d_a - d_b)`` over the degrees of freedom (zeros when neither centre moves)."""
        row = [sp.S.Zero] * len(self.dofs)
        ends = [(a, 1), (b, -1)]
        if not any(self.translates(e) or (carrier is not None and self.translates(carrier)) for e, _ in ends):
            return row
        angle = self._line_of_action(c, a, b, where)
        for end, sign in ends:
            centre = self.centres.get(end.body.name)
            if centre is None and isinstance(end.body, Planet) and carrier is not None:
                centre = self.centres.get(carrier.body.name)
            if centre is None:
                continue
            for dof, (ax, ay) in zip(centre.translations, centre.axes):
                row[dof.index] += sign * _trig(sp.cos(angle) * ax + sp.sin(angle) * ay)
        return row

    # ------------------------------------------------------------------ bearings as couplings
    def _bearing_couplings(self, bearing: Bearing) -> list[ResolvedCoupling]:
        """A bearing's couplings: one per translation (its deflection: the centre relative to the housing, or a
        planet's relative to its pin on the carrier) and its torsional support."""
        where = f"Bearing {bearing.name!r}"
        rb = self.body(bearing.on, where)
        out = []
        centre = self.centres[rb.body.name]
        stiffness = self._positive(bearing.stiffness, "the bearing stiffness", where)
        damping = self._positive(bearing.damping, "the bearing damping", where, allow_zero=True)
        stiffness_y = stiffness if bearing.stiffness_y is None else \
            self._positive(bearing.stiffness_y, "the bearing stiffness", where)
        damping_y = damping if bearing.damping_y is None else \
            self._positive(bearing.damping_y, "the bearing damping", where, allow_zero=True)
        anisotropic = stiffness_y != stiffness or damping_y != damping
        if anisotropic and self.frame == "carrier" and not isinstance(rb.body, Planet) \
                and self.frame_carrier is not None and not self.frame_carrier.fixed:
            raise ModelError("a bearing in the turning carrier's frame must be isotropic (its stiffness in x and y the "
                             "same); give no stiffness_y/damping_y", where)
        names = bearing.coordinates or ()
        for k, dof in enumerate(centre.translations):
            row = [sp.S.Zero] * len(self.dofs)
            row[dof.index] = sp.S.One
            if isinstance(rb.body, Planet):
                self._pin_motion(rb, dof, centre.axes[k], row, where)
            direction = "y" if dof.motion in ("y", "tangential") else "x"
            coordinate = names[k] if k < len(names) else f"{direction}_{rb.body.name}"
            out.append(ResolvedCoupling(
                component=bearing, kind="bearing", a=rb, b=rb, row=tuple(row), scale=sp.S.One,
                stiffness=stiffness_y if direction == "y" else stiffness,
                damping=damping_y if direction == "y" else damping,
                backlash=sp.S.Zero, variation=sp.S.One, mesh_phase=sp.S.Zero,
                label=f"{bearing.name}_{direction}", coordinate_name=coordinate))
        if bearing.torsional is not None:
            out.append(self._torsional_support(bearing, rb, names[len(centre.translations)]
                                               if len(names) > len(centre.translations) else None))
        return out

    def _pin_motion(self, planet: ResolvedBody, dof: ResolvedBody, axis, row: list, where: str) -> None:
        """Subtract the motion of the planet's pin along ``axis``: the carrier's centre, and for the tangential
        direction the carrier's rotation times the orbit radius."""
        carrier = self.body(planet.body.carrier, f"Planet {planet.body.name!r}")
        centre = self.centres.get(carrier.body.name)
        if centre is not None:
            for cdof, (cx, cy) in zip(centre.translations, centre.axes):
                row[cdof.index] -= _trig(axis[0] * cx + axis[1] * cy)
        if dof.motion == "tangential" and not carrier.fixed:
            row[carrier.index] -= self._orbit(planet)

    def _orbit(self, planet: ResolvedBody) -> sp.Expr:
        where = f"Planet {planet.body.name!r}"
        if planet.body.orbit is None:
            raise ModelError("translates on its pin, so the carrier's rotation moves the pin by the orbit radius: "
                             "give Planet(..., orbit='r_c')", where)
        return self._positive(planet.body.orbit, "the orbit radius", where)

    def _torsional_support(self, bearing: Bearing, rb: ResolvedBody, coordinate: Optional[str]) -> ResolvedCoupling:
        where = f"Bearing {bearing.name!r}"
        if rb.fixed:
            raise ModelError(f"holds {rb.body.name!r} torsionally, but it is declared fixed (it has no angle); give "
                             "no torsional= or declare it turning", where)
        if rb.radius is not None:
            scale = rb.radius
        else:
            orbits = [self._orbit(p) for p in self.bodies if isinstance(p.body, Planet)
                      and self.body(p.body.carrier, "").body is rb.body and p.body.orbit is not None]
            if not orbits:
                raise ModelError(f"{rb.body.name!r} has no base radius to give its torsional support's twist a length: "
                                 "support a Gear, or a carrier whose planets declare orbit=", where)
            scale = orbits[0]
        row = [sp.S.Zero] * len(self.dofs)
        row[rb.index] = sp.S.One
        return ResolvedCoupling(
            component=bearing, kind="shaft", a=rb, b=rb, row=tuple(row), scale=scale,
            stiffness=self._positive(bearing.torsional, "the torsional support's stiffness", where),
            damping=self._positive(bearing.torsional_damping, "the torsional support's damping", where, allow_zero=True),
            backlash=sp.S.Zero, variation=sp.S.One, mesh_phase=sp.S.Zero,
            label=f"{bearing.name}_u", coordinate_name=coordinate or f"u_{rb.body.name}")

    # ------------------------------------------------------------------ the geometry's numbers as symbols
    def _with_geometry_symbols(self, couplings: list[ResolvedCoupling]) -> list[ResolvedCoupling]:
        """The rows with each sine and cosine of a pressure angle and each radical of a planet's position replaced by
        a symbol (``self.geometry``: symbol -> what it stands for). The Lagrangian and the reduction then run on
        rational functions of plain symbols, which SymPy handles fast; their relations (cos^2 + sin^2 = 1,
        sqrt_3^2 = 3) are not used, so the algebra holds for any values, and :meth:`with_geometry` puts the numbers
        back in every result."""
        self.geometry: dict[sp.Symbol, sp.Expr] = {}
        if not self.translations:
            return couplings
        atoms = named_generators([e for rc in couplings for e in rc.row])
        if not atoms:
            return couplings
        self.geometry = {symbol: atom for atom, symbol in atoms.items()}
        return [replace(rc, row=tuple(sp.expand(e.xreplace(atoms)) for e in rc.row)) for rc in couplings]

    def with_geometry(self, expr):
        """``expr`` with the geometry's symbols replaced by what they stand for (see :meth:`_with_geometry_symbols`)."""
        geometry = getattr(self, "geometry", None)
        return expr.xreplace(geometry) if geometry and hasattr(expr, "xreplace") else expr

    # ------------------------------------------------------------------ the turning frame
    @property
    def frame_turns(self) -> bool:
        """True when translations are written in a turning carrier's frame whose terms the model keeps."""
        return (self.frame == "carrier" and self.frame_carrier is not None and not self.frame_carrier.fixed
                and self.model.frame_terms)

    def frame_energy(self) -> sp.Expr:
        """The kinetic energy the frame's turning adds: ``m Omega (d' . (z x d)) + m Omega^2 |d|^2 / 2`` per
        translating body (constants, total derivatives and the constant centrifugal force m Omega^2 r_c of a
        planet, which Lin & Parker leave out too, dropped)."""
        if not self.frame_turns:
            return sp.S.Zero
        speed = sp.Symbol(CARRIER_SPEED, real=True)
        out = sp.S.Zero
        for centre in self.centres.values():
            coords = [d.angle for d in centre.translations]
            mass = centre.translations[0].inertia
            out += mass * speed**2 * sp.Add(*(q**2 for q in coords)) / 2
            if len(coords) == 2:
                u, v = coords
                out += centre.handedness * mass * speed * (u * sp.diff(v, t) - v * sp.diff(u, t))
        return out
