"""Natural frequencies and mode shapes of a drivetrain's linear, time-averaged system.

From the drivetrain's Lagrangian with the backlash closed and every mesh at its mean stiffness:
the mass matrix is that of the inertias, the stiffness matrix ``K = sum_c k_c J_c^T J_c`` adds each
coupling's deflection row ``J_c`` (``r_a psi_a - r_b psi_b`` for a mesh, ``psi_b - psi_a`` for a shaft)
with its mean stiffness ``k_c`` (the declared stiffness times the mean of its variation over a mesh
period). ``K phi = w^2 M phi`` is solved through ``M^(-1/2) K M^(-1/2)`` (M is diagonal), which stays
symmetric, so repeated eigenvalues (the planet modes of a planetary set) come out with an orthonormal
basis of their eigenspace and are reported with their multiplicity. Any basis of that eigenspace is right, and
LAPACK's depends on the BLAS kernel (the CPU): the shapes shown are its canonical basis
(:func:`canonical_basis`), the same on every machine.

Rigid-body modes are those of the reduction (the null space of the deflection rows): as many zero
frequencies as it finds, with its shapes. With physical values (:mod:`gearsym.physical`) frequencies
are in Hz; without, they are angular frequencies in the model's time unit 1/omega_n, with the
component values the nondimensional model implies (the first mesh's stiffness from the time-unit
condition, a second one's from its group K; inertias and radii without a declared value taken as 1).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from ..errors import GearsymError
from ..reduction.statics import mean_over, mean_stiffness, number as _number
from ..model.symbols import parameter_symbol, tau

#: eigenvalues within this fraction of the largest count as one (a degenerate frequency)
DEGENERATE = 1e-8


@dataclass(frozen=True)
class Mode:
    """One natural mode: its frequency, whether it is a rigid-body mode, how many modes share its frequency,
    and its shape by body angle and by relative coordinate (largest angle component 1)."""

    frequency: float
    kind: str  # "rigid" | "elastic"
    multiplicity: int
    angles: dict[str, float]
    coordinates: dict[str, float]

    def as_dict(self) -> dict:
        return {"frequency": self.frequency, "kind": self.kind, "multiplicity": self.multiplicity,
                "angles": self.angles, "coordinates": self.coordinates}


@dataclass(frozen=True)
class Modes:
    """Every mode of a drivetrain, in ascending frequency (rigid-body modes first, at zero)."""

    model: str
    unit: str  # "Hz", or "omega_n" (angular frequency in the model's time unit)
    modes: tuple[Mode, ...]
    values: dict[str, float]  # the component values used (SI with physical values)
    assumed: tuple[str, ...] = ()  # parameters without a value, taken as 1
    shapes: str = field(default="angles: body angles psi_i; coordinates: relative coordinates x = T psi "
                                  "(mesh deflections and shaft twists as lengths)")

    @property
    def frequencies(self) -> tuple[float, ...]:
        return tuple(m.frequency for m in self.modes)

    @property
    def elastic(self) -> tuple[Mode, ...]:
        return tuple(m for m in self.modes if m.kind == "elastic")

    def as_dict(self) -> dict:
        """JSON-ready: the keys of ``gearsym modes --format json``."""
        return {"model": self.model, "unit": self.unit, "frequencies": list(self.frequencies),
                "modes": [m.as_dict() for m in self.modes], "shapes": self.shapes, "values": self.values,
                "assumed": list(self.assumed)}


def physical_modes(scaling, formulas: Mapping[str, object] | None = None) -> Modes:
    """The natural modes of a scaled drivetrain (a :class:`~gearsym.scales.map.Scaling`), in Hz; ``formulas``
    (default the scaling's own) replace mesh stiffness functions (their mean is what a linear, time-averaged
    system sees)."""
    nd = scaling.model
    formulas = scaling.functions if formulas is None else formulas
    values = {**scaling.values, **scaling.formula_values}
    return _solve(nd, dict(scaling.si_values), "Hz", (), _formula_means(nd, formulas, values))


def nondimensional_modes(nd, settings: Mapping[str, object]) -> Modes:
    """The natural modes of a reduced drivetrain without physical values, in its time unit 1/omega_n;
    ``settings`` are parameter values (``kS=0.5``) or stiffness formulas (``k="1+0.2*cos(tau)"``)."""
    functions = {f.name for f in nd.functions}
    formulas = {k: v for k, v in settings.items() if k in functions}
    numbers = {k: v for k, v in settings.items() if k not in functions}
    values, assumed = _nondimensional_values(nd, numbers)
    return _solve(nd, values, "omega_n", assumed, _formula_means(nd, formulas, values))


def _formula_means(nd, formulas: Mapping[str, object], values: Mapping[str, float]) -> dict[str, float]:
    """For each mesh whose stiffness function a formula replaces: the formula's mean over its period over the
    declared function's (the factor its mean stiffness changes by)."""
    out = {}
    for f in nd.functions:
        if f.name not in formulas:
            continue
        new = nd.stiffness_formula(f, formulas[f.name])
        period = float(f.period)
        where = f"stiffness function {f.name}"
        old = mean_over(f.expression, tau, period, values, where)
        if old == 0:
            raise GearsymError(f"{nd.name}: the declared {f.name}(tau) has mean 0; its modes have no mean stiffness")
        out[f.mesh] = mean_over(new, tau, period, values, where) / old
    return out


