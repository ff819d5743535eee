"""Code generation: SymPy model -> CasADi functions -> C -> shared library.

``translate`` (SymPy to SX) -> ``time_tables`` (split off periodic tables and
constants) -> ``functions`` (RK4 with exact variational equations, loops in
MX) -> ``generate`` (deterministic C and manifest) -> ``compiler`` (cached
shared libraries) -> ``compiled`` (the :class:`CompiledModel` the analyses use);
``verbs`` is how the analyses take either a compiled model or a system.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from .compiled import CompiledModel, RunInputs, TangentRun, TangentRuns
from .compiler import CompilerError, cache_dir
from .loops import LoopOptions
from .verbs import engine_verb

#: the code generator's own names, imported on first use (SymPy): a model whose library is cached never needs them
_GENERATOR = {"build_functions": "gearsym.codegen.functions", "code_hash": "gearsym.codegen.generate",
              "compile_model": "gearsym.codegen.build", "write_code": "gearsym.codegen.generate",
              "load_shipped": "gearsym.codegen.portable", "ship": "gearsym.codegen.portable"}

__all__ = ["CompiledModel", "CompilerError", "LoopOptions", "RunInputs", "TangentRun", "TangentRuns", "build_functions",
           "cache_dir", "code_hash", "compile_model", "engine_verb", "load_shipped", "ship", "write_code"]


def __getattr__(name: str):
    if name not in _GENERATOR:
        raise AttributeError(f"module 'gearsym.codegen' has no attribute {name!r}")
    value = getattr(importlib.import_module(_GENERATOR[name]), name)
    globals()[name] = value
    return value


if TYPE_CHECKING:
    from .build import compile_model
    from .functions import build_functions
    from .generate import code_hash, write_code
    from .portable import load_shipped, ship
