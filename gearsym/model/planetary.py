"""Planetary sets: the mesh phase each planet's position gives, and where a planet can be assembled.

:class:`PlanetaryPhasing` is a base of :class:`~gearsym.model.resolved.ResolvedDrivetrain` (Parker & Lin
2004): a planet at the position psi_n sees the central gear's teeth shifted by ``-s Z psi_n``, and a planet
between a sun and a ring fits only where ``(Z_s + Z_r) psi_n / 2 pi`` is whole.
"""
from __future__ import annotations

import random
from dataclasses import replace
from functools import cached_property
from typing import Optional

import sympy as sp

from ..errors import ModelError
from .components import Planet
from .expressions import to_expr
from .linear_algebra import numeric_nullspace
from .resolved_components import ResolvedBody, ResolvedCoupling



def _whole_turns_removed(angle: sp.Expr) -> sp.Expr:
    """``angle`` moved into [0, 2 pi) (a mesh phase is 2 pi-periodic), exactly for rational multiples of pi."""
    turns = angle / (2 * sp.pi)
    return 2 * sp.pi * (turns - sp.floor(turns))


class PlanetaryPhasing:
    """Mesh phasing and assembly of the planets of a resolved drivetrain."""

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
        modes = numeric_nullspace(rows.xreplace(self._numeric_values()))
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

    def carrier_speed_ratio(self) -> sp.Expr:
        """The carrier's nominal speed (counterclockwise in the frame) over the forcing frequency, exact, from the
        tooth counts: the steady rotation of the gears rolling with pitch radii in the ratio of their teeth, the
        first mesh's frequency its central gear's teeth times its speed relative to the carrier, over its order."""
        meshes = [rc for rc in self.couplings if rc.kind == "mesh"]
        where = f"{self.model.name}: the turning frame (set_frame_terms)"
        rows = [list(rc.row[:len(self.bodies)]) for rc in self.couplings if rc.kind == "shaft"]  # (held: supports)
        for rc in meshes:
            teeth = [end.body.tooth_count for end in (rc.a, rc.b)]
            if None in teeth:
                raise ModelError("the carrier's speed in the frame's Coriolis and centripetal terms follows from the "
                                 f"tooth counts, and mesh {rc.name!r} has a gear without teeth=: declare them, or "
                                 "model.set_frame_terms(False) (Lin & Parker's stationary model)", where)
            sign = 1 if any(getattr(end.body, "internal", False) for end in (rc.a, rc.b)) else -1
            turn_a, turn_b = (row[:len(self.bodies)] for row in rc.turning) if rc.turning[0] else (
                self._unit_row(rc.a)[:len(self.bodies)], self._unit_row(rc.b)[:len(self.bodies)])
            rows.append([teeth[0] * x + sign * teeth[1] * y for x, y in zip(turn_a, turn_b)])
        modes = sp.Matrix(rows).nullspace()
        if len(modes) != 1:
            raise ModelError(f"the gears' kinematics leave {len(modes)} rotations free, so the carrier's speed is not "
                             "set by the forcing frequency; model.set_frame_terms(False) leaves the frame's terms out",
                             where)
        u = modes[0]
        driven = [f.body for f in self.forcing if f.amplitude.could_extract_minus_sign() is False and f.order == 0]
        inputs = [rb for rb in self.bodies if rb.body.speed_parameter] + driven + self.bodies
        reference = next(rb for rb in inputs if u[rb.index] != 0)
        u = u if u[reference.index] > 0 else -u
        first = meshes[0]
        central = next((e for e in (first.a, first.b) if not isinstance(e.body, Planet)), first.a)
        turning = first.turning[0] if central is first.a else first.turning[1]
        rate = abs(sum(e * x for e, x in zip(turning[:len(self.bodies)], u))) if turning else abs(u[central.index])
        carrier = self.frame_carrier
        return sp.nsimplify(self._senses.get(carrier.body.name, 1) * u[carrier.index] * first.order
                            / (central.body.tooth_count * rate))

    def _numeric_values(self) -> dict[sp.Symbol, sp.Expr]:
        """Numbers for the radii in the deflection rows: declared defaults and physical values, else generic
        positive ones (the signs of rates in a gear train do not depend on the radii's exact values)."""
        rng = random.Random(7)
        free = sorted({s for rc in self.couplings for e in rc.row for s in e.free_symbols}, key=str)
        out = {}
        for s in free:
            value = self._default_value(s)
            if value is None and s.name in self.model._physical:
                value = self.model._physical[s.name].si
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
