"""The boundaries of a stability chart: located along the grid lines where stability changes, and joined into
curves.

Between two neighbours of a grid line of which one is stable and the other not, the boundary is found by
bisection on that line (the other parameter held): each round evaluates the midpoints of every bracket still
wider than the tolerance at once (one monodromy matrix each, in the lanes), so a boundary point costs
log2(step / tolerance) periods of the linearised system, and the grid can stay coarse. The located points are
then joined cell by cell (marching squares: a cell whose corners change stability holds one piece of a curve,
or two where the stable corners are opposite, told apart by the mean of the corners' largest moduli) into
curves, open at the chart's edge or closed.
"""
from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from itertools import repeat
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..checks import json_safe


class Crossing(NamedTuple):
    """A boundary point on a grid line: along the first axis (``axis`` 0: between columns j and j + 1 of row i)
    or the second (``axis`` 1: between rows i and i + 1 of column j); ``value`` on that axis, located to within
    ``error``; ``kind``: the instability on its unstable side (at the last unstable point evaluated). (A named
    tuple: a chart has thousands, made in a fraction of a dataclass's time.)"""

    axis: int
    i: int
    j: int
    value: float
    error: float
    kind: str | None
    located: bool = True  # False where the bisection met a point without a result (no static state or orbit)


@dataclass(frozen=True)
class Boundary:
    """One boundary curve: its points (first axis, second axis), whether it closes, its kind (the most common
    along it) and the kind at each point."""

    points: np.ndarray  # (k, 2)
    closed: bool
    kind: str | None
    kinds: tuple[str | None, ...]

    def as_dict(self, names: tuple[str, ...]) -> dict:
        return json_safe({"kind": self.kind, "closed": self.closed, "axes": list(names),
                          "points": self.points.tolist(), "kinds": list(self.kinds)})


#: evaluate(points (k, 2) on the axes, near (k,) index of the grid point whose result may start it)
#: -> (unstable (k,), kind (k,), valid (k,))
Evaluate = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


