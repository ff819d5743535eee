"""A model's loops, compiled (or evaluated in-process), behind one small object.

:func:`compile_model` is the high-level entry (a model name and settings in,
a :class:`CompiledModel` out, from the cache when it can); the analyses in
:mod:`gearsym.analysis` take a ``CompiledModel`` so that a sweep builds it once
and only changes the parameter vector.
"""
from __future__ import annotations

import sys
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import casadi as ca
import numpy as np

from ..errors import GearsymError, ModelError, UnknownParameterError
from ..system import FirstOrderSystem
from .compiler import CompilerError, cache_dir, compile_library, find_compiler, NO_COMPILER_HINT
from .functions import LoopOptions, build_functions
from .generate import code_hash, read_manifest, write_code

BACKENDS = ("auto", "compiled", "in-process")

#: every function the generated library exports
FUNCTION_NAMES = ("rhs", "jacobian", "constants", "table", "lyapunov_chunk", "lyapunov_period",
                  "orbit_chunk", "orbit_period", "trajectory")


@dataclass(frozen=True)
class RunInputs:
    """What the loops need for one parameter point, computed once: tables of time and constants."""

    p: np.ndarray
    table: ca.DM
    constants: ca.DM
    period: float
    t0: float


@dataclass(frozen=True)
class TangentRun:
    """Raw output of ``periods`` forcing periods with tangent vectors."""

    strobe: np.ndarray  # n x periods: the state after each period
    log_stretch: np.ndarray  # n x periods: log of each Gram-Schmidt norm
    low: np.ndarray  # observed x periods: minimum over each period's steps
    high: np.ndarray
    Q: np.ndarray  # final orthonormal tangent vectors (columns)


