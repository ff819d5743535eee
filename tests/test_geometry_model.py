"""Gears declared from their geometry in the symbolic model (issue 27, phase 2): ``Gear.from_geometry`` and
``Mesh.from_gears``.

The independent checks are written here: the gear body's inertia by the disk-with-bore formula; the stiffness
curve's mean and Fourier coefficients by SciPy's adaptive quadrature of the curve itself (``MeshStiffness.at``, with
its jumps as break points), not by the path-of-contact integrals the model's coefficients come from; the error of
the series in the model by Parseval's identity; a pair declared from its geometry runs derive -> compile ->
lyap, sweep and orbits in physical units, with its natural frequency and mean mesh force from the formulas.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import quad, quad_vec

import gearsym
from conftest import reduced
from gearsym import Drivetrain, Gear, Integration, Mesh, ModelError, Torque
from gearsym.geometry import gear_geometry
from gearsym.model.symbols import phi

STEEL_DENSITY = 7850.0  # kg/m^3

# a pair of the test's own: 30/60 teeth, module 2 mm, 20 deg, 12 mm face, profile shifts, bores 20 and 30 mm
PINION = dict(teeth=30, module="2 mm", pressure_angle="20 deg", face_width="12 mm", profile_shift=0.2,
              bore_diameter="20 mm")
WHEEL = dict(teeth=60, module="2 mm", pressure_angle="20 deg", face_width="12 mm", profile_shift=-0.1,
             bore_diameter="30 mm")


def disk_with_bore(teeth, module, pressure_angle_deg, face_width, shift, bore, addendum=1.0, dedendum=1.25):
    """ISO 6336-1's gear body, typed here: a disk of the mean of tip and root diameters less the bore, in SI."""
    d = teeth * module
    d_tip, d_root = d + 2 * module * (addendum + shift), d - 2 * module * (dedendum - shift)
    d_m = (d_tip + d_root) / 2
    inertia = STEEL_DENSITY * math.pi * face_width * (d_m**4 - bore**4) / 32  # integral of r^2 dm over the annulus
    return inertia, d / 2 * math.cos(math.radians(pressure_angle_deg))


def geared_pair(harmonics: int = 7, smoothed: bool = True) -> Drivetrain:
    model = Drivetrain("geared_pair")
    pinion = model.add(Gear.from_geometry("pinion", inertia="I1", base_radius="r1", speed="speed", **PINION))
    wheel = model.add(Gear.from_geometry("wheel", inertia="I2", base_radius="r2", **WHEEL))
    model.add(Mesh.from_gears("mesh", pinion, wheel, harmonics=harmonics, smoothed=smoothed))
    model.add(Torque("M1", on=pinion, mean="M1"))
    model.add(Torque("M2", on=wheel, mean="M2", load=True))
    model.set_physical(cZ="400 N*s/m", eta="80 um", M1="40 N*m", M2="80 N*m", speed="3000 rpm")
    return model


def mesh_of(model: Drivetrain) -> Mesh:
    return next(c for c in model.couplings if isinstance(c, Mesh))


def independent_coefficients(curve, order: int):
    """k / mean's mean square and its cosine and sine coefficients, n = 1 ... order, by SciPy's adaptive quadrature
    of the sampled curve between its jumps (single <-> double contact), and the mean: every integrand at once
    (quad_vec, one adaptive subdivision for all of them, to the same tolerance)."""
    split = 2 * math.pi * (curve.contact_ratio - math.floor(curve.contact_ratio))
    n = np.arange(1, order + 1)

    def integrands(p):
        k = float(curve.at(np.array([p]))[0])
        return np.concatenate([[k, k * k], k * np.cos(n * p), k * np.sin(n * p)])

    total = sum(quad_vec(integrands, a, b, epsabs=0, epsrel=1e-10, limit=2000)[0]
                for a, b in ((0.0, split), (split, 2 * math.pi)))
    mean = total[0] / (2 * math.pi)
    square = total[1] / (2 * math.pi) / mean**2
    return mean, square, total[2:2 + order] / (math.pi * mean), total[2 + order:] / (math.pi * mean)


