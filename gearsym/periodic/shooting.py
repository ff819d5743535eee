"""The period-n stroboscopic map of a forced model, its exact Jacobian, and Newton on P^n(y) - y = 0.

One forcing period of the state and of the raw tangent matrix comes from the generated
``monodromy_period`` (the same crossing-located RK4 steps as every run, the exact variational equations
Q' = J Q along them): the derivative of the map by the state is exact to the integration's accuracy. The
right-hand side is continuous across the backlash (g is), so no saltation matrix is needed where a tooth
takes up or leaves contact: only J jumps there, and each substep of a located step integrates its own.

*Multiple shooting* cuts the orbit of n periods into K = n * segments pieces with a state each,
z_0 ... z_(K-1), and asks for continuity: phi_k(z_k) - z_(k+1) = 0 (z_K = z_0). The Jacobian is block
cyclic (M_k on the diagonal, -I beside it); the monodromy matrix is M_(K-1) ... M_0. A strongly unstable
orbit (multipliers of 1e8 and more) or a long one (period 8) keeps a well conditioned Newton system
that way, where one shot over the whole orbit would lose every digit to the growth of M.

The derivative of the map by a parameter is a forward finite difference of the compiled map (one more
shot at parameter + h): the parameter enters the tables of time and the constants in ways the
generated code does not differentiate, and the Newton iteration needs it only for its one column (an
error of 1e-7 in it slows convergence by as little), while the fold test reads the tangent's parameter
component, which vanishes where M - I is singular whatever that column holds.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..checks import whole_number
from ..codegen import CompiledModel, RunInputs
from ..codegen.loops import SHOOTING_SEGMENTS
from ..errors import GearsymError

#: Newton stops when every residual component is below this times (1 + the largest |state|)
TOLERANCE = 1e-10
#: relative step of the finite difference in the parameter
PARAMETER_STEP = 1e-7
#: shooting systems with more unknowns than this are solved as sparse matrices (a long orbit's)
SPARSE_ABOVE = 400


@dataclass(frozen=True)
class Shooting:
    """How an orbit is shot: ``period_multiple`` periods (a period-n orbit), each in ``segments`` pieces
    (multiple shooting; 1, 2 or 4 when the steps per period divide by 4; for a period of several forcing
    periods, a gear's revolution, a multiple of them: one or more per mesh period)."""

    period_multiple: int = 1
    segments: int = 1

    def __post_init__(self):
        object.__setattr__(self, "period_multiple", whole_number(self.period_multiple, "the period multiple", 1))
        object.__setattr__(self, "segments", whole_number(self.segments, "segments per period", 1))

    @property
    def count(self) -> int:
        """Shooting segments over the whole orbit."""
        return self.period_multiple * self.segments

    def doubled(self) -> "Shooting":
        return Shooting(2 * self.period_multiple, self.segments)


def pieces_per_period(steps_per_period: int) -> int:
    """The pieces the generated code cuts a forcing period into (``monodromy_segment``): up to
    ``SHOOTING_SEGMENTS``, the largest number the steps divide into; known before the code is built."""
    return max(d for d in range(1, SHOOTING_SEGMENTS + 1) if steps_per_period % d == 0)


def check_segments(segments: int, pieces: int, where: str = "", steps: int | None = None) -> None:
    """``segments`` shooting segments per period must divide the period's ``pieces``."""
    if pieces % segments:
        allowed = ", ".join(str(d) for d in range(1, pieces + 1) if pieces % d == 0)
        raise GearsymError(f"{where}{segments} shooting segments per period do not divide the period's {pieces} pieces"
                           + (f" ({steps} steps)" if steps else "") + f": choose {allowed}")


@dataclass
class Evaluation:
    """The residual and Jacobian blocks of the shooting problem at one (z, parameter)."""

    z: np.ndarray  # (K, n): the segments' start states
    value: float  # the parameter
    inputs: RunInputs
    landing: np.ndarray  # (K, n): phi_k(z_k)
    blocks: list  # K matrices M_k = d phi_k / d z_k
    low: np.ndarray  # (observed,): the minimum over every step of the orbit
    high: np.ndarray
    d_parameter: np.ndarray | None = None  # (K, n): d phi_k / d parameter, when asked for
    _monodromy: np.ndarray | None = field(default=None, repr=False)
    _residual: np.ndarray | None = field(default=None, repr=False)

    @property
    def residual(self) -> np.ndarray:
        """phi_k(z_k) - z_(k+1), flattened (made once: Newton and its tests read it several times)."""
        if self._residual is None:
            r = self.landing - self.z[0]
            r[:-1] = self.landing[:-1] - self.z[1:]
            self._residual = r.reshape(-1)
        return self._residual

    def error(self) -> float:
        return float(np.abs(self.residual).max() / (1.0 + np.abs(self.z).max()))

    def jacobian(self) -> np.ndarray:
        """d residual / d z: M_k on the diagonal blocks, -I on the next block (cyclically)."""
        K, n = self.z.shape
        J = np.zeros((K * n, K * n))
        for k, M in enumerate(self.blocks):
            J[k * n:(k + 1) * n, k * n:(k + 1) * n] = M
            nxt = (k + 1) % K
            J[k * n:(k + 1) * n, nxt * n:(nxt + 1) * n] -= np.eye(n)
        return J

    def newton_step(self) -> np.ndarray:
        """The Newton step -J^-1 r (K x n). A long orbit (a revolution of hundreds of mesh periods, shot once per
        mesh period) has a block-cyclic Jacobian of 2 K n^2 nonzeros: it is solved as the sparse system it is."""
        K, n = self.z.shape
        if K * n <= SPARSE_ABOVE:
            return np.linalg.solve(self.jacobian(), -self.residual).reshape(self.z.shape)
        from scipy.sparse import coo_matrix
        from scipy.sparse.linalg import spsolve

        rows, cols, values = [], [], []
        block_rows, block_cols = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        for k, M in enumerate(self.blocks):
            rows.append(k * n + block_rows.ravel())
            cols.append(k * n + block_cols.ravel())
            values.append(np.asarray(M).ravel())
            nxt = (k + 1) % K
            rows.append(k * n + np.arange(n))
            cols.append(nxt * n + np.arange(n))
            values.append(-np.ones(n))
        J = coo_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(K * n, K * n)).tocsc()
        step = spsolve(J, -self.residual)
        if not np.all(np.isfinite(step)):
            raise np.linalg.LinAlgError("singular shooting system")
        return np.asarray(step).reshape(self.z.shape)

    @property
    def monodromy(self) -> np.ndarray:
        """M_(K-1) ... M_0: the Jacobian of the period-n map at z_0."""
        if self._monodromy is None:
            M = self.blocks[0]
            for B in self.blocks[1:]:
                M = B @ M
            self._monodromy = M
        return self._monodromy


