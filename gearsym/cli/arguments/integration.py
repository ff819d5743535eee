"""The options every integrating command shares, declared once: the command-line face of
:class:`~gearsym.options.Integration`, and the one way a command turns MODEL and --set into a compiled model."""
from __future__ import annotations

import argparse
import itertools
import re
from collections.abc import Callable

import gearsym  # the face: its verbs load on first use, so a cached model's run never loads the generator

from ...cached import cached_scaling, load_compiled
from ...checks import check_run
from ...options import BACKENDS, INTEGRATORS, STEPS_PER_PERIOD, Integration
from .settings import checked_formulas, model_settings


def add_integration_arguments(parser: argparse.ArgumentParser, *, periods: int | None = 400, discard: int = 100,
                              steps_help: str = (f"steps per forcing period (a mesh period of the first mesh; default at "
                                                 f"least {STEPS_PER_PERIOD}, more if the fastest mode needs them)")) -> None:
    """--periods, --discard (with this command's run length; none for ``periods=None``, a command whose runs
    the data decide), --steps-per-period, --plain, --backend."""
    group = parser.add_argument_group("integration (the same for every command that integrates)")
    if periods is not None:
        group.add_argument("--periods", type=int, default=periods,
                           help=f"periods in all, the discarded ones included (default {periods}): forcing "
                                "periods, or for a model whose meshes repeat only together its common period (61 "
                                "mesh periods for a 23/61, 19/47 box: the run says which)")
        group.add_argument("--discard", type=int, default=discard,
                           help=f"transient periods left out of every result (default {discard})")
    group.add_argument("--steps-per-period", type=int, default=None, help=steps_help)
    group.add_argument("--plain", action="store_true",
                       help="the paper's plain RK4: do not split the steps where the backlash switches (by default "
                            "they are split, which keeps the exponents 4th order; see docs/engine.md)")
    group.add_argument("--locate-crossings", action="store_true", help=argparse.SUPPRESS)  # the default now
    group.add_argument("--backend", choices=BACKENDS, default="auto",
                       help="compiled C, CasADi in-process, or auto (compiled when a C compiler exists)")
    group.add_argument("--integrator", choices=INTEGRATORS, default="auto",
                       help="the step: explicit RK4, the stiff RODAS4 (linearly implicit, its W-matrix from the exact "
                            "Jacobian), or auto (default): chosen with the steps from the model's fastest linearised "
                            "mode, and said (docs/engine.md)")


def integration_from(args: argparse.Namespace, steps_per_period: int | None = None, *,
                     exponents: bool = True) -> Integration:
    """The command's options, checked before any work: ``steps_per_period`` if the command chose them (else
    --steps-per-period); a run too coarse, or (for ``exponents``) too short to mean anything, is refused, and
    one in the grey zone warned about."""
    steps = next((s for s in (steps_per_period, args.steps_per_period) if s is not None), STEPS_PER_PERIOD)
    run = {"periods": args.periods, "discard": args.discard} if hasattr(args, "periods") else {}
    if exponents and run:
        check_run(steps_per_period=steps, measured=args.periods - args.discard, discard=args.discard)
    else:
        check_run(steps_per_period=steps)
    return Integration(**run, steps_per_period=steps, locate_crossings=not args.plain, backend=args.backend,
                       integrator=getattr(args, "integrator", "auto"))


def chosen_over(args: argparse.Namespace, options: Integration, axes) -> Integration:
    """``options`` with the step chosen for every point of the engine's ``axes`` (name -> values: their ends
    decide; an integrator asked is kept): a sweep or a continuation compiles once, at the step its fastest point
    needs."""
    if options.integrator != "auto" or not axes:
        return options
    ends = [{name: float(v) for name, v in zip(axes, point)}
            for point in itertools.product(*[(min(v), max(v)) for v in axes.values()])]
    return gearsym.chosen_integration(options, system_from(args), ends)