@pytest.fixture(scope="module")
def spur_mesh():
    return mesh_of(gearsym.load_model("spur_pair"))


@pytest.fixture(scope="module")
def spur_coefficients(spur_mesh):
    return independent_coefficients(spur_mesh.computed.curve, 40)


# ------------------------------------------------------------------ the gear body
def test_the_inertia_from_geometry_is_a_disk_with_its_bore():
    model = geared_pair()
    for name, radius, gear in (("I1", "r1", PINION), ("I2", "r2", WHEEL)):
        inertia, base = disk_with_bore(gear["teeth"], 2e-3, 20.0, 12e-3, gear["profile_shift"],
                                       float(gear["bore_diameter"].split()[0]) * 1e-3)
        assert model.physical[name].si == pytest.approx(inertia, rel=1e-9)
        assert model.physical[radius].si == pytest.approx(base, rel=1e-9)
    # spur_pair's gears: 28 teeth, 3.175 mm, 20 deg, 6.35 mm face, 20 mm bore
    inertia, base = disk_with_bore(28, 3.175e-3, 20.0, 6.35e-3, 0.0, 20e-3)
    spur = gearsym.load_model("spur_pair").physical
    assert spur["I1"].si == spur["I2"].si == pytest.approx(inertia, rel=1e-9)
    assert spur["r1"].si == pytest.approx(base, rel=1e-9)


def test_a_gear_from_a_geometry_in_si_is_the_gear_from_its_quantities():
    given = gear_geometry(teeth=30, module=2e-3, pressure_angle=math.radians(20), face_width=12e-3,
                          profile_shift=0.2, bore_diameter=20e-3)
    assert Gear.from_geometry("g", given).geometry == Gear.from_geometry("g", **PINION).geometry
    gear = Gear.from_geometry("g", given)
    assert (gear.inertia, gear.base_radius, gear.teeth) == ("I_g", "r_g", 30)


# ------------------------------------------------------------------ the stiffness in the model
def test_the_mean_stiffness_in_the_model_is_the_curves_mean(spur_mesh, spur_coefficients):
    mean = spur_coefficients[0]
    assert gearsym.load_model("spur_pair").physical["kZ"].si == pytest.approx(mean, rel=1e-9)
    # and the variation the model integrates has mean 1 (its constant term), so kZ k(phi) has the curve's mean
    variation = spur_mesh.variation
    assert float(sp.integrate(variation, (phi, 0, 2 * sp.pi)) / (2 * sp.pi)) == pytest.approx(1.0, abs=1e-15)
    # the time unit of the reduction is that mean over the pair's effective mass
    s = gearsym.scaling("spur_pair")
    p = gearsym.load_model("spur_pair").physical
    omega_n = math.sqrt(mean * (p["r1"].si ** 2 / p["I1"].si + p["r2"].si ** 2 / p["I2"].si))
    assert s.omega_n.to("rad/s").magnitude == pytest.approx(omega_n, rel=1e-9)


def series(variation: sp.Expr):
    return sp.lambdify(phi, variation, "numpy")


