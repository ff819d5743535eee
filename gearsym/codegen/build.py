"""Building a :class:`CompiledModel`: from the process, the library cache, or from scratch.

Order of preference, cheapest first: a model already loaded in this process
(same code hash and backend); a compiled library in the cache; the committed
C in ``generated/<model>/`` if its manifest carries this model's hash; newly
generated C in the cache. Parameter values never enter the hash, so they
never cause any of this.
"""
from __future__ import annotations

import sys
import time
from dataclasses import replace
from pathlib import Path

import casadi as ca

from ..errors import GearsymError
from ..system import FirstOrderSystem
from .compiled import CompiledModel
from .compiler import FALLBACK_NOTE, cache_dir, compile_library, compilers_looked_for, find_compiler
from .functions import LoopOptions, build_functions
from .generate import code_hash, read_manifest, write_code
from .native import load_native

BACKENDS = ("auto", "compiled", "in-process")

#: every function the generated library exports
FUNCTION_NAMES = ("rhs", "jacobian", "constants", "table", "lyapunov_chunk", "lyapunov_period",
                  "orbit_chunk", "orbit_period", "trajectory")

_LOADED: dict[tuple, CompiledModel] = {}
_WARNED = set()


def compile_model(
    model,
    *,
    steps_per_period: int = 200,
    backend: str = "auto",
    chunk_periods: int = 50,
    locate_crossings: bool = False,
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
    with a warning). ``verbose`` says on stderr when it compiles (seconds, once).
    ``locate_crossings``: split each RK4 step that crosses a backlash switching surface at the crossing
    (4th order Lyapunov exponents instead of 1st; see :mod:`gearsym.codegen.functions`).
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
    options = LoopOptions(steps_per_period=steps_per_period, chunk_periods=chunk_periods,
                          locate_crossings=bool(locate_crossings))
    digest = code_hash(system, options)
    timings = {"symbolic": time.perf_counter() - start}

    if backend == "auto":
        backend = "compiled" if find_compiler() else "in-process"
        if backend == "in-process" and "no-cc" not in _WARNED:
            _WARNED.add("no-cc")
            print(f"gearsym: warning: {FALLBACK_NOTE.format(what=compilers_looked_for())}", file=sys.stderr)
    key = (digest, backend)
    if key in _LOADED:  # same code: reuse the loaded functions, with these parameter values
        base = _LOADED[key]
        return replace(base.clone(), system=system, check=check)

    code_dir = code_directory(system.name, digest)
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
        lib = compile_library(source, system.name, announce=_to_stderr if verbose else None)
        if lib.compiled:
            timings["compile"] = lib.seconds
        library = lib.path
        functions = {name: ca.external(name, str(lib.path)) for name in FUNCTION_NAMES}
    native = load_native(library, functions) if library else None
    compiled = CompiledModel(system, options, digest, functions, backend, library, timings, check, native)
    _LOADED[key] = compiled
    return compiled


def compiled_and_values(model, settings: dict, *, steps_per_period: int = 200, backend: str = "auto",
                        verbose: bool = False, locate_crossings: bool = False) -> tuple[CompiledModel, dict]:
    """The two ways into every analysis: a prebuilt CompiledModel with ``settings`` as parameter values
    (the low-level call, nothing rebuilt), or a model compiled with ``settings`` as its defaults."""
    if isinstance(model, CompiledModel):
        return model, dict(settings)
    return compile_model(model, steps_per_period=steps_per_period, backend=backend, verbose=verbose,
                         locate_crossings=locate_crossings, **settings), {}


def code_directory(name: str, digest: str) -> Path:
    """Where the C of the code ``digest`` is: the committed ``generated/<model>/`` if its manifest carries
    this hash (no need to generate it again), else the cache."""
    committed = _generated_dir() / name
    if (read_manifest(committed) or {}).get("hash") == digest:
        return committed
    return cached_code_directory(name, digest)


def cached_code_directory(name: str, digest: str) -> Path:
    """Where the cache keeps the C of the code ``digest`` when it is generated (or received) here."""
    return cache_dir() / "code" / f"{name}-{digest[:16]}"


def _to_stderr(message: str) -> None:
    print(f"gearsym: {message}", file=sys.stderr, flush=True)


def _generated_dir() -> Path:
    from ..registry import REPO_ROOT  # registry imports the model layer; keep codegen importable alone
    return REPO_ROOT / "generated"
