"""Code generation: SymPy model -> CasADi functions -> C -> shared library.

``translate`` (SymPy to SX) -> ``time_tables`` (split off periodic tables and
constants) -> ``functions`` (RK4 with exact variational equations, loops in
MX) -> ``generate`` (deterministic C and manifest) -> ``compiler`` (cached
shared libraries) -> ``compiled`` (the :class:`CompiledModel` the analyses use);
``verbs`` is how the analyses take either a compiled model or a system.
"""
from .build import compile_model
from .compiled import CompiledModel, RunInputs, TangentRun
from .compiler import CompilerError, cache_dir
from .functions import LoopOptions, build_functions
from .generate import code_hash, write_code
from .verbs import engine_verb

__all__ = ["CompiledModel", "CompilerError", "LoopOptions", "RunInputs", "TangentRun", "build_functions",
           "cache_dir", "code_hash", "compile_model", "engine_verb", "write_code"]
