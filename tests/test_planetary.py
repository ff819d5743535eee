"""Planetary gear sets (closed kinematic loops): the reduction against the unreduced Lagrange equations, which
coupling closes a loop, mesh phasing and the classes of natural modes of equally spaced planets.

The independent check is typed here: the Lagrange equations of the sun, the carrier and the planets in their
absolute rotations (Lin & Parker's rotational model, ring held), integrated in SciPy next to the reduced
equations, which SciPy integrates too (the engine is checked against SciPy elsewhere).
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import sympy as sp

import gearsym
from conftest import reduced, system
from gearsym import Disk, Drivetrain, Gear, Harmonic, Mesh, ModelError, Planet, Torque
from gearsym import natural_modes
from gearsym.model.symbols import parameter_symbol, tau

TEETH = dict(sun=26, ring=94)
PLANETS = 3
#: component values of the test set (nondimensional); kZ, cZ, kZ_r, cZ_r follow from the time unit below
COMPONENTS = dict(I_s=2.0, I_p=1.5, I_c=12.0, r_s=1.3, r_p=1.7, r_r=4.7, eta=0.4, kv=0.3, M_s=3.0, M_a=1.5,
                  M_c=14.0, Theta=0.2)
OMEGA = 0.8


@functools.cache  # one drivetrain (and so one reduction) per order; tests must not change it
def planetary_set(ring_meshes_first: bool = False) -> Drivetrain:
    """Three planets with the ring held, each mesh with stiffness 1 + kv cos(phi) and backlash eta."""
    m = Drivetrain("test_planetary")
    sun = m.add(Gear("sun", inertia="I_s", base_radius="r_s", teeth=TEETH["sun"]))
    ring = m.add(Gear("ring", base_radius="r_r", teeth=TEETH["ring"], internal=True, fixed=True))
    carrier = m.add(Disk("carrier", inertia="I_c"))
    planets = [m.add(Planet(f"p{n + 1}", inertia="I_p", base_radius="r_p", carrier=carrier,
                            position=2 * sp.pi * n / PLANETS)) for n in range(PLANETS)]
    sun_meshes = [Mesh(f"s{n + 1}", sun, p, variation="1 + kv*cos(phi)", coordinate=f"x{n + 1}", damping_group="zeta")
                  for n, p in enumerate(planets)]
    ring_meshes = [Mesh(f"r{n + 1}", ring, p, stiffness="kZ_r", damping="cZ_r", variation="1 + kv*cos(phi)",
                        coordinate=f"y{n + 1}", damping_group="zeta_r", stiffness_group="K_r")
                   for n, p in enumerate(planets)]
    for mesh in (ring_meshes + sun_meshes if ring_meshes_first else sun_meshes + ring_meshes):
        m.add(mesh)
    m.add(Torque("M_s", on=sun, mean="M_s", harmonics=(Harmonic("M_a", phase="Theta", group="B1"),)))
    m.add(Torque("M_c", on=carrier, mean="M_c", load=True))
    return m


def stiffnesses() -> dict[str, float]:
    """kZ and kZ_r with the time-unit condition for either mesh declared first (a mesh's r^2/I along its line
    times its stiffness is 1), and damping of 4 % of critical."""
    c = COMPONENTS
    sun_line = c["r_s"] ** 2 / c["I_s"] + c["r_p"] ** 2 / c["I_p"] + (c["r_s"] + c["r_p"]) ** 2 / c["I_c"]
    ring_line = c["r_p"] ** 2 / c["I_p"] + (c["r_r"] - c["r_p"]) ** 2 / c["I_c"]
    return dict(kZ=1 / sun_line, kZ_r=1 / ring_line, cZ=0.08 / sun_line, cZ_r=0.08 / ring_line)


def reduced_rhs(model: Drivetrain):
    """The reduced first-order system at the test values, as a NumPy function of (tau, y), and its states."""
    nd = gearsym.reduce(model)
    physical = {**COMPONENTS, **stiffnesses()}
    at = {parameter_symbol(k): v for k, v in physical.items()}
    values = {gr.name: float(gr.definition.xreplace(at)) for gr in nd.groups if gr.kind == "free"}
    system = nd.system(**values, omega=OMEGA, **{k: v for k, v in physical.items() if k in nd.parameter_names})
    symbols = [tau, *system.states, *system.parameter_symbols]
    backlash = {"g": lambda x, eta: x if x >= 0 else (x + eta if x <= -eta else 0.0)}
    f = sp.lambdify(symbols, list(system.rhs), modules=[backlash, "math"])
    p = [system.parameters[s.name] for s in system.parameter_symbols]
    return (lambda s, y: f(s, *y, *p)), system


def lagrange_rhs():
    """The unreduced equations in the absolute angles (sun, carrier, planets), typed here, in the time t."""
    c, k = COMPONENTS, stiffnesses()
    positions = [2 * math.pi * n / PLANETS for n in range(PLANETS)]

    def g(x):
        return x if x >= 0 else (x + c["eta"] if x <= -c["eta"] else 0.0)

    def rhs(t, y):
        (s, car, *p), (ws, wc, *wp) = y[:2 + PLANETS], y[2 + PLANETS:]
        torque_s = c["M_s"] + c["M_a"] * math.cos(OMEGA * t + c["Theta"])
        acc_p, torque_c = [], -c["M_c"]
        for n in range(PLANETS):
            # Parker & Lin: a planet at psi_n meshes with the sun's teeth psi_n behind (-Z_s psi_n) and the ring's
            # psi_n ahead (+Z_r psi_n), the sun turning forward and the ring backward relative to the carrier
            d_s = c["r_s"] * s - c["r_p"] * p[n] - (c["r_s"] + c["r_p"]) * car
            v_s = c["r_s"] * ws - c["r_p"] * wp[n] - (c["r_s"] + c["r_p"]) * wc
            d_r = c["r_p"] * p[n] - (c["r_r"] - c["r_p"]) * car
            v_r = c["r_p"] * wp[n] - (c["r_r"] - c["r_p"]) * wc
            f_s = k["kZ"] * (1 + c["kv"] * math.cos(OMEGA * t - TEETH["sun"] * positions[n])) * g(d_s) + k["cZ"] * v_s
            f_r = k["kZ_r"] * (1 + c["kv"] * math.cos(OMEGA * t + TEETH["ring"] * positions[n])) * g(d_r) \
                + k["cZ_r"] * v_r
            torque_s -= c["r_s"] * f_s
            torque_c += (c["r_s"] + c["r_p"]) * f_s + (c["r_r"] - c["r_p"]) * f_r
            acc_p.append(c["r_p"] * (f_s - f_r) / c["I_p"])
        return [ws, wc, *wp, torque_s / c["I_s"], torque_c / c["I_c"], *acc_p]

    def deflections(y):
        s, car, *p = y[:2 + PLANETS]
        return {**{f"s{n + 1}": c["r_s"] * s - c["r_p"] * p[n] - (c["r_s"] + c["r_p"]) * car for n in range(PLANETS)},
                **{f"r{n + 1}": c["r_p"] * p[n] - (c["r_r"] - c["r_p"]) * car for n in range(PLANETS)}}

    return rhs, deflections


#: initial angles (sun, carrier, planets) and rates: the meshes start apart by up to twice the backlash
PSI0 = [0.9, 0.05, -0.4, 0.3, 0.1]
RATE0 = [0.0, 0.1, 0.5, -0.3, 0.2]
T_END = 40.0


def reduced_deflections(model: Drivetrain, t: np.ndarray) -> dict[str, np.ndarray]:
    """Every mesh's deflection along the reduced model's trajectory from the angles PSI0, RATE0."""
    from scipy.integrate import solve_ivp

    f, system = reduced_rhs(model)
    _, lagrange_deflections = lagrange_rhs()
    x0, rate0 = lagrange_deflections(PSI0), lagrange_deflections(np.concatenate([RATE0, RATE0]))
    y0 = []
    for c in system.couplings:
        if not c.closes_loop:
            y0 += [x0[c.name], rate0[c.name] / OMEGA]  # velocities are d/dtau = (d/dt)/omega
    sol = solve_ivp(f, (0.0, OMEGA * t[-1]), y0, method="DOP853", t_eval=OMEGA * t, rtol=1e-9, atol=1e-11)
    states = dict(zip((s.name for s in system.states), sol.y))
    out = {}
    for c in system.couplings:
        contact = sp.lambdify([sp.Symbol(n, real=True) for n in states], c.contact, "numpy")
        out[c.name] = np.asarray(contact(*states.values())) * np.ones_like(t)
    return out


@pytest.fixture(scope="module")
def lagrange():
    from scipy.integrate import solve_ivp

    rhs, deflections = lagrange_rhs()
    t = np.linspace(0.0, T_END, 1201)
    sol = solve_ivp(rhs, (0.0, T_END), PSI0 + RATE0, method="DOP853", t_eval=t, rtol=1e-9, atol=1e-11)
    return t, deflections(sol.y)


def test_every_mesh_deflection_of_the_reduced_planetary_set_follows_the_unreduced_lagrange_equations(lagrange):
    t, expected = lagrange
    got = reduced_deflections(planetary_set(), t)
    scale = max(np.max(np.abs(v)) for v in expected.values())
    eta = COMPONENTS["eta"]
    assert any(np.any((v > -eta) & (v < 0)) for v in expected.values())  # contact is lost along the way
    assert any(np.any(v < -eta) for v in expected.values()) and any(np.any(v > 0) for v in expected.values())
    for name in expected:
        assert np.max(np.abs(got[name] - expected[name])) < 1e-6 * scale, name


def test_declaring_the_ring_meshes_first_closes_the_loops_elsewhere_but_gives_the_same_mesh_deflections(lagrange):
    t, expected = lagrange
    model = planetary_set(ring_meshes_first=True)
    red = gearsym.reduce(model).reduction
    assert [c.name for c in red.coordinates] == ["y1", "y2", "y3", "x1"]
    assert [d.name for d in red.dependent] == ["x2", "x3"]
    got = reduced_deflections(model, t)
    scale = max(np.max(np.abs(v)) for v in expected.values())
    for name in expected:
        assert np.max(np.abs(got[name] - expected[name])) < 1e-6 * scale, name


def test_each_loop_closing_deflection_is_the_combination_the_kinematics_give():
    red = gearsym.reduce(planetary_set()).reduction
    x1, x2, x3, y1 = (sp.Symbol(n, real=True) for n in ("x1", "x2", "x3", "y1"))
    combos = {d.name: d.in_states()[0] for d in red.dependent}
    # y_n - y_1 = r_p (psi_n - psi_1) = x_1 - x_n: the planets differ only in their own angle
    assert combos == {"y2": x1 - x2 + y1, "y3": x1 - x3 + y1}


def test_a_planets_mesh_phase_follows_its_position_and_the_central_gears_teeth():
    phases = {rc.name: rc.planet_phase for rc in planetary_set().resolved.couplings}
    # -Z_s psi_n for the sun, +Z_r psi_n for the ring (mod 2 pi): 26 * 2 pi/3 and 94 * 2 pi/3
    assert phases == {"s1": 0, "s2": 2 * sp.pi / 3, "s3": 4 * sp.pi / 3, "r1": 0, "r2": 2 * sp.pi / 3,
                      "r3": 4 * sp.pi / 3}


def test_a_planet_that_cannot_be_assembled_between_sun_and_ring_is_refused():
    m = Drivetrain("misplaced")
    sun = m.add(Gear("sun", inertia="I_s", base_radius="r_s", teeth=26))
    ring = m.add(Gear("ring", base_radius="r_r", teeth=94, internal=True, fixed=True))
    carrier = m.add(Disk("carrier", inertia="I_c"))
    p = m.add(Planet("p1", inertia="I_p", base_radius="r_p", carrier=carrier, position="pi/7"))
    m.add(Mesh("s1", sun, p))
    m.add(Mesh("r1", ring, p))
    with pytest.raises(ModelError, match=r"Planet 'p1': cannot be assembled at pi/7 rad.*360/\(Z_sun \+ Z_ring\) = 3 "):
        m.resolved


@functools.cache
def planets_of(count: int, ring_fixed: bool = True) -> gearsym.NondimensionalModel:
    """The shipped planetary set with ``count`` planets (models/planetary.py's build), reduced once a session."""
    if count == 3 and ring_fixed:
        return reduced("planetary")
    from models.planetary import build

    return gearsym.reduce(build(count, ring_fixed=ring_fixed))


@pytest.mark.parametrize("planets", [3, 4, 5])
@pytest.mark.slow
def test_equally_spaced_planets_give_rotational_modes_and_planet_modes_of_multiplicity_n_minus_1(planets):
    modes = natural_modes(planets_of(planets)).elastic
    planet_modes = [m for m in modes if m.multiplicity == planets - 1]
    rotational = [m for m in modes if m.multiplicity == 1]
    assert len(rotational) == 2 and len(planet_modes) == planets - 1 and len(modes) == planets + 1
    for mode in planet_modes:  # the sun and the carrier at rest (the ring is held), the planets opposed
        assert abs(mode.angles["sun"]) < 1e-9 and abs(mode.angles["carrier"]) < 1e-9
        assert abs(sum(mode.angles[f"planet{n + 1}"] for n in range(planets))) < 1e-9
    for mode in rotational:  # every planet moves alike
        assert np.ptp([mode.angles[f"planet{n + 1}"] for n in range(planets)]) < 1e-9


@pytest.mark.slow
def test_a_repeated_frequencys_modes_are_the_same_whatever_basis_lapack_returns(monkeypatch):
    """Any basis of the planet modes' plane is right, and another BLAS kernel (another CPU) returns another:
    docs/planetary.md's listing changed on an AMD EPYC. The modes shown are the plane's reduced row echelon
    basis, so a rotated eigenbasis gives the same shapes."""
    model = planets_of(4)
    plain = natural_modes(model)
    eigh = np.linalg.eigh
    turn = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]

    def rotated(matrix):  # the planet modes' three vectors turned within their space
        values, vectors = eigh(matrix)
        tied = [i for i in range(len(values)) if np.sum(np.isclose(values, values[i], rtol=1e-8)) == 3]
        vectors[:, tied] = vectors[:, tied] @ turn
        return values, vectors

    monkeypatch.setattr(np.linalg, "eigh", rotated)
    turned = natural_modes(model)
    assert [m.multiplicity for m in turned.modes] == [1, 1, 3, 3, 3, 1]
    for a, b in zip(plain.modes, turned.modes):
        assert a.frequency == pytest.approx(b.frequency, rel=1e-12)
        assert [a.angles[k] for k in a.angles] == pytest.approx([b.angles[k] for k in a.angles], abs=1e-9)
    planet = [m.angles[f"planet{n}"] for m in turned.modes if m.multiplicity == 3 for n in range(1, 5)]
    assert planet == pytest.approx([1, 0, 0, -1, 0, 1, 0, -1, 0, 0, 1, -1], abs=1e-9)


