"""Shaft-order terms of a mesh: what a gear's revolution adds to its mesh, as SymPy expressions of the mesh phase.

A gear of Z teeth turns once in Z mesh periods, so at the mesh phase phi (2 pi per mesh period) its angle is
phi / Z, and everything fixed on the gear repeats once per revolution, phi -> phi + 2 pi Z. The terms here are
what the declaration stage (:mod:`.faults`) and the data loop's effects (:mod:`gearsym.fit.shaft_effects`) add
to a mesh, built by the same functions:

* a **transmission error** at the gear's shaft order N: ``A cos(N phi/Z + theta)`` (eccentricity, run-out);
* a **local tooth fault**: the mesh stiffness times ``1 - q s_n(phi)``, with ``s_n`` the share of the mesh
  stiffness carried by the pair of tooth n (:func:`tooth_share`): 1/2 while it shares the load with a
  neighbour (double contact), 1 while it carries it alone, 0 out of mesh;
* **lost contact width** (pitting, a spall) over part of a tooth's path: the share times the window of that
  part (:func:`path_window`);
* **spacing errors**: a transmission error that takes the value e_n while tooth n carries the load
  (:func:`tooth_by_tooth`).

Teeth are counted from tau = 0: tooth n (1, ..., Z) of a gear is the one in single contact in mesh period n
(phi in [2 pi (n - 1), 2 pi n)) and again every Z mesh periods; the mesh stiffness variation's double contact is
centred on phi = 0 mod 2 pi (:func:`~gearsym.model.stiffness.rectangular_mesh_stiffness`), so that pair comes
into mesh at phi = 2 pi (n - 1) - pi (e - 1) and leaves at 2 pi n + pi (e - 1), e the contact ratio.

Every window is smooth and periodic over one revolution (no floor or mod, which would make the tables of time
jump): a product of two smooth steps, ``(1 + tanh(kappa sin(a + h)))(1 + tanh(kappa sin(h - a)))/4``, a the
gear's angle from the window's centre and h its half width, with kappa chosen so that each edge rises over
``edge`` mesh periods (from 12 % to 88 %) (:func:`window`).
"""
from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..errors import ModelError

#: mesh periods over which the edge of a tooth's window rises (RK4 at 200 steps per mesh period takes 20 steps
#: over it: the term is smooth for the integrator, and still sharp on the scale of one mesh period)
DEFAULT_EDGE = sp.Rational(1, 10)


def _rational(value, what: str, where: str) -> sp.Expr:
    expr = sp.nsimplify(value) if isinstance(value, (int, float)) else sp.sympify(value, strict=True)
    if not expr.is_number:
        raise ModelError(f"{what} must be a number, got {value!r}", where)
    return sp.Rational(expr) if expr.is_Rational else expr


def teeth_of(teeth, where: str) -> sp.Integer:
    """A tooth count: a whole number of at least 3."""
    if isinstance(teeth, bool) or not isinstance(teeth, (int, sp.Integer)) or int(teeth) < 3:
        raise ModelError(f"a tooth count must be a whole number of at least 3, got {teeth!r}", where)
    return sp.Integer(int(teeth))


def gear_angle(phi: sp.Expr, teeth) -> sp.Expr:
    """The gear's angle at the mesh phase ``phi``: phi / Z."""
    return phi / teeth


def window(phi: sp.Expr, teeth, centre, length, edge=DEFAULT_EDGE) -> sp.Expr:
    """About 1 while the mesh phase is within ``length``/2 mesh periods of ``centre`` (in mesh periods, counted
    from phi = 0), about 0 elsewhere; periodic over one revolution of the gear of ``teeth`` teeth. ``centre``
    may be a parameter (a tooth that the data loop moves); ``length`` and ``edge`` are numbers.

    ``S(a + h) S(h - a)`` with ``S(z) = (1 + tanh(kappa sin z))/2``, a the gear's angle from the centre and h the
    half width: each factor a smooth step at one edge (sin z is z there), periodic; the product is the window as
    long as it is shorter than half a revolution. kappa = Z/(pi edge) makes each edge rise over ``edge`` mesh
    periods (12 % to 88 %), and since S(-z) = 1 - S(z), the windows of neighbouring teeth that share an edge add
    up to 1 across it."""
    Z = sp.Integer(teeth)
    length, edge = sp.nsimplify(length), sp.nsimplify(edge)
    if not edge > 0:
        raise ModelError(f"the edge of a window must be positive, got {edge}", "tooth window")
    if not (0 < length and length + 4 * edge < Z / 2):
        raise ModelError(f"a window of {length} mesh periods (edges {edge}) needs a gear of more than "
                         f"{2 * (length + 4 * edge)} teeth: it must stay well within half a revolution, not {Z}",
                         "tooth window")
    half = sp.pi * length / Z
    sharpness = sp.Float(f"{float(Z / (sp.pi * edge)):.12g}")  # (12 digits: the same C everywhere)
    angle = (phi - 2 * sp.pi * centre) / Z
    return (1 + sp.tanh(sharpness * sp.sin(angle + half))) * (1 + sp.tanh(sharpness * sp.sin(half - angle))) / 4


