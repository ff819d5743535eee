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
from ..model.components import Planet
from ..model.linear_algebra import pivot_columns
from ..reduction.coordinates import deflection_matrix, relative_coordinates
from ..reduction.statics import mean_over, mean_stiffness, number as _number
from ..model.symbols import parameter_symbol, tau

#: eigenvalues within this fraction of the largest count as one (a degenerate frequency)
DEGENERATE = 1e-8


@dataclass(frozen=True)
class Mode:
    """One natural mode: its frequency, its kind, how many modes share its frequency, and its shape by degree of
    freedom (body angles by the body's name, a centre's translations as ``sun.x``, ``planet1.radial``; largest
    component 1) and by relative coordinate.

    The kind: "rigid" for a rigid-body mode; for a drivetrain whose bodies all turn only, "elastic"; for a planetary
    set whose members translate, Lin & Parker's classes: "rotational" (the central members only turn, every
    planet moves alike), "translational" (the central members only translate, a pair of equal frequency) and
    "planet" (the central members still); for other drivetrains on bearings, the degrees of freedom that hold
    most of the mode's kinetic energy ("pinion.y+wheel.y")."""

    frequency: float
    kind: str
    multiplicity: int
    angles: dict[str, float]  # every degree of freedom's component (rotations by the body's name)
    coordinates: dict[str, float]
    unit: str = "Hz"

    @property
    def shape(self) -> dict[str, float]:
        return self.angles

    def as_dict(self) -> dict:
        return {"frequency": {"value": self.frequency, "unit": self.unit}, "kind": self.kind,
                "multiplicity": self.multiplicity, "shape": self.angles, "coordinates": self.coordinates}


@dataclass(frozen=True)
class Modes:
    """Every mode of a drivetrain, in ascending frequency (rigid-body modes first, at zero)."""

    model: str
    unit: str  # "Hz", or "omega_n" (angular frequency in the model's time unit)
    modes: tuple[Mode, ...]
    values: dict[str, float]  # the component values used (SI with physical values)
    assumed: tuple[str, ...] = ()  # parameters without a value, taken as 1
    shapes: str = field(default="shape: body angles psi_i (and a centre's translations on its bearing); "
                                  "coordinates: relative coordinates x = T psi (mesh deflections, shaft twists and "
                                  "bearing deflections as lengths)")

    @property
    def frequencies(self) -> tuple[float, ...]:
        return tuple(m.frequency for m in self.modes)

    @property
    def elastic(self) -> tuple[Mode, ...]:
        return tuple(m for m in self.modes if m.kind != "rigid")

    def as_dict(self) -> dict:
        """JSON-ready: the keys of ``gearsym modes --format json`` (each mode's frequency as value and unit)."""
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


@dataclass(frozen=True)
class _Kinematics:
    """What the modes need of a reduction: the resolved drivetrain, its coordinates, T and rigid-body modes."""

    resolved: object
    coordinates: tuple
    transform: sp.Matrix
    rigid_modes: tuple
    name: str

    @property
    def reduction(self):
        return self


def drivetrain_modes(drivetrain, values: Mapping[str, float], unit: str = "Hz") -> Modes:
    """The natural modes of a declared drivetrain at ``values`` (every parameter of its masses, inertias, rows and
    couplings, in SI for Hz), from its kinematics alone: the coordinates and rigid-body modes, not the whole
    reduction (a drivetrain on bearings has many degrees of freedom, and its modes need no Lagrange equations)."""
    rd = drivetrain.resolved
    coordinates, transform = relative_coordinates(rd)
    rigid = _rigid_modes_at(rd, values)
    light = _Kinematics(rd, tuple(coordinates), transform.applyfunc(rd.with_geometry), tuple(rigid), drivetrain.name)
    return _solve(light, dict(values), unit, ())