@pytest.mark.parametrize("model, planets, rigid, central", [
    ("differential with 4 planets", 4, 2, ("sun", "ring", "carrier")),
    ("planetary_two_stage", 3, 1, ("sun", "carrier", "pinion", "wheel")),
])
@pytest.mark.slow
def test_a_free_ring_or_a_driven_parallel_stage_keeps_the_planet_modes_with_every_other_body_at_rest(
        model, planets, rigid, central):
    modes = natural_modes(planets_of(planets, ring_fixed=False) if model.startswith("differential") else reduced(model))
    assert sum(m.kind == "rigid" for m in modes.modes) == rigid
    planet_modes = [m for m in modes.elastic if m.multiplicity == planets - 1]
    assert len(planet_modes) == planets - 1
    for mode in planet_modes:
        assert max(abs(mode.angles[b]) for b in central) < 1e-9


def test_an_effect_asked_for_a_loop_closing_mesh_is_refused_naming_the_meshes_with_coordinates():
    from gearsym.fit.effects import site

    with pytest.raises(ModelError, match=r"no mesh force g\(x, eta\) acting on coordinate 'y2' \(meshes.* act on "
                                         r"x1, x2, x3, y1\)"):
        site(system("planetary"), "mesh", "y2")


def _with(declare) -> Drivetrain:
    """A sun, a held ring, a carrier and one planet, changed by ``declare(m, sun, ring, carrier)``."""
    m = Drivetrain("bad")
    sun = m.add(Gear("sun", inertia="I_s", base_radius="r_s"))
    ring = m.add(Gear("ring", base_radius="r_r", internal=True, fixed=True))
    carrier = m.add(Disk("carrier", inertia="I_c"))
    declare(m, sun, ring, carrier)
    return m