def tooth_share(phi: sp.Expr, teeth, tooth, contact_ratio, edge=DEFAULT_EDGE) -> sp.Expr:
    """The share of the mesh stiffness that the pair of tooth ``tooth`` carries: 1/2 over its whole path of
    contact (``contact_ratio`` mesh periods, the window W_n), and another 1/2 where it carries the load alone,
    in mesh while neither neighbour is: W_n (1 - W_(n-1)) (1 - W_(n+1)). So the shares of all teeth add up to
    1 - (1 - W_n)(1 - W_(n+1)) where two pairs share the load: exactly 1 wherever one of them is fully in mesh,
    and the edges of the double and single contact are the same ones."""
    e = sp.nsimplify(contact_ratio)
    if not 1 < e < 2:
        raise ModelError(f"the contact ratio must lie in (1, 2), got {contact_ratio}", "tooth share")
    whole = [window(phi, teeth, tooth + k - sp.Rational(1, 2), e, edge) for k in (-1, 0, 1)]
    return whole[1] / 2 + whole[1] * (1 - whole[0]) * (1 - whole[2]) / 2


def path_coordinate(phi: sp.Expr, teeth, tooth, contact_ratio) -> sp.Expr:
    """w = sin(a) / sin(h): -1 where the pair of ``tooth`` comes into mesh, +1 where it leaves, a the gear's angle from
    the middle of its time in mesh and h half that time's angle (pi e / Z); along its path of contact, a smooth
    coordinate of the contact's position that repeats once per revolution (a loss along the path is a polynomial in
    it: :class:`~gearsym.model.faults.ToothFault`'s ``along_path``)."""
    e = sp.nsimplify(contact_ratio)
    Z = sp.Integer(teeth)
    half = sp.pi * e / Z
    return sp.sin((phi - 2 * sp.pi * (tooth - sp.Rational(1, 2))) / Z) / sp.sin(half)


def path_window(phi: sp.Expr, teeth, tooth, contact_ratio, start, end, edge=DEFAULT_EDGE) -> sp.Expr:
    """About 1 while the pair of tooth ``tooth`` is between the fractions ``start`` and ``end`` of its path of
    contact (0: where it comes into mesh, 1: where it leaves)."""
    e, a, b = (sp.nsimplify(v) for v in (contact_ratio, start, end))
    if not 0 <= a < b <= 1:
        raise ModelError(f"a part of the path of contact runs from a fraction start to end with 0 <= start < end <= 1,"
                         f" got {start}, {end}", "path window")
    centre = tooth - sp.Rational(1, 2) - e / 2 + e * (a + b) / 2
    return window(phi, teeth, centre, e * (b - a), edge)


def shaft_harmonic(phi: sp.Expr, teeth, order: int, amplitude, phase) -> sp.Expr:
    """``amplitude cos(order phi / Z + phase)``: a transmission error at the gear's shaft order ``order``."""
    return amplitude * sp.cos(order * gear_angle(phi, teeth) + phase)


def tooth_by_tooth(phi: sp.Expr, teeth, errors: Sequence, edge) -> sp.Expr:
    """``errors[n - 1]`` while tooth n carries the load, blended over the double contact: a tooth-by-tooth
    transmission error (spacing errors)."""
    Z = int(teeth)
    if len(errors) != Z:
        raise ModelError(f"spacing errors need one value per tooth ({Z}), got {len(errors)}", "spacing errors")
    return sp.Add(*(err * window(phi, Z, n - sp.Rational(1, 2), 1, edge) for n, err in enumerate(errors, 1)))


def revolution_frequency(teeth) -> sp.Rational:
    """The gear's shaft frequency over its mesh frequency: 1/Z."""
    return sp.Rational(1, int(teeth))
