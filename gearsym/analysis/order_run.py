"""The order spectrum of a simulated run: the model's trajectory after its transient, one coordinate's samples
(every RK4 step, or a subsample), analysed in orders of the mesh with each gear's sidebands labelled
(:mod:`.orders`). The gears and their tooth counts are the system's (``Coupling.gears``: declared on ``Gear``, or
``--teeth``); a run over whole periods of a model with shaft-order terms covers whole revolutions."""
from __future__ import annotations

from ..codegen import CompiledModel, engine_verb
from ..errors import GearsymError
from ..options import Integration
from .poincare import phase_trajectory
from .orders import MESH_HARMONICS, SIDEBANDS, OrderSpectrum, order_spectrum

#: samples per mesh period kept for the spectrum (every RK4 step is more than the mesh harmonics need)
SAMPLES_PER_CYCLE = 50


def mesh_gears(system, coordinate: str | None = None) -> tuple[str, dict[str, int], float]:
    """(coordinate, gear -> teeth, mesh order) of the mesh on ``coordinate`` (default the first mesh whose gears
    have tooth counts)."""
    meshes = [c for c in getattr(system, "couplings", ()) if c.kind == "mesh" and not c.closes_loop]
    chosen = [c for c in meshes if coordinate in (None, c.coordinate)]
    for c in chosen:
        if c.gears and all(g.teeth for g in c.gears):
            return c.coordinate, {g.gear: g.teeth for g in c.gears}, float(c.order or 1)
    where = f"the mesh on {coordinate!r}" if coordinate else "no mesh"
    raise GearsymError(f"{system.name}: {where} has gears with tooth counts, which an order spectrum labels its "
                       "sidebands by: declare Gear(..., teeth=Z) or give --teeth Z1,Z2 (teeth=(Z1, Z2))")


@engine_verb
def simulated_order_spectrum(model: CompiledModel, *, options: Integration | None = None, coordinate: str | None = None,
                             y0=None, mesh_harmonics: int = MESH_HARMONICS, sidebands: int = SIDEBANDS,
                             **values: float) -> OrderSpectrum:
    """The order spectrum of ``coordinate`` (default the mesh deflection of the first geared mesh) over the
    ``periods - discard`` periods after the transient of a run of ``model``."""
    options = model.run_options(options)
    system = getattr(model.system, "full", model.system)
    name, gears, mesh_order = mesh_gears(system, coordinate)
    run = phase_trajectory(model, options=options, y0=y0, **values)
    stride = max(1, model.steps_per_cycle // SAMPLES_PER_CYCLE)
    tau, x = run.time[:-1:stride], run[name][:-1:stride]
    shown = ", ".join(f"{k}={v:g}" for k, v in zip(model.parameter_names, model.parameter_vector(values)))
    span = f"{options.measured * model.cycles} mesh periods after {options.discard * model.cycles}"
    return order_spectrum(tau, x, gears, mesh_order=mesh_order, channel=name, mesh_harmonics=mesh_harmonics,
                          sidebands=sidebands, title=f"{model.name}: {span}; {shown}")