@pytest.mark.parametrize("declare, message", [
    (lambda m, s, r, c: (m.add(Planet("p", base_radius="r_p", carrier=c, fixed=True)), m.add(Mesh("m", s, "p"))),
     r"Planet 'p': a planet cannot be fixed; fix its carrier instead"),
    (lambda m, s, r, c: (m.add(Planet("p", inertia="I_p", base_radius="r_p")), m.add(Mesh("m", s, "p"))),
     r"Planet 'p': needs its carrier: Planet\(..., carrier=carrier_body\)"),
    (lambda m, s, r, c: (m.add(Gear("ring2", inertia="I", base_radius="r", internal=True)), m.add(Mesh("m", r, "ring2"))),
     r"Mesh 'm': joins two ring gears"),
    (lambda m, s, r, c: (m.add(Planet("p", inertia="I_p", base_radius="r_p", carrier=c)), m.add(Mesh("m", s, "p")),
                         m.add(Mesh("n", r, "p")), m.add(Torque("T", on=r, mean="M"))),
     r"Torque 'T': acts on 'ring', which is fixed"),
    (lambda m, s, r, c: (m.add(Planet("p", inertia="I_p", base_radius="r_p", carrier=c, position="pi/2")),
                         m.add(Mesh("m", s, "p")), m.add(Mesh("n", r, "p"))),
     r"Mesh 'm': planet 'p' sits at pi/2, so the mesh phase needs the teeth of 'sun'"),
])
def test_a_planetary_declaration_that_cannot_work_is_refused_in_one_line(declare, message):
    with pytest.raises(ModelError, match=message):
        _with(declare).resolved


