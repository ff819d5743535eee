"""The drivetrain at rest under its mean loads: the reduced equations' static solution against the unreduced
Lagrange equations solved by SciPy, for every shipped topology (chains, trees, loops) and a motor-coupling-gear
train; the length unit of a physical model is that static deflection; unbalanced mean torques are refused.

The reference here is written independently: Lagrange's equations of the declared drivetrain (in the body
angles, before any reduction) with every rate and acceleration zero, every harmonic zero and every mesh at its
mean stiffness, solved by ``scipy.optimize.least_squares`` with the rigid-body rotations pinned; the
deflections are then ``C_c psi`` of each coupling.
"""
from __future__ import annotations

import math
import random
import re

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import least_squares

import gearsym
from conftest import load
from gearsym import Disk, Drivetrain, Gear, Mesh, Shaft, Torque
from gearsym.errors import ModelError
from gearsym.reduction.statics import static_state, torque_imbalance
from gearsym.model.symbols import parameter_symbol, phi, t

DRIVETRAINS = ("one_stage", "one_stage_resonant", "flexible_shaft", "two_stage", "planetary",
               "planetary_differential", "planetary_two_stage", "spur_pair")


def motor_coupling_gear() -> Drivetrain:
    """Motor disk -> coupling shaft -> pinion 23 T -> mesh -> wheel 61 T -> shaft -> load disk (the issue's)."""
    m = Drivetrain("motor_coupling_gear")
    motor = m.add(Disk("motor", inertia="Im"))
    pinion = m.add(Gear("pinion", inertia="I1", base_radius="r1", teeth=23, speed="speed"))
    wheel = m.add(Gear("wheel", inertia="I2", base_radius="r2", teeth=61))
    load_disk = m.add(Disk("load", inertia="IL"))
    m.add(Shaft("coupling", motor, pinion, stiffness="kc", coordinate="xc"))
    m.add(Mesh("mesh", pinion, wheel, stiffness="kZ", damping="cZ", backlash="eta", coordinate="x"))
    m.add(Shaft("output", wheel, load_disk, stiffness="ko", coordinate="xo"))
    m.add(Torque("M1", on=motor, mean="M1"))
    m.add(Torque("M3", on=load_disk, mean="M3", load=True))
    r1 = 32.42e-3
    m.set_physical(Im="0.05 kg*m^2", I1="4e-4 kg*m^2", I2="2e-2 kg*m^2", IL="0.3 kg*m^2", r1=f"{r1 * 1e3} mm",
                   r2=f"{r1 * 61 / 23 * 1e3:.12g} mm", kc="1e5 N*m/rad", ko="4e5 N*m/rad", kZ="2e8 N/m",
                   cZ="600 N*s/m", eta="50 um", M1="100 N*m", M3="265.2 N*m", k_a=0.2, speed="3000 rpm")
    m.set_length_scale("static")
    return m


def _values(model: Drivetrain, seed: int) -> dict[str, float]:
    """Random positive values for every parameter of the drivetrain's fields, harmonics zero, torques balanced
    (rigid-body modes and the torque balance of unforced shafts: Eq. 10), variations at their declared defaults."""
    rd = model.resolved
    rng = random.Random(seed)
    names = set()
    for rb in rd.bodies:
        names |= {s.name for s in rb.inertia.free_symbols} | ({s.name for s in rb.radius.free_symbols} if rb.radius is not None else set())
    for rc in rd.couplings:
        for e in (rc.stiffness, rc.damping, rc.backlash, *rc.row):
            names |= {s.name for s in sp.sympify(e).free_symbols}
    torque_names = [s.name for f in rd.forcing if f.order == 0 for s in f.amplitude.free_symbols]
    names |= set(torque_names)
    values = {n: rng.uniform(0.5, 2.0) for n in sorted(names)}
    declared = {**model.defaults, **{k: v.si for k, v in model.physical.items()}}
    for rc in rd.couplings:  # the variation's parameters (k_a ...) and the radii of gears with teeth at theirs
        for s in rc.variation.free_symbols - {phi}:
            values[s.name] = float(declared.get(s.name, 0.2))
    for rb in rd.bodies:
        if rb.radius is not None and rb.body.tooth_count:
            values.update({s.name: float(declared[s.name]) for s in rb.radius.free_symbols if s.name in declared})
    for f in rd.forcing:
        if f.order:
            values.update({s.name: 0.0 for s in f.amplitude.free_symbols})
    nd = gearsym.reduce(model)
    equations = [c.equation.lhs - c.equation.rhs for c in nd.conditions if c.kind == "torque_balance"]
    red = nd.reduction
    for u in red.rigid_modes:
        equations.append(sum(u[f.body.index] * f.amplitude for f in rd.forcing if f.order == 0))
    unknown = [parameter_symbol(n) for n in reversed(torque_names)][:len(equations)]
    known = {parameter_symbol(k): v for k, v in values.items() if parameter_symbol(k) not in unknown}
    solved = sp.solve([sp.sympify(e).xreplace(known) for e in equations], unknown, dict=True)
    assert solved, "the torques cannot be balanced"
    values.update({s.name: float(v) for s, v in solved[0].items()})
    return values