def grid_crossings(unstable: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """The grid lines' neighbours that differ in stability: rows (axis, i, j) as in :class:`Crossing`."""
    along = valid[:, :-1] & valid[:, 1:] & (unstable[:, :-1] != unstable[:, 1:])
    across = valid[:-1, :] & valid[1:, :] & (unstable[:-1, :] != unstable[1:, :])
    (i0, j0), (i1, j1) = np.nonzero(along), np.nonzero(across)
    return np.column_stack([np.repeat([0, 1], [len(i0), len(i1)]), np.concatenate([i0, i1]),
                            np.concatenate([j0, j1])]).astype(np.int64)


def midpoints(edges: np.ndarray, a: np.ndarray, b: np.ndarray, unstable: np.ndarray,
              kind: np.ndarray) -> list[Crossing]:
    """The crossings of ``edges`` at the midpoints of their grid lines (not located), each with the kind of its
    unstable end."""
    axis, i, j = edges.T
    i2, j2 = i + (axis == 1), j + (axis == 0)
    lo, hi = np.where(axis == 0, a[j], b[i]), np.where(axis == 0, a[j2], b[i2])
    kinds = np.where(unstable[i, j], kind[i, j], kind[i2, j2]).tolist()
    return list(map(Crossing._make, zip(axis.tolist(), i.tolist(), j.tolist(), ((lo + hi) / 2).tolist(),
                                        (np.abs(hi - lo) / 2).tolist(), kinds, repeat(True))))


def refine(edges: np.ndarray, a: np.ndarray, b: np.ndarray, unstable: np.ndarray,
           kind: np.ndarray, evaluate: Evaluate, tolerance: tuple[float, float],
           progress: Callable[[int, int], None] | None = None) -> list[Crossing]:
    """Bisect every edge (rows of :func:`grid_crossings`) to ``tolerance`` (per axis), all edges of a round at
    once."""
    if not len(edges):
        return []
    E = len(edges)
    axis, i, j = edges.T
    i2, j2 = i + (axis == 1), j + (axis == 0)
    first = np.where(axis == 0, a[j], b[i])
    second = np.where(axis == 0, a[j2], b[i2])
    first_unstable = unstable[i, j]
    stable_end = np.where(first_unstable, second, first)
    unstable_end = np.where(first_unstable, first, second)
    near = np.where(first_unstable, i2 * len(a) + j2, i * len(a) + j)  # the stable end's grid point
    kinds = np.where(first_unstable, kind[i, j], kind[i2, j2]).astype(object)
    tol = np.where(axis == 0, tolerance[0], tolerance[1])
    located = np.ones(E, dtype=bool)
    rounds = 0
    while True:
        active = np.nonzero(located & (np.abs(unstable_end - stable_end) > tol))[0]
        if progress:
            progress(E - len(active), E)
        if not len(active):
            break
        mid = (stable_end[active] + unstable_end[active]) / 2
        points = np.empty((len(active), 2))
        on_a = axis[active] == 0
        points[:, 0] = np.where(on_a, mid, a[j[active]])
        points[:, 1] = np.where(on_a, b[i[active]], mid)
        now_unstable, now_kind, valid = evaluate(points, near[active])
        located[active[~valid]] = False
        go = active[valid]
        up, k = now_unstable[valid], now_kind[valid]
        unstable_end[go[up]] = mid[valid][up]
        kinds[go[up]] = k[up]
        stable_end[go[~up]] = mid[valid][~up]
        rounds += 1
    return list(map(Crossing._make, zip(axis.tolist(), i.tolist(), j.tolist(),
                                        ((stable_end + unstable_end) / 2).tolist(),
                                        (np.abs(unstable_end - stable_end) / 2).tolist(), kinds.tolist(),
                                        located.tolist())))


def curves(crossings: list[Crossing], a: np.ndarray, b: np.ndarray, unstable: np.ndarray, valid: np.ndarray,
           largest: np.ndarray) -> list[Boundary]:
    """The crossings joined into curves (see the module docstring); with one grid line (a 1-D chart) each
    crossing is a boundary of one point. The cells are scanned at once (numpy); the walk along the links is
    the only loop, one step a crossing."""
    if len(b) == 1 or len(a) == 1:
        return [Boundary(np.array([_position(c, a, b)]), False, c.kind, (c.kind,)) for c in crossings]
    K, na, nb = len(crossings), len(a), len(b)
    if not K:
        return []
    columns = list(zip(*crossings))  # (the fields of every crossing, a tuple each)
    axis, i, j = (np.array(columns[k], dtype=np.int64) for k in range(3))
    value, kinds_of = np.array(columns[3], dtype=float), columns[5]
    # each grid line's crossing (its index, -1 where none): along the first axis (nb x na-1), the second (nb-1 x na)
    along = np.full((nb, na - 1), -1, dtype=np.int64)
    across = np.full((nb - 1, na), -1, dtype=np.int64)
    first = axis == 0
    along[i[first], j[first]] = np.nonzero(first)[0]
    across[i[~first], j[~first]] = np.nonzero(~first)[0]
    # the cells a crossing borders (row by row), each one's sides in the order bottom, right, top, left
    ci = np.concatenate([i, np.where(first, i - 1, i)])
    cj = np.concatenate([j, np.where(first, j, j - 1)])
    inside = (ci >= 0) & (ci < nb - 1) & (cj >= 0) & (cj < na - 1)
    cell = np.unique(ci[inside] * (na - 1) + cj[inside])
    ci, cj = cell // (na - 1), cell % (na - 1)
    whole = valid[ci, cj] & valid[ci + 1, cj] & valid[ci, cj + 1] & valid[ci + 1, cj + 1]
    sides = np.column_stack([along[ci, cj], across[ci, cj + 1], along[ci + 1, cj], across[ci, cj]])
    present = sides >= 0
    count = present.sum(axis=1)
    two, four = whole & (count == 2), whole & (count == 4)
    ps = sides[two]  # (cells, 4): the two present sides first, in their order
    ps = np.take_along_axis(ps, np.argsort(~present[two], axis=1, kind="stable"), axis=1)[:, :2]
    pair_cells = (ci[two], cj[two])
    ci, cj = ci[four], cj[four]
    centre = (largest[ci, cj] + largest[ci, cj + 1] + largest[ci + 1, cj] + largest[ci + 1, cj + 1]) / 4 > 1.0
    joins = unstable[ci, cj] == centre  # the corner (ci, cj) joins the centre: cut off the other two
    s4 = sides[four]
    bottom, right, top, left = s4[:, 0], s4[:, 1], s4[:, 2], s4[:, 3]
    saddles = np.stack([np.column_stack([bottom, np.where(joins, right, left)]),
                        np.column_stack([top, np.where(joins, left, right)])], axis=1)  # (cells, 2 pairs, 2)
    # the pairs in the order of their cells (row by row), each link in both directions in that order
    cell = np.concatenate([pair_cells[0] * na + pair_cells[1], np.repeat(ci * na + cj, 2)])
    pairs = np.concatenate([ps, saddles.reshape(-1, 2)])
    pairs = pairs[np.argsort(cell, kind="stable")]
    source = pairs.reshape(-1)  # (p, q), (q, p) of each pair, in order
    target = pairs[:, ::-1].reshape(-1)
    order = np.argsort(source, kind="stable")
    source, target = source[order], target[order]
    # each crossing's links (two at most: a crossing borders two cells, each links it once), in that order
    degree = np.bincount(source, minlength=K)
    at = np.cumsum(degree) - degree
    one, two = np.full(K, -1, dtype=np.int64), np.full(K, -1, dtype=np.int64)
    one[degree >= 1] = target[at[degree >= 1]]
    two[degree == 2] = target[at[degree == 2] + 1]
    positions = np.column_stack([np.where(first, value, a[j]), np.where(first, b[i], value)])
    one_of, two_of = one.tolist(), two.tolist()
    seen = [False] * K
    out = []
    for start in np.concatenate([np.flatnonzero(degree == 1), np.flatnonzero(degree != 1)]).tolist():
        if seen[start]:
            continue
        chain, previous, node = [start], -1, start
        seen[start] = True
        while True:  # (to the first link not yet walked)
            n = one_of[node]
            if n < 0 or n == previous or seen[n]:
                n = two_of[node]
                if n < 0 or n == previous or seen[n]:
                    break
            previous, node = node, n
            chain.append(node)
            seen[node] = True
        closed = len(chain) > 2 and start in (one_of[chain[-1]], two_of[chain[-1]])
        if closed:
            chain.append(start)
        kinds = tuple(kinds_of[k] for k in chain)
        common = Counter(k for k in kinds if k is not None).most_common(1)
        out.append(Boundary(positions[chain], closed, common[0][0] if common else None, kinds))
    return out


def _position(c: Crossing, a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    return (c.value, float(b[c.i])) if c.axis == 0 else (float(a[c.j]), c.value)