def test_derive_json_lists_each_loop_closing_deflection_with_its_combination(capsys):
    import json

    from gearsym.cli import main

    assert main(["derive", "planetary", "--format", "json"]) == 0
    closing = json.loads(capsys.readouterr().out)["closing"]
    assert [(c["name"], c["coupling"], c["combination"]) for c in closing] == [
        ("y2", "ring_planet2", "x1 - x2 + y1"), ("y3", "ring_planet3", "x1 - x3 + y1")]


def test_the_modes_table_keeps_its_columns_apart_and_prints_rounding_as_zero(capsys):
    """It ran columns together ('elastic x2-1.099e-16 2.192e-16') and printed 1e-16 where the docs say 0."""
    from gearsym.cli import main

    assert main(["modes", "planetary"]) == 0
    header, *rows = [line for line in capsys.readouterr().out.splitlines()
                     if "|" in line and not line.startswith("shapes")]
    names = header.split("|")[0].split()[2:] + header.split("|")[1].split()
    for row in rows:
        left, right = row.split("|")
        cells = left.split()[1:] + right.split()  # (after the frequency)
        kind_words = 2 if "x2" in cells[:2] else 1
        values = cells[kind_words:]
        assert len(values) == len(names), f"columns run together: {row!r}"
        assert not any("e-1" in v for v in values), f"rounding printed as a number: {row!r}"
    planet_mode = next(r for r in rows if "elastic x2" in r).split("|")[0].split()
    assert planet_mode[3:5] == ["0", "0"]  # the sun and the carrier at rest
    from gearsym.cli.modes import shown, table_row

    wide = [shown(-1.2345678e-5)] * 3  # ten characters each
    assert table_row("0  rigid", wide, wide).split() == ["0", "rigid", *wide, "|", *wide]


def test_model_module_gives_a_shipped_models_builder_wherever_gearsym_runs(tmp_path, monkeypatch):
    """planetary.md's `from models.planetary import build` fails outside the clone."""
    monkeypatch.chdir(tmp_path)
    planetary = gearsym.model_module("planetary")
    assert callable(planetary.build) and planetary.model is gearsym.load_model("planetary")
    with pytest.raises(gearsym.GearsymError, match="takes the name of a model"):
        gearsym.model_module("models/planetary.py")
