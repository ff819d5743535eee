"""The SI frame of a model with physical values: its FMU works in seconds, metres and newtons.

From the model's scaling (:func:`gearsym.scaling`: its time unit T, length unit L and the engine's values):
states in m and m/s, the forcing phase tau = omega t / T, mesh forces in N, and every physical value as a
parameter in SI, with the unit it was declared in as display unit and the description ``describe`` gave it.

Which physical values may change at run time is measured on the scaling itself, not assumed: each value is
doubled and tripled (0 -> one and two of its units), and it is *tunable* if the units T and L stay the same and
every engine value it moves follows a power of it (B1 = its value at M1a x (M1a / M1a_0), omega the same in the
speed): then the wrapper's C reproduces the scaling exactly at any value. Every other value (the inertias,
radii and the mesh stiffness, which move omega_n and so T; the mean torques, which move the static deflection L
under the default length scale) is baked into the engine's values and marked fixed.
"""
from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..errors import GearsymError
from ..physical.results import point_units
from ..scales.map import Scaling
from ..scales.settings import physical_settings
from ..units import Measure, Quantity, measure, si_factor
from .frame import Frame, PhysicalParameter, Term, Unit
from .variables import undescribed

#: SI units by the exponents of (mass, length, time) of a value (angles are dimensionless: rad/s is 1/s)
_NAMES = {(1, 0, -2): "N/m", (1, 0, -1): "N.s/m", (1, 2, -2): "N.m", (1, 2, -1): "N.m.s", (1, 2, 0): "kg.m2",
          (0, 1, 0): "m",
          (0, 0, -1): "rad/s", (1, 1, -2): "N", (0, 0, 1): "s", (1, 0, 0): "kg", (0, 1, -1): "m/s",
          (0, 1, -2): "m/s2"}
#: the FMU's own quantities: their SI unit and the display unit shown by default
_OWN = {"time": Unit("s", (("s", 1),), (("ms", 1e3),)),
        "length": Unit("m", (("m", 1),), (("mm", 1e3), ("um", 1e6))),
        "rate": Unit("m/s", (("m", 1), ("s", -1)), (("mm/s", 1e3),)),
        "acceleration": Unit("m/s2", (("m", 1), ("s", -2))),
        "angular_rate": Unit("rad/s", (("rad", 1), ("s", -1))),
        "angular_acceleration": Unit("rad/s2", (("rad", 1), ("s", -2))),
        "force": Unit("N", (("kg", 1), ("m", 1), ("s", -2)), (("kN", 1e-3),)),
        "angle": Unit("rad", (("rad", 1),))}
_DISPLAYS = {"length": "um", "rate": "mm/s"}

#: how closely a probed engine value must follow a power of the physical value (and the units stay put)
TOLERANCE = 1e-11
#: the powers looked for
POWERS = (1, -1, 2, -2, 3, -3)


def physical_frame(nd, values: Mapping[str, object], system) -> Frame | None:
    """The frame of the reduced drivetrain ``nd`` with ``values`` (as ``gearsym.load`` takes them), whose engine
    system is ``system``; None for a model without physical values."""
    split = physical_settings(nd, dict(values))
    if split is None:
        return None
    length_scale, physical, _ = split
    base = Scaling.of(nd, length_scale, **physical)
    T, L = float(base.time.to("s").magnitude), float(base.length.to("m").magnitude)
    engine = {k: v for k, v in base.values.items() if k in system.parameters}  # (a formula may drop some)
    if "omega" not in engine or not base.speed:
        raise GearsymError(f"{nd.name}: an FMU in SI needs the operating speed (declare it on a gear: "
                           "Gear(..., teeth=N, speed='speed')), which sets the forcing phase in seconds")
    inputs = base.inputs
    drivetrain = nd.drivetrain
    descriptions = {**system.descriptions, **drivetrain.descriptions}
    parameters, engine_base = [], dict(engine)
    for name in sorted(inputs, key=lambda n: (n != base.speed.parameter, list(inputs).index(n))):
        q = inputs[name]
        unit, display = _unit(q)
        found = _terms(nd, length_scale, physical, name, q, engine, T, L)
        if found is None:  # it no longer enters the model (a stiffness formula replaced k_a's function)
            continue
        terms, at = found
        for term in terms:
            if term.reference != q.si:  # (a value of 0: the engine's at one unit)
                engine_base[term.engine] = at[term.engine]
        parameters.append(PhysicalParameter(name, q.si, unit, display,
                                            descriptions.get(name) or undescribed(system, name), tuple(terms)))
    kinds = {}
    for c in system.couplings:
        if not c.closes_loop:
            kinds[c.coordinate], kinds[c.velocity] = (("length", "rate") if c.kind == "mesh" else
                                                      ("angle", "angular_rate"))
    per_unit = point_units(base).per_unit  # (a shaft's coordinate: L / its radius in rad per unit)
    scales = {name: per_unit[name] / L for name in kinds if name in per_unit}
    missing = [s for s in system.state_names if s not in kinds]
    if missing:
        raise GearsymError(f"{nd.name}: the states {', '.join(missing)} are no coupling's coordinate or rate, so "
                           "the FMU cannot give them SI units")
    meshes = [c for c in drivetrain.couplings if type(c).__name__ == "Mesh"]
    stiffness = {}
    for mesh in meshes:
        own = _si(inputs, getattr(mesh, "stiffness", None))
        if own is None:
            raise GearsymError(f"{nd.name}: the stiffness of mesh {mesh.name!r} must be a physical value (e.g. "
                               "stiffness='kZ' with kZ in N/m) for the FMU's mesh forces in N")
        stiffness[mesh.name] = own / engine_mean_stiffness(system, mesh.name, engine)
    damping = {c.name: c.damping for c in meshes if isinstance(c.damping, str) and c.damping in inputs}
    return Frame(True, T, L, "omega", tuple(parameters), engine_base, kinds, stiffness, damping,
                 units=_OWN, displays=_DISPLAYS, scales=scales)


