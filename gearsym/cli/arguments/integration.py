"""The options every integrating command shares, declared once: the command-line face of
:class:`~gearsym.options.Integration`, the command line's checks of a run's length and steps (:func:`check_run`:
their messages name the flags), and what a command asks of its MODEL (:func:`model_request`), read once
into a :class:`~gearsym.opening.ModelRequest` that :func:`~gearsym.opening.open_model` opens."""
from __future__ import annotations

import argparse
import re

from ...errors import GearsymError, warn
from ...opening import ModelRequest
from ...options import BACKENDS, INTEGRATORS, STEPS_PER_PERIOD, Integration
from .settings import model_settings


#: RK4 steps per forcing period: fewer than MIN do not resolve the forcing at all (refused); fewer than FEW
#: leave the paper's models' exponents and amplitudes off by a per cent or more (one_stage at 8 steps: 3 %)
MIN_STEPS_PER_PERIOD = 8
FEW_STEPS_PER_PERIOD = 20

#: measured periods (after the transient): the standard error comes from 10 batches of at least one period
#: each (refused below), and an exponent within 5/(measured time) of zero counts as zero (warned below FEW)
MIN_MEASURED_PERIODS = 10
FEW_MEASURED_PERIODS = 50


def check_run(*, steps_per_period: int | None = None, measured: int | None = None, discard: int | None = None,
              measured_is: str = "--periods minus --discard") -> None:
    """Refuse a run too coarse or too short to mean anything, and warn (one line) in the grey zone below
    the usual values; ``measured_is`` says how the measured periods came about, for the message."""
    if steps_per_period is not None:
        steps = steps_per_period  # (a whole number: argparse's, or the command's own choice)
        if steps < MIN_STEPS_PER_PERIOD:
            raise GearsymError(f"{steps} RK4 steps per forcing period (--steps-per-period) cannot resolve the "
                               f"forcing: give at least {MIN_STEPS_PER_PERIOD} (200 is the default)")
        if steps < FEW_STEPS_PER_PERIOD:
            warn(f"{steps} RK4 steps per forcing period are coarse: exponents and amplitudes may be off by a per "
                 f"cent or more ({FEW_STEPS_PER_PERIOD} or more are safer, 200 is the default)")
    if measured is not None:
        if measured < 1:
            raise GearsymError(f"no measured periods ({measured_is} is {measured}): need discard < periods")
        if measured < MIN_MEASURED_PERIODS:
            raise GearsymError(f"{measured} measured periods ({measured_is}) are too few: exponents need at least "
                               f"{MIN_MEASURED_PERIODS} for a standard error (the defaults measure 300)")
        if measured < FEW_MEASURED_PERIODS:
            warn(f"only {measured} measured periods ({measured_is}): an exponent within 5/(measured time) of zero "
                 f"counts as zero, so the regime is uncertain ({FEW_MEASURED_PERIODS} or more are safer)")
    if discard == 0:
        warn("no transient discarded (--discard 0): the exponents and amplitudes include the start")


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


def model_request(args: argparse.Namespace, options: Integration | None = None, *,
                  settings: dict | None = None) -> ModelRequest:
    """What the command asks of its MODEL, read once: the name or file, its --set and --teeth values (``settings``
    if the command read them already; a formula's numbers are checked when the model is built), the run's
    ``options`` (from :func:`integration_from`, or the command's own) and --quiet."""
    return ModelRequest(args.model, model_settings(args, cached=True) if settings is None else settings,
                        options or Integration(), verbose=not getattr(args, "quiet", False), given_as="--set")


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