class OrbitMap:
    """The shooting problem of one compiled model: the period-n map at any value of one parameter (or of
    none), with every other parameter held at ``values``."""

    def __init__(self, model: CompiledModel, shooting: Shooting, parameter: str | None = None,
                 values: dict | None = None):
        self.model, self.shooting, self.parameter = model, shooting, parameter
        self.p = model.parameter_vector(values or {})
        S = model.shooting_pieces
        check_segments(shooting.segments, S, f"{model.name}: ", model.steps_per_period)
        self.pieces = S // shooting.segments
        self.index = None if parameter is None else model.parameter_names.index(parameter)
        self.n = model.dimension
        self._inputs: RunInputs = model.prepare(self.p)
        self._kept: dict[float, RunInputs] = {}

    @property
    def value(self) -> float | None:
        return None if self.index is None else float(self.p[self.index])

    def inputs(self, value: float | None) -> RunInputs:
        """The run inputs at ``value`` of the parameter (the last few kept: Newton and its finite difference
        ask for the same ones again and again)."""
        if self.index is None or value is None or value == self._inputs.p[self.index]:
            return self._inputs
        kept = self._kept.get(value)
        if kept is None:
            if not np.isfinite(value):
                raise GearsymError(f"{self.model.name}: {self.parameter} became {value} in the continuation")
            p = self._inputs.p.copy()
            p[self.index] = value
            kept = self._kept[value] = self.model.retune(self._inputs, p)
            if len(self._kept) > 4:
                del self._kept[next(iter(self._kept))]
        return kept

    def period(self, value: float | None = None) -> float:
        """The orbit's period in the model's time: n forcing periods."""
        return self.shooting.period_multiple * self.inputs(value).period

    def evaluate(self, z: np.ndarray, value: float | None = None, d_parameter: bool = False) -> Evaluation:
        """Every segment shot from its start in ``z`` (K x n), with its Jacobian; with ``d_parameter``, the
        derivative of the landings by the parameter too (a forward difference)."""
        inputs = self.inputs(value)
        landing, blocks, low, high = self._shots(z, inputs)
        ev = Evaluation(z, value, inputs, landing, blocks, low, high)
        if d_parameter:
            if self.index is None:
                raise GearsymError("the shooting problem has no parameter to differentiate by")
            h = PARAMETER_STEP * max(1.0, abs(value))
            shifted, _, _, _ = self._shots(z, self.inputs(value + h))
            ev.d_parameter = (shifted - landing) / h
        return ev

    def _shots(self, z: np.ndarray, inputs: RunInputs):
        K, m = self.shooting.count, self.shooting.segments
        landing, blocks = np.empty_like(z), []
        low = high = None
        for k in range(K):
            shot = self.model.shoot(z[k], inputs, self.pieces, first=(k % m) * self.pieces)
            landing[k] = shot.state
            blocks.append(shot.M)
            low = shot.low if low is None else np.minimum(low, shot.low)
            high = shot.high if high is None else np.maximum(high, shot.high)
        return landing, blocks, low, high

    def spread(self, y0: np.ndarray, value: float | None = None) -> np.ndarray:
        """Start states of every segment from one state at the section: the trajectory from ``y0`` (K x n)."""
        inputs = self.inputs(value)
        z = np.empty((self.shooting.count, self.n))
        z[0] = y0
        for k in range(1, self.shooting.count):
            m = self.shooting.segments
            z[k] = self.model.shoot(z[k - 1], inputs, self.pieces, first=((k - 1) % m) * self.pieces).state
        return z