def engine_mean_stiffness(system, mesh: str, values: Mapping[str, float]) -> float:
    """The mean over the system's period of a mesh's stiffness in the engine (1 for the first mesh: the time
    unit's condition; K2, its mean relative to the first's, for a second): sampled at 4096 points, which is its
    exact mean for any series of fewer harmonics."""
    import sympy as sp

    coupling = next(c for c in system.couplings if c.name == mesh)
    numbers = {s: values[s.name] for s in sp.sympify(coupling.stiffness, strict=True).free_symbols if s.name in values}
    k = sp.lambdify(system.time, sp.sympify(coupling.stiffness, strict=True).xreplace(numbers), "numpy")
    tau = np.linspace(0.0, float(system.period_at(values)), 4096, endpoint=False)
    return float(np.mean(np.broadcast_to(np.asarray(k(tau), dtype=float), tau.shape)))


def _si(inputs, name) -> float | None:
    return inputs[name].si if isinstance(name, str) and name in inputs else None


def _terms(nd, length_scale, physical, name, q, engine, T, L) -> tuple[list[Term], dict] | None:
    """How the physical value ``name`` (now ``q``) enters the engine's values, measured on the scaling: its
    terms, and the engine's values at the terms' reference (see the module's docstring); no terms: fixed; None:
    it moves nothing at all (not part of the model's equations)."""
    si = q.si
    one = measure(f"1 {q.unit}" if q.unit else 1.0, name)
    probes = (q.with_si(si * 2), q.with_si(si * 3)) if si != 0 else (one, one.with_si(one.si * 2))
    factors = (2.0, 3.0) if si != 0 else (1.0, 2.0)
    seen = []
    for probe in probes:
        try:
            s = Scaling.of(nd, length_scale, **{**physical, name: probe})
            values = {k: v for k, v in s.values.items() if k in engine}
            units = (float(s.time.to("s").magnitude), float(s.length.to("m").magnitude))
        except GearsymError:
            return [], {}
        if not all(math.isclose(a, b, rel_tol=TOLERANCE) for a, b in zip(units, (T, L))) or set(values) != set(engine):
            return [], {}
        seen.append(values)
    moved = [k for k in engine if not all(math.isclose(v[k], engine[k], rel_tol=TOLERANCE, abs_tol=0) for v in seen)]
    if not moved:
        return None
    terms, at = [], {}
    for k in moved:
        if si != 0:  # engine value x factor ** power at both probes
            ratios = [v[k] / engine[k] if engine[k] != 0 else math.nan for v in seen]
            power = next((a for a in POWERS if all(math.isclose(r, f ** a, rel_tol=TOLERANCE)
                                                   for r, f in zip(ratios, factors))), None)
            reference = si
        else:  # 0 now, c x value ** power: from one unit
            first, second = seen[0][k], seen[1][k]
            power = next((a for a in POWERS if a > 0 and engine[k] == 0 and first != 0
                          and math.isclose(second / first, 2.0 ** a, rel_tol=TOLERANCE)), None)
            reference, at[k] = one.si, first
        if power is None:
            return [], {}
        terms.append(Term(k, power, reference))
    return terms, at


def _unit(q: Measure) -> tuple[Unit | None, str | None]:
    """The SI unit of a value's dimension, with the unit it was given in as display unit."""
    exponents = tuple(int(e) for e in q.dims)
    if any(float(e) != d for e, d in zip(exponents, q.dims)):
        raise GearsymError(f"{q} has a dimension an FMU unit is not made of here (whole powers of mass, length "
                           "and time)")
    if not any(exponents):
        return None, None
    name = _NAMES.get(exponents) or ".".join(f"{b}{e if e != 1 else ''}" for b, e in zip(("kg", "m", "s"), exponents)
                                             if e)
    base = tuple((b, e) for b, e in zip(("kg", "m", "s"), exponents) if e)
    if name == "rad/s":
        base += (("rad", 1),)
    display = _display(q.unit)
    factor = 1.0 / si_factor(q.unit) if q.unit else 1.0
    if not q.unit or display == name or math.isclose(factor, 1.0, rel_tol=1e-12):  # (given in the SI unit itself)
        return Unit(name, base), None
    return Unit(name, base, ((display, factor),)), display


def _display(unit: str) -> str:
    """A unit as modelDescription.xml spells it (ASCII: um, N.m, kg.m2)."""
    return f"{Quantity(1, unit).units:~C}".replace("µ", "u").replace("**", "")