def system_from(args: argparse.Namespace):
    """The system of the command's MODEL with its --set values (names and files are resolved here, at the edge)."""
    return gearsym.load(args.model, **model_settings(args))


def scaling_of(model, settings: dict):
    """The scaling of ``model`` with ``settings`` (--set values), or None for a model without physical values."""
    if not gearsym.is_physical(model, **settings):
        return None
    physical = dict(settings)
    length_scale = physical.pop("length_scale", None)
    return gearsym.scaling(model, length_scale, **physical)  # (a stiffness formula too: the mesh forces use it)


def scaling_from(args: argparse.Namespace):
    """The scaling of the command's MODEL and --set values (a cached one when the start-up cache has its numbers),
    or None for a model without physical values."""
    settings = model_settings(args, cached=True)
    return cached_scaling(args.model, settings, lambda: scaling_of(args.model, checked_formulas(settings)))


def compiled_from(args: argparse.Namespace, options: Integration | None = None, system=None,
                  before: Callable[[object], object] | None = None):
    """The compiled model of the command's MODEL with its --set values (or of ``system``); ``before(system)``:
    the command's checks of its request against the loaded system, made before it is compiled (seconds)."""
    settings = model_settings(args, cached=True)  # (a formula's numbers are checked if the model is built)
    options = options or integration_from(args)  # checked before the model is reduced (seconds)
    verbose = not getattr(args, "quiet", False)

    def checked_and_compiled(system):
        if before is not None:
            before(system)
        return gearsym.compile_model(system, options, verbose=verbose)

    if system is not None:
        return checked_and_compiled(system)
    return load_compiled(args.model, settings, options, verbose=verbose,
                         compile=lambda: checked_and_compiled(gearsym.load(args.model, **checked_formulas(settings))),
                         scaling=lambda: scaling_of(args.model, settings))


def step_line(compiled, scaling=None) -> str:
    """One line: the step the run takes and why (the choice from the fastest linearised mode), in seconds and Hz
    for a model with physical values."""
    integration = compiled.integration
    cycle = getattr(compiled.system, "cycle", 0.0) or compiled.system.cycle_at()  # (a cached model's: its summary's)
    steps = compiled.steps_per_cycle
    first = scaling.point_units().meshes[0].name if scaling is not None and scaling.point_units().meshes else None
    per = f"mesh period of {first!r}" if first else "forcing period"
    span = (f", {compiled.steps_per_period} per period of {compiled.cycles} of them" if compiled.cycles > 1 else "")
    why = integration.choice or "as asked"
    # the point of a sweep's range whose fastest mode chose the step (fastest_mode.chosen_integration), if not the
    # model's own: its step in seconds and its mode in Hz are at that point's speed
    at = re.search(r" at omega=(\S+?)(?=[:;)\s]|$)", why)
    if scaling is not None:
        units = scaling.point_units()
        omega = float(at[1]) if at else compiled.system.parameters.get("omega", 1.0)
        to_s = 1.0 / (omega * units.omega_n)  # seconds per unit of tau
        where = ""
        if at:  # (from the point units, which a cached model's stand-in scaling has too)
            where = f" at {float(units.speed_of(omega)):.4g} {units.speed_unit}"
            why = why.replace(at[0], where)
        h = f"h = {cycle / steps * to_s * 1e6:.4g} µs{where}"
    else:
        h = f"h = {cycle / steps:.4g}"
    if scaling is not None and "fastest linearised mode" in why:  # its rate in Hz too
        rate = float(why.split("fastest linearised mode ")[1].split(":")[0].split()[0])
        why = why.replace(f"fastest linearised mode {rate:.4g}",
                          f"fastest linearised mode {rate:.4g} per unit time = {rate / to_s / (2 * 3.141592653589793):.4g} Hz")
    return f"step: {integration.method_name}, {steps} per {per}{span}, {h}; {why}"
