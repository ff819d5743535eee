"""A compiled model that travels to another process or machine (a Dask worker), and is loaded there.

:func:`ship` packs what a worker needs, all of it picklable: the
:class:`FirstOrderSystem` (a few KB of SymPy), the :class:`LoopOptions`, the
code hash and backend; for the compiled backend also the library's bytes and
file name, the flags it was built with, the :func:`binary_key` of the machine
that built it, and the generated C source (about 0.3 MB each way).

:func:`load_shipped`, on the worker:

* compiled backend, same binary key (same system, architecture, C library
  and, for ``-march=native``, CPU): the shipped bytes are written into the
  worker's library cache under the name :func:`compile_library` gave them
  (atomically; kept if already there) and loaded. No compiler is needed, and
  the results are the client's to the bit.
* compiled backend, another binary key: the shipped C is compiled there with
  the shipped flags (:func:`compile_library`, cached like any library). The
  worker needs a C compiler; with ``-march=native`` its results may differ
  from the client's in the last bits (another CPU, other instructions).
* in-process backend: the CasADi functions are rebuilt from the system
  (0.05-0.1 s; CasADi's own serialisation would carry 1-2 MB instead of a few
  KB). The worker's code hash must equal the shipped one, which proves it
  builds the same functions.

Parameter checks travel with the system (its ``constraints``); a sweep checks
every value on the client before any work anyway.
"""
from __future__ import annotations

import logging
import os
import socket
import time
from dataclasses import dataclass
from pathlib import Path

import casadi as ca

from ..errors import GearsymError
from ..options import Integration
from ..files.atomic import writing
from ..files.private import CACHE_ADVICE, write_private
from ..system import FirstOrderSystem
from ..version import __version__
from .build import keep_generated
from .code_files import cached_code_directory, code_directory, is_committed, source_describes, source_file
from .compiled import CompiledModel
from .compiler import CompilerError, binary_key, compile_flags, compile_library, library_path
from .functions import build_functions
from .loops import LoopOptions
from .generate import code_hash, write_code
from .library import library_describes, library_functions
from .native import load_native
from .trust import record, trusted

log = logging.getLogger("gearsym")


@dataclass(frozen=True)
class ShippedModel:
    """Everything a worker needs to load one CompiledModel (pickles to a few KB, plus the library and C)."""

    system: FirstOrderSystem
    options: LoopOptions
    integration: Integration
    hash: str
    backend: str  # "compiled" | "in-process"
    versions: tuple[str, str]  # gearsym and casadi of the client
    library_name: str = ""  # compiled backend: the file name compile_library gave it
    library: bytes = b""
    flags: tuple[str, ...] = ()
    binary_key: str = ""  # of the machine that built ``library``
    source: bytes = b""  # the generated C, to rebuild elsewhere
    timed: frozenset[str] = frozenset()  # the parameters in the tables of time (CompiledModel.timed)
    table_texts: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        return self.system.name

    def __repr__(self) -> str:  # Dask shows it in errors and on its dashboard: no SymPy, no bytes
        built = f", library built for {self.binary_key}" if self.library else ""
        return f"ShippedModel({self.name}, code {self.hash[:12]}, {self.backend}{built})"


def ship(compiled: CompiledModel) -> ShippedModel:
    """``compiled`` packed for another process or machine (see the module docstring)."""
    system = compiled.system.full  # (a cached model's summary: the system it stands for)
    base = dict(system=system, options=compiled.options, integration=compiled.integration,
                hash=compiled.hash, backend=compiled.backend, versions=_versions(), timed=compiled.timed,
                table_texts=compiled.table_texts)
    if compiled.backend != "compiled":
        return ShippedModel(**base)
    name = compiled.name
    code_dir = code_directory(name, compiled.hash)
    source = code_dir / source_file(name)
    if not is_committed(code_dir, name) and trusted(source, source_describes(name, compiled.hash)) is None:
        # (the cache was cleaned since the library was built, or its C is not what gearsym wrote: generate it)
        with writing(code_dir, CACHE_ADVICE):
            keep_generated(write_code(build_functions(system, compiled.options), code_dir, compiled.hash), system)
    library = trusted(compiled.library, library_describes(system, compiled.hash))
    if library is None:
        raise GearsymError(f"{compiled.library} changed since it was loaded; run again to compile it anew")
    flags = compile_flags()
    return ShippedModel(**base, library_name=compiled.library.name, library=library,
                        flags=flags, binary_key=binary_key(flags), source=source.read_bytes())


def load_shipped(shipped: ShippedModel) -> CompiledModel:
    """Load a shipped model in this process: from its bytes, rebuilt from its C, or (in-process) from its system."""
    start = time.perf_counter()
    mine = _versions()
    if mine != shipped.versions:
        raise GearsymError(
            f"{_host()} runs gearsym {mine[0]} with casadi {mine[1]}, the client gearsym {shipped.versions[0]} "
            f"with casadi {shipped.versions[1]}: install the same versions on every worker")
    if shipped.backend != "compiled":
        if code_hash(shipped.system, shipped.options) != shipped.hash:
            raise GearsymError(f"{_host()}: its gearsym generates other code for {shipped.name} than the client's "
                               "(the code hash differs); install the same gearsym on every worker")
        functions = build_functions(shipped.system, shipped.options).functions
        return CompiledModel(shipped.system, shipped.options, shipped.hash, functions, "in-process",
                             timings={"load": time.perf_counter() - start}, integration=shipped.integration,
                             timed=shipped.timed, table_texts=shipped.table_texts)
    timings = {}
    if shipped.binary_key == binary_key(shipped.flags):
        path = _write_library(shipped)
    else:
        path = _rebuild(shipped, timings)
    functions = library_functions(path)
    timings["load"] = time.perf_counter() - start
    return CompiledModel(shipped.system, shipped.options, shipped.hash, functions, "compiled", path, timings,
                         load_native(path, functions), shipped.integration, shipped.timed, shipped.table_texts)


def _write_library(shipped: ShippedModel) -> Path:
    """The shipped bytes in this machine's cache, under the name compile_library gave them (atomically, with the
    record of what they are: the client built them)."""
    target = library_path(shipped.library_name)
    describes = library_describes(shipped.system, shipped.hash)
    if trusted(target, describes) != shipped.library:  # (e.g. a worker on the client's machine has it already)
        record(target, shipped.library, describes)
        write_private(target, shipped.library, 0o700)  # concurrent workers write the same bytes
    return target


def _rebuild(shipped: ShippedModel, timings: dict) -> Path:
    """The shipped C compiled here (the library was built for another system, CPU or C library)."""
    source = cached_code_directory(shipped.name, shipped.hash) / source_file(shipped.name)
    if trusted(source, source_describes(shipped.name, shipped.hash)) != shipped.source:
        record(source, shipped.source, source_describes(shipped.name, shipped.hash))
        write_private(source, shipped.source)
    try:
        lib = compile_library(source, shipped.name, flags=shipped.flags,
                              describes=library_describes(shipped.system, shipped.hash))
    except CompilerError as exc:
        raise CompilerError(f"{_host()}: the {shipped.name} library sent by the client was built for another "
                            f"system, CPU or C library, so this worker compiles it and cannot: {exc}") from None
    if lib.compiled:
        timings["compile"] = lib.seconds
        log.warning("gearsym: %s compiled %s for its own CPU (%.1f s); its results may differ from the client's "
                    "in the last bits", _host(), shipped.name, lib.seconds)
    return lib.path


def _versions() -> tuple[str, str]:
    return __version__, ca.__version__


def _host() -> str:
    return f"worker {socket.gethostname()} (pid {os.getpid()})"
