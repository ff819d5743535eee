"""The potential-energy integrals and the mesh-stiffness curve, against computations written here independently.

The tooth's form is rebuilt here another way: the fillet by rolling the rack and taking the point of the tool
tip's rounding whose normal passes through the pitch point (parametrised by the rolling angle, not by the
normal's angle), the involute by its polar equation in the radius; the integrals are SciPy's adaptive
quadrature (``scipy.integrate.quad``) in those parameters, with derivatives by the complex step. None of it
calls gearsym's profile or quadrature.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from gearsym.geometry import (GearGeometry, GearPair, Material, StiffnessOptions, mesh_stiffness, pair_compliances,
                              pair_stiffness)
from gearsym.geometry.tooth_energy import tooth_compliances

E, NU = 2.06e11, 0.3


def inv(a):
    return math.tan(a) - a


class IndependentTooth:
    """One gear's tooth, from its rack and blank, written from the definitions (ISO 21771, ISO 53)."""

    def __init__(self, z, m, alpha_n, x=0.0, ha=1.0, hf=1.25, rho=0.38, beta=0.0):
        self.alpha = math.atan(math.tan(alpha_n) / math.cos(beta))  # transverse
        mt = m / math.cos(beta)
        self.r = mt * z / 2
        self.rb = self.r * math.cos(self.alpha)
        self.ra = self.r + m * (ha + x)
        self.rf = self.r - m * (hf - x)
        self.rho = rho * m
        # the rack: the tooth space on the generating line is the tooth's thickness there
        s = mt * (math.pi / 2 + 2 * x * math.tan(alpha_n))
        self.psi_b = s / (2 * self.r) + inv(self.alpha)
        self.depth = m * (hf - x) - self.rho          # the rounding's centre below the generating line
        self.along = s / 2 + self.rho / math.cos(self.alpha) + self.depth * math.tan(self.alpha)

    # -- the fillet by rolling: gear fixed, rack rolled by phi ----------------------------------------
    def fillet_point(self, phi):
        T = self.r * np.array([np.sin(phi), np.cos(phi)])
        e1 = np.array([np.cos(phi), -np.sin(phi)])
        e2 = np.array([np.sin(phi), np.cos(phi)])
        C = T + (self.along - self.r * phi) * e1 - self.depth * e2
        d = C - T
        n = d / np.sqrt(d[0] * d[0] + d[1] * d[1])  # (no abs: the complex step goes through)
        return C + self.rho * n

    def fillet_range(self):
        """Rolling angles from the root (the normal through the pitch point is radial) to where the rounding
        meets the straight flank."""
        return self.along / self.r, (self.along + self.depth / math.tan(self.alpha)) / self.r

    # -- the involute by its polar equation ------------------------------------------------------------
    def involute_point(self, R):
        theta = self.psi_b - (np.tan(np.arccos(self.rb / R)) - np.arccos(self.rb / R))
        return np.array([R * np.sin(theta), R * np.cos(theta)])

    def form_radius(self):
        q = self.fillet_point(self.fillet_range()[1])
        return float(math.hypot(*q))

    def contact(self, R):
        """(x_c, y_c, load angle) for a contact at radius R."""
        xc, yc = self.involute_point(R)
        return float(xc), float(yc), math.tan(math.acos(self.rb / R)) - self.psi_b


def d_dt(f, t, h=1e-20):
    """The derivative by the complex step (exact to rounding)."""
    return np.imag(f(t + 1j * h)) / h


def independent_compliances(tooth: IndependentTooth, R: float, width: float):
    """Bending, shear, axial compliance of ``tooth`` loaded at radius R (Yang & Lin's energies), by quad."""
    G = E / (2 * (1 + NU))
    xc, yc, tau = tooth.contact(R)
    c, s = math.cos(tau), math.sin(tau)

    def pieces(point, t):
        x, y = point(t)
        dy = d_dt(lambda u: point(u)[1], t)
        return x, y, dy

    def bending(point, t):
        x, y, dy = pieces(point, t)
        return (c * (yc - y) - xc * s) ** 2 / (E * (2 * x) ** 3 * width / 12) * dy

    def direct(point, t):
        x, y, dy = pieces(point, t)
        return dy / (2 * x * width)

    lo, hi = tooth.fillet_range()  # y grows with phi along the fillet
    Rf = tooth.form_radius()
    opts = dict(epsabs=0.0, epsrel=1e-12, limit=200)
    b = integrate.quad(lambda t: bending(tooth.fillet_point, t), lo, hi, **opts)[0] \
        + integrate.quad(lambda t: bending(tooth.involute_point, t), Rf, R, **opts)[0]
    d = integrate.quad(lambda t: direct(tooth.fillet_point, t), lo, hi, **opts)[0] \
        + integrate.quad(lambda t: direct(tooth.involute_point, t), Rf, R, **opts)[0]
    return {"bending": b, "shear": 1.2 * c * c / G * d, "axial": s * s / E * d}


