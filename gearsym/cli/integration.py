"""The options every integrating command shares, declared once: the command-line face of
:class:`~gearsym.options.Integration`, and the one way a command turns MODEL and --set into a compiled model."""
from __future__ import annotations

import argparse

import gearsym  # the face: its verbs load on first use, so a cached model's run never loads the generator

from ..cached import cached_scaling, load_compiled
from ..checks import check_run
from ..options import BACKENDS, STEPS_PER_PERIOD, Integration
from .settings import checked_formulas, model_settings


def add_integration_arguments(parser: argparse.ArgumentParser, *, periods: int | None = 400, discard: int = 100,
                              steps_help: str = f"RK4 steps per forcing period (default {STEPS_PER_PERIOD})") -> None:
    """--periods, --discard (with this command's run length; none for ``periods=None``, a command whose runs
    the data decide), --steps-per-period, --plain, --backend."""
    group = parser.add_argument_group("integration (the same for every command that integrates)")
    if periods is not None:
        group.add_argument("--periods", type=int, default=periods,
                           help=f"forcing periods in all, the discarded ones included (default {periods})")
        group.add_argument("--discard", type=int, default=discard,
                           help=f"transient periods left out of every result (default {discard})")
    group.add_argument("--steps-per-period", type=int, default=None, help=steps_help)
    group.add_argument("--plain", action="store_true",
                       help="the paper's plain RK4: do not split the steps where the backlash switches (by default "
                            "they are split, which keeps the exponents 4th order; see docs/engine.md)")
    group.add_argument("--locate-crossings", action="store_true", help=argparse.SUPPRESS)  # the default now
    group.add_argument("--backend", choices=BACKENDS, default="auto",
                       help="compiled C, CasADi in-process, or auto (compiled when a C compiler exists)")


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
    return Integration(**run, steps_per_period=steps, locate_crossings=not args.plain, backend=args.backend)


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


def compiled_from(args: argparse.Namespace, options: Integration | None = None, system=None):
    """The compiled model of the command's MODEL with its --set values (or of ``system``)."""
    options = options or integration_from(args)  # checked before the model is reduced (seconds)
    verbose = not getattr(args, "quiet", False)
    if system is not None:
        return gearsym.compile_model(system, options, verbose=verbose)
    settings = model_settings(args, cached=True)  # (a formula's numbers are checked if the model is built)
    return load_compiled(args.model, settings, options, verbose=verbose,
                         compile=lambda: gearsym.compile_model(gearsym.load(args.model, **checked_formulas(settings)),
                                                               options, verbose=verbose),
                         scaling=lambda: scaling_of(args.model, settings))