def test_the_fourier_series_in_the_model_is_the_curves_to_the_accuracy_its_order_implies(spur_mesh,
                                                                                          spur_coefficients):
    """The model's coefficients are the curve's own times Lanczos's sigma factors; its L2 distance from the curve
    is Parseval's: the sigma factors' share of the kept terms plus the terms left out."""
    mean, square, a, b = spur_coefficients
    order = 7
    sigma = np.array([np.sinc(n / (order + 1)) for n in range(1, order + 1)])  # sin(pi x) / (pi x)
    expr = sp.expand(spur_mesh.variation)
    model_a = np.array([float(expr.coeff(sp.cos(n * phi))) for n in range(1, order + 1)])
    model_b = np.array([float(expr.coeff(sp.sin(n * phi))) for n in range(1, order + 1)])
    assert model_a == pytest.approx(sigma * a[:order], abs=1e-8)
    assert model_b == pytest.approx(sigma * b[:order], abs=1e-8)
    assert expr.coeff(sp.cos(8 * phi)) == 0 and expr.coeff(sp.sin(8 * phi)) == 0
    # Parseval: ||k/mean - S||^2 / 2 pi = sum (1 - sigma)^2 (a^2 + b^2) / 2 over the kept terms + the rest of the power
    kept = np.sum((a[:order] ** 2 + b[:order] ** 2)) / 2
    rest = square - 1 - kept
    predicted = math.sqrt(np.sum((1 - sigma) ** 2 * (a[:order] ** 2 + b[:order] ** 2)) / 2 + rest)
    curve, f = spur_mesh.computed.curve, series(spur_mesh.variation)
    split = 2 * math.pi * (curve.contact_ratio - 1)
    measured = math.sqrt(sum(quad(lambda p: (float(curve.at(np.array([p]))[0]) / mean - f(p)) ** 2, lo, hi,
                                  epsrel=1e-10, limit=200)[0] for lo, hi in ((0, split), (split, 2 * math.pi)))
                         / (2 * math.pi))
    assert measured == pytest.approx(predicted, rel=1e-5)
    assert 0.03 < measured < 0.1  # seven smoothed harmonics: a few per cent of the mean, as docs/geometry.md says


def test_the_plain_series_is_the_best_of_its_order_and_converges_as_the_power_left_out():
    """Unsmoothed, the series of order N is the curve's orthogonal projection: its L2 error is exactly the power
    of the harmonics above N (from the independent coefficients), falling as N grows."""
    errors = []
    for order in (3, 12):
        mesh = mesh_of(geared_pair(harmonics=order, smoothed=False))
        curve, f = mesh.computed.curve, series(mesh.variation)
        mean, square, a, b = independent_coefficients(curve, order)
        split = 2 * math.pi * (curve.contact_ratio - 1)
        measured = math.sqrt(sum(quad(lambda p: (float(curve.at(np.array([p]))[0]) / mean - f(p)) ** 2, lo, hi,
                                      epsrel=1e-10, limit=200)[0] for lo, hi in ((0, split), (split, 2 * math.pi)))
                             / (2 * math.pi))
        assert measured == pytest.approx(math.sqrt(square - 1 - np.sum(a**2 + b**2) / 2), rel=1e-5)
        errors.append(measured)
    assert errors[1] < 0.7 * errors[0]


def test_the_default_series_stays_within_the_curves_extremes(spur_mesh):
    """Why the default smooths (docs/geometry.md): no Gibbs overshoot beyond the curve's own minimum and maximum."""
    curve, f = spur_mesh.computed.curve, series(spur_mesh.variation)
    values = f(np.linspace(0.0, 2 * math.pi, 4001)) * curve.mean
    assert curve.min <= values.min() and values.max() <= curve.max
    plain = series(Mesh.from_gears("m", *(Gear.from_geometry(n, spur_mesh.gear_a.geometry) for n in "ab"),
                                   smoothed=False).variation)
    overshoot = plain(np.linspace(0.0, 2 * math.pi, 4001)) * curve.mean
    assert overshoot.min() < curve.min or overshoot.max() > curve.max  # what the sigma factors remove


