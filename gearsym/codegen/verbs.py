"""The calling convention of every verb that runs the engine, split by type (as ChaosTools.jl does).

A verb is written once, for a :class:`CompiledModel` (the low-level call: nothing is built, only the
parameter vector changes, which is what a sweep wants). :func:`engine_verb` adds the high-level call on a
:class:`FirstOrderSystem`, which compiles the system with the call's options and calls the low-level
method on the result. Names and files of models are resolved before this (``gearsym.load``): a string
gets an error saying so.
"""
from __future__ import annotations

import functools
import sys
from collections.abc import Callable

from ..errors import GearsymError
from ..options import Integration
from .build import compile_model
from .compiled import CompiledModel


def engine_verb(method=None, *, default: Integration | Callable[..., Integration] | None = None):
    """``method(compiled, ..., options=None, ...)`` as a verb on a CompiledModel or a FirstOrderSystem.

    On a compiled model, ``options=None`` means the options it was compiled with. A system is compiled with
    the call's options, else with ``default`` (the verb's own run length, e.g. a longer transient; or a function
    of the call's keywords that gives it), else with ``Integration()``.
    """
    if method is None:
        return functools.partial(engine_verb, default=default)

    @functools.singledispatch
    def verb(model, *args, options: Integration | None = None, **kwargs):
        if _is_system(model):
            chosen = default(**kwargs) if callable(default) else default
            return method(compile_model(model, options or chosen or Integration()), *args, **kwargs)
        hint = (f"; resolve the name first: {method.__name__}(gearsym.load({model!r}), ...)"
                if isinstance(model, str) else "")
        raise GearsymError(f"{method.__name__} takes a compiled model or a FirstOrderSystem, got "
                           f"{type(model).__name__}{hint}")

    verb.register(CompiledModel, method)
    return functools.update_wrapper(verb, method)


def _is_system(value) -> bool:
    """Whether ``value`` is a FirstOrderSystem, without importing gearsym.system (SymPy) to ask: if it is not
    imported, no system exists."""
    system = sys.modules.get("gearsym.system")
    return system is not None and isinstance(value, system.FirstOrderSystem)
