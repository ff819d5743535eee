"""The drivetrain at rest under its mean loads: the static solution of the reduced equations, and the
mean torque balance that a steady operating point needs.

At rest every rate is zero and every time-varying term takes its mean over a period: a mesh's stiffness
its declared stiffness times the mean of its variation, a harmonic torque zero. The reduced equations
``x_i'' = -sum_c factor_ic law_c + forcing_i`` then say ``sum_c factor_ic law_c(d_c) = F_i``, with each
coupling's law in its deflection ``d_c`` (a coordinate, or the combination of coordinates of a coupling
that closes a loop): ``k_c g(d_c, eta_c)`` for a mesh, ``k_c d_c`` for a shaft. That is piecewise linear in
the coordinates (the backlash), and semismooth Newton solves it exactly in a few steps, for chains, trees
and loops alike. Numbers only: the values are in any consistent units (SI for a model with physical values).

The coordinates are relative: they hold whether or not the train as a whole accelerates. A steady
operating point needs more, that the mean torques do no net work in every rigid-body rotation
(``u^T Q = 0`` for each rigid mode ``u``): :func:`torque_imbalance` says by how much they fail.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

from ..errors import GearsymError
from ..model.resolved_components import ResolvedCoupling
from ..model.symbols import parameter_symbol, phi
from .reduction import Reduction

#: samples of a mesh period for the mean of its stiffness variation (exact for Fourier series of lower degree)
MEAN_SAMPLES = 1024
#: Newton steps before the static solution is declared not found (each step changes the contact of a mesh)
MAX_STEPS = 60


#: numbers :func:`number` gave, by expression and the values of its parameters (a scaling probed value by value,
#: as an FMU's frame is measured, solves the statics again for each probe: most of its expressions keep their values)
_NUMBERS: dict[tuple, float] = {}
_NUMBERS_KEPT = 8192


def number(expr: sp.Expr, values: Mapping[str, float], what: str) -> float:
    """``expr`` at ``values``, or a one-line error naming what has no value."""
    expr = sp.sympify(expr, strict=True)
    names = _parameters_of(expr)
    key = (expr, tuple(repr(values.get(n)) for n in names))  # (repr: -0.0 is not 0.0, 1 not 1.0)
    if key in _NUMBERS:
        return _NUMBERS[key]
    # only the parameters ``expr`` has (a planetary set's scaling evaluates thousands of small expressions, each
    # against every value of the model: a Float made for each value was most of the time)
    value = expr.xreplace({parameter_symbol(n): sp.Float(values[n]) for n in names if n in values})
    if not value.is_number:
        missing = ", ".join(sorted(s.name for s in value.free_symbols))
        raise GearsymError(f"{what} needs a value for {missing}")
    result = float(value)
    if not math.isfinite(result):
        raise GearsymError(f"{what} is {result} at these values")
    if len(_NUMBERS) >= _NUMBERS_KEPT:
        _NUMBERS.clear()
    _NUMBERS[key] = result
    return result


@lru_cache(maxsize=4096)
def _parameters_of(expr: sp.Expr) -> tuple[str, ...]:
    """The names of the parameters in ``expr`` (its symbols that are parameters' own)."""
    return tuple(sorted(s.name for s in expr.free_symbols if s == parameter_symbol(s.name)))


def mean_over(expr: sp.Expr, variable: sp.Symbol, period: float, values: Mapping[str, float], what: str) -> float:
    """The mean of ``expr`` over one ``period`` of ``variable`` (sampled: exact for a Fourier series of lower
    degree than half the samples)."""
    shape = expr.xreplace({parameter_symbol(n): v for n, v in values.items()})
    if shape.free_symbols - {variable}:
        missing = ", ".join(sorted(s.name for s in shape.free_symbols - {variable}))
        raise GearsymError(f"{what} needs a value for {missing}")
    mean = _sampled_mean(shape, variable, float(period))
    if not math.isfinite(mean):
        raise GearsymError(f"{what} is not finite over its period")
    return mean


@lru_cache(maxsize=256)  # (a scaling probes many values: the meshes of a planetary set share their shape)
def _sampled_mean(shape: sp.Expr, variable: sp.Symbol, period: float) -> float:
    samples = np.linspace(0.0, period, MEAN_SAMPLES, endpoint=False)
    with np.errstate(all="ignore"):
        sampled = np.asarray(sp.lambdify(variable, shape, "numpy")(samples), dtype=float) * np.ones(MEAN_SAMPLES)
    return float(np.mean(sampled))


def mean_stiffness(rc: ResolvedCoupling, values: Mapping[str, float]) -> float:
    """A coupling's stiffness averaged over a mesh period (a shaft's is its own)."""
    k = number(rc.stiffness, values, f"the stiffness of {rc.name!r}")
    if rc.kind != "mesh":
        return k
    return k * mean_over(rc.variation, phi, 2 * math.pi, values, f"the stiffness variation of {rc.name!r}")


@dataclass(frozen=True)
class StaticState:
    """The reduced drivetrain at rest under its mean loads (numbers in the units of the values given)."""

    coordinates: dict[str, float]  # each relative coordinate (a state)
    deflections: dict[str, float]  # each coupling's deflection, by coupling name (loop-closing ones too)
    mesh_forces: dict[str, float]  # each mesh's static force k g(d, eta), by mesh name
    contact: dict[str, str]  # each mesh's flank: "drive" (d >= 0), "gap" or "back" (d <= -eta)
    bearing_forces: dict[str, float] = None  # each bearing direction's static force k d (gears on bearings)


@dataclass(frozen=True)
class _Law:
    """One coupling at rest: its deflection row in the coordinates, mean stiffness and backlash."""

    name: str
    kind: str
    row: np.ndarray
    stiffness: float
    backlash: float

    def force(self, d: float) -> float:
        if self.kind != "mesh":
            return self.stiffness * d
        return self.stiffness * (d if d >= 0 else (0.0 if d > -self.backlash else d + self.backlash))

    def slope(self, d: float) -> float:
        if self.kind != "mesh":
            return self.stiffness
        return self.stiffness * (1.0 if (d >= 0 or d <= -self.backlash) else 0.0)

    def flank(self, d: float) -> str:
        return "drive" if d >= 0 else ("gap" if d > -self.backlash else "back")


def static_state(red: Reduction, values: Mapping[str, float]) -> StaticState:
    """The static solution of ``red``'s equations at ``values`` (every parameter of its couplings, factors and
    mean torques); a one-line error where there is none (a mesh that never closes, a stiffness of zero)."""
    n = len(red.coordinates)
    index = {c.name: i for i, c in enumerate(red.coordinates)}
    laws = []
    for d in red.deflections:
        rc = d.coupling
        row = np.zeros(n)
        if d.independent:
            row[index[d.name]] = 1.0
        else:
            for c, a in d.combination:
                row[index[c.name]] += number(a, values, f"the deflection of {rc.name!r}")
        backlash = number(rc.backlash, values, f"the backlash of {rc.name!r}") if rc.kind == "mesh" else 0.0
        laws.append(_Law(rc.name, rc.kind, row, mean_stiffness(rc, values), backlash))
    by_name = {law.name: law for law in laws}
    factors = np.zeros((n, len(laws)))
    position = {law.name: k for k, law in enumerate(laws)}
    for ct in red.coupling_terms:
        factors[ct.row, position[ct.coupling.name]] += number(ct.factor, values,
                                                              f"the factor of {ct.coupling.name!r}")
    load = np.zeros(n)
    for ft in red.forcing_terms:
        if ft.source.order == 0:
            load[ft.row] += number(ft.coefficient, values, f"the mean torque {ft.source.torque.name!r}")
    x = _solve(laws, factors, load, red.drivetrain.name)
    deflections = {law.name: float(law.row @ x) for law in laws}
    return StaticState(
        coordinates={c.name: float(x[i]) for i, c in enumerate(red.coordinates)},
        deflections=deflections,
        mesh_forces={name: by_name[name].force(d) for name, d in deflections.items() if by_name[name].kind == "mesh"},
        contact={name: by_name[name].flank(d) for name, d in deflections.items() if by_name[name].kind == "mesh"},
        bearing_forces={name: by_name[name].force(d) for name, d in deflections.items()
                        if by_name[name].kind == "bearing"},
    )


def _solve(laws: list[_Law], factors: np.ndarray, load: np.ndarray, model: str) -> np.ndarray:
    """Semismooth Newton on ``factors @ law(row @ x) = load``: exact once every mesh's flank is right."""
    n = factors.shape[0]
    x = np.zeros(n)
    scale = max(float(np.max(np.abs(load))), 1e-300)

    def residual(x):
        return factors @ np.array([law.force(float(law.row @ x)) for law in laws]) - load

    r = residual(x)
    for _ in range(MAX_STEPS):
        jacobian = factors @ np.array([law.slope(float(law.row @ x)) * law.row for law in laws])
        if np.linalg.matrix_rank(jacobian) < n and any(law.flank(float(law.row @ x)) == "gap" for law in laws
                                                        if law.kind == "mesh"):
            step = _closing_step(laws, factors, load, x)
        else:
            try:
                step = np.linalg.solve(jacobian, -r)
            except np.linalg.LinAlgError:
                step = np.linalg.lstsq(jacobian, -r, rcond=None)[0]
        x = x + step
        r = residual(x)
        if float(np.max(np.abs(r))) <= 1e-12 * scale or not np.any(load):
            return x
    raise GearsymError(f"{model}: the drivetrain has no static equilibrium under its mean loads (a mesh that "
                       "never closes, or a coupling without stiffness, leaves a load nothing holds)")


def _closing_step(laws: list[_Law], factors: np.ndarray, load: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The step from ``x`` when meshes in their backlash gap leave nothing to hold the load (the Jacobian is
    singular, and Newton's step would not move them): each such mesh is taken to close on the flank the load
    pushes it toward (the back flank if the step with its stiffness restored opens it further, else the drive
    flank), and the step is the one to the solution of those flanks' linear laws (exact if they are the right
    ones; the next steps correct them if not)."""
    d = [float(law.row @ x) for law in laws]
    gap = [law.kind == "mesh" and law.flank(di) == "gap" for law, di in zip(laws, d)]
    slopes = [law.stiffness if closing else law.slope(di) for law, di, closing in zip(laws, d, gap)]
    stiff = factors @ np.array([s * law.row for s, law in zip(slopes, laws)])
    forces = np.array([law.force(di) for law, di in zip(laws, d)])
    toward = np.linalg.lstsq(stiff, load - factors @ forces, rcond=None)[0]
    for k, (law, di, closing) in enumerate(zip(laws, d, gap)):
        if closing:  # the linear law of the flank it closes on, at its deflection now
            forces[k] = law.stiffness * (di + law.backlash if float(law.row @ toward) < 0 else di)
    return np.linalg.lstsq(stiff, load - factors @ forces, rcond=None)[0]


@dataclass(frozen=True)
class Imbalance:
    """The mean torques' net work per unit rotation in one rigid-body mode, referred to the body ``reference``
    (the torque on its axis that would make the train accelerate alike), and what would balance it."""

    reference: str
    net: float  # torque on the reference body's axis (the values' unit of torque)
    balancing: tuple[tuple[str, str, float], ...]  # (torque, body, the mean value that balances the train)


def torque_imbalance(red: Reduction, values: Mapping[str, float], reference: str | None = None,
                     tolerance: float = 1e-9) -> list[Imbalance]:
    """For each rigid-body mode, the mean torques' imbalance (empty if they balance to ``tolerance`` of the
    largest).
    ``reference`` names the body the net torque is referred to (default: the first that turns in the mode)."""
    rd = red.resolved
    out = []
    for mode in red.rigid_modes:
        u = [number(e, values, "a rigid-body mode") for e in mode]
        bodies = [rb for rb in rd.bodies if abs(u[rb.index]) > 1e-12]
        ref = next((rb for rb in bodies if rb.body.name == reference), bodies[0] if bodies else None)
        if ref is None:
            continue
        u = [e / u[ref.index] for e in u]
        terms = []
        for f in rd.forcing:
            if f.order == 0 and not f.body.fixed:
                terms.append((f, u[f.body.index] * number(f.amplitude, values, f"the torque {f.torque.name!r}")))
        net = math.fsum(w for _, w in terms)
        largest = max((abs(w) for _, w in terms), default=0.0)
        if largest == 0.0 or abs(net) <= tolerance * largest:
            continue
        balancing = []
        for f, work in terms:
            share = u[f.body.index]
            amplitude = work / share  # signed: a load torque enters with -1
            sign = -1.0 if f.torque.load else 1.0
            balancing.append((f.torque.name, f.body.body.name, sign * (amplitude - net / share)))
        out.append(Imbalance(ref.body.name, net, tuple(balancing)))
    return out