def _nondimensional_values(nd, settings) -> tuple[dict[str, float], tuple[str, ...]]:
    """Component values in the model's own units: declared defaults and ``settings``, the mesh stiffnesses from
    the time-unit condition and the K groups, and 1 for what is left."""
    rd = nd.reduction.resolved
    values = {**nd.declared_defaults, **{k: nd.check_value(k, v) for k, v in settings.items()}}
    values.update({k: float(v) for k, v in nd.drivetrain.defaults.items()
                   if k not in values and isinstance(v, (int, float))})
    needed = set()
    for rb in rd.bodies:
        needed |= {s.name for s in rb.inertia.free_symbols | (rb.radius.free_symbols if rb.radius is not None else set())}
    for rc in rd.couplings:
        needed |= {s.name for s in sp.Matrix(rc.row).free_symbols}
    assumed = tuple(sorted(n for n in needed if n not in values))
    values.update({n: 1.0 for n in assumed})
    for f in nd.functions:
        rc = nd._mesh(f)
        if not isinstance(rc.stiffness, sp.Symbol) or rc.stiffness.name in values:
            continue
        if rc is nd._mesh(nd.functions[0]):
            condition = next(c for c in nd.conditions if c.kind == "time_unit").equation
            equation = condition.lhs - condition.rhs
        else:
            group = next(gr for gr in nd.groups if gr.role == "stiffness" and rc.stiffness in gr.definition.free_symbols)
            equation = group.definition - values.get(group.name, 1.0)
        solved = sp.solve(equation.xreplace({parameter_symbol(k): v for k, v in values.items()
                                             if parameter_symbol(k) != rc.stiffness}), rc.stiffness)
        values[rc.stiffness.name] = float(solved[0])
    return values, assumed