def _unreduced_deflections(model: Drivetrain, values: dict[str, float]) -> dict[str, float]:
    """Lagrange's equations at rest (rates and accelerations zero, mean stiffness) solved by SciPy."""
    rd = model.resolved
    subs = {parameter_symbol(k): v for k, v in values.items()}
    n = len(rd.bodies)
    psi = sp.symbols(f"p0:{n}", real=True)
    at_rest = {}
    for rb, p in zip(rd.bodies, psi):
        at_rest[sp.Derivative(rb.angle, (t, 2))] = 0
        at_rest[sp.Derivative(rb.angle, t)] = 0
    angles = {rb.angle: p for rb, p in zip(rd.bodies, psi)}
    means = {}
    for rc in rd.couplings:
        if rc.kind == "mesh":
            samples = np.linspace(0, 2 * np.pi, 2048, endpoint=False)
            shape = sp.lambdify(phi, rc.variation.xreplace(subs), "numpy")(samples)
            means[rd.stiffness_at(rc)] = float(rc.stiffness.xreplace(subs)) * float(np.mean(np.ones(2048) * shape))
    residual = []
    for eq in rd.equations_of_motion:
        e = (eq.lhs - eq.rhs).xreplace(at_rest).xreplace(means).xreplace(angles)
        e = e.xreplace(subs).subs(t, 0.123)  # (harmonics are zero: time enters nowhere else)
        residual.append(e.rewrite(sp.Piecewise))
    f = sp.lambdify([psi], residual, "numpy")
    modes = [np.array([float(x.xreplace(subs)) for x in u]) for u in gearsym.reduce(model).reduction.rigid_modes]
    scale = max(abs(values[n]) for n in values) or 1.0
    rows = [np.array([float(e.xreplace(subs)) for e in rc.row]) for rc in rd.couplings]

    def fun(p):
        return np.concatenate([np.asarray(f(p), dtype=float) / scale, [m @ p for m in modes]])

    # from the teeth in contact everywhere (g(x) = x: a linear solve), then every flank as it is
    linear = sp.lambdify([psi], [e.replace(lambda a: isinstance(a, sp.Piecewise), lambda a: a.args[0][0])
                                 for e in residual], "numpy")
    jac = np.array([np.asarray(linear(np.eye(n)[k]), dtype=float) - np.asarray(linear(np.zeros(n)), dtype=float)
                    for k in range(n)]).T
    start = np.linalg.lstsq(np.vstack([jac, *modes]), np.concatenate([-np.asarray(linear(np.zeros(n)), dtype=float),
                                                                        np.zeros(len(modes))]), rcond=None)[0]
    solution = least_squares(fun, start, xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm")
    assert np.max(np.abs(fun(solution.x))) < 1e-10
    out = {}
    for rc, row in zip(rd.couplings, rows):
        out[rc.name] = float(row @ solution.x) * (float(rc.scale.xreplace(subs)) if rc.kind == "shaft" else 1.0)
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", DRIVETRAINS)
def test_the_static_solution_of_the_reduced_equations_is_that_of_lagranges(name):
    model = load(name)
    for seed in (1, 2):
        values = _values(model, seed)
        ours = static_state(gearsym.reduce(model).reduction, values).deflections
        theirs = _unreduced_deflections(model, values)
        for coupling, d in theirs.items():
            assert ours[coupling] == pytest.approx(d, rel=1e-8, abs=1e-12 * max(map(abs, theirs.values()))), \
                (name, seed, coupling)
        assert not torque_imbalance(gearsym.reduce(model).reduction, values)


def test_a_motor_coupling_gear_train_rests_at_its_mesh_force_over_its_stiffness():
    model = motor_coupling_gear()
    s = gearsym.scaling(model)
    force = 100 / 32.42e-3  # the motor's torque reaches the pinion whole: F = M1/r1 = 3084.5 N
    # (265.2 N m balances 100 N m through 23/61 to 6e-5: what is left accelerates the train, and the pinion's
    # share of it takes as much of the mesh force)
    assert s.static_deflection.to("um").magnitude == pytest.approx(force / 2e8 * 1e6, rel=1e-4)  # 15.4 um
    assert s.length.to("um").magnitude == pytest.approx(15.4226, rel=1e-4)
    assert s.statics.mesh_forces["mesh"] == pytest.approx(force, rel=1e-4)
    values = {**{k: v.si for k, v in s.inputs.items()}, "M3": 100 * 61 / 23}  # exactly balanced, for Lagrange
    theirs = _unreduced_deflections(model, values)
    assert static_state(s.model.reduction, values).deflections == pytest.approx(theirs, rel=1e-8)


def test_the_length_unit_does_not_move_the_start_or_the_answer():
    base = gearsym.scaling("spur_pair")
    other = gearsym.scaling("spur_pair", "backlash")
    x0 = base.initial["x"] * base.length_si
    assert other.initial["x"] * other.length_si == pytest.approx(x0, rel=1e-12)  # the same metres
    assert x0 == pytest.approx(base.static_deflection_si, rel=1e-12)  # spur_pair starts at its static deflection


@pytest.mark.parametrize("settings, balancing", [
    ({"M3": "0 N*m"}, r"M3 = 265\.217 N·m on 'load'"),
    ({"M1": "50 N*m"}, r"M1 = 99\.993\d* N·m on 'motor' or M3 = 132\.609 N·m on 'load'"),
])
def test_unbalanced_mean_torques_are_refused_with_the_torque_that_balances_them(settings, balancing):
    with pytest.raises(ModelError, match=r"the mean torques do not balance") as err:
        gearsym.scaling(motor_coupling_gear(), **settings)
    assert "N·m" in str(err.value)
    assert re.search(balancing, str(err.value)), str(err.value)


def test_a_model_whose_first_mesh_carries_no_load_says_so_but_still_derives():
    model = motor_coupling_gear()
    model.set_physical(M1="0 N*m", M3="0 N*m")
    with pytest.raises(gearsym.GearsymError, match=r"static deflection of mesh 'mesh' under the mean load is 0 µm "
                                                   r"\(the mesh carries no mean load\)"):
        gearsym.scaling(model).length
    page = gearsym.render(gearsym.derive(model), "markdown")
    assert "L | none: the static deflection" in page
    assert math.isfinite(gearsym.scaling(model, "backlash").values["B0"])
