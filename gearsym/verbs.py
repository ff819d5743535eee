"""The face's verbs that run the engine: each takes a compiled model or a system, which it compiles first.

The low-level verbs (:func:`~gearsym.codegen.verbs.engine_verb`, in the analysis, sweep, periodic and data
stages) take a :class:`~gearsym.codegen.compiled.CompiledModel`; here each gets its high-level call, split by
the argument's type (``functools.singledispatch``), as ChaosTools.jl builds a ``TangentDynamicalSystem`` and
calls the low-level method on it: a :class:`~gearsym.system.FirstOrderSystem` is compiled with the call's
options (else the verb's own default, else ``Integration()``).
"""
from __future__ import annotations

import functools

from .analysis.attractors import find_attractors as _find_attractors
from .analysis.lyapunov import lyapunov_spectrum as _lyapunov_spectrum
from .analysis.orbits import phase_trajectory as _phase_trajectory, poincare_samples as _poincare_samples
from .analysis.order_run import simulated_order_spectrum as _simulated_order_spectrum
from .codegen.build import compile_model
from .codegen.compiled import CompiledModel
from .data.simulate import simulate_measurements as _simulate_measurements
from .errors import GearsymError
from .options import Integration
from .periodic.branches import continue_orbits as _continue_orbits
from .periodic.orbit import periodic_orbit as _periodic_orbit
from .sweep.run import run_sweep as _run_sweep
from .system import FirstOrderSystem


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


lyapunov_spectrum = high_level(_lyapunov_spectrum)
poincare_samples = high_level(_poincare_samples)
phase_trajectory = high_level(_phase_trajectory)
find_attractors = high_level(_find_attractors)
run_sweep = high_level(_run_sweep)
periodic_orbit = high_level(_periodic_orbit)
continue_orbits = high_level(_continue_orbits)
simulate_measurements = high_level(_simulate_measurements)
simulated_order_spectrum = high_level(_simulated_order_spectrum)

__all__ = ["continue_orbits", "find_attractors", "high_level", "lyapunov_spectrum", "periodic_orbit",
           "phase_trajectory", "poincare_samples", "run_sweep", "simulate_measurements", "simulated_order_spectrum"]