def _solve(nd, values: dict[str, float], unit: str, assumed: tuple[str, ...],
           factors: Mapping[str, float] | None = None) -> Modes:
    rd = nd.reduction.resolved
    names = [rb.body.name for rb in rd.bodies]
    inertia = np.array([_number(rb.inertia, values, f"the inertia of {rb.body.name!r}") for rb in rd.bodies])
    stiffness = np.zeros((len(names), len(names)))
    for rc in rd.couplings:
        row = np.array([_number(e, values, f"the deflection of {rc.name!r}") for e in rc.row])
        stiffness += mean_stiffness(rc, values) * (factors or {}).get(rc.name, 1.0) * np.outer(row, row)
    transform = np.array([[_number(e, values, "the coordinate change") for e in r]
                          for r in nd.reduction.transform.tolist()])
    scale = 1.0 / np.sqrt(inertia)
    eigenvalues, vectors = np.linalg.eigh(scale[:, None] * stiffness * scale[None, :])
    shapes = scale[:, None] * vectors  # mass-normalised phi = M^(-1/2) y
    rigid = [np.array([_number(e, values, "a rigid-body mode") for e in u]) for u in nd.reduction.rigid_modes]
    top = max(float(np.max(np.abs(eigenvalues))), 1e-300)
    if rigid and np.max(np.abs(eigenvalues[:len(rigid)])) > 1e-9 * top:
        raise GearsymError(f"{nd.name}: {len(rigid)} rigid-body mode(s) but the stiffness matrix has no such zero "
                           "eigenvalues (a coupling with zero stiffness?)")
    order = np.argsort(eigenvalues)
    elastic = [int(i) for i in order[len(rigid):]]
    to_unit = (lambda w: w / (2 * math.pi)) if unit == "Hz" else (lambda w: w)
    coordinates = [c.name for c in nd.coordinates]
    modes = [_mode(0.0, "rigid", len(rigid), u, names, transform, coordinates) for u in rigid]
    for group in _repeated(elastic, eigenvalues, DEGENERATE * top):
        w = to_unit(math.sqrt(max(float(np.mean(eigenvalues[group])), 0.0)))
        for shape in canonical_basis(shapes[:, group].T):
            modes.append(_mode(w, "elastic", len(group), shape, names, transform, coordinates))
    used = set()
    for rb in rd.bodies:
        used |= rb.inertia.free_symbols | (rb.radius.free_symbols if rb.radius is not None else set())
    for rc in rd.couplings:
        used |= rc.stiffness.free_symbols | rc.variation.free_symbols | sp.Matrix(rc.row).free_symbols
    shown = {n: v for n, v in values.items() if parameter_symbol(n) in used}
    return Modes(nd.name, unit, tuple(modes), shown, assumed)


def _repeated(order: list[int], eigenvalues: np.ndarray, within: float) -> list[list[int]]:
    """The indices ``order`` (ascending eigenvalues) in groups of one frequency: each eigenvalue within ``within``
    of the group's first."""
    groups: list[list[int]] = []
    for i in order:
        if groups and abs(float(eigenvalues[i]) - float(eigenvalues[groups[-1][0]])) <= within:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


#: a component below this fraction of a basis's largest is rounding (a body at rest in the subspace)
AT_REST = 1e-9


def canonical_basis(rows: np.ndarray) -> list[np.ndarray]:
    """The basis of the span of ``rows`` that does not depend on which basis LAPACK returned: its reduced row
    echelon form (the first body that moves in the subspace is 1 in the first vector and 0 in the others, the
    next such body likewise in the second, ...). A repeated frequency's eigenvectors are any basis of their
    plane: another BLAS kernel (another CPU) rotates them, this form does not. One row is returned as it is."""
    rows = np.array(rows, dtype=float)
    if len(rows) == 1:
        return [rows[0]]
    scale = float(np.max(np.abs(rows)))
    rows[np.abs(rows) <= AT_REST * scale] = 0.0
    pivot_row = 0
    for column in range(rows.shape[1]):
        if pivot_row == len(rows):
            break
        below = np.abs(rows[pivot_row:, column])
        if below.max() <= AT_REST * scale:
            continue
        best = pivot_row + int(np.argmax(below))
        rows[[pivot_row, best]] = rows[[best, pivot_row]]
        rows[pivot_row] /= rows[pivot_row, column]
        for other in range(len(rows)):
            if other != pivot_row:
                rows[other] -= rows[other, column] * rows[pivot_row]
        rows[np.abs(rows) <= AT_REST * max(1.0, float(np.max(np.abs(rows))))] = 0.0
        pivot_row += 1
    return list(rows)


def _mode(frequency: float, kind: str, multiplicity: int, shape: np.ndarray, names: list[str],
          transform: np.ndarray, coordinates: list[str]) -> Mode:
    """A mode with its shape scaled so that its largest angle component (the first of equal ones) is +1."""
    size = np.abs(shape)
    big = int(np.flatnonzero(size >= size.max() * (1 - 1e-9))[0])
    shape = shape / shape[big]
    return Mode(frequency, kind, multiplicity, {n: float(v) for n, v in zip(names, shape)},
                {c: float(v) for c, v in zip(coordinates, transform @ shape)})