CASES = [  # (z, m, alpha_n, x, beta, rho): spur, shifted, many teeth, helical with a 25 deg rack
    (28, 3.175e-3, math.radians(20), 0.0, 0.0, 0.38),
    (19, 3.2e-3, math.radians(20), 0.3, 0.0, 0.38),
    (62, 2e-3, math.radians(20), -0.1, 0.0, 0.38),
    (23, 4e-3, math.radians(25), 0.2, math.radians(12), 0.25),
]


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"z{c[0]}-x{c[3]}-b{round(math.degrees(c[4]))}")
def test_the_energy_integrals_match_an_independent_quadrature_of_the_same_formulas(case):
    z, m, alpha, x, beta, rho = case
    gear = GearGeometry(z, m, alpha, 10e-3, profile_shift=x, helix_angle=beta, fillet_coefficient=rho,
                        material=Material(E, NU))
    tooth = IndependentTooth(z, m, alpha, x, rho=rho, beta=beta)
    assert gear.profile.form_radius == pytest.approx(tooth.form_radius(), rel=1e-12, abs=0)
    for R in np.linspace(tooth.form_radius() * 1.001, tooth.ra, 5):
        tau = tooth.contact(R)[2]
        ours = tooth_compliances(gear.profile, gear.material, 10e-3, np.array([tau]), 24)
        theirs = independent_compliances(tooth, R, 10e-3)
        for name in ("bending", "shear", "axial"):
            assert ours[name][0] == pytest.approx(theirs[name], rel=1e-9, abs=0), (name, R)


def test_the_quadrature_converges_as_its_points_double():
    """Against the independent SciPy quadrature: the error falls by more than 8 for each doubling (exponentially,
    Gauss–Legendre on smooth pieces) down to rounding."""
    z, m, alpha = 28, 3.175e-3, math.radians(20)
    gear = GearGeometry(z, m, alpha, 10e-3, material=Material(E, NU))
    tooth = IndependentTooth(z, m, alpha)
    R = 0.5 * (tooth.form_radius() + tooth.ra)
    reference = independent_compliances(tooth, R, 10e-3)
    tau = np.array([tooth.contact(R)[2]])
    errors = []
    for n in (2, 4, 8, 16):
        ours = tooth_compliances(gear.profile, gear.material, 10e-3, tau, n)
        errors.append(max(abs(ours[k][0] / reference[k] - 1) for k in ("bending", "shear", "axial")))
    assert errors[0] > 1e-4  # (the coarse rule is visibly off, so the test sees the convergence)
    assert all(later < earlier / 8 for earlier, later in zip(errors, errors[1:])), errors
    ours = tooth_compliances(gear.profile, gear.material, 10e-3, tau, 24)  # the default
    assert max(abs(ours[k][0] / reference[k] - 1) for k in reference) < 1e-12


def test_hertz_alone_is_pi_E_w_over_4_1_minus_nu2_per_pair_and_its_mean_is_eps_alpha_times_it():
    gear = GearGeometry(28, 3.175e-3, math.radians(20), 6.35e-3)
    result = mesh_stiffness(GearPair(gear, gear), terms=("hertz",))
    k_h = math.pi * E * 6.35e-3 / (4 * (1 - NU ** 2))
    pairs = np.where(result.phase < 2 * math.pi * (result.contact_ratio - 1), 2, 1)
    assert np.allclose(result.stiffness, pairs * k_h, rtol=1e-13, atol=0)
    assert result.mean == pytest.approx(result.contact_ratio * k_h, rel=1e-12, abs=0)
    assert (result.min, result.max) == pytest.approx((k_h, 2 * k_h), rel=1e-13, abs=0)


