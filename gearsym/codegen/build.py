"""Building a :class:`CompiledModel`: from the process, the library cache, or from scratch.

Order of preference, cheapest first: a model already loaded in this process
(same code hash and backend); a compiled library in the cache; the committed
C in ``generated/<model>/`` if its manifest carries this model's hash; newly
generated C in the cache. Parameter values never enter the hash, so they
never cause any of this. The input is a :class:`FirstOrderSystem`: finding and
reducing models by name is the caller's (``gearsym.load``), not the code generator's.
"""
from __future__ import annotations

import os
import sys
import time
from dataclasses import replace
from pathlib import Path

from ..errors import GearsymError
from ..options import Integration
from ..files.atomic import writing
from ..files.private import CACHE_ADVICE
from ..system import FirstOrderSystem
from .code_files import code_directory, is_committed, lanes_describes, lanes_file, source_describes, source_file
from .compiled import CompiledModel
from .compiler import compile_library
from .functions import build_functions
from .generate import code_hash, write_code
from .library import library_describes, library_functions, model_key, resolve_backend
from .loaded import keep, loaded
from .loops import LoopOptions
from .native import load_native
from .fastest_mode import fastest_rate
from .step_choice import chosen
from .time_tables import split_rhs
from .trust import record, trusted


def compile_model(system: FirstOrderSystem, options: Integration = Integration(), *,
                  verbose: bool = False) -> CompiledModel:
    """Generate, compile (or take from the cache) and load the functions of ``system``.

    ``options`` (an :class:`~gearsym.options.Integration`) shape the code: its steps per period, whether
    steps that cross a backlash surface are split there, and the backend ("compiled", "in-process", or
    "auto": compiled if a C compiler exists, else in-process with a warning). Its run length is what the
    analyses use by default on the returned model. The system's parameter values become the model's
    defaults; they never enter the code, so another value never rebuilds anything. ``verbose`` says on
    stderr when it compiles (seconds, once).
    """
    if not isinstance(system, FirstOrderSystem):
        raise GearsymError(f"compile_model takes a FirstOrderSystem, got {_kind(system)}; for a model name or file "
                           "use gearsym.load(...) first, e.g. compile_model(gearsym.load('one_stage'))")
    if not isinstance(options, Integration):
        raise GearsymError(f"options must be a gearsym.Integration, got {type(options).__name__}")
    start = time.perf_counter()
    fastest = fastest_rate(system)
    options = chosen(options, fastest, system.cycle_at())  # the integrator and steps, from the fastest mode
    loops = LoopOptions.of(options, system.cycles)
    digest = code_hash(system, loops)
    timings = {"symbolic": time.perf_counter() - start}
    backend = resolve_backend(options.backend)
    key = model_key(digest, backend)
    found = loaded(key)
    if found is not None:  # same code: reuse the loaded functions, with this system's values and these options
        return replace(found.clone(), system=system, integration=options, fastest=fastest)
    if backend == "in-process":
        t = time.perf_counter()
        functions, library = build_functions(system, loops).functions, None
        timings["build"] = time.perf_counter() - t
    else:
        functions, library = _compiled_functions(system, loops, digest, timings, verbose)
    native = load_native(library, functions) if library else None
    timed, texts = timed_tables(system, loops)
    compiled = CompiledModel(system, loops, digest, functions, backend, library, timings, native, options,
                             timed, texts, fastest)
    return keep(key, compiled)


def timed_tables(system: FirstOrderSystem, loops: LoopOptions) -> tuple[frozenset[str], tuple[str, ...]]:
    """The parameters that enter the tables of time or the period, and the tables as text."""
    tables = [e for _, e in split_rhs(system, loops.locate_crossings).tables]
    names = frozenset(s.name for e in (*tables, system.period) for s in e.free_symbols) & set(system.parameters)
    return names, tuple(str(e) for e in tables)


def _compiled_functions(system: FirstOrderSystem, loops: LoopOptions, digest: str, timings: dict,
                        verbose: bool) -> tuple[dict, Path]:
    """The library of ``digest``: C from generated/ or the cache (generated here if missing or not the C gearsym
    wrote), compiled once."""
    code_dir = code_directory(system.name, digest)
    source = code_dir / source_file(system.name)
    lanes = code_dir / lanes_file(system.name)
    if not is_committed(code_dir, system.name) and (trusted(source, source_describes(system.name, digest)) is None
                                                    or trusted(lanes, lanes_describes(system.name, digest)) is None):
        t = time.perf_counter()
        mf = build_functions(system, loops)
        timings["build"] = time.perf_counter() - t
        t = time.perf_counter()
        with writing(code_dir, CACHE_ADVICE):  # (the cache's disk full: said as such)
            keep_generated(write_code(mf, code_dir, digest), system)
        timings["generate"] = time.perf_counter() - t
    lib = compile_library(source, system.name, announce=_to_stderr if verbose else None,
                          describes=library_describes(system, digest))
    if lib.compiled:
        timings["compile"] = lib.seconds
    return library_functions(lib.path), lib.path


def keep_generated(code, system) -> None:
    """Generated C of ``system`` just written into the cache (a :class:`~.generate.GeneratedCode`): made private and
    recorded, the model's C as the C of its library (its states and parameters too: a library damaged since is
    compiled again from it without the model, :func:`~.library.library_from_code`)."""
    for path in (code.manifest, code.source, code.lanes):
        os.chmod(path, 0o600)  # (the files were made with the umask's mode)
    record(code.source, code.source.read_bytes(), library_describes(system, code.hash))
    record(code.lanes, code.lanes.read_bytes(), lanes_describes(code.source.stem, code.hash))


def _kind(value) -> str:
    return f"the string {value!r}" if isinstance(value, str) else f"a {type(value).__name__}"


def _to_stderr(message: str) -> None:
    print(f"gearsym: {message}", file=sys.stderr, flush=True)


