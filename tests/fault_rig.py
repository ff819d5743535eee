"""A gear pair with shaft-order faults, simulated independently of gearsym: the one-stage equations typed here,
with a tooth fault, an eccentric gear or spacing errors typed from their physical description (not from gearsym's
formulas), integrated by SciPy's DOP853 (Hairer's code, through scipy.integrate.ode as tests/rig.py does: far less
overhead per step than solve_ivp's, which took 2-4 s a record) and sampled as a rig records.

    x'' = -2 zeta x'/omega + (B0 + B1 cos(tau + Theta))/omega^2 - k(tau) (1 - q s(tau)) g(x - e(tau), eta)/omega^2

with k(tau) gearsym's default stiffness variation (tests/rig.py's STIFFNESS, checked against its formula there),
u = tau / 2 pi the mesh periods since tau = 0, and for a gear of Z teeth, its tooth n in single contact in mesh
period n (counted from 1) and in mesh from u = n - 1 - (e - 1)/2 to n + (e - 1)/2 (contact ratio e = 1.6):

* a tooth fault: s(tau) the faulty pair's share of the mesh stiffness, 1/2 in double contact and 1 in single
  contact, each edge a smoothstep over 0.1 mesh periods (gearsym uses tanh windows: the shapes differ slightly);
* a crack that lowers the *whole* mesh stiffness by q while its tooth is in mesh (not the pair's share: the shape of
  no named fault of the library), edges smoothsteps over 0.15 mesh periods;
* an eccentric gear: e(tau) = A cos(u 2 pi / Z + psi);
* spacing errors: e(tau) = e_n while tooth n carries the load, blended by smoothsteps over the double contact.
"""
from __future__ import annotations

import math

import numpy as np

import rig

CONTACT = 1.6
EDGE = 0.1
T = 2 * math.pi


def smoothstep(z: float, width: float) -> float:
    """0 below -width/2, 1 above width/2, C1 in between."""
    s = min(1.0, max(0.0, z / width + 0.5))
    return s * s * (3 - 2 * s)


def _around(u: float, start: float, teeth: int) -> float:
    """u - start moved by whole revolutions into [-teeth/2, teeth/2)."""
    return (u - start + teeth / 2) % teeth - teeth / 2


def tooth_share(u: float, teeth: int, tooth: int) -> float:
    """The share of the mesh stiffness the pair of ``tooth`` carries at u mesh periods."""
    w = _around(u, tooth - 1, teeth)  # mesh periods since the start of its single-contact period's mesh period
    d = CONTACT - 1
    if not -d / 2 - EDGE < w < 1 + d / 2 + EDGE:  # out of mesh, every edge flat: exactly 0 (most of a revolution)
        return 0.0
    whole = smoothstep(w + d / 2, EDGE) - smoothstep(w - 1 - d / 2, EDGE)
    single = smoothstep(w - d / 2, EDGE) - smoothstep(w - 1 + d / 2, EDGE)
    return 0.5 * whole + 0.5 * single


def in_mesh(u: float, teeth: int, tooth: int, edge: float = 0.15) -> float:
    """About 1 while the pair of ``tooth`` is in mesh (from u = tooth - 1 - (e - 1)/2 to tooth + (e - 1)/2)."""
    w = _around(u, tooth - 1, teeth)
    d = CONTACT - 1
    if not -d / 2 - edge < w < 1 + d / 2 + edge:  # out of mesh, both edges flat: exactly 0
        return 0.0
    return smoothstep(w + d / 2, edge) - smoothstep(w - 1 - d / 2, edge)


def spacing_error(u: float, teeth: int, errors) -> float:
    """errors[n - 1] while tooth n carries the load, blended over the double contact."""
    n = int(math.floor(u)) % teeth  # the tooth (0-based) of this mesh period
    f = u - math.floor(u)
    d = CONTACT - 1
    before, after = errors[(n - 1) % teeth], errors[(n + 1) % teeth]
    here = errors[n]
    rise = smoothstep(f, d)  # from the previous tooth over the double contact around the period's start
    fall = smoothstep(f - 1, d)  # to the next one around its end
    return before + (here - before) * rise + (after - here) * fall


class Pair:
    """The typed equations of one pair: ``fault`` (gear 1 or 2, tooth, q), ``whole`` (gear, tooth, q: the whole mesh
    stiffness lowered while the tooth is in mesh), ``eccentric`` (gear, A, psi), ``spacing`` (gear, errors); ``teeth``
    = (Z1, Z2)."""

    def __init__(self, teeth=(11, 17), fault=None, eccentric=None, spacing=None, whole=None, **values):
        self.teeth, self.fault, self.eccentric, self.spacing, self.whole = teeth, fault, eccentric, spacing, whole
        self.p = {**rig.DEFAULTS, **values}

    def stiffness(self, tau: float) -> float:
        k = 1 + self.p["k_a"] * rig.variation(tau)
        if self.fault:
            gear, tooth, q = self.fault
            k *= 1 - q * tooth_share(tau / T, self.teeth[gear - 1], tooth)
        if self.whole:
            gear, tooth, q = self.whole
            k *= 1 - q * in_mesh(tau / T, self.teeth[gear - 1], tooth)
        return k

    def error(self, tau: float) -> float:
        e = 0.0
        if self.eccentric:
            gear, A, psi = self.eccentric
            e += A * math.cos(tau / self.teeth[gear - 1] + psi)
        if self.spacing:
            gear, errors = self.spacing
            e += spacing_error(tau / T, self.teeth[gear - 1], errors)
        return e

    def rhs(self, omega: float):
        p = self.p

        def f(tau, y):
            x, v = y
            a = -2 * p["zeta"] * v / omega + (p["B0"] + p["B1"] * math.cos(tau + p["Theta"])) / omega**2 \
                - self.stiffness(tau) * rig.backlash(x - self.error(tau), p["eta"]) / omega**2
            return (v, a)

        return f

    def record(self, omega: float, *, periods: float, transient: float, samples_per_period: int = 25,
               y0=(1.0, 0.0)) -> dict[str, np.ndarray]:
        """One run at ``omega`` from ``y0`` at tau = 0: ``transient`` mesh periods, then ``periods`` sampled
        ``samples_per_period`` times a mesh period; tau as simulated (the record starts where the transient ends)."""
        t0 = transient * T
        tau = t0 + (T / samples_per_period) * np.arange(int(round(periods * samples_per_period)))
        # (max_step: no step strides over a fault's edges, 0.1 mesh periods wide)
        x, v = rig.dop853_samples(self.rhs(omega), y0, tau, max_step=T / 40)
        return {"tau": tau, "x": x, "v": v}


def write(path, runs, noise: float = 0.01, seed: int = 3):
    """The runs [(omega, record), ...] as a tidy CSV (tau, record, omega, x with noise)."""
    return rig.write(path, runs, ("x",), noise=noise, seed=seed)