def test_a_rigid_body_leaves_out_exactly_sainsots_foundation_compliance():
    """Sainsot, Velex & Duverger 2004, typed here from the paper's coefficients, with u_f from where the line of
    action crosses the tooth's centre line and S_f the chord of the tooth at the root circle."""
    table = {"L": (-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045),
             "M": (60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086),
             "P": (-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236),
             "Q": (-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904)}
    z, m, alpha, w, bore = 30, 3e-3, math.radians(20), 12e-3, 0.03
    gear = GearGeometry(z, m, alpha, w, bore_diameter=bore)
    pair = GearPair(gear, gear)
    tooth = IndependentTooth(z, m, alpha)
    theta_f = tooth.along / tooth.r  # where the fillet meets the root circle
    h = tooth.rf / (bore / 2)
    L, M, P, Q = (A / theta_f ** 2 + B * h * h + C * h / theta_f + D / theta_f + Ee * h + F
                  for A, B, C, D, Ee, F in table.values())
    s = np.linspace(*pair.path_of_contact, 7)
    full = pair_compliances(pair, s)
    rigid = pair_compliances(pair, s, terms=("hertz", "bending", "shear", "axial"))
    for along, key in ((s, "foundation1"), (pair.line_of_action - s, "foundation2")):
        for value, t in zip(full[key], along):
            R = math.hypot(tooth.rb, t)
            xc, yc, tau = tooth.contact(R)
            u = (yc - xc * math.tan(tau)) - tooth.rf
            S = 2 * tooth.rf * math.sin(theta_f)
            expected = math.cos(tau) ** 2 / (E * w) * (L * (u / S) ** 2 + M * u / S + P * (1 + Q * math.tan(tau) ** 2))
            assert value == pytest.approx(expected, rel=1e-12, abs=0)
    assert sum(full.values()) - sum(rigid.values()) == pytest.approx(full["foundation1"] + full["foundation2"], rel=1e-12, abs=0)
    k_full = mesh_stiffness(pair).mean
    k_rigid = mesh_stiffness(pair, terms=("hertz", "bending", "shear", "axial")).mean
    assert k_rigid > 1.5 * k_full  # the body is a large part of the compliance (docs/geometry.md)


@pytest.fixture(scope="module")
def nasa():
    gear = GearGeometry(28, 3.175e-3, math.radians(20), 6.35e-3, bore_diameter=0.02)
    pair = GearPair(gear, gear)
    return pair, mesh_stiffness(pair)


def test_double_contact_is_the_sum_of_the_two_pairs_one_base_pitch_apart(nasa):
    pair, result = nasa
    start, end = pair.path_of_contact
    pitch = pair.base_pitch
    for phi in np.linspace(0.0, 2 * math.pi, 37)[:-1]:
        s = start + phi / (2 * math.pi) * pitch
        expected = pair_stiffness(pair, np.array([s]))[0]
        if s + pitch < end:
            expected += pair_stiffness(pair, np.array([s + pitch]))[0]
        assert result.at(phi) == pytest.approx(expected, rel=1e-13, abs=0), phi
    double = [z for z in result.zones if z.pairs == 2][0]
    assert double.end == pytest.approx(2 * math.pi * (result.contact_ratio - 1), rel=1e-14, abs=0)


def test_the_mean_is_the_stiffness_integrated_along_the_path_of_contact_over_the_base_pitch(nasa):
    pair, result = nasa
    start, end = pair.path_of_contact
    integral = integrate.quad(lambda s: pair_stiffness(pair, np.array([s]))[0], start, end, epsrel=1e-13)[0]
    assert result.mean == pytest.approx(integral / pair.base_pitch, rel=1e-11, abs=0)
    assert result.min <= result.stiffness.min() and result.max >= result.stiffness.max()


def test_the_fourier_coefficients_are_the_exact_integrals_of_the_curve(nasa):
    _, result = nasa
    order = 6
    series = result.fourier(order)
    jump = 2 * math.pi * (result.contact_ratio - 1)

    def coefficient(f):  # over the two smooth pieces, by SciPy
        return sum(integrate.quad(lambda p: result.at(p) * f(p), a, b, epsrel=1e-12)[0]
                   for a, b in ((0.0, jump), (jump, 2 * math.pi))) / (math.pi * result.mean)

    for n in range(1, order + 1):
        assert series.cos[n - 1] == pytest.approx(coefficient(lambda p: math.cos(n * p)), abs=1e-11)
        assert series.sin[n - 1] == pytest.approx(coefficient(lambda p: math.sin(n * p)), abs=1e-11)
    # more terms come closer in the mean square (the curve jumps, so not uniformly)
    phase = np.linspace(0, 2 * math.pi, 2001)[:-1]
    errors = [np.sqrt(np.mean((result.fourier(n)(phase) - result.at(phase)) ** 2)) for n in (1, 4, 16, 64)]
    assert all(b < a for a, b in zip(errors, errors[1:])), errors


