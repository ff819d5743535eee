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
from dataclasses import dataclass

import numpy as np

from ..checks import json_safe


@dataclass(frozen=True)
class Crossing:
    """A boundary point on a grid line: along the first axis (``axis`` 0: between columns j and j + 1 of row i)
    or the second (``axis`` 1: between rows i and i + 1 of column j); ``value`` on that axis, located to within
    ``error``; ``kind``: the instability on its unstable side (at the last unstable point evaluated)."""

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


def grid_crossings(unstable: np.ndarray, valid: np.ndarray) -> list[tuple[int, int, int]]:
    """The grid lines' neighbours that differ in stability: (axis, i, j) as in :class:`Crossing`."""
    out = []
    along = valid[:, :-1] & valid[:, 1:] & (unstable[:, :-1] != unstable[:, 1:])
    out += [(0, int(i), int(j)) for i, j in zip(*np.nonzero(along))]
    across = valid[:-1, :] & valid[1:, :] & (unstable[:-1, :] != unstable[1:, :])
    out += [(1, int(i), int(j)) for i, j in zip(*np.nonzero(across))]
    return out


def refine(edges: list[tuple[int, int, int]], a: np.ndarray, b: np.ndarray, unstable: np.ndarray,
           kind: np.ndarray, evaluate: Evaluate, tolerance: tuple[float, float],
           progress: Callable[[int, int], None] | None = None) -> list[Crossing]:
    """Bisect every edge to ``tolerance`` (per axis), all edges of a round at once."""
    if not edges:
        return []
    E = len(edges)
    axis = np.array([e[0] for e in edges])
    i = np.array([e[1] for e in edges])
    j = np.array([e[2] for e in edges])
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
    return [Crossing(int(axis[e]), int(i[e]), int(j[e]), float((stable_end[e] + unstable_end[e]) / 2),
                     float(abs(unstable_end[e] - stable_end[e]) / 2), kinds[e], bool(located[e])) for e in range(E)]


def curves(crossings: list[Crossing], a: np.ndarray, b: np.ndarray, unstable: np.ndarray, valid: np.ndarray,
           largest: np.ndarray) -> list[Boundary]:
    """The crossings joined into curves (see the module docstring); with one grid line (a 1-D chart) each
    crossing is a boundary of one point."""
    at = {(c.axis, c.i, c.j): c for c in crossings}
    if len(b) == 1 or len(a) == 1:
        return [Boundary(np.array([_position(c, a, b)]), False, c.kind, (c.kind,)) for c in crossings]
    links: dict[tuple, list[tuple]] = {key: [] for key in at}
    cells = set()  # the cells a crossing borders
    for axis, i, j in at:
        cells |= {(i, j), (i - 1, j)} if axis == 0 else {(i, j), (i, j - 1)}
    whole = (valid[:-1, :-1] & valid[1:, :-1] & valid[:-1, 1:] & valid[1:, 1:]).tolist()
    corner = unstable.tolist()
    for ci, cj in sorted(cells):
        if not (0 <= ci < len(b) - 1 and 0 <= cj < len(a) - 1) or not whole[ci][cj]:
            continue
        bottom, top, left, right = (0, ci, cj), (0, ci + 1, cj), (1, ci, cj), (1, ci, cj + 1)
        present = [e for e in (bottom, right, top, left) if e in at]
        if len(present) == 2:
            pairs = [tuple(present)]
        elif len(present) == 4:
            centre = float(np.mean(largest[ci:ci + 2, cj:cj + 2])) > 1.0
            if corner[ci][cj] == centre:  # the corner (ci, cj) joins the centre: cut off the other two
                pairs = [(bottom, right), (top, left)]
            else:
                pairs = [(bottom, left), (top, right)]
        else:
            continue
        for p, q in pairs:
            links[p].append(q)
            links[q].append(p)
    seen, out = set(), []
    starts = [k for k, v in links.items() if len(v) == 1] + [k for k, v in links.items() if len(v) != 1]
    for start in starts:
        if start in seen:
            continue
        chain, previous, node = [start], None, start
        seen.add(start)
        while True:
            following = [n for n in links[node] if n != previous and n not in seen]
            if not following:
                break
            previous, node = node, following[0]
            chain.append(node)
            seen.add(node)
        closed = len(chain) > 2 and start in links[chain[-1]]
        kinds = tuple(at[k].kind for k in chain)
        points = np.array([_position(at[k], a, b) for k in chain])
        if closed:
            points = np.vstack([points, points[:1]])
            kinds = kinds + kinds[:1]
        common = Counter(k for k in kinds if k is not None).most_common(1)
        out.append(Boundary(points, closed, common[0][0] if common else None, kinds))
    return out


def _position(c: Crossing, a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    return (c.value, float(b[c.i])) if c.axis == 0 else (float(a[c.j]), c.value)
