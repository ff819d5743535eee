"""The order spectrum of a simulated run: the model's trajectory after its transient, one coordinate's samples
(every RK4 step, or a subsample), analysed in orders of the mesh with each gear's sidebands labelled
(:mod:`.orders`). The gears and their tooth counts are the system's (``Coupling.gears``: declared on ``Gear``, or
``--teeth``); a run over whole periods of a model with shaft-order terms covers whole revolutions."""
from __future__ import annotations

from ..codegen import CompiledModel, engine_verb
from ..errors import GearsymError
from ..options import Integration
from .poincare import phase_trajectory
from .orders import MESH_HARMONICS, SIDEBANDS, OrderSpectrum, order_lines, order_spectrum

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


def other_meshes(system, coordinate: str, mesh_order: float) -> dict[str, tuple[float, dict[str, int]]]:
    """The train's meshes other than the one on ``coordinate`` whose gears have tooth counts: name -> (its
    frequency in orders of that mesh, its gears and teeth)."""
    return {c.name: (float(c.order or 1) / mesh_order, {g.gear: g.teeth for g in c.gears})
            for c in getattr(system, "couplings", ()) if c.kind == "mesh" and c.coordinate != coordinate
            and c.gears and all(g.teeth for g in c.gears)}


def samples_per_cycle(highest: float) -> int:
    """Samples per mesh period that resolve orders up to ``highest`` (four per cycle of it, at least
    :data:`SAMPLES_PER_CYCLE`)."""
    return max(SAMPLES_PER_CYCLE, int(4 * highest) + 1)


@engine_verb
def simulated_order_spectrum(model: CompiledModel, *, options: Integration | None = None, coordinate: str | None = None,
                             y0=None, mesh_harmonics: int = MESH_HARMONICS, sidebands: int = SIDEBANDS,
                             scale: float = 1.0, unit: str = "", **values: float) -> OrderSpectrum:
    """The order spectrum of ``coordinate`` (default the mesh deflection of the first geared mesh) over the
    ``periods - discard`` periods after the transient of a run of ``model``, every mesh's lines labelled, sampled
    above the highest order labelled; the signal times ``scale`` in ``unit`` (a physical model's µm)."""
    options = model.run_options(options)
    system = getattr(model.system, "full", model.system)
    name, gears, mesh_order = mesh_gears(system, coordinate)
    meshes = other_meshes(system, name, mesh_order)
    highest = max(ln.order for ln in order_lines(gears, mesh_harmonics, sidebands, meshes))
    needed = samples_per_cycle(highest)
    if model.steps_per_cycle < needed:
        raise GearsymError(f"{model.name}: orders up to {highest:.4g} need {needed} samples per mesh period, more "
                           f"than the run's {model.steps_per_cycle} steps: give --steps-per-period {needed} (or "
                           "fewer --mesh-harmonics)")
    run = phase_trajectory(model, options=options, y0=y0, **values)
    stride = max(1, model.steps_per_cycle // needed)
    tau, x = run.time[:-1:stride], run[name][:-1:stride] * scale
    shown = ", ".join(f"{k}={v:g}" for k, v in zip(model.parameter_names, model.parameter_vector(values)))
    span = f"{options.measured * model.cycles} mesh periods after {options.discard * model.cycles}"
    return order_spectrum(tau, x, gears, mesh_order=mesh_order, channel=name, mesh_harmonics=mesh_harmonics,
                          sidebands=sidebands, title=f"{model.name}: {span}; {shown}", meshes=meshes, unit=unit)
