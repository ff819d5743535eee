"""The parts of a resolved drivetrain: a body with its angle, a coupling with its deflection row, a torque term."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import sympy as sp

from .symbols import omega, phi, t
from .components import Body, Coupling, Torque


@dataclass(frozen=True)
class ResolvedBody:
    """One degree of freedom of a body: its rotation (``motion`` "rotation": the paper's psi_i), or a translation
    of its centre on its bearing ("x", "y"; a planet's "radial", "tangential" in the carrier's frame)."""

    body: Body
    index: Optional[int]  # 0-based position among the degrees of freedom (rotations first); None if fixed
    angle: sp.Expr  # the coordinate as a function of t: psi_i(t), X_body(t) ...; 0 for a fixed body
    inertia: Optional[sp.Expr]  # moment of inertia (a mass for a translation); None for a fixed body
    radius: Optional[sp.Expr]
    motion: str = "rotation"  # "rotation" | "x" | "y" | "radial" | "tangential"

    @property
    def fixed(self) -> bool:
        return self.index is None

    @property
    def label(self) -> str:
        """The body's name, with the direction for a translation (``sun.x``, ``planet1.radial``)."""
        return self.body.name if self.motion == "rotation" else f"{self.body.name}.{self.motion}"


@dataclass(frozen=True)
class ResolvedCoupling:
    """A mesh or shaft with its expressions parsed and its kinematics set up."""

    component: Coupling  # (a Bearing for "bearing" couplings and torsional supports)
    kind: str  # "mesh" | "shaft" | "bearing" (a torsional support is a "shaft" to the ground)
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
    # shaft-order terms (:mod:`.faults`), in the mesh phase phi: the fraction of stiffness lost, the transmission
    # error (a length), and the tooth counts of the gears whose revolution they repeat on
    loss: sp.Expr = sp.S.Zero
    error: sp.Expr = sp.S.Zero
    revolutions: tuple[int, ...] = ()
    label: Optional[str] = None  # a bearing's direction: its own name ("b1_x"), not the component's
    coordinate_name: Optional[str] = None  # the default name of its coordinate, where the component gives none

    @property
    def name(self) -> str:
        return self.label or self.component.name

    @property
    def shaft_frequencies(self) -> tuple[sp.Expr, ...]:
        """The frequencies (over the forcing's) at which the shaft-order terms repeat: order / Z of each gear."""
        return tuple(self.order / z for z in self.revolutions)

    def in_time(self, expr: sp.Expr) -> sp.Expr:
        """A term in the mesh phase written in time t."""
        return expr.subs(phi, self.mesh_phase) if expr != 0 else sp.S.Zero

    def variation_at(self, phase: sp.Expr) -> sp.Expr:
        """The stiffness variation k at the mesh phase ``phase`` (an expression in t or tau), times the factor
        (1 - loss) where shaft-order terms take stiffness away (a tooth fault, once per revolution): the one
        place that factor is applied, for the Lagrangian and the reduction alike."""
        varied = self.variation.subs(phi, phase)
        return varied if self.loss == 0 else varied * (1 - self.loss.subs(phi, phase))


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