# ------------------------------------------------------------------ derive -> compile -> lyap / sweep / orbits
@pytest.mark.slow
def test_a_pair_declared_from_geometry_derives_compiles_and_runs_in_physical_units():
    model = geared_pair()
    nd = gearsym.reduce(model)  # derive: the series is a term of the reduced equations' k(tau)
    formula = sp.expand(nd.reduction.resolved.couplings[0].variation)
    assert formula.coeff(sp.cos(7 * phi)) != 0 and formula.coeff(sp.sin(phi)) != 0
    s = gearsym.scaling(model, speed="3000 rpm")
    p = model.physical
    omega_n = math.sqrt(mesh_of(model).computed.curve.mean * (p["r1"].si ** 2 / p["I1"].si
                                                              + p["r2"].si ** 2 / p["I2"].si))
    assert s.omega_n.to("rad/s").magnitude == pytest.approx(omega_n, rel=1e-9)
    options = Integration(periods=120, discard=80)
    compiled = gearsym.compile_model(s.system(), options)
    point = s.to_physical(gearsym.lyapunov_spectrum(compiled))
    assert point.exponents.units == gearsym.units.Quantity(1, "1/s").units
    assert np.all(point.exponents.magnitude < 0)  # damped, periodic
    # on a periodic orbit in contact the pinion does not accelerate on average: mean mesh force M1 / r1
    assert point.mesh_force["mesh"]["mean"].to("N").magnitude == pytest.approx(40.0 / p["r1"].si, rel=1e-6)
    sweep = gearsym.run_sweep(s, {"speed": ["2000 rpm", "3000 rpm"]}, options=options, execution=gearsym.Execution(1, "threads"))
    assert list(sweep["speed"]) == [2000.0, 3000.0] and sweep.units["A_x"] == "µm"
    assert np.all(np.isfinite(sweep["A_x"])) and np.all(sweep["A_x"] > 0)
    orbits = s.to_physical(gearsym.continue_orbits(compiled, "omega", s.omega("2000 rpm"), s.omega("2200 rpm")))
    assert orbits.parameter == "speed" and orbits.units["A_x"] == "µm"
    assert orbits.branches and len(orbits.branches[0]) >= 2
    assert orbits.branches[0].values[-1] == pytest.approx(2200.0, rel=1e-9)  # reached, in rpm


# ------------------------------------------------------------------ refused before any work
@pytest.mark.parametrize("call, message", [
    (lambda: Gear.from_geometry("g", teeth=20, module=2, pressure_angle="20 deg", face_width="10 mm"),
     "module=2 has no unit, and a length needs one: write module='2 mm'"),
    (lambda: Gear.from_geometry("g", teeth=20, module="2 mm", pressure_angle="20 mm", face_width="10 mm"),
     "pressure_angle=20 mm is not an angle"),
    (lambda: Gear.from_geometry("g", teeth=20, module="2 mm", face_width="10 mm"), "needs pressure_angle"),
    (lambda: Gear.from_geometry("g", teeth=20, module="2 mm", pressure_angle="20 deg", face_width="10 mm", bore=1),
     "unknown gear dimension bore"),
    (lambda: Mesh.from_gears("m", Gear("a", inertia="I1", base_radius="r1"), Gear.from_geometry("b", **WHEEL)),
     "meshes with 'a', which was not declared from its geometry"),
    (lambda: Mesh.from_gears("m", Gear.from_geometry("a", **PINION), Gear.from_geometry("b", **WHEEL),
                             harmonics=0), "harmonics must be a whole number from 1 to 100"),
])
def test_bad_geometry_is_one_line(call, message):
    with pytest.raises(ModelError, match=None) as info:
        call()
    assert message in str(info.value) and "\n" not in str(info.value)


def test_two_gears_giving_one_parameter_two_values_are_refused():
    model = Drivetrain("clash")
    model.add(Gear.from_geometry("a", inertia="I", base_radius="r1", **PINION))
    with pytest.raises(ModelError, match="gives I = .* but 'a' gave it"):
        model.add(Gear.from_geometry("b", inertia="I", base_radius="r2", **WHEEL))


@pytest.mark.slow
def test_the_located_crossings_converge_at_fourth_order_with_the_computed_stiffness():
    """At 12 000 rpm spur_pair's teeth separate; with the series smooth in time, the located crossings keep RK4's
    fourth order (step halving divides the error by about 16) and beat the unlocated steps by orders of magnitude."""
    system = gearsym.scaling("spur_pair", speed="12000 rpm").system()

    def final(steps, locate):
        options = Integration(periods=20, discard=0, steps_per_period=steps, locate_crossings=locate)
        r = gearsym.lyapunov_spectrum(gearsym.compile_model(system, options))
        return np.array(list(r.final_state.values()))

    reference = final(3200, True)
    located = [np.abs(final(steps, True) - reference).max() for steps in (200, 400)]
    unlocated = np.abs(final(200, False) - reference).max()
    assert 10 < located[0] / located[1] < 24
    assert located[0] < 1e-2 * unlocated