def _rigid_modes_at(rd, values: Mapping[str, float]) -> list[np.ndarray]:
    """The rigid-body modes at ``values``, the basis the exact null space has (each free column of the deflection
    rows' echelon form at generic values 1 in its own mode, 0 in the others'), solved in numbers: the modes need
    their values only, and the exact null space of a planetary set on bearings takes SymPy seconds."""
    rows = deflection_matrix(rd)
    pivots = pivot_columns(rows)
    free = [j for j in range(rows.cols) if j not in pivots]
    if not free:
        return []
    a = np.array([[_number(rd.with_geometry(e), values, "a deflection row") for e in r] for r in rows.tolist()])
    modes = []
    for f in free:
        u = np.zeros(rows.cols)
        u[f] = 1.0
        u[pivots] = np.linalg.lstsq(a[:, pivots], -a[:, f], rcond=None)[0]
        u[np.abs(u) <= AT_REST * np.max(np.abs(u))] = 0.0  # (a body at rest in the mode, but for rounding)
        modes.append(u)
    return modes


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
    names = [d.label for d in rd.dofs]
    inertia = np.array([_number(d.inertia, values, f"the {'inertia' if d.motion == 'rotation' else 'mass'} of "
                                                   f"{d.body.name!r}") for d in rd.dofs])
    stiffness = np.zeros((len(names), len(names)))
    for rc in rd.couplings:
        row = np.array([_number(rd.with_geometry(e), values, f"the deflection of {rc.name!r}") for e in rc.row])
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
    classify = _kinds(rd, inertia)
    modes = [_mode(0.0, "rigid", len(rigid), u, names, transform, coordinates, unit) for u in rigid]
    for group in _repeated(elastic, eigenvalues, DEGENERATE * top):
        w = to_unit(math.sqrt(max(float(np.mean(eigenvalues[group])), 0.0)))
        kind = classify(shapes[:, group]) if classify else "elastic"
        for shape in canonical_basis(shapes[:, group].T):
            modes.append(_mode(w, kind, len(group), shape, names, transform, coordinates, unit))
    used = set()
    for rb in rd.dofs:
        used |= rb.inertia.free_symbols | (rb.radius.free_symbols if rb.radius is not None else set())
    for rc in rd.couplings:
        used |= rc.stiffness.free_symbols | rc.variation.free_symbols
        used |= sp.Matrix([rd.with_geometry(e) for e in rc.row]).free_symbols
    shown = {n: v for n, v in values.items() if parameter_symbol(n) in used}
    return Modes(nd.name, unit, tuple(modes), shown, assumed)


#: a central member's share of a mode's kinetic energy below this counts as none (Lin & Parker's classes)
STILL = 1e-9


def _kinds(rd, inertia: np.ndarray):
    """The classifier of a drivetrain with translations (None for one whose bodies only turn): Lin & Parker's
    classes for a planetary set whose planets translate, else the degrees of freedom that hold most of the
    kinetic energy."""
    if not rd.translations:
        return None
    planets = {d.body.name for d in rd.dofs if isinstance(d.body, Planet)}
    if planets and any(isinstance(d.body, Planet) for d in rd.translations):
        central_turn = [i for i, d in enumerate(rd.dofs) if d.body.name not in planets and d.motion == "rotation"]
        central_move = [i for i, d in enumerate(rd.dofs) if d.body.name not in planets and d.motion != "rotation"]

        def lin_parker(space: np.ndarray) -> str:
            energy = inertia[:, None] * space**2
            total = float(np.sum(energy))
            turn = float(np.sum(energy[central_turn])) / total
            move = float(np.sum(energy[central_move])) / total
            if turn < STILL and move < STILL:
                return "planet"
            if move < STILL:
                return "rotational"
            if turn < STILL:
                return "translational"
            return "mixed"

        return lin_parker
    labels = [d.label for d in rd.dofs]

    def dominant(space: np.ndarray) -> str:
        energy = np.sum(inertia[:, None] * space**2, axis=1)
        share = energy / float(np.sum(energy))
        top = [labels[i] for i in np.argsort(-share) if share[i] >= 0.2][:3]
        return "+".join(top) if top else labels[int(np.argmax(share))]

    return dominant


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
          transform: np.ndarray, coordinates: list[str], unit: str = "Hz") -> Mode:
    """A mode with its shape scaled so that its largest component (the first of equal ones) is +1."""
    size = np.abs(shape)
    big = int(np.flatnonzero(size >= size.max() * (1 - 1e-9))[0])
    shape = shape / shape[big]
    return Mode(frequency, kind, multiplicity, {n: float(v) for n, v in zip(names, shape)},
                {c: float(v) for c, v in zip(coordinates, transform @ shape)}, unit)