def newton(problem: OrbitMap, z: np.ndarray, value: float | None = None, *, max_iterations: int = 40,
           tolerance: float = TOLERANCE) -> tuple[Evaluation, int]:
    """Newton on the shooting residual at a fixed parameter value, with step halving when the residual
    grows (a start far from the orbit). Returns the evaluation at the solution and the iterations taken;
    raises :class:`NotConverged` if it does not get there."""
    ev = problem.evaluate(z, value)
    for iteration in range(max_iterations + 1):
        if ev.error() <= tolerance:
            return ev, iteration
        try:
            step = ev.newton_step()
        except np.linalg.LinAlgError:
            break
        scale, before = 1.0, np.linalg.norm(ev.residual)
        for _ in range(12):  # halve the step until the residual does not grow much
            trial = _try_evaluate(problem, ev.z + scale * step, value)
            if trial is not None and np.linalg.norm(trial.residual) < max(before, 1e-300) * 2.0:
                break
            scale /= 2
        else:
            break
        ev = trial
    raise NotConverged(f"no periodic orbit found: Newton's residual stayed at {ev.error():.2g} "
                       f"(relative to the state) after {max_iterations} iterations")


def _try_evaluate(problem: OrbitMap, z: np.ndarray, value, d_parameter: bool = False) -> Evaluation | None:
    """``problem.evaluate``, or None where the shot diverges (a Newton step thrown too far)."""
    if not np.all(np.isfinite(z)):
        return None
    try:
        return problem.evaluate(z, value, d_parameter)
    except GearsymError:
        return None


class NotConverged(GearsymError):
    """Newton did not reach a periodic orbit."""
