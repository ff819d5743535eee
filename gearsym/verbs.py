"""The face's verbs that run the engine: each takes a compiled model or a system, which it compiles first.

The low-level verbs (:func:`~gearsym.codegen.verbs.engine_verb`, in the analysis, sweep, periodic and data
stages) take a :class:`~gearsym.codegen.compiled.CompiledModel`; here each gets its high-level call, split by
the argument's type (``functools.singledispatch``), as ChaosTools.jl builds a ``TangentDynamicalSystem`` and
calls the low-level method on it: a :class:`~gearsym.system.FirstOrderSystem` is compiled with the call's
options (else the verb's own default, else ``Integration()``).
"""
from __future__ import annotations

import functools
import importlib
from collections.abc import Mapping

from . import VERBS
from .codegen.build import compile_model
from .codegen.compiled import CompiledModel
from .errors import GearsymError
from .options import Execution, Integration
from .physical.answers import PhysicalScaling
from .physical.stability import chart_in_units
from .physical.sweeps import axes_with_units, nondimensional_axes
from .stability.chart import static_chart
from .stability.linearised import compile_linearisation
from .stability.verb import stability_chart as _stability_chart
from .sweep.run import run_sweep as _run_sweep
from .system import FirstOrderSystem
from .units import is_quantity


def high_level(verb):
    """``verb`` (a low-level verb on a CompiledModel) on a CompiledModel or a FirstOrderSystem."""

    @functools.singledispatch
    def call(model, *args, options: Integration | None = None, **kwargs):
        hint = (f"; resolve the name first: {verb.__name__}(gearsym.load({model!r}), ...)"
                if isinstance(model, str) else "")
        raise GearsymError(f"{verb.__name__} takes a compiled model or a FirstOrderSystem, got "
                           f"{type(model).__name__}{hint}")

    @call.register
    def _compiled(model: CompiledModel, *args, options: Integration | None = None, **kwargs):
        return verb(model, *args, options=options, **kwargs)

    @call.register
    def _system(model: FirstOrderSystem, *args, options: Integration | None = None, **kwargs):
        default = verb.default_options
        chosen = default(**kwargs) if callable(default) else default
        return verb(compile_model(model, options or chosen or Integration()), *args, **kwargs)

    return functools.update_wrapper(call, verb)


#: the face's verbs, made from the low-level verbs the face lists (gearsym.VERBS)
_made = {name: high_level(getattr(importlib.import_module(module), name)) for name, module in VERBS.items()}
globals().update(_made)
run_sweep = _made["run_sweep"]


def _numbers_only(engine):
    """``engine`` (run_sweep on a compiled model or a system), refusing a physical value on an axis with the call
    that sweeps it."""
    @functools.wraps(engine)
    def call(model, axes, *args, **kwargs):
        for name, values in (axes.items() if isinstance(axes, Mapping) else ()):
            value = next((v for v in values if is_quantity(v)), None)
            if value is not None:
                raise GearsymError(f"run_sweep: {name}={value!r} is a physical value, and {model.name} here takes the "
                                   f"engine's numbers: sweep the model's scaling, gearsym.run_sweep(gearsym.scaling("
                                   f"{model.name!r}), {{{name!r}: [{value!r}, ...]}}), which gives the engine its "
                                   "numbers and the result in these units")
        return engine(model, axes, *args, **kwargs)

    return call


for _kind in (CompiledModel, FirstOrderSystem):
    run_sweep.register(_kind)(_numbers_only(run_sweep.dispatch(_kind)))


@run_sweep.register
def _physical_sweep(model: PhysicalScaling, axes, *, options: Integration | None = None, **kwargs):
    """A sweep of a model with physical values (``gearsym.scaling(...)``): axes of physical values with their
    units (``{"speed": ["1000 rpm", "2000 rpm"]}``, pint Quantities, or ``"speed=1000rpm:3000rpm:500rpm"``) become
    the nondimensional parameters they move, other keywords that are physical values (``kZ="2e8 N/m"``) fix
    them, and the result comes back in physical units (along the values as given)."""
    engine_keywords = {"mode", "direction", "y0", "out", "overwrite", "poincare", "execution", "on_point"}
    physical = {k: v for k, v in kwargs.items() if k not in engine_keywords}
    at = model.with_values(**physical) if physical else model
    given = axes_with_units(axes)
    engine_axes = nondimensional_axes(at, given, "run_sweep")
    compiled = compile_model(at.system(), options or Integration())
    result = _run_sweep(compiled, engine_axes, options=options,
                        **{k: v for k, v in kwargs.items() if k in engine_keywords})
    return at.to_physical(result, given=given)
stability_chart = _made["stability_chart"]


@stability_chart.register
def _system_chart(model: FirstOrderSystem, grid, *, about: str = "static", options: Integration | None = None,
                  execution: Execution | None = None, **kwargs):
    """About the static state only the linearisation is compiled (the model's own loops are not needed)."""
    verbose = (execution or Execution()).verbose
    if about == "static":
        return static_chart(compile_linearisation(model, options, verbose=verbose), grid, execution=execution,
                            **kwargs)
    return _stability_chart(compile_model(model, options or Integration(), verbose=verbose), grid, about=about,
                            execution=execution, **kwargs)


@stability_chart.register
def _physical_chart(model: PhysicalScaling, grid, *, options: Integration | None = None, **kwargs):
    """A chart of a model with physical values (``gearsym.scaling(...)``): axes with units (``{"speed":
    ["1000 rpm", ...]}``) become the nondimensional parameters they move; the chart comes back along them."""
    given = axes_with_units(grid)
    engine_axes = nondimensional_axes(model, given, "stability_chart")
    chart = _system_chart(model.system(), engine_axes, options=options, **kwargs)
    return chart_in_units(chart, tuple(given), tuple(engine_axes))


__all__ = ["high_level", *VERBS]