@dataclass
class CompiledModel:
    """One model's generated functions, for any parameter values."""

    system: FirstOrderSystem
    options: LoopOptions
    hash: str
    functions: Mapping[str, ca.Function]
    backend: str  # "compiled" | "in-process"
    library: Path | None = None
    timings: dict[str, float] = field(default_factory=dict)
    check: Callable[[str, float], float] | None = None

    # ---------------------------------------------------------------- names
    @property
    def name(self) -> str:
        return self.system.name

    @property
    def dimension(self) -> int:
        return self.system.dimension

    @property
    def state_names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.system.states)

    @property
    def observed(self) -> tuple[str, ...]:
        return tuple(s for s in self.state_names if s in self.system.observed)

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(self.system.parameters)

    @property
    def steps_per_period(self) -> int:
        return self.options.steps_per_period

    # ---------------------------------------------------------------- inputs
    def parameter_vector(self, values: Mapping[str, float] | None = None, **more: float) -> np.ndarray:
        """The model's parameter vector: its values, with ``values``/``more`` overriding (names checked)."""
        merged = dict(self.system.parameters)
        for name, value in {**(values or {}), **more}.items():
            if name not in merged:
                raise UnknownParameterError(name, merged, self.name)
            merged[name] = self.check(name, value) if self.check else float(value)
        return np.array([merged[n] for n in self.parameter_names], dtype=float)

    def prepare(self, p: np.ndarray | Mapping[str, float] | None = None, t0: float = 0.0) -> RunInputs:
        p = self.parameter_vector(p) if p is None or isinstance(p, Mapping) else np.asarray(p, dtype=float)
        if p.shape != (len(self.parameter_names),):
            raise GearsymError(f"{self.name}: expected {len(self.parameter_names)} parameter values "
                               f"({', '.join(self.parameter_names)}), got shape {p.shape}")
        c, period = self.functions["constants"](p)
        period = float(period)
        if not (np.isfinite(period) and period > 0):
            raise ModelError(f"the forcing period is {period} at these parameter values; it must be positive",
                             self.name)
        table = self.functions["table"](t0, p)
        return RunInputs(p, table, c, period, float(t0))

    def initial_state(self, y0=None) -> np.ndarray:
        if y0 is None:
            return np.array(self.system.initial_vector)
        if isinstance(y0, Mapping):
            unknown = set(y0) - set(self.state_names)
            if unknown:
                raise GearsymError(f"{self.name}: unknown states {sorted(unknown)} in the initial state; "
                                   f"states are {', '.join(self.state_names)}")
            return np.array([float(y0.get(s, 0.0)) for s in self.state_names])
        y = np.asarray(y0, dtype=float).reshape(-1)
        if y.shape != (self.dimension,):
            raise GearsymError(f"{self.name}: the initial state needs {self.dimension} values "
                               f"({', '.join(self.state_names)}), got {y.size}")
        return y

    # ---------------------------------------------------------------- runs
    def tangent_run(self, y0, periods: int, inputs: RunInputs, Q0=None) -> TangentRun:
        """``periods`` forcing periods of the state and n tangent vectors, re-orthonormalised every period."""
        n = self.dimension
        y = ca.DM(self.initial_state(y0))
        Q = ca.DM(np.eye(n) if Q0 is None else np.asarray(Q0, dtype=float))
        parts = []
        for fname, count in self._schedule(periods, "lyapunov"):
            f = self.functions[fname]
            for _ in range(count):
                strobe, Q, logs, low, high = f(y, Q, inputs.table, inputs.constants)
                y = strobe[:, -1]
                parts.append((strobe, logs, low, high))
        strobe, logs, low, high = (_hcat([p[i] for p in parts], rows) for i, rows in
                                   enumerate((n, n, len(self.observed), len(self.observed))))
        return TangentRun(strobe, logs, low, high, np.array(Q))

    def orbit_run(self, y0, periods: int, inputs: RunInputs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The state after each of ``periods`` periods (stroboscopic samples), with each period's min and max."""
        y = ca.DM(self.initial_state(y0))
        parts = []
        for fname, count in self._schedule(periods, "orbit"):
            f = self.functions[fname]
            for _ in range(count):
                strobe, low, high = f(y, inputs.table, inputs.constants)
                y = strobe[:, -1]
                parts.append((strobe, low, high))
        m = len(self.observed)
        return tuple(_hcat([p[i] for p in parts], rows) for i, rows in enumerate((self.dimension, m, m)))

    def trajectory(self, y0, periods: int, inputs: RunInputs) -> tuple[np.ndarray, np.ndarray]:
        """Every RK4 step of ``periods`` periods: times (steps,) and states (n, steps), the start included."""
        y = ca.DM(self.initial_state(y0))
        cols = [np.array(y)]
        for _ in range(periods):
            states = self.functions["trajectory"](y, inputs.table, inputs.constants)
            cols.append(np.array(states))
            y = states[:, -1]
        states = np.hstack(cols)
        h = inputs.period / self.steps_per_period
        return inputs.t0 + h * np.arange(states.shape[1]), states

    def rhs(self, t: float, y, p) -> np.ndarray:
        return np.array(self.functions["rhs"](t, y, p)).reshape(-1)

    def jacobian(self, t: float, y, p) -> np.ndarray:
        return np.array(self.functions["jacobian"](t, y, p))

    def _schedule(self, periods: int, kind: str) -> list[tuple[str, int]]:
        if periods < 0:
            raise GearsymError(f"the number of periods must not be negative, got {periods}")
        chunks, rest = divmod(int(periods), self.options.chunk_periods)
        return [(f"{kind}_chunk", chunks), (f"{kind}_period", rest)]


def _generated_dir() -> Path:
    from ..registry import REPO_ROOT
    return REPO_ROOT / "generated"


def _hcat(blocks, rows: int) -> np.ndarray:
    return np.hstack([np.array(b) for b in blocks]) if blocks else np.zeros((rows, 0))


# ============================================================================ building
_LOADED: dict[tuple, CompiledModel] = {}
_WARNED = set()


def compile_model(
    model,
    *,
    steps_per_period: int = 200,
    backend: str = "auto",
    chunk_periods: int = 50,
    verbose: bool = False,
    **settings,
) -> CompiledModel:
    """Generate, compile (or take from the cache) and load a model's functions.

    ``model`` is a model name, a path, a Drivetrain, a NondimensionalModel or a
    FirstOrderSystem; ``settings`` give parameter values or replace a mesh
    stiffness (``k="1 + 0.2*cos(tau)"``). Parameter values never change the
    code; they become the defaults of the returned object.
    ``backend``: "compiled" (fail without a C compiler), "in-process" (CasADi's
    virtual machine) or "auto" (compiled if a compiler exists, else in-process
    with a warning).
    """
    from ..reduce import NondimensionalModel, reduce
    from ..registry import load_model, system_for

    if backend not in BACKENDS:
        raise GearsymError(f"unknown backend {backend!r}; choose one of {', '.join(BACKENDS)}")
    start = time.perf_counter()
    loaded = model if isinstance(model, (FirstOrderSystem, NondimensionalModel)) else load_model(model)
    check = None
    if isinstance(loaded, FirstOrderSystem):
        system = system_for(loaded, **settings)
    else:
        nd = loaded if isinstance(loaded, NondimensionalModel) else reduce(loaded)
        system = system_for(nd, **settings)
        check = nd.check_value
    options = LoopOptions(steps_per_period=steps_per_period, chunk_periods=chunk_periods)
    digest = code_hash(system, options)
    timings = {"symbolic": time.perf_counter() - start}

    if backend == "auto":
        backend = "compiled" if find_compiler() else "in-process"
        if backend == "in-process" and "no-cc" not in _WARNED:
            _WARNED.add("no-cc")
            print(f"gearsym: warning: {NO_COMPILER_HINT.format(what='$CC, cc, gcc, clang')}", file=sys.stderr)
    key = (digest, backend)
    if key in _LOADED:  # same code: reuse the loaded functions, with these parameter values
        base = _LOADED[key]
        return CompiledModel(system, options, digest, base.functions, backend, base.library, dict(base.timings), check)

    code_dir = cache_dir() / "code" / f"{system.name}-{digest[:16]}"
    committed = _generated_dir() / system.name
    if (read_manifest(committed) or {}).get("hash") == digest:
        code_dir = committed  # the committed C of this very model: no need to generate it again
    library = None
    if backend == "in-process":
        t = time.perf_counter()
        functions = build_functions(system, options).functions
        timings["build"] = time.perf_counter() - t
    else:
        manifest = read_manifest(code_dir)
        source = code_dir / f"{system.name}.c"
        if not (manifest and manifest.get("hash") == digest and source.is_file()):
            t = time.perf_counter()
            mf = build_functions(system, options)
            timings["build"] = time.perf_counter() - t
            t = time.perf_counter()
            write_code(mf, code_dir, digest)
            timings["generate"] = time.perf_counter() - t
        if verbose:
            print(f"gearsym: compiling {system.name} ({source})", file=sys.stderr)
        lib = compile_library(source, system.name)
        if lib.compiled:
            timings["compile"] = lib.seconds
        library = lib.path
        functions = {name: ca.external(name, str(lib.path)) for name in FUNCTION_NAMES}
    compiled = CompiledModel(system, options, digest, functions, backend, library, timings, check)
    _LOADED[key] = compiled
    return compiled
