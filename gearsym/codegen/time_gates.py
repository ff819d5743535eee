"""Which of the fit's time values a window can skip: those that only matter while some parameter is not 0.

The compiled window step (:mod:`.windows`) computes what depends on time and the parameters alone once per time
point: the time values W (a library's tooth windows, shaft- and mesh-order harmonics) and their derivatives D by
the parameters. A library of candidate effects has all of them, but a fit or a scan has most effects at 0: a tooth
fault at severity 0 still had its window (tanh of its tooth's phase) computed at every step, most of the step's work.

A time value W_k is *gated* by a parameter p_j when, with p_j = 0, nothing the step computes depends on W_k: the
values that are then 0 themselves (W_i = p_j (...), their derivatives by the other parameters 0 too) set to 0, the
rest of the right-hand side no longer contains W_k, and W_k's own derivatives only multiply derivatives by p_j's
column. Found structurally (CasADi substitutes p_j = 0 and folds the products by 0), so it holds for any values: a
window whose p_j is 0 and that does not ask for p_j's column keeps W_k (and its row of D) at their values at the
window's start, and every result is what the whole computation gives (a product by 0 is 0 either way; not W_k = 0,
which a division by W_k would turn into 0 * inf).
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca


@dataclass(frozen=True)
class TimeGroup:
    """Time values computed together: skipped in a window where every parameter of one of ``gates`` is 0 and not
    asked for (no gate: always computed)."""

    gates: tuple[tuple[int, ...], ...]  # sets of parameter indices
    rows: tuple[int, ...]  # the values' indices in W


def time_groups(rest: ca.SX, w: ca.SX, values: ca.SX, d_values: ca.SX, p: ca.SX) -> list[TimeGroup]:
    """The time values ``values`` (symbols ``w`` in ``rest``, the right-hand side without them; ``d_values`` their
    derivatives by ``p``) grouped by the parameters that gate them (see the module docstring): each single parameter
    that does, or else the fewest of those the value depends on that do together (a harmonic's cosine and sine
    amplitudes), in order of first value."""
    nw, m = w.numel(), p.numel()
    symbols = [e.element_hash() for e in w.nonzeros()]
    d_rows, d_cols = d_values.sparsity().get_triplet()

    def unused(zeroed: list[int]) -> set[int]:
        """The values nothing depends on while the parameters ``zeroed`` are 0."""
        at = ca.vertcat(*(p[j] for j in zeroed))
        zeros = ca.SX.zeros(len(zeroed))
        zero = [e.is_zero() for e in ca.substitute(values, at, zeros).nonzeros()]
        for k, i, e in zip(d_rows, d_cols, ca.substitute(d_values, at, zeros).nonzeros()):
            if i not in zeroed and not e.is_zero():  # (a derivative by another parameter is left)
                zero[k] = False
        vanish = [k for k in range(nw) if zero[k]]
        kept = ca.substitute(rest, ca.vertcat(at, *(w[k] for k in vanish)), ca.SX.zeros(len(zeroed) + len(vanish)))
        left = {e.element_hash() for e in ca.symvar(kept)}
        return set(vanish) | {k for k in range(nw) if symbols[k] not in left}

    gates: list[list[tuple[int, ...]]] = [[] for _ in range(nw)]
    for j in range(m):
        if ca.depends_on(values, p[j]) or ca.depends_on(rest, p[j]):
            for k in unused([j]):
                gates[k].append((j,))
    for k in range(nw):
        if gates[k]:
            continue
        depends = [j for j in range(m) if ca.depends_on(values[k], p[j])]
        # all of them, or all but one (a frequency the value is divided by is no gate), then the fewest: each one
        # dropped that the others gate the value without
        together = next((s for s in [depends, *([i for i in depends if i != j] for j in depends)]
                         if len(s) > 1 and k in unused(s)), None)
        if together is None:
            continue
        for j in list(together):
            if len(together) > 1 and k in unused([i for i in together if i != j]):
                together.remove(j)
        gates[k].append(tuple(together))
    groups: dict[tuple, list[int]] = {}
    for k in range(nw):
        groups.setdefault(tuple(gates[k]), []).append(k)
    return [TimeGroup(gate, tuple(rows)) for gate, rows in groups.items()]
