"""The low-level calling convention of every verb that runs the engine (split by type, as ChaosTools.jl does).

A verb is written once, for a :class:`CompiledModel` (the low-level call: nothing is built, only the
parameter vector changes, which is what a sweep wants). :func:`engine_verb` marks it: it says what the verb
takes and keeps the options a high-level call compiles with. The high-level call on a
:class:`~gearsym.system.FirstOrderSystem`, which compiles the system and calls the low-level verb on the
result, is made from it on the face (:mod:`gearsym.verbs`), above the code generator, so that running a
compiled model never loads the generator. Names and files of models are resolved before either
(``gearsym.load``).
"""
from __future__ import annotations

import functools
from collections.abc import Callable

from ..errors import GearsymError
from ..options import Integration
from .compiled import CompiledModel


def engine_verb(method=None, *, default: Integration | Callable[..., Integration] | None = None):
    """``method(compiled, ..., options=None, ...)`` as a verb on a CompiledModel; ``default`` is the options a
    high-level call compiles a system with when it gives none (the verb's own run length, e.g. a longer
    transient; or a function of the call's keywords that gives it)."""
    if method is None:
        return functools.partial(engine_verb, default=default)

    @functools.wraps(method)
    def verb(model, *args, **kwargs):
        if not isinstance(model, CompiledModel):
            kind = "a FirstOrderSystem" if hasattr(model, "rhs") else type(model).__name__
            hint = (f"; for {kind} call gearsym.{method.__name__}(...), which compiles it first"
                    if hasattr(model, "rhs") else
                    f"; resolve the name first: gearsym.{method.__name__}(gearsym.load({model!r}), ...)"
                    if isinstance(model, str) else "")
            raise GearsymError(f"{method.__module__}.{method.__name__} takes a compiled model, got {kind}{hint}")
        return method(model, *args, **kwargs)

    verb.default_options = default
    return verb
