"""A model's library through CasADi and the backend a run asks for: what a cached start-up needs.

The models this process loaded are kept in the one table of :mod:`.loaded`, under :func:`model_key`.
Nothing here needs SymPy; CasADi is imported only when a function is asked of it (a run of the compiled backend
calls the library directly, :mod:`.native`, and never does).
"""
from __future__ import annotations

import sys
from collections.abc import Iterator, Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from ..options import Integration
from .compiled import CompiledModel
from .code_files import code_directory, is_committed, read_manifest, source_file
from .compiler import FALLBACK_NOTE, compile_library, compilers_looked_for, find_compiler
from .loaded import keep, loaded
from .loops import LoopOptions
from .native import load_native
from .trust import check, differences

if TYPE_CHECKING:
    import casadi as ca

#: every function the generated library exports
FUNCTION_NAMES = ("rhs", "jacobian", "constants", "table", "lyapunov_chunk", "lyapunov_period",
                  "orbit_chunk", "orbit_period", "trajectory", "monodromy_segment", "monodromy_period")

_WARNED = set()


def model_key(digest: str, backend: str) -> tuple:
    """The key of a compiled model in the process's table (:mod:`.loaded`): its code and its backend."""
    return ("model", digest, backend)


def resolve_backend(asked: str) -> str:
    """"auto" is compiled where a C compiler exists (else in-process, said once on stderr)."""
    if asked != "auto":
        return asked
    if find_compiler():
        return "compiled"
    if "no-cc" not in _WARNED:
        _WARNED.add("no-cc")
        print(f"gearsym: warning: {FALLBACK_NOTE.format(what=compilers_looked_for())}", file=sys.stderr)
    return "in-process"


class LibraryFunctions(Mapping):
    """The generated functions of the library at ``path`` through CasADi (``casadi.external``), each loaded when
    first asked for: a run that calls the library directly never imports CasADi."""

    def __init__(self, path: Path):
        self.path = path
        self._loaded: dict[str, ca.Function] = {}

    def __getitem__(self, name: str) -> ca.Function:
        if name not in FUNCTION_NAMES:
            raise KeyError(name)
        if name not in self._loaded:
            import casadi as ca

            self._loaded[name] = ca.external(name, str(self.path))
        return self._loaded[name]

    def __iter__(self) -> Iterator[str]:
        return iter(FUNCTION_NAMES)

    def __len__(self) -> int:
        return len(FUNCTION_NAMES)


def library_functions(path: Path) -> LibraryFunctions:
    """The generated functions of the library at ``path``, through CasADi (loaded on first use)."""
    return LibraryFunctions(path)


def library_describes(system, digest: str) -> dict:
    """What a model's library is, as its record keeps it: a summary that points at it is checked against this
    (``system``: a FirstOrderSystem or the start-up cache's summary of one)."""
    return {"model": system.name, "code": digest, "states": list(system.state_names),
            "parameters": list(system.parameters)}


def library_model(system, digest: str, library: Path, options: Integration, timed: frozenset[str],
                  table_texts: tuple[str, ...], fastest: float = 0.0) -> CompiledModel:
    """The compiled model of ``system`` whose ``library`` (compiled and checked before) holds the code ``digest``:
    the one this process loaded already, with its functions' work arrays of its own, else the library loaded here
    and kept (:mod:`.loaded`)."""
    key = model_key(digest, "compiled")
    found = loaded(key)
    if found is not None:
        return replace(found.clone(), system=system, integration=options)
    loops = LoopOptions.of(options, system.cycles)  # (the key's loops count steps per forcing period)
    functions = library_functions(library)
    return keep(key, CompiledModel(system, loops, digest, functions, "compiled", library, {},
                                   load_native(library, functions), options, timed, table_texts, fastest))


def library_from_code(system, digest: str, announce=None) -> Path | None:
    """The library of the code ``digest`` of ``system`` (a start-up cache's summary) compiled from its C, without
    the model (no SymPy, no reduction): the C of the committed ``generated/<model>/``, whose manifest names this
    code, these states and parameters, or the cache's C, whose record says it is this library's C (its bytes as
    gearsym wrote them). None when neither vouches for it: the caller loads the model and generates the C.
    ``announce(message)`` is told before the compiler runs (seconds)."""
    describes = library_describes(system, digest)
    code_dir = code_directory(system.name, digest)
    source = code_dir / source_file(system.name)
    if is_committed(code_dir, system.name):
        manifest = read_manifest(code_dir) or {}
        said = {"model": manifest.get("model"), "code": manifest.get("hash"), "states": manifest.get("states"),
                "parameters": manifest.get("parameters")}
    else:
        verdict = check(source)  # (silent: a C not to trust is said once, by the compile that makes it again)
        said = verdict.describes if verdict.data is not None else None
    if said is None or differences(said, describes) is not None:
        return None
    return compile_library(source, system.name, announce=announce, describes=describes).path
