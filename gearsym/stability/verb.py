"""The verb: a stability chart of a compiled model, about its static state or its period-1 orbit."""
from __future__ import annotations

from dataclasses import replace

from ..codegen.compiled import CompiledModel
from ..codegen.verbs import engine_verb
from ..errors import GearsymError
from ..options import Execution, Integration
from .chart import ABOUT, StabilityChart, orbit_chart, static_chart
from .linearised import compile_linearisation, static_recipe


@engine_verb
def stability_chart(model: CompiledModel, grid, *, about: str = "static", options: Integration | None = None,
                    refine: bool = True, tolerance=None, execution: Execution | None = None,
                    **values: float) -> StabilityChart:
    """The stability chart of ``model`` over ``grid`` (``{"omega": values, "k_a": values}``, or ``--param``
    strings): about its static state (default: the model linearised there, backlash at its static deflection)
    or about its period-1 orbit (``about="orbit"``: found by shooting from the static state). The other
    parameters at ``values`` (else the model's). ``tolerance``: the boundaries' (one number, or one per axis;
    default 1e-7 of each axis's range); ``refine=False``: boundaries at the midpoints of the grid lines;
    ``execution``: threads, the lanes (on by default), progress."""
    if about not in ABOUT:
        raise GearsymError(f"about={about!r}: linearise about 'static' (the static state) or 'orbit' (the "
                           "period-1 orbit)")
    system = getattr(model.system, "full", model.system)
    if about == "static":
        lin = compile_linearisation(system, options or model.integration,
                                    verbose=(execution or Execution()).verbose)
        defaults = dict(zip(model.parameter_names, model.parameter_vector(values).tolist()))
        lin = replace(lin, base_parameters=defaults)
        return static_chart(lin, grid, refine=refine, tolerance=tolerance, execution=execution)
    model.run_options(options)
    return orbit_chart(model, static_recipe(system), grid, refine=refine, tolerance=tolerance, execution=execution,
                       **values)