def test_a_helical_pair_converges_as_its_slices_double_and_keeps_its_mean():
    g1 = GearGeometry(27, 3e-3, math.radians(20), 30e-3, helix_angle=math.radians(18), bore_diameter=0.02)
    g2 = GearGeometry(44, 3e-3, math.radians(20), 30e-3, helix_angle=-math.radians(18), bore_diameter=0.04)
    pair = GearPair(g1, g2)
    phase = np.linspace(0, 2 * math.pi, 97)[:-1] + 0.01
    curves = {n: mesh_stiffness(pair, StiffnessOptions(slices=n, phase_points=8)) for n in (5, 10, 20, 40, 160)}
    means = [c.mean for c in curves.values()]
    # each slice has the same mean, and every compliance scales with 1/width: the mean is the transverse spur's
    spur_mean = integrate.quad(lambda s: pair_stiffness(pair, np.array([s]))[0], *pair.path_of_contact,
                               epsrel=1e-13)[0] / pair.base_pitch
    assert means == pytest.approx([spur_mean] * len(means), rel=1e-11, abs=0)
    # each slice's jumps misplace at most a slice's share of a pair: first order in 1/slices
    fine = curves[160].at(phase)
    errors = [np.max(np.abs(curves[n].at(phase) / fine - 1)) for n in (5, 10, 20, 40)]
    assert all(b < 0.8 * a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 0.02


def test_the_tooth_profile_is_continuous_where_the_fillet_meets_the_involute():
    for z, x in ((28, 0.0), (40, 0.5), (12, 0.0)):  # 12 teeth: undercut (a warning)
        with pytest.warns(Warning) if z == 12 else _no_warning():
            gear = GearGeometry(z, 2e-3, math.radians(20), 10e-3, profile_shift=x)
        p = gear.profile
        xf, yf, _ = p.fillet(np.array(p.junction))
        xi, yi, _ = p.involute(np.array(p.form_parameter))
        assert (xf, yf) == pytest.approx((xi, yi), rel=1e-12, abs=0)


class _no_warning:
    def __enter__(self):
        import warnings

        self._catch = warnings.catch_warnings()
        self._catch.__enter__()
        warnings.simplefilter("error")

    def __exit__(self, *exc):
        return self._catch.__exit__(*exc)


def test_a_curve_in_chunks_is_the_same_and_a_huge_one_is_refused_first(monkeypatch):
    from gearsym.errors import GearsymError
    from gearsym.geometry import meshing

    gear = GearGeometry(28, 3.175e-3, math.radians(20), 6.35e-3, bore_diameter=0.02)
    pair = GearPair(gear, gear)
    whole = mesh_stiffness(pair, phase_points=64)
    monkeypatch.setattr(meshing, "_CHUNK_ELEMENTS", 500)  # a few phases at a time
    chunked = mesh_stiffness(pair, phase_points=64)
    assert np.array_equal(whole.stiffness, chunked.stiffness) and whole.mean == chunked.mean
    helical = GearGeometry(30, 3e-3, math.radians(20), 20e-3, helix_angle=0.2, bore_diameter=0.02)
    other = GearGeometry(30, 3e-3, math.radians(20), 20e-3, helix_angle=-0.2, bore_diameter=0.02)
    def no_work(*args, **kwargs):
        raise AssertionError("the work started before the size was checked")

    monkeypatch.setattr(meshing, "pair_stiffness", no_work)
    with pytest.raises(GearsymError, match="evaluations allowed"):
        mesh_stiffness(GearPair(helical, other), phase_points=100_000, slices=100)


def test_the_geometry_stage_imports_no_sympy_pint_or_casadi():
    """It sits below the model stage: SI floats and numpy only (the command line reads units above it)."""
    import subprocess
    import sys

    code = ("import sys, gearsym.geometry as g; import math; "
            "k = g.mesh_stiffness(g.gear_pair(*(2 * [g.gear_geometry(teeth=30, module=2e-3, pressure_angle=0.35, "
            "face_width=0.01, bore_diameter=0.02)])), phase_points=16); "
            "print(sorted(m for m in ('sympy', 'pint', 'casadi', 'scipy', 'matplotlib') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
